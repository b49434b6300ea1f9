//! `proxima collide A B [options]`: mesh-vs-mesh contacts, distances or
//! proximity tests with the cost counters [sources: bvh-cost, pose-format].
//!
//! ```text
//! proxima collide A B [--bv aabb|kdop14|kdop18|kdop26|obb|sphere]
//!                     [--split mean|median|sah] [--leaf N]
//!                     [--rotation auto|refit|conservative]
//!                     [--first | --distance | --within D]
//!                     [--poses FILE] [--stats] [--time]
//! ```
//! Each pose (12 numbers per line: a row-major rotation, then a translation; `#`
//! comments and blank lines are skipped) moves the first mesh; the second stays at
//! the identity. Without `--poses`, one identity pose. Prints one line per pose:
//! `pairs N` (distinct intersecting triangle pairs) or, with `--first`, `hit 0|1`;
//! with `--distance`, `distance D I J` (the meshes' distance, `0` if they
//! intersect, with 9 significant digits, and a nearest pair of triangles, I of A
//! and J of B: `Proximity::distance`); with `--within D`, `within 0|1` (whether
//! that distance is at most `D`: `Proximity::within`, with an early exit);
//! `--stats` appends `nv NV np NP nu NU`. `--time` prints the mean time per query on
//! stderr (loading and BVH builds excluded). Bad input: one line naming the file
//! (and line), exit code 2.

use proxima::geom::{Aabb, Sphere};
use proxima::glam::Affine3A;
use proxima::narrow::{
    BoundingVolume, BuildOptions, Collider, CostCounters, Kdop14, Kdop18, Kdop26, Mesh, Obb,
    Proximity, RotationUpdate, SplitRule, TriMesh,
};
use proxima_harness::poses;
use std::fmt::Write as _;
use std::time::Instant;

const USAGE: &str = "usage: proxima collide A B [--bv aabb|kdop14|kdop18|kdop26|obb|sphere] \
[--split mean|median|sah] [--leaf N] [--rotation auto|refit|conservative] \
[--first | --distance | --within D] [--poses FILE] [--stats] [--time]";

/// What each pose asks.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Query {
    /// Every intersecting triangle pair (`pairs N`).
    Pairs,
    /// Whether any pair intersects (`hit 0|1`).
    First,
    /// The distance and a nearest triangle pair (`distance D I J`).
    Distance,
    /// Whether the distance is at most the margin (`within 0|1`).
    Within(f64),
}

/// Parsed command line.
struct Args {
    a: String,
    b: String,
    bv: String,
    build: BuildOptions,
    rotation: RotationUpdate,
    query: Query,
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
        query: Query::Pairs,
        poses: None,
        stats: false,
        time: false,
    };
    // At most one of --first, --distance, --within.
    fn set_query(slot: &mut Query, q: Query, name: &str) -> Result<(), String> {
        if *slot != Query::Pairs {
            return Err(format!(
                "{name}: only one of --first, --distance, --within ({USAGE})"
            ));
        }
        *slot = q;
        Ok(())
    }
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
            "--first" => set_query(&mut out.query, Query::First, "--first")?,
            "--distance" => set_query(&mut out.query, Query::Distance, "--distance")?,
            "--within" => {
                let v = value("--within")?;
                match v.parse::<f64>() {
                    Ok(d) if d.is_finite() && d >= 0.0 => {
                        set_query(&mut out.query, Query::Within(d), "--within")?
                    }
                    _ => {
                        return Err(format!(
                            "--within needs a finite non-negative distance, got '{v}'"
                        ))
                    }
                }
            }
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

