//! Helpers shared by the CLI tests: run the built `proxima` binary on a trace.

#![allow(dead_code)] // each test file uses a part

use std::path::PathBuf;
use std::process::Command;

/// The CLI's list of indices (the library's `IndexKind`s), so the tests always
/// cover every index.
#[allow(unused_imports)] // not every test file uses it
pub use proxima_harness::indices;

/// What a run of the binary gave.
pub struct Out {
    pub code: i32,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `proxima ARGS…`.
pub fn proxima(args: &[&str]) -> Out {
    let o = Command::new(env!("CARGO_BIN_EXE_proxima"))
        .args(args)
        .output()
        .expect("the binary runs");
    Out {
        code: o.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&o.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
    }
}

/// Writes `text` to a fresh file named after `name` in the test temp dir.
pub fn write_trace(name: &str, text: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let p = dir.join(format!("{name}-{}.trace", std::process::id()));
    std::fs::write(&p, text).expect("temp dir is writable");
    p
}

/// `proxima replay TRACE EXTRA…` on a trace given as text.
pub fn replay(name: &str, text: &str, extra: &[&str]) -> Out {
    let p = write_trace(name, text);
    let path = p.to_str().unwrap().to_string();
    let mut args = vec!["replay", path.as_str()];
    args.extend_from_slice(extra);
    let out = proxima(&args);
    let _ = std::fs::remove_file(&p);
    out
}
