//! W5 mesh vs mesh [sources: w5]: rob.obj vs env.obj at 1,000 random poses (FCL's
//! distribution: translations in [-3000,3000]²×[0,3000], uniformly random
//! rotations), all pairs and first contact, for every BV type; and SKINbody vs
//! BONERibcage at a few poses. Criterion reports the time of the whole batch; the
//! per-query figure and the mean counters are printed on stderr.
//!
//! `cargo bench -p proxima --bench mesh_collision`

use criterion::{criterion_group, criterion_main, Criterion};
use proxima::geom::{Aabb, Sphere};
use proxima::glam::{Affine3A, Quat, Vec3};
use proxima::narrow::{
    BoundingVolume, BuildOptions, Collider, CostCounters, Kdop14, Kdop18, Kdop26, Mesh, Obb,
    RotationUpdate, SplitRule, TriMesh,
};
use rand::{Rng, SeedableRng};
use std::hint::black_box;
use std::time::{Duration, Instant};

fn data(name: &str) -> TriMesh {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/");
    proxima::io::load(format!("{path}{name}")).expect("mesh")
}

fn poses(n: usize, lo: Vec3, hi: Vec3, seed: u64) -> Vec<Affine3A> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let (u1, u2, u3): (f32, f32, f32) = (rng.gen(), rng.gen(), rng.gen());
            let tau = std::f32::consts::TAU;
            let q = Quat::from_xyzw(
                (1.0 - u1).sqrt() * (tau * u2).sin(),
                (1.0 - u1).sqrt() * (tau * u2).cos(),
                u1.sqrt() * (tau * u3).sin(),
                u1.sqrt() * (tau * u3).cos(),
            )
            .normalize();
            let t = Vec3::new(
                rng.gen_range(lo.x..=hi.x),
                rng.gen_range(lo.y..=hi.y),
                rng.gen_range(lo.z..=hi.z),
            );
            Affine3A::from_rotation_translation(q, t)
        })
        .collect()
}

struct Case<'a> {
    name: &'static str,
    a: &'a TriMesh,
    b: &'a TriMesh,
    poses: &'a [Affine3A],
}

fn run_all<BV: BoundingVolume>(
    c: &mut Criterion,
    case: &Case,
    build: BuildOptions,
    rotation: RotationUpdate,
    tag: &str,
) {
    let ma = Mesh::<BV>::from_trimesh(case.a.clone(), build).unwrap();
    let mb = Mesh::<BV>::from_trimesh(case.b.clone(), build).unwrap();
    let mut col = Collider::<BV>::new(rotation);
    for first in [false, true] {
        // Counters and a quick timing for the summary line.
        let mut sum = CostCounters::default();
        let mut pairs = 0usize;
        let start = Instant::now();
        for p in case.poses {
            let k = if first {
                let f = col.first_contact(&ma, p, &mb).unwrap();
                pairs += f.pair.is_some() as usize;
                f.counters
            } else {
                let r = col.all_pairs(&ma, p, &mb).unwrap();
                pairs += r.pairs.len();
                r.counters
            };
            sum.nv += k.nv;
            sum.np += k.np;
            sum.nu += k.nu;
        }
        let us = start.elapsed().as_secs_f64() * 1e6 / case.poses.len() as f64;
        let n = case.poses.len() as f64;
        let mode = if first { "first" } else { "all" };
        eprintln!(
            "{:<10} {:<7} {:<5} {tag:<16} {us:>9.2} us/query  nv {:>8.1} np {:>8.1} nu {:>7.1}  {} {pairs}",
            case.name,
            BV::NAME,
            mode,
            sum.nv as f64 / n,
            sum.np as f64 / n,
            sum.nu as f64 / n,
            if first { "hits" } else { "pairs" },
        );
        c.bench_function(&format!("{}/{}/{mode}/{tag}", case.name, BV::NAME), |bch| {
            bch.iter(|| {
                for p in case.poses {
                    if first {
                        black_box(col.first_contact(&ma, p, &mb).unwrap());
                    } else {
                        black_box(col.all_pairs(&ma, p, &mb).unwrap());
                    }
                }
            })
        });
    }
}

fn every_bv(c: &mut Criterion, case: &Case, build: BuildOptions, tag: &str) {
    let r = RotationUpdate::Refit;
    run_all::<Aabb>(c, case, build, r, tag);
    run_all::<Kdop14>(c, case, build, r, tag);
    run_all::<Kdop18>(c, case, build, r, tag);
    run_all::<Kdop26>(c, case, build, r, tag);
    run_all::<Obb>(c, case, build, r, tag);
    run_all::<Sphere>(c, case, build, r, tag);
}

fn bench(c: &mut Criterion) {
    let rob = data("rob.obj");
    let env = data("env.obj");
    let p = poses(
        1000,
        Vec3::new(-3000.0, -3000.0, 0.0),
        Vec3::new(3000.0, 3000.0, 3000.0),
        1,
    );
    let case = Case {
        name: "rob-env",
        a: &rob,
        b: &env,
        poses: &p,
    };
    let median = BuildOptions {
        split: SplitRule::Median,
        leaf_size: 1,
    };
    every_bv(c, &case, median, "median");
    let sah = BuildOptions {
        split: SplitRule::Sah,
        leaf_size: 1,
    };
    every_bv(c, &case, sah, "sah");
    run_all::<Kdop18>(
        c,
        &case,
        sah,
        RotationUpdate::Conservative,
        "sah-conservative",
    );
    run_all::<Kdop18>(c, &case, sah, RotationUpdate::Auto, "sah-auto");

    let skin = data("SKINbody.stl");
    let ribs = data("BONERibcage.stl");
    // Small offsets around the rest pose: the rib cage sits inside the body.
    let p = poses(8, Vec3::splat(-0.02), Vec3::splat(0.02), 2);
    let case = Case {
        name: "skin-ribs",
        a: &skin,
        b: &ribs,
        poses: &p,
    };
    run_all::<Kdop18>(c, &case, sah, RotationUpdate::Refit, "sah-refit");
    run_all::<Kdop18>(c, &case, sah, RotationUpdate::Auto, "sah-auto");
    run_all::<Obb>(c, &case, sah, RotationUpdate::Auto, "sah");
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    targets = bench
}
criterion_main!(benches);
