//! The loose k-d tree's shape and its update and pair-search times (wall
//! clock, medians per frame) on a moving workload, for each density given: a
//! tuning probe, and a small program to run under callgrind.
//!
//! `cargo run --release -p proxima-bench --example lkd_probe -- w1|w2|w3|w9 N FRAMES DENSITY...`
use proxima::broad::{LooseKdConfig, LooseKdTree, SpatialIndex, SpatialIndexExt};
use proxima_harness::workloads::{Kind, Workload};
use std::ops::ControlFlow;
use std::time::{Duration, Instant};

fn median(mut v: Vec<Duration>) -> f64 {
    v.sort();
    v[v.len() / 2].as_secs_f64() * 1e3
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 4 {
        return Err("usage: lkd_probe w1|w2|w3|w9 N FRAMES DENSITY...".into());
    }
    let kind = Kind::parse(&args[0]).ok_or("unknown workload")?;
    let n: usize = args[1].parse()?;
    let frames: usize = args[2].parse()?;
    for d in &args[3..] {
        let d: f32 = d.parse()?;
        let mut w = Workload::new(kind, n, 1);
        let scene = w.scene();
        let mut cfg = LooseKdConfig::for_scene(&scene.hint());
        cfg.density = d;
        let mut t = LooseKdTree::with_config(cfg)?;
        let handles: Vec<_> = w
            .spheres
            .iter()
            .enumerate()
            .map(|(i, s)| t.insert(*s, i as u32))
            .collect::<Result<_, _>>()?;
        let (mut up, mut pr) = (Vec::new(), Vec::new());
        let mut count = 0u64;
        for _ in 0..frames {
            w.step();
            let t0 = Instant::now();
            for (h, s) in handles.iter().zip(&w.spheres) {
                t.update(*h, *s)?;
            }
            up.push(t0.elapsed());
            let t0 = Instant::now();
            count = 0;
            let _ = t.for_each_pair(|_, _, _, _| {
                count += 1;
                ControlFlow::Continue(())
            });
            pr.push(t0.elapsed());
        }

        let s = t.stats();
        println!(
            "{} n={n} d={d}: update {:.2} ms pairs {:.2} ms ({count} pairs); nodes {} leaves {} depth {} max/node {} per depth {:?}",
            args[0], median(up), median(pr), s.nodes, s.leaves, s.max_depth, s.max_items_per_node, s.items_per_depth
        );
    }
    Ok(())
}
