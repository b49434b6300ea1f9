//! The world scenes on FCL 0.7 through the `fcl_world` harness of
//! `crates/proxima-bench/peers/` (built by `scripts/peers.sh`; protocol in its
//! README): one process per scene and broad-phase update mode, reading the trace
//! file, printing `contacts P T` per `contacts` line and `# frame_us median M
//! mean X` (wall clock).

use std::path::{Path, PathBuf};
use std::process::Command;

/// The harness binary: `$PEERS_OUT/fcl_world`, else `target/peers/fcl_world` of
/// this workspace; `None` when it is not there.
pub fn harness() -> Option<PathBuf> {
    let dir = std::env::var_os("PEERS_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/peers"));
    let bin = dir.join("fcl_world");
    bin.is_file().then_some(bin)
}

/// One harness run.
#[derive(Clone, Debug, Default)]
pub struct FclRun {
    /// `(P, T)` per `contacts` line (`T` 0 with `--first`).
    pub answers: Vec<(usize, usize)>,
    /// Median and mean frame time, µs.
    pub median_us: f64,
    /// See `median_us`.
    pub mean_us: f64,
    /// `update all` or `update moved`: the broad-phase update of the run.
    pub update: String,
    /// `# lib` (library and version).
    pub lib: String,
}

/// Runs `bin` on `trace` with `--update update` (`all` or `moved`).
pub fn run(
    bin: &Path,
    trace: &Path,
    first: bool,
    reps: usize,
    update: &str,
) -> Result<FclRun, String> {
    let mut cmd = Command::new(bin);
    cmd.arg(trace)
        .args(["--reps", &reps.max(1).to_string(), "--update", update]);
    if first {
        cmd.arg("--first");
    }
    let o = cmd
        .output()
        .map_err(|e| format!("cannot run {}: {e}", bin.display()))?;
    let text = String::from_utf8_lossy(&o.stdout);
    if !o.status.success() {
        let err = String::from_utf8_lossy(&o.stderr);
        return Err(format!(
            "{} exits with {}: {}",
            bin.display(),
            o.status,
            err.lines().last().unwrap_or("")
        ));
    }
    parse(&text, update)
}

/// Reads the harness's output.
pub fn parse(text: &str, update: &str) -> Result<FclRun, String> {
    let mut r = FclRun {
        update: update.into(),
        ..FclRun::default()
    };
    let num = |s: Option<&str>| -> Result<f64, String> {
        s.and_then(|s| s.parse().ok())
            .ok_or_else(|| format!("fcl_world: unexpected output {text:.200}"))
    };
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["contacts", p] => r.answers.push((num(Some(p))? as usize, 0)),
            ["contacts", p, t] => r
                .answers
                .push((num(Some(p))? as usize, num(Some(t))? as usize)),
            ["#", "frame_us", "median", m, "mean", x] => {
                r.median_us = num(Some(m))?;
                r.mean_us = num(Some(x))?;
            }
            ["#", "lib", rest @ ..] => r.lib = rest.join(" "),
            _ => {}
        }
    }
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_answers_and_times() {
        let r = parse(
            "contacts 3 17\ncontacts 0 0\n# lib fcl 0.7.0\n# frame_us median 12.5 mean 13.0\n",
            "all",
        )
        .unwrap();
        assert_eq!(r.answers, [(3, 17), (0, 0)]);
        assert_eq!((r.median_us, r.mean_us), (12.5, 13.0));
        assert_eq!(r.lib, "fcl 0.7.0");
        let f = parse("contacts 2\n# frame_us median 1 mean 2\n", "moved").unwrap();
        assert_eq!(f.answers, [(2, 0)]);
        assert!(parse("contacts x\n", "all").is_err());
    }
}
