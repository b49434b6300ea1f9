//! Random operation sequences on every index against `BruteForce`, `validate()`
//! after each (the decoder and the checks are shared with the proptest suite).
#![no_main]

#[path = "../../crates/proxima/tests/ops/runner.rs"]
mod runner;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    runner::run(data);
});
