//! k-nearest probe: 100k-style point clouds (radius 0, uniform in a unit
//! cube, metric "center", the radius hint the Python binding gives point
//! clouds), queries one by one in random order and in Morton order
//! ([`proxima::broad::morton_order`], what `Index.nearest` does with a
//! batch). Points are inserted in their order, or in Morton order with a
//! 7th argument `morton`. Wall-clock medians, and a small program to run under callgrind.
//!
//! `cargo run --release -p proxima-bench --example knn_probe -- KIND N K [REPS [QUERIES [random|sorted|both [morton]]]]`
use proxima::broad::SpatialIndex;
use proxima::broad::{morton_order, IndexKind, Metric, Nearest, Neighbor, SceneHint};
use proxima::geom::Sphere;
use proxima::glam::Vec3;
use std::time::Instant;

/// A deterministic stream in `[0, 1)` (xorshift).
fn rng(mut s: u64) -> impl FnMut() -> f32 {
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() < 3 {
        return Err(
            "usage: knn_probe KIND N K [REPS [QUERIES [random|sorted|both [morton]]]]".into(),
        );
    }
    let kind: IndexKind = a[0].parse()?;
    let n: usize = a[1].parse()?;
    let k: usize = a[2].parse()?;
    let reps: usize = a.get(3).map_or(Ok(3), |s| s.parse())?;
    let m: usize = a.get(4).map_or(Ok(n), |s| s.parse())?;
    let only = a
        .get(5)
        .cloned()
        .filter(|s| s != "both")
        .unwrap_or_default();
    let mut r = rng(7);
    let points: Vec<Vec3> = (0..n).map(|_| Vec3::new(r(), r(), r())).collect();
    let queries: Vec<Vec3> = (0..m).map(|_| Vec3::new(r(), r(), r())).collect();
    let mut hint = SceneHint::from_spheres(points.iter().map(|&c| Sphere::new(c, 0.0)), n);
    hint.r_max = 0.5 * (1.0 / n as f32).cbrt();
    hint.r_largest = hint.r_largest.max(hint.r_max);
    let mut index = kind.build::<u32>(&hint)?;
    let insert_order: Vec<u32> = if a.get(6).is_some_and(|s| s == "morton") {
        morton_order(&points)
    } else {
        (0..n as u32).collect()
    };
    for i in insert_order {
        index.insert(Sphere::new(points[i as usize], 0.0), i)?;
    }
    let sorted: Vec<Vec3> = morton_order(&queries)
        .into_iter()
        .map(|i| queries[i as usize])
        .collect();
    let mut buf: Vec<Neighbor> = Vec::new();
    for (name, qs) in [("random", &queries), ("sorted", &sorted)] {
        if !only.is_empty() && only != name {
            continue;
        }
        let mut times = Vec::new();
        let mut sum = 0f64;
        for _ in 0..reps {
            let t0 = Instant::now();
            sum = 0.0;
            for &p in qs.iter() {
                let q = Nearest::new(p, k).metric(Metric::Center);
                index.nearest_into(&q, None, &mut buf)?;
                sum += buf.iter().map(|x| x.distance as f64).sum::<f64>();
            }
            times.push(t0.elapsed().as_secs_f64());
        }
        times.sort_by(f64::total_cmp);
        let us = times[reps / 2] / m as f64 * 1e6;
        println!("{kind:?} n={n} k={k} {name:<7} {us:8.3} us/query (distance sum {sum:.6})");
    }
    Ok(())
}
