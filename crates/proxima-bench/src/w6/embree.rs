//! W6 peer: Embree 3.13 through the C++ harness `w6_rays` (built by
//! `scripts/peers.sh`; `crates/proxima-bench/peers/README.md` says how it drives
//! Embree). The bench writes its rays in the harness's binary format, runs it on
//! the same mesh file, and reads back its answers (from `rtcIntersect1`), its
//! build time and, per mode (one ray per call, packets, streams), its time per
//! ray on one thread and on K threads. The fastest mode of the run is the
//! denominator.

use super::caster::Answer;
use proxima::geom::Ray;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// The harness binary: `$PEERS_OUT/w6_rays`, else `target/peers/w6_rays` of this
/// workspace; `None` when it was not built (CI never builds it).
pub fn find() -> Option<PathBuf> {
    let dir = std::env::var_os("PEERS_OUT").map_or_else(
        || PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../target/peers")),
        PathBuf::from,
    );
    let bin = dir.join("w6_rays");
    bin.is_file().then_some(bin)
}

/// The rays in the harness's binary format: `PXRAYS01`, a little-endian `u64`
/// count, then 7 little-endian `f32` per ray (origin, direction, `max_t`).
pub fn encode(rays: &[Ray]) -> Vec<u8> {
    let mut b = Vec::with_capacity(16 + 28 * rays.len());
    b.extend_from_slice(b"PXRAYS01");
    b.extend_from_slice(&(rays.len() as u64).to_le_bytes());
    for r in rays {
        let o = r.origin.to_array();
        let d = r.dir.to_array();
        for x in o.iter().chain(&d).chain(std::iter::once(&r.max_t)) {
            b.extend_from_slice(&x.to_le_bytes());
        }
    }
    b
}

/// One mode's time per ray.
#[derive(Clone, Debug)]
pub struct Mode {
    /// `single`, `packet16` (or 8/4), `stream`.
    pub name: String,
    /// On one thread.
    pub one: Duration,
    /// On `threads` threads (wall time).
    pub many: Duration,
}

/// What one harness run reported.
#[derive(Clone, Debug)]
pub struct EmbreeRun {
    /// `embree 3.13.5`.
    pub lib: String,
    /// Closest hit of each ray (`rtcIntersect1`).
    pub answers: Vec<Answer>,
    /// Wall time of `rtcCommitScene` (Embree's own threads).
    pub build: Duration,
    /// Every mode measured.
    pub modes: Vec<Mode>,
    /// The K of the K-thread column.
    pub threads: usize,
}

impl EmbreeRun {
    /// The fastest mode on one thread.
    pub fn best_one(&self) -> Option<&Mode> {
        self.modes.iter().min_by_key(|m| m.one)
    }

    /// The fastest mode on K threads.
    pub fn best_many(&self) -> Option<&Mode> {
        self.modes.iter().min_by_key(|m| m.many)
    }
}

fn ns(s: &str) -> Result<Duration, String> {
    time(s, 1e-9)
}

/// A time of `unit` seconds, parsed as a float (scaling a rounded nanosecond
/// `Duration` up would lose the fraction: `2.5` ms must not become 3 ms).
fn time(s: &str, unit: f64) -> Result<Duration, String> {
    let x: f64 = s.parse().map_err(|_| format!("w6_rays: bad time {s:?}"))?;
    Ok(Duration::from_secs_f64(x.max(0.0) * unit))
}

