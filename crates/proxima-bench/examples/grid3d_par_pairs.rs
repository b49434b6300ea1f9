//! Pair finding of `UniformGrid3d` on W1, sequential and through `ParallelPairs`
//! on 1 and 2 threads (wall clock, medians per frame; counts checked equal).
//!
//! `cargo run --release -p proxima-bench --example grid3d_par_pairs -- [N] [FRAMES]`

use proxima::broad::{ParallelPairs, SpatialIndex, SpatialIndexExt, UniformGrid3d};
use proxima_harness::workloads::{Kind, Workload};
use std::ops::ControlFlow;
use std::time::{Duration, Instant};

fn median(mut v: Vec<Duration>) -> f64 {
    v.sort();
    v[v.len() / 2].as_secs_f64() * 1e3
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: usize = args
        .next()
        .map(|a| a.parse())
        .transpose()?
        .unwrap_or(100_000);
    let frames: usize = args.next().map(|a| a.parse()).transpose()?.unwrap_or(20);
    let mut w = Workload::new(Kind::W1, n, 1);
    let scene = w.scene();
    let mut g = UniformGrid3d::new(scene.world, scene.r_max)?;
    let handles: Vec<_> = w
        .spheres
        .iter()
        .enumerate()
        .map(|(i, s)| g.insert(*s, i as u32))
        .collect::<Result<_, _>>()?;
    let pools = [
        rayon::ThreadPoolBuilder::new().num_threads(1).build()?,
        rayon::ThreadPoolBuilder::new().num_threads(2).build()?,
    ];
    let (mut seq, mut par1, mut par2) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..frames {
        w.step();
        for (h, s) in handles.iter().zip(&w.spheres) {
            g.update(*h, *s)?;
        }
        let t = Instant::now();
        let mut count = 0u64;
        let _ = g.for_each_pair(|_, _, _, _| {
            count += 1;
            ControlFlow::Continue(())
        });
        seq.push(t.elapsed());
        for (pool, out) in pools.iter().zip([&mut par1, &mut par2]) {
            let t = Instant::now();
            let c = pool.install(|| g.par_count_pairs());
            out.push(t.elapsed());
            assert_eq!(c, count, "parallel count differs");
        }
    }
    println!(
        "UniformGrid3d W1 n={n} frames={frames} (wall ms, median): sequential {:.3}, par 1 thread {:.3}, par 2 threads {:.3}",
        median(seq),
        median(par1),
        median(par2)
    );
    Ok(())
}