/// One pose's answer, formatted after the timed loop.
enum Answer {
    Pairs(usize),
    Hit(bool),
    Distance(f64, u32, u32),
    Within(bool),
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
    let mut proximity = Proximity::<BV>::new(args.rotation);
    let mut results: Vec<(Answer, CostCounters)> = Vec::with_capacity(poses.len());
    let start = Instant::now();
    for pose in poses {
        let r = match args.query {
            Query::First => {
                let f = collider.first_contact(&a, pose, &b);
                let f = f.map_err(|e| e.to_string())?;
                (Answer::Hit(f.pair.is_some()), f.counters)
            }
            Query::Pairs => {
                let c = collider.all_pairs(&a, pose, &b);
                let c = c.map_err(|e| e.to_string())?;
                (Answer::Pairs(c.pairs.len()), c.counters)
            }
            Query::Distance => {
                let d = proximity.distance(&a, pose, &b);
                let d = d.map_err(|e| e.to_string())?;
                let (i, j) = d.triangles;
                (Answer::Distance(d.distance, i, j), d.counters)
            }
            Query::Within(margin) => {
                let w = proximity.within(&a, pose, &b, margin);
                let w = w.map_err(|e| e.to_string())?;
                (Answer::Within(w), proximity.counters())
            }
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
    for (answer, c) in results {
        let _ = match answer {
            Answer::Pairs(n) => write!(out, "pairs {n}"),
            Answer::Hit(h) => write!(out, "hit {}", h as u8),
            Answer::Distance(d, i, j) => write!(out, "distance {} {i} {j}", significant9(d)),
            Answer::Within(w) => write!(out, "within {}", w as u8),
        };
        if args.stats {
            let _ = write!(out, " nv {} np {} nu {}", c.nv, c.np, c.nu);
        }
        out.push('\n');
    }
    Ok(out)
}

/// `x` with 9 significant digits, as C's `%.9g`: positional for exponents from
/// -4 to 8, else `1.5e-07` / `2.5e+20` form; trailing zeros dropped.
fn significant9(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    // Rounded to 9 digits first: the exponent is the rounded value's.
    let sci = format!("{x:.8e}");
    let (mantissa, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let trim = |s: &str| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if (-4..9).contains(&exp) {
        trim(&format!("{x:.*}", (8 - exp) as usize))
    } else {
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{}e{sign}{:02}", trim(mantissa), exp.abs())
    }
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
        assert!(a.query == Query::First && a.bv == "obb" && a.build.split == SplitRule::Sah);
        for bad in [
            &["a", "b", "--within"][..],
            &["a", "b", "--within", "-1"],
            &["a", "b", "--within", "NaN"],
            &["a", "b", "--within", "inf"],
            &["a", "b", "--within", "x"],
            &["a", "b", "--distance", "--first"],
            &["a", "b", "--first", "--within", "1"],
            &["a", "b", "--within", "1", "--distance"],
        ] {
            assert!(parse_args(&s(bad)).is_err(), "{bad:?}");
        }
        let a = parse_args(&s(&["a", "b", "--within", "2.5"])).unwrap();
        assert_eq!(a.query, Query::Within(2.5));
        let a = parse_args(&s(&["a", "b", "--within", "0", "--stats"])).unwrap();
        assert!(a.query == Query::Within(0.0) && a.stats);
        let a = parse_args(&s(&["--distance", "a", "b"])).unwrap();
        assert!(a.query == Query::Distance && a.a == "a" && a.b == "b");
    }

    #[test]
    fn nine_significant_digits() {
        for (x, want) in [
            (0.0, "0"),
            (2.0, "2"),
            (0.1, "0.1"),
            (1.0 / 3.0, "0.333333333"),
            (123456789.4, "123456789"),
            (999999999.6, "1e+09"),
            (1234567890.0, "1.23456789e+09"),
            (9.9999999996, "10"),
            (1e-5, "1e-05"),
            (1.25e-5, "1.25e-05"),
            (0.0001234567891, "0.000123456789"),
            (3.0e37, "3e+37"),
            (f64::MIN_POSITIVE, "2.22507386e-308"),
        ] {
            assert_eq!(significant9(x), want, "{x:e}");
            // Within half a unit of the 9th digit.
            let back: f64 = want.parse().unwrap();
            assert!((back - x).abs() <= 5e-9 * x.abs(), "{x:e} {want}");
        }
    }
}
