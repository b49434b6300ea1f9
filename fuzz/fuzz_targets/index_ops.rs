//! Random operation sequences on every index against `BruteForce`, `validate()`
//! after each (the decoder and the checks, `proxima_harness::ops`, are shared
//! with the proptest suite).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    proxima_harness::ops::run(data);
});
