//! Octree k-nearest probe by leaf size: N radius-0 points uniform in a cube
//! of side `4·N^(1/3)` (W7's density), inserted in Morton order, M random
//! queries by surface distance, one `LinearOctree` per `max_per_leaf` given
//! (merge below half of it). Wall-clock medians of 5; small enough to run
//! under callgrind (`--toggle-collect` does not see the inlined search: read
//! `nearest_into`'s inclusive count).
//!
//! `cargo run --release -p proxima-bench --example knn_leaf -- N K M LEAF [LEAF ...]`
use proxima::broad::SpatialIndex;
use proxima::broad::{LinearOctree, Nearest, Neighbor, OctreeConfig, SceneHint};
use proxima::geom::Sphere;
use proxima::glam::Vec3;
use rand::{Rng, SeedableRng};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() < 4 {
        return Err("usage: knn_leaf N K M LEAF [LEAF ...]".into());
    }
    let n: usize = a[0].parse()?;
    let k: usize = a[1].parse()?;
    let m: usize = a[2].parse()?;
    let side = 4.0 * (n as f32).cbrt();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let mut r = || Vec3::new(rng.gen(), rng.gen(), rng.gen()) * side;
    let points: Vec<Vec3> = (0..n).map(|_| r()).collect();
    let queries: Vec<Vec3> = (0..m).map(|_| r()).collect();
    let hint = SceneHint::from_spheres(points.iter().map(|&c| Sphere::new(c, 0.0)), n);
    for leaf in a[3..].iter().map(|s| s.parse::<u32>()) {
        let leaf = leaf?;
        let mut cfg = OctreeConfig::for_scene(&hint);
        cfg.max_per_leaf = leaf;
        cfg.merge_below = leaf / 2;
        let mut t = LinearOctree::<u32>::with_config(cfg)?;
        for i in proxima::broad::morton_order(&points) {
            t.insert(Sphere::new(points[i as usize], 0.0), i)?;
        }
        let mut buf: Vec<Neighbor> = Vec::new();
        let mut times = Vec::new();
        for _ in 0..5 {
            let t0 = Instant::now();
            for &p in &queries {
                t.nearest_into(&Nearest::new(p, k), None, &mut buf)?;
            }
            times.push(t0.elapsed().as_secs_f64());
        }
        times.sort_by(f64::total_cmp);
        println!("leaf {leaf:3}: {:.3} us/query", times[2] / m as f64 * 1e6);
    }
    Ok(())
}
