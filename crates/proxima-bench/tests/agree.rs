//! Every benchmarked structure finds the same pairs as `BruteForce` on a tiny
//! version of every workload (a few frames). Light on purpose: runs in CI.

use proxima_bench::registry::entries;
use proxima_bench::run::{measure, Clock, PairLedger};
use proxima_harness::workloads::{Kind, Workload};

/// Pair count by the definition (exact closed test on every pair).
fn brute(w: &Workload) -> u64 {
    let s = &w.spheres;
    let mut n = 0;
    for i in 0..s.len() {
        for j in i + 1..s.len() {
            n += u64::from(s[i].intersects_sphere(&s[j]));
        }
    }
    n
}

#[test]
fn every_structure_counts_the_brute_force_pairs() {
    const FRAMES: usize = 6;
    for kind in Kind::ALL {
        // W2's box is fixed (1000 x 1000 x 10): it needs more spheres to have pairs.
        let n = if kind == Kind::W2 { 4000 } else { 400 };
        // The reference counts, frame by frame, straight from the workload.
        let mut ledger = PairLedger::new();
        let mut w = Workload::new(kind, n, 11);
        let mut total = 0;
        for _ in 0..FRAMES {
            w.step();
            let c = brute(&w);
            total += c;
            ledger.check(w.frame(), "definition", c);
        }
        assert!(total > 0, "{kind:?}: a test without pairs proves nothing");
        let all = entries();
        assert!(all.len() >= 2);
        for e in &all {
            // Panics on the first frame whose count differs.
            let m = measure(e, kind, n, 11, FRAMES, Clock::Wall, &mut ledger);
            assert_eq!(m.pair_total, total, "{} on {kind:?}", e.name);
            assert!(m.memory > 0);
        }
    }
}

#[test]
#[should_panic(expected = "PAIR COUNT MISMATCH")]
fn the_ledger_fails_loudly() {
    let mut l = PairLedger::new();
    l.check(3, "a", 10);
    l.check(3, "b", 11);
}
