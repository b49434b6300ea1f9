//! W5's C++ peers: FCL 0.7 and coal 3.0, each with its OBBRSS and OBB trees, run
//! through the `w5_mesh` harness of `crates/proxima-bench/peers/` (built by
//! `scripts/peers.sh`; its README gives the protocol) on the same meshes and the
//! same poses, with their answers checked against ours.
//!
//! The harness is a separate process per (library, volume, mode): it builds both
//! trees, runs every pose `reps` times and prints one answer line per pose, then
//! `# build_us A B` and `# query_us median M mean X min Y` (wall clock). The
//! poses are written to a file with Rust's shortest round-trip formatting of the
//! `f32` values, so both sides move the mesh by the same numbers.

use super::check;
use proxima::glam::Affine3A;
use proxima::narrow::TriMesh;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The peer configurations W5 runs: library and bounding volume (both libraries'
/// "oriented" volumes, the ones they traverse without rebuilding per pose).
pub const CONFIGS: [(&str, &str); 4] = [
    ("coal", "obbrss"),
    ("coal", "obb"),
    ("fcl", "obbrss"),
    ("fcl", "obb"),
];

/// The directory of the harness binaries: `$PEERS_OUT`, else `target/peers` of
/// this workspace; `None` when `w5_mesh` is not there.
pub fn harness_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("PEERS_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/peers"));
    dir.join("w5_mesh").is_file().then_some(dir)
}

/// Writes `poses` in the pose format [sources: pose-format] (row-major rotation,
/// then translation; `{}` of each `f32`, which reads back as the same `f32`).
pub fn write_poses(path: &Path, poses: &[Affine3A]) -> Result<(), String> {
    let mut s = String::new();
    for p in poses {
        let m = p.matrix3;
        let row = |r: usize| [m.x_axis[r], m.y_axis[r], m.z_axis[r]];
        let t = p.translation;
        let nums = [row(0), row(1), row(2), [t.x, t.y, t.z]];
        let line: Vec<String> = nums.iter().flatten().map(|v| format!("{v}")).collect();
        s.push_str(&line.join(" "));
        s.push('\n');
    }
    std::fs::write(path, s).map_err(|e| format!("{}: {e}", path.display()))
}

/// The touching tolerance of each library (absolute distance): coal's leaf test is
/// GJK, which reports triangles within `gjk_tolerance` (1e-6 by default) as
/// intersecting; FCL's triangle test is exact here (none).
const TOLERANCE: [(&str, f32); 1] = [("coal", 1e-6)];

/// One run of the harness: its answer per pose and its timings.
#[derive(Clone, Debug, Default)]
pub struct HarnessRun {
    /// `pairs N` or `hit 0|1` per pose, as numbers.
    pub answers: Vec<u64>,
    /// `distance D I J` per pose (`--mode distance`): `D` and the triangles.
    pub distances: Vec<(f64, u64, u64)>,
    /// Build time of each tree (`# build_us A B`), µs.
    pub build_us: (f64, f64),
    /// Median and mean time per query, µs (wall clock, over poses × reps).
    pub median_us: f64,
    /// See `median_us`.
    pub mean_us: f64,
    /// `# lib` line: library and version.
    pub lib: String,
}

/// One peer configuration on one mesh pair, both modes.
#[derive(Clone, Debug)]
pub struct PeerRun {
    /// `coal obbrss`, ...
    pub name: String,
    /// Library and version (`coal 3.0.3`).
    pub version: String,
    /// Build time of each tree, µs.
    pub build_us: (f64, f64),
    /// All pairs: median and mean µs per query.
    pub all: (f64, f64),
    /// First contact: median and mean µs per query.
    pub first: (f64, f64),
    /// Pair count per pose.
    pub counts: Vec<u64>,
    /// Hit per pose.
    pub hits: Vec<bool>,
    /// Poses whose answer differs from ours only by triangle pairs within the
    /// library's touching tolerance (checked: see `check_against`).
    pub tolerance_poses: usize,
    /// Extra pairs the peer reports on those poses.
    pub tolerance_pairs: u64,
}