/// Parses the harness's output for `n` rays.
pub fn parse(out: &str, n: usize) -> Result<EmbreeRun, String> {
    let mut run = EmbreeRun {
        lib: String::new(),
        answers: Vec::with_capacity(n),
        build: Duration::ZERO,
        modes: Vec::new(),
        threads: 1,
    };
    let mut mismatches = None;
    for line in out.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["hit", "-"] => run.answers.push(None),
            ["hit", tri, t] => {
                let tri = tri.parse().map_err(|_| format!("w6_rays: {line:?}"))?;
                let t = t.parse().map_err(|_| format!("w6_rays: {line:?}"))?;
                run.answers.push(Some((tri, t)));
            }
            ["#", "lib", rest @ ..] => run.lib = rest.join(" "),
            ["#", "build_ms", ms, ..] => run.build = time(ms, 1e-3)?,
            ["#", "threads", _, k] => run.threads = k.parse().map_err(|_| line.to_string())?,
            ["#", "ns_per_ray", mode, one, many] => run.modes.push(Mode {
                name: mode.to_string(),
                one: ns(one)?,
                many: ns(many)?,
            }),
            ["#", "mode_mismatches", m] => mismatches = m.parse::<usize>().ok(),
            _ => {}
        }
    }
    if run.answers.len() != n {
        return Err(format!(
            "w6_rays answered {} of {n} rays",
            run.answers.len()
        ));
    }
    match mismatches {
        Some(0) => {}
        Some(m) => return Err(format!("w6_rays: its modes disagree on {m} answers")),
        None => return Err("w6_rays: no `# mode_mismatches` line".into()),
    }
    if run.modes.is_empty() {
        return Err("w6_rays: no `# ns_per_ray` line".into());
    }
    Ok(run)
}

/// Runs the harness `bin` on `mesh` (a file path) and `rays` with `threads`
/// threads for the K-thread column and `reps` passes per mode (median), one-thread
/// passes on thread CPU time when `cpu`.
pub fn run(
    bin: &Path,
    mesh: &str,
    rays: &[Ray],
    threads: usize,
    reps: usize,
    cpu: bool,
) -> Result<EmbreeRun, String> {
    let file = std::env::temp_dir().join(format!(
        "proxima-w6-{}-{}.rays",
        std::process::id(),
        rays.len()
    ));
    std::fs::write(&file, encode(rays)).map_err(|e| format!("{}: {e}", file.display()))?;
    let out = Command::new(bin)
        .args(["--lib", "embree", mesh])
        .arg(&file)
        .args([
            "--threads",
            &threads.to_string(),
            "--reps",
            &reps.to_string(),
        ])
        .args(["--clock", if cpu { "cpu" } else { "wall" }])
        .output();
    let _ = std::fs::remove_file(&file);
    let out = out.map_err(|e| format!("{}: {e}", bin.display()))?;
    if !out.status.success() {
        return Err(format!(
            "{} failed ({}): {}",
            bin.display(),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    parse(&String::from_utf8_lossy(&out.stdout), rays.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proxima::glam::Vec3;

    #[test]
    fn encodes_the_harness_format() {
        let r = Ray::with_max_t(Vec3::new(1.0, 2.0, 3.0), Vec3::X, 0.5);
        let b = encode(&[r, Ray::new(Vec3::ZERO, Vec3::Y)]);
        assert_eq!(b.len(), 16 + 2 * 28);
        assert_eq!(&b[..8], b"PXRAYS01");
        assert_eq!(u64::from_le_bytes(b[8..16].try_into().unwrap()), 2);
        let f = |i: usize| f32::from_le_bytes(b[16 + 4 * i..20 + 4 * i].try_into().unwrap());
        assert_eq!((f(0), f(1), f(2), f(3), f(6)), (1.0, 2.0, 3.0, 1.0, 0.5));
        assert_eq!(f(7 + 6), f32::INFINITY);
    }

    #[test]
    fn parses_answers_modes_and_checks() {
        let out = "hit 3 1.5\nhit -\n# lib embree 3.13.5\n# build_ms 2.5 quality high\n# threads 1 2\n# ns_per_ray single 100.0 60.0\n# ns_per_ray packet16 150.0 50.0\n# mode_mismatches 0\n";
        let r = parse(out, 2).unwrap();
        assert_eq!(r.answers, vec![Some((3, 1.5)), None]);
        assert_eq!(r.build, Duration::from_micros(2500));
        assert_eq!(r.threads, 2);
        assert_eq!(r.best_one().unwrap().name, "single");
        assert_eq!(r.best_many().unwrap().name, "packet16");
        assert!(parse(out, 3).is_err());
        assert!(parse(&out.replace("mismatches 0", "mismatches 4"), 2).is_err());
    }
}
