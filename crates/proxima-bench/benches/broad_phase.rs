//! Broad-phase frame time (update every object + find all pairs) on the standard
//! workloads, for every Proxima index and parry3d in the same run:
//! W1 at 10k and 100k, W2, W3 and W9 at 100k. Pair counts are checked equal across
//! structures on every frame (a mismatch panics).
//!
//! `cargo bench -p proxima-bench --bench broad_phase [-- FILTER]`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode};
use proxima_bench::registry::entries;
use proxima_bench::run::PairLedger;
use proxima_harness::workloads::{Kind, Workload};
use std::hint::black_box;
use std::time::Duration;

const SEED: u64 = 1;

fn workload_group(c: &mut Criterion, kind: Kind, n: usize) {
    let mut group = c.benchmark_group(format!("{}_{}k", kind.name(), n / 1000));
    // Few, long samples: one frame at 100k is tens of milliseconds, and the whole
    // bench must finish in a few minutes on a shared 2-core machine.
    group.sample_size(10);
    // Flat: every sample runs the same number of frames (frames are long).
    group.sampling_mode(SamplingMode::Flat);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(if n > 20_000 { 4 } else { 2 }));
    let mut ledger = PairLedger::new();
    for entry in entries().iter().filter(|e| e.runs_on(n)) {
        let mut w = Workload::new(kind, n, SEED);
        let mut s = entry.make(&w.scene());
        s.build(&w.spheres);
        group.bench_function(BenchmarkId::from_parameter(entry.label()), |b| {
            b.iter(|| {
                w.step();
                s.update(&w.spheres);
                let pairs = s.count_pairs();
                ledger.check(w.frame(), entry.name, pairs);
                black_box(pairs)
            })
        });
    }
    group.finish();
}

fn broad_phase(c: &mut Criterion) {
    workload_group(c, Kind::W1, 10_000);
    workload_group(c, Kind::W1, 100_000);
    workload_group(c, Kind::W2, 100_000);
    workload_group(c, Kind::W3, 100_000);
    workload_group(c, Kind::W9, 100_000);
}

criterion_group!(benches, broad_phase);
criterion_main!(benches);
