//! A frame loop for instruction-count profiles: one index (as `proxima-bench`
//! builds it, from the scene's hint) on one workload, build then `frames` frames of
//! `update_many` + `count_pairs`, nothing else timed or printed but the pair
//! total. Light on dependencies, so a release build is quick; the phases are the
//! inclusive costs of `AnyIndex::update_many` and `AnyIndex::count_pairs`:
//!
//! `valgrind --tool=callgrind target/release/examples/index_profile w1 100000 5 LooseKdTree`
//!
//! Timings belong to `proxima-bench`; this prints only what it counted.

use proxima::broad::{IndexKind, SpatialIndex};
use proxima_harness::workloads::{Kind, Workload};

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let kind = Kind::parse(a.first().map_or("w1", String::as_str)).expect("workload w1|w2|w3|w9");
    let n: usize = a.get(1).map_or(100_000, |s| s.parse().expect("N"));
    let frames: usize = a.get(2).map_or(5, |s| s.parse().expect("frames"));
    let name = a.get(3).map_or("LooseKdTree", String::as_str);
    let index_kind = IndexKind::ALL
        .into_iter()
        .find(|k| k.type_name().eq_ignore_ascii_case(name))
        .expect("an index type name (LooseKdTree, UniformGrid3d, ...)");
    let mut w = Workload::new(kind, n, 1);
    let mut index = index_kind
        .build(&w.scene().hint())
        .expect("index for the scene");
    let handles: Vec<_> = w
        .spheres
        .iter()
        .enumerate()
        .map(|(i, s)| index.insert(*s, i as u32).expect("insert"))
        .collect();
    let mut total = 0;
    for _ in 0..frames {
        w.step();
        index
            .update_many(handles.iter().copied().zip(w.spheres.iter().copied()))
            .expect("update");
        total += index.count_pairs();
    }
    println!(
        "{} {kind:?} n={n} frames={frames}: {total} pairs",
        index_kind.type_name()
    );
}
