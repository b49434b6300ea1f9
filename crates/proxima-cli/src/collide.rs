//! `proxima collide A B [options]`: mesh-vs-mesh contacts with the cost
//! counters [sources: bvh-cost, pose-format].
//!
//! ```text
//! proxima collide A B [--bv aabb|kdop14|kdop18|kdop26|obb|sphere]
//!                     [--split mean|median|sah] [--leaf N]
//!                     [--rotation auto|refit|conservative] [--first]
//!                     [--poses FILE] [--stats] [--time]
//! ```
//! Each pose (12 numbers per line: a row-major rotation, then a translation; `#`
//! comments and blank lines are skipped) moves the first mesh; the second stays at
//! the identity. Without `--poses`, one identity pose. Prints one line per pose:
//! `pairs N` (distinct intersecting triangle pairs) or, with `--first`, `hit 0|1`;
//! `--stats` appends `nv NV np NP nu NU`. `--time` prints the mean time per query on
//! stderr (loading and BVH builds excluded). Bad input: one line naming the file
//! (and line), exit code 2.

use proxima::geom::{Aabb, Sphere};
use proxima::glam::Affine3A;
use proxima::narrow::{
    BoundingVolume, BuildOptions, Collider, CostCounters, Kdop14, Kdop18, Kdop26, Mesh, Obb,
    RotationUpdate, SplitRule, TriMesh,
};
use proxima_harness::poses;
use std::fmt::Write as _;
use std::time::Instant;

const USAGE: &str = "usage: proxima collide A B [--bv aabb|kdop14|kdop18|kdop26|obb|sphere] \
[--split mean|median|sah] [--leaf N] [--rotation auto|refit|conservative] [--first] \
[--poses FILE] [--stats] [--time]";

/// Parsed command line.
struct Args {
    a: String,
    b: String,
    bv: String,
    build: BuildOptions,
    rotation: RotationUpdate,
    first: bool,
    poses: Option<String>,
    stats: bool,
    time: bool,
}

fn parse_args(args: &[String]) -> Result<Args, String> {
    let mut files = Vec::new();
    let mut out = Args {
        a: String::new(),
        b: String::new(),
        bv: "kdop18".into(),
        build: BuildOptions::default(),
        rotation: RotationUpdate::Auto,
        first: false,
        poses: None,
        stats: false,
        time: false,
    };
    let mut it = args.iter();
    while let Some(arg) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .cloned()
                .ok_or_else(|| format!("{name} needs a value ({USAGE})"))
        };
        match arg.as_str() {
            "--bv" => {
                let v = value("--bv")?;
                if !["aabb", "kdop14", "kdop18", "kdop26", "obb", "sphere"].contains(&v.as_str()) {
                    return Err(format!("unknown bounding volume '{v}' ({USAGE})"));
                }
                out.bv = v;
            }
            "--split" => {
                out.build.split = match value("--split")?.as_str() {
                    "mean" => SplitRule::Mean,
                    "median" => SplitRule::Median,
                    "sah" => SplitRule::Sah,
                    v => return Err(format!("unknown split rule '{v}' ({USAGE})")),
                }
            }
            "--leaf" => {
                let v = value("--leaf")?;
                out.build.leaf_size = match v.parse::<usize>() {
                    Ok(n) if n >= 1 => n,
                    _ => return Err(format!("--leaf needs a positive integer, got '{v}'")),
                }
            }
            "--rotation" => {
                out.rotation = match value("--rotation")?.as_str() {
                    "auto" => RotationUpdate::Auto,
                    "refit" => RotationUpdate::Refit,
                    "conservative" => RotationUpdate::Conservative,
                    v => return Err(format!("unknown rotation update '{v}' ({USAGE})")),
                }
            }
            "--poses" => out.poses = Some(value("--poses")?),
            "--first" => out.first = true,
            "--stats" => out.stats = true,
            "--time" => out.time = true,
            s if s.starts_with("--") => return Err(format!("unknown option '{s}' ({USAGE})")),
            s => files.push(s.to_string()),
        }
    }
    if files.len() != 2 {
        return Err(format!("expected two mesh files ({USAGE})"));
    }
    out.b = files.pop().unwrap_or_default();
    out.a = files.pop().unwrap_or_default();
    Ok(out)
}