fn parse_output(text: &str, mode: &str) -> Result<HarnessRun, String> {
    let mut r = HarnessRun::default();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        let num = |s: &str| {
            s.parse::<f64>()
                .map_err(|_| format!("harness line {line:?}: not a number"))
        };
        match w.as_slice() {
            ["pairs", n] if mode == "all" => r.answers.push(num(n)? as u64),
            ["hit", h] if mode == "first" => r.answers.push(num(h)? as u64),
            ["distance", d, i, j] if mode == "distance" => {
                r.distances.push((num(d)?, num(i)? as u64, num(j)? as u64))
            }
            ["#", "lib", rest @ ..] => r.lib = rest.join(" "),
            ["#", "build_us", a, b] => r.build_us = (num(a)?, num(b)?),
            ["#", "query_us", "median", m, "mean", x, ..] => {
                r.median_us = num(m)?;
                r.mean_us = num(x)?;
            }
            ["#", ..] | [] => {}
            _ => return Err(format!("unexpected harness line {line:?}")),
        }
    }
    Ok(r)
}

/// Runs `w5_mesh --lib LIB --bv BV A B POSES --mode MODE --reps REPS`.
pub fn run_harness(
    dir: &Path,
    (lib, bv): (&str, &str),
    meshes: (&Path, &Path),
    poses: &Path,
    mode: &str,
    reps: usize,
) -> Result<HarnessRun, String> {
    let out = Command::new(dir.join("w5_mesh"))
        .args(["--lib", lib, "--bv", bv])
        .arg(meshes.0)
        .arg(meshes.1)
        .arg(poses)
        .args(["--mode", mode, "--reps", &reps.to_string()])
        .output()
        .map_err(|e| format!("w5_mesh: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "w5_mesh --lib {lib} --bv {bv} --mode {mode}: {} {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    parse_output(&String::from_utf8_lossy(&out.stdout), mode)
}

/// Runs one configuration in both modes and checks its answers against ours
/// (`counts`, `hits`): equal, except that a peer may report extra pairs on a pose
/// where that many non-intersecting triangle pairs lie within `tolerance` of each
/// other (coal counts pairs within its GJK tolerance as touching; README
/// "Tolerances"). Every other difference goes to `errors`.
#[allow(clippy::too_many_arguments)]
pub fn run_config(
    dir: &Path,
    config: (&str, &str),
    files: (&Path, &Path),
    pose_file: &Path,
    reps: usize,
    (a, b, poses): (&TriMesh, &TriMesh, &[Affine3A]),
    (counts, hits): (&[u64], &[bool]),
    errors: &mut Vec<String>,
) -> Result<PeerRun, String> {
    let all = run_harness(dir, config, files, pose_file, "all", reps)?;
    let first = run_harness(dir, config, files, pose_file, "first", reps)?;
    let name = format!("{} {}", config.0, config.1);
    for r in [&all, &first] {
        if r.answers.len() != poses.len() {
            return Err(format!(
                "{name}: {} answers for {} poses",
                r.answers.len(),
                poses.len()
            ));
        }
    }
    let mut run = PeerRun {
        name: name.clone(),
        version: all.lib.clone(),
        build_us: all.build_us,
        all: (all.median_us, all.mean_us),
        first: (first.median_us, first.mean_us),
        counts: all.answers.clone(),
        hits: first.answers.iter().map(|&h| h != 0).collect(),
        tolerance_poses: 0,
        tolerance_pairs: 0,
    };
    let tolerance = TOLERANCE
        .iter()
        .find(|t| t.0 == config.0)
        .map_or(0.0, |t| t.1);
    for (i, pose) in poses.iter().enumerate() {
        let (theirs, ours) = (run.counts[i], counts[i]);
        let (their_hit, our_hit) = (run.hits[i], hits[i]);
        if theirs == ours && their_hit == our_hit {
            continue;
        }
        // A peer may only see more: extra pairs within its tolerance.
        let near = if tolerance > 0.0 && theirs >= ours && (their_hit || !our_hit) {
            check::near_pairs(a, pose, b, tolerance) as u64
        } else {
            0
        };
        let count_ok = theirs == ours || (theirs > ours && theirs - ours <= near);
        let hit_ok = their_hit == our_hit || (their_hit && !our_hit && near > 0);
        if count_ok && hit_ok {
            run.tolerance_poses += 1;
            run.tolerance_pairs += theirs - ours;
        } else {
            errors.push(format!(
                "{name} pose {i}: {theirs} pairs, hit {their_hit}; ours {ours} pairs, hit {our_hit} ({near} non-intersecting pairs within its tolerance {tolerance:e})"
            ));
        }
    }
    Ok(run)
}
