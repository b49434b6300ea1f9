//! Bounded property tests: random operation sequences on every index against
//! `BruteForce` (decoded from bytes by the same runner as the fuzz target
//! `index_ops`), and regression inputs found by fuzzing.

mod runner;

use proptest::prelude::*;

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
