//! Bounded property tests: random operation sequences on every index against
//! `BruteForce` (decoded from bytes by the same runner as the fuzz target
//! `index_ops`, `proxima_harness::ops`), and regression inputs found by fuzzing.

use proptest::prelude::*;
use proxima_harness::ops as runner;

proptest! {
    // Modest case count: CI stays fast; the fuzz target runs the long searches.
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn op_sequences_match_brute_force(data in proptest::collection::vec(any::<u8>(), 0..1200)) {
        runner::run(&data);
    }
}

/// Runs the bytes of the file named by `OPS_INPUT` (a fuzz artifact), if set.
#[test]
fn replay_ops_input_file() {
    if let Some(p) = std::env::var_os("OPS_INPUT") {
        runner::run(&std::fs::read(p).unwrap());
    }
}

/// Every `index_ops` input in `fuzz/found/` that found a bug runs clean now (the
/// regression test of each fuzz finding; the hash grid's empty-strip-range hang
/// has no other).
#[test]
fn fuzz_found_inputs_pass() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fuzz/found");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with("index_ops-") {
            runner::run(&std::fs::read(&p).unwrap());
            n += 1;
        }
    }
    assert!(n >= 3, "found inputs are missing");
}
