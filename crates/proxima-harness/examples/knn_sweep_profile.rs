//! k nearest and sphere sweeps on a static set (issue #14's W7/W8 shapes,
//! until `proxima-bench` has them): W1's 100k spheres (or their centres as
//! radius-0 points), every index built from the scene's hint, then `q`
//! queries each. Prints, per index, the median of 5 timed passes in ns per
//! query and a checksum of the answers (equal across indices: they are
//! exact), so that ratios are read within one run; or, with `profile`, one
//! pass of one index for callgrind:
//!
//! `knn_sweep_profile knn points 100000 10000 10 [INDEX|all] [profile]`
//! `knn_sweep_profile sweep spheres 100000 10000 0 [INDEX|all] [profile]`

use proxima::broad::{IndexKind, Nearest, SpatialIndex};
use proxima::geom::{Sphere, SphereSweep};
use proxima_harness::workloads::{Kind, Workload};
use rand::{Rng, SeedableRng};
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let mode = a.first().map_or("knn", String::as_str).to_string();
    let points = a.get(1).map_or("points", String::as_str) == "points";
    let n: usize = a.get(2).map_or(100_000, |s| s.parse().expect("N"));
    let q: usize = a.get(3).map_or(10_000, |s| s.parse().expect("queries"));
    let k: usize = a.get(4).map_or(10, |s| s.parse().expect("k"));
    let which = a.get(5).map_or("all", String::as_str);
    let profile = a.get(6).is_some_and(|s| s == "profile");
    let w = Workload::new(Kind::W1, n, 1);
    let scene = w.scene();
    let world = scene.world;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let mut pt =
        || world.min + (world.max - world.min) * proxima::glam::Vec3::from(rng.gen::<[f32; 3]>());
    let knn: Vec<Nearest> = (0..q).map(|_| Nearest::new(pt(), k)).collect();
    let sweeps: Vec<SphereSweep> = (0..q)
        .map(|_| {
            let from = pt();
            let to = from + (pt() - from).normalize_or_zero() * 10.0;
            SphereSweep::new(from, to, 0.5)
        })
        .collect();
    for kind in IndexKind::ALL {
        if which != "all" && !kind.type_name().eq_ignore_ascii_case(which) {
            continue;
        }
        let mut index = kind.build(&scene.hint()).expect("index");
        for (i, s) in w.spheres.iter().enumerate() {
            let s = if points {
                Sphere::new(s.center, 0.0)
            } else {
                *s
            };
            index.insert(s, i as u32).expect("insert");
        }
        let mut out = Vec::new();
        let mut pass = || {
            let mut sum = 0u64;
            let t = Instant::now();
            if mode == "knn" {
                for query in &knn {
                    index.nearest_into(query, None, &mut out).expect("knn");
                    sum += out.iter().map(|n| n.handle.index() as u64).sum::<u64>();
                }
            } else {
                for sw in &sweeps {
                    if let Some(h) = index.sweep_first(sw, None).expect("sweep") {
                        sum += h.handle.index() as u64 + 1;
                    }
                }
            }
            (t.elapsed().as_nanos() as f64 / q as f64, sum)
        };
        if profile {
            let (ns, sum) = pass();
            println!("{} {mode} {ns:.0} ns/query sum {sum}", kind.type_name());
            continue;
        }
        let mut runs: Vec<(f64, u64)> = (0..5).map(|_| pass()).collect();
        runs.sort_by(|x, y| x.0.total_cmp(&y.0));
        println!(
            "{:16} {mode} {} n={n} k={k}: median {:.0} ns/query (min {:.0}) sum {}",
            kind.type_name(),
            if points { "points" } else { "spheres" },
            runs[2].0,
            runs[0].0,
            runs[2].1
        );
    }
}
