//! Rough timing of the linear octree on workload W1 [sources: w1]: N spheres with
//! radii in [0.5, 2] in a cube of side 4·N^(1/3), each moving a small random step
//! per frame and bouncing off the walls; a frame = update all + find all pairs.
//! Also compares the pair traversal with one sphere query per object.
//!
//! `cargo run --release -p proxima --example octree_w1 -- [N] [frames] [max_per_leaf] [flat]`
//! (criterion benches against peers live in the bench crate; this is a quick look.)

use proxima::broad::{LinearOctree, OctreeConfig, SpatialIndex, SpatialIndexExt};
use proxima::geom::{Aabb, Sphere};
use proxima::glam::{vec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::ops::ControlFlow;
use std::time::Instant;

/// Seconds this thread has run on a CPU (from /proc, so a loaded machine does not
/// inflate the figures); wall-clock time where /proc is unavailable.
fn cpu_seconds(start: &Instant) -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map(|ns| ns * 1e-9)
        .unwrap_or_else(|| start.elapsed().as_secs_f64())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let frames: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(10);
    let mpl: u32 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(32);
    // W1 by default; `flat` gives W2 (1000 x 1000 x 10).
    let flat = args.get(4).is_some_and(|s| s == "flat");
    let hi = if flat {
        vec3(1000.0, 1000.0, 10.0)
    } else {
        Vec3::splat(4.0 * (n as f32).cbrt())
    };
    let world = Aabb::new(Vec3::ZERO, hi);
    let mut rng = Pcg64::seed_from_u64(1);
    let cfg = OctreeConfig {
        max_per_leaf: mpl,
        merge_below: mpl / 2,
        ..OctreeConfig::new(world)
    };
    let mut t = LinearOctree::with_config(cfg).unwrap();
    let mut objs: Vec<(Sphere, Vec3)> = (0..n)
        .map(|_| {
            let c = vec3(
                rng.gen_range(0.0..hi.x),
                rng.gen_range(0.0..hi.y),
                rng.gen_range(0.0..hi.z),
            );
            let v = vec3(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            ) * 0.1;
            (Sphere::new(c, rng.gen_range(0.5..2.0)), v)
        })
        .collect();
    let clock = Instant::now();
    let now = || cpu_seconds(&clock);
    let t0 = now();
    let hs: Vec<_> = objs
        .iter()
        .map(|(s, _)| t.insert(*s, ()).unwrap())
        .collect();
    println!(
        "N = {n}, max_per_leaf = {mpl}: build {:.1} ms (CPU time)",
        (now() - t0) * 1e3
    );
    let (mut upd, mut prs, mut npairs) = (0.0, 0.0, 0);
    for _ in 0..frames {
        let t0 = now();
        for (h, (s, v)) in hs.iter().zip(objs.iter_mut()) {
            let mut c = s.center + *v;
            for a in 0..3 {
                if c[a] < 0.0 || c[a] > hi[a] {
                    v[a] = -v[a];
                    c[a] = c[a].clamp(0.0, hi[a]);
                }
            }
            s.center = c;
            t.update(*h, *s).unwrap();
        }
        let t1 = now();
        npairs = 0;
        let _ = t.for_each_pair(|_, _, _, _| {
            npairs += 1;
            ControlFlow::Continue(())
        });
        let t2 = now();
        upd += t1 - t0;
        prs += t2 - t1;
    }
    let f = frames as f64;
    println!(
        "per frame: update {:.2} ms, pairs {:.2} ms ({npairs} pairs), total {:.2} ms",
        upd / f * 1e3,
        prs / f * 1e3,
        (upd + prs) / f * 1e3
    );
    let t0 = now();
    let mut q = 0usize;
    for (h, (s, _)) in hs.iter().zip(&objs) {
        let _ = t.for_each_in(*s, |o, _, _| {
            if o > *h {
                q += 1;
            }
            ControlFlow::Continue(())
        });
    }
    println!(
        "pairs by one sphere query per object: {:.2} ms ({q} pairs)",
        (now() - t0) * 1e3
    );
    println!("{:?}", t.stats());
    println!("memory {:.1} MB", t.memory_bytes() as f64 / 1e6);
}