fn load(path: &str) -> Result<TriMesh, String> {
    proxima::io::load(path).map_err(|e| {
        let s = e.to_string();
        // Loader messages may already name the file.
        if s.contains(path) {
            s
        } else {
            format!("{path}: {s}")
        }
    })
}

/// Runs the command; returns the process exit code.
pub fn main(args: &[String]) -> i32 {
    match run(args) {
        Ok(out) => {
            print!("{out}");
            0
        }
        Err(msg) => {
            eprintln!("proxima collide: {msg}");
            2
        }
    }
}

fn run(args: &[String]) -> Result<String, String> {
    let args = parse_args(args)?;
    let a = load(&args.a)?;
    let b = load(&args.b)?;
    let poses = match &args.poses {
        None => vec![Affine3A::IDENTITY],
        Some(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| format!("{p}: {e}"))?;
            poses::parse(p, &text)?
        }
    };
    match args.bv.as_str() {
        "aabb" => queries::<Aabb>(&args, a, b, &poses),
        "kdop14" => queries::<Kdop14>(&args, a, b, &poses),
        "kdop26" => queries::<Kdop26>(&args, a, b, &poses),
        "obb" => queries::<Obb>(&args, a, b, &poses),
        "sphere" => queries::<Sphere>(&args, a, b, &poses),
        _ => queries::<Kdop18>(&args, a, b, &poses),
    }
}

fn queries<BV: BoundingVolume>(
    args: &Args,
    a: TriMesh,
    b: TriMesh,
    poses: &[Affine3A],
) -> Result<String, String> {
    let a = Mesh::<BV>::from_trimesh(a, args.build).map_err(|e| e.to_string())?;
    let b = Mesh::<BV>::from_trimesh(b, args.build).map_err(|e| e.to_string())?;
    let mut collider = Collider::<BV>::new(args.rotation);
    let mut results: Vec<(usize, CostCounters)> = Vec::with_capacity(poses.len());
    let start = Instant::now();
    for pose in poses {
        let r = if args.first {
            let f = collider
                .first_contact(&a, pose, &b)
                .map_err(|e| e.to_string())?;
            (f.pair.is_some() as usize, f.counters)
        } else {
            let c = collider
                .all_pairs(&a, pose, &b)
                .map_err(|e| e.to_string())?;
            (c.pairs.len(), c.counters)
        };
        results.push(r);
    }
    let elapsed = start.elapsed();
    if args.time {
        eprintln!(
            "time {:.2} us/query ({} queries, bv {}, {} + {} triangles)",
            elapsed.as_secs_f64() * 1e6 / poses.len().max(1) as f64,
            poses.len(),
            BV::NAME,
            a.trimesh().len(),
            b.trimesh().len()
        );
    }
    let mut out = String::new();
    for (n, c) in results {
        let _ = if args.first {
            write!(out, "hit {n}")
        } else {
            write!(out, "pairs {n}")
        };
        if args.stats {
            let _ = write!(out, " nv {} np {} nu {}", c.nv, c.np, c.nu);
        }
        out.push('\n');
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn argument_errors() {
        let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        assert!(parse_args(&s(&["a.obj"])).is_err());
        assert!(parse_args(&s(&["a", "b", "--bv", "cube"])).is_err());
        assert!(parse_args(&s(&["a", "b", "--leaf", "0"])).is_err());
        assert!(parse_args(&s(&["a", "b", "--split"])).is_err());
        let a = parse_args(&s(&["a", "b", "--bv", "obb", "--first", "--split", "sah"])).unwrap();
        assert!(a.first && a.bv == "obb" && a.build.split == SplitRule::Sah);
    }
}
