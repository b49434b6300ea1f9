//! `proxima world` on arbitrary bytes: the world-trace parser must return a
//! trace or a one-line error; every index (k-DOP18) and every bounding volume
//! (default index) must then run the trace with the same answers as the
//! brute-force world, in all-pairs and first-contact mode, or reject a pose the
//! parser let through with a typed error. Mesh files are not read: `mesh NAME
//! FILE` takes FILE from a few built-in meshes (`tri`, `tet`, `cube`, `quad`),
//! so the fuzzer spends its time on poses and queries. The parser, the engine
//! and the brute-force world are the CLI's, from `proxima_harness`.
#![no_main]

use proxima::broad::IndexKind;
use proxima::glam::Vec3;
use proxima::narrow::TriMesh;
use proxima::world::WorldConfig;
use proxima_harness::{world_replay, world_trace};

/// The built-in meshes by file name.
fn load(file: &str) -> Result<TriMesh, String> {
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let (vertices, triangles) = match file {
        "tri" => (
            vec![v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.)],
            vec![[0, 1, 2]],
        ),
        "quad" => (
            vec![
                v(-1., -1., 0.),
                v(1., -1., 0.),
                v(1., 1., 0.),
                v(-1., 1., 0.),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        ),
        "tet" => (
            vec![v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.), v(0., 0., 1.)],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        ),
        "cube" => {
            let c = (0..8)
                .map(|i| {
                    v(
                        (i & 1) as f32 - 0.5,
                        ((i >> 1) & 1) as f32 - 0.5,
                        (i >> 2) as f32 - 0.5,
                    )
                })
                .collect();
            let t = vec![
                [0, 2, 3],
                [0, 3, 1],
                [4, 5, 7],
                [4, 7, 6],
                [0, 1, 5],
                [0, 5, 4],
                [2, 6, 7],
                [2, 7, 3],
                [0, 4, 6],
                [0, 6, 2],
                [1, 3, 7],
                [1, 7, 5],
            ];
            (c, t)
        }
        other => return Err(format!("no built-in mesh '{other}'")),
    };
    TriMesh::new(vertices, triangles).map_err(|e| e.to_string())
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let Ok(trace) = world_trace::WorldTrace::parse_with(data, load) else {
        return;
    };
    // Keep each input cheap: the brute-force world is quadratic.
    if trace.ops.len() > 400 || trace.max_live > 40 {
        return;
    }
    for first in [false, true] {
        let oracle = world_replay::run_oracle(&trace, first);
        let mut runs = Vec::new();
        for kind in IndexKind::ALL {
            let config = WorldConfig {
                index: Some(kind),
                ..WorldConfig::default()
            };
            runs.push((
                kind.name(),
                world_replay::run_bv("kdop18", &trace, config, first),
            ));
        }
        for bv in world_replay::BVS {
            runs.push((
                bv,
                world_replay::run_bv(bv, &trace, WorldConfig::default(), first),
            ));
        }
        // A pose beyond the world's coordinate limit is an error, not an
        // answer: then every run must reject the same operation.
        let rejected: Vec<Option<usize>> = runs
            .iter()
            .map(|(_, r)| r.as_ref().err().map(|e| e.0))
            .collect();
        assert!(
            rejected.iter().all(|r| *r == rejected[0]),
            "the runs reject different operations: {rejected:?}"
        );
        for (name, run) in runs {
            let Ok(run) = run else { continue };
            if let Some(i) = world_replay::first_difference(&oracle.answers, &run.answers) {
                panic!(
                    "{name} (first: {first}) disagrees with the brute-force world at query {i}: {:?} vs {:?}",
                    run.answers.get(i),
                    oracle.answers.get(i)
                );
            }
        }
    }
});
