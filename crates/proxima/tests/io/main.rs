//! Mesh loader tests: the shared data meshes load with their documented counts;
//! round trips through every format; malformed input gives `Error::Parse` that
//! names the line or byte offset.

mod data;
mod malformed;
mod roundtrip;

use proxima::{Error, FileLocation};

/// Asserts a parse error at `at` whose message contains `needle`.
pub fn assert_parse_error<T: std::fmt::Debug>(
    r: proxima::Result<T>,
    at: FileLocation,
    needle: &str,
) {
    match r {
        Err(Error::Parse { at: got, msg, .. }) => {
            assert_eq!(got, at, "wrong location for '{msg}'");
            assert!(msg.contains(needle), "'{msg}' does not mention '{needle}'");
        }
        other => panic!("expected a parse error at {at:?} ('{needle}'), got {other:?}"),
    }
}
