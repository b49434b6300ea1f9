//! W5-distance: mesh–mesh distance and "within a margin" at the W5 poses
//! (issue #15's benchmark), through every bounding-volume type with SAH trees.
//!
//! `proxima-bench w5-distance [--poses FILE] [--pairs rob-env,bunny,...] [--n N]
//! [--seed S] [--bv aabb,kdop18,...] [--margin-frac F] [--brute K]
//! [--rotation auto|refit|conservative] [--clock cpu|wall] [--peers auto|none]
//! [--peer-reps R] [--json]`
//!
//! - Poses as W5 ([`crate::w5`]): `rob-env` reads the pose file (FCL's
//!   distribution), the other pairs use `--n` generated poses.
//! - Per bounding volume: mean and median time per `distance` query and per
//!   `within` query (margin: `--margin-frac` times the fixed mesh's diagonal,
//!   default 0.01), the mean cost counters `Nv/Np/Nu` of the distance query, and
//!   the poses in contact (distance 0) and within the margin.
//! - Checked in the same run (exit code 1 otherwise): every volume gives the
//!   same distance (bit for bit) on every pose; `within` agrees with it; on the
//!   first `--brute` poses (default 3; fewer on big pairs) the distance equals
//!   the minimum of `triangle_distance` over all triangle pairs.
//! - The C++ peers (`--peers auto`, the default, when `scripts/peers.sh` has
//!   built them): coal 3.0 and FCL 0.7 OBBRSS `distance` (the volume both
//!   libraries' distance traversal is fastest with; the only one coal's
//!   distance takes besides RSS) through the `w5_mesh` harness
//!   ([`crate::w5::peers`]) on the same poses, `--peer-reps` times each (wall
//!   clock); their distances are checked against ours (within `1e-5` of the
//!   fixed mesh's diagonal; on intersecting poses, at most that), and the
//!   table gives our medians over coal's. Use `--clock wall` for ratios.
//!
//! For instruction counts (stable on a shared machine) run one volume under
//! callgrind with `--toggle-collect='*Proximity*distance*'` (the distance
//! queries only) or `'*Proximity<BV>::run'` (both; no trailing `*`, which would
//! also toggle on `run`'s closures; `within` is inlined into its caller, so read
//! its share from `run`'s callers with `callgrind_annotate --tree=caller`).

use crate::run::{median, Clock};
use crate::w5::{peers, poses};
use proxima::geom::{Aabb, Sphere};
use proxima::glam::{Affine3A, Vec3};
use proxima::narrow::{
    triangle_distance, BoundingVolume, BuildOptions, Kdop14, Kdop18, Kdop26, Mesh, Obb, Proximity,
    RotationUpdate, TriMesh,
};
use std::fmt::Write as _;
use std::process::ExitCode;
use std::time::Duration;

const USAGE: &str = "usage: proxima-bench w5-distance [--poses FILE] [--pairs rob-env,bunny,teapot,hand-forearm,skin-ribcage] [--n N] [--seed S] [--bv aabb,kdop14,kdop18,kdop26,obb,sphere] [--margin-frac F] [--brute K] [--rotation auto|refit|conservative] [--clock cpu|wall] [--peers auto|none] [--peer-reps R] [--json]";

/// The peers' distance configurations (library, volume).
const PEERS: [(&str, &str); 2] = [("coal", "obbrss"), ("fcl", "obbrss")];
/// A peer's distance may differ from ours by this fraction of the fixed mesh's
/// diagonal (issue #15's test tolerance; GJK-based leaf tests stop early).
const PEER_TOLERANCE: f64 = 1e-5;

/// The mesh pairs of W5: name, moving mesh, fixed mesh (files in `shared/data/`).
const PAIRS: [(&str, &str, &str); 5] = [
    ("rob-env", "rob.obj", "env.obj"),
    ("bunny", "bunny.obj", "bunny.obj"),
    ("teapot", "teapot.obj", "teapot.obj"),
    ("hand-forearm", "hand_3finger.stl", "forearm.stl"),
    ("skin-ribcage", "SKINbody.stl", "BONERibcage.stl"),
];
const BVS: [&str; 6] = ["aabb", "kdop14", "kdop18", "kdop26", "obb", "sphere"];
const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/");
const DEFAULT_POSES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data/rob-env-1000.poses");
/// Cap on brute-force triangle pairs per mesh pair.
const BRUTE_BUDGET: usize = 30_000_000;

struct Args {
    poses: String,
    pairs: Vec<String>,
    bvs: Vec<String>,
    n: usize,
    seed: u64,
    margin_frac: f64,
    brute: usize,
    rotation: RotationUpdate,
    clock: Clock,
    peers: bool,
    peer_reps: usize,
    json: bool,
}

fn list(s: String, known: &[&str], what: &str) -> Result<Vec<String>, String> {
    let v: Vec<String> = s
        .split(',')
        .filter(|s| !s.is_empty())
        .map(String::from)
        .collect();
    match v.iter().find(|x| !known.contains(&x.as_str())) {
        Some(x) => Err(format!("unknown {what} {x:?}")),
        None => Ok(v),
    }
}

fn parse(mut it: impl Iterator<Item = String>) -> Result<Args, String> {
    let mut a = Args {
        poses: DEFAULT_POSES.into(),
        pairs: vec!["rob-env".into(), "bunny".into()],
        bvs: BVS.iter().map(|s| s.to_string()).collect(),
        n: 200,
        seed: 5,
        margin_frac: 0.01,
        brute: 3,
        rotation: RotationUpdate::Auto,
        clock: Clock::ThreadCpu,
        peers: true,
        peer_reps: 3,
        json: false,
    };
    let names: Vec<&str> = PAIRS.iter().map(|p| p.0).collect();
    while let Some(flag) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match flag.as_str() {
            "--poses" => a.poses = value("--poses")?,
            "--pairs" => a.pairs = list(value("--pairs")?, &names, "mesh pair")?,
            "--bv" => a.bvs = list(value("--bv")?, &BVS, "bounding volume")?,
            "--n" => a.n = crate::run::num(&value("--n")?)?,
            "--seed" => a.seed = crate::run::num(&value("--seed")?)?,
            "--margin-frac" => {
                a.margin_frac = crate::run::num(&value("--margin-frac")?)?;
                if !(a.margin_frac >= 0.0 && a.margin_frac.is_finite()) {
                    return Err("--margin-frac must be finite and >= 0".into());
                }
            }
            "--brute" => a.brute = crate::run::num(&value("--brute")?)?,
            "--rotation" => {
                a.rotation = match value("--rotation")?.as_str() {
                    "auto" => RotationUpdate::Auto,
                    "refit" => RotationUpdate::Refit,
                    "conservative" => RotationUpdate::Conservative,
                    o => {
                        return Err(format!(
                            "--rotation takes auto, refit or conservative, not {o:?}"
                        ))
                    }
                }
            }
            "--clock" => a.clock = Clock::parse(&value("--clock")?)?,
            "--peers" => {
                a.peers = match value("--peers")?.as_str() {
                    "auto" => true,
                    "none" => false,
                    o => return Err(format!("--peers takes auto or none, not {o:?}")),
                }
            }
            "--peer-reps" => a.peer_reps = crate::run::num::<usize>(&value("--peer-reps")?)?.max(1),
            "--json" => a.json = true,
            "-h" | "--help" => return Err(String::new()),
            o => return Err(format!("unknown argument {o:?}")),
        }
    }
    Ok(a)
}

/// One bounding-volume type on one mesh pair.
struct BvRun {
    name: &'static str,
    distance: Vec<Duration>,
    within: Vec<Duration>,
    /// Per pose: the distance and whether `within` said yes.
    values: Vec<f64>,
    inside: Vec<bool>,
    /// Mean counters of the distance query, then of the within query.
    counters: [f64; 6],
}

fn measure<BV: BoundingVolume>(
    a: &TriMesh,
    b: &TriMesh,
    poses: &[Affine3A],
    margin: f64,
    args: &Args,
) -> Result<BvRun, String> {
    let o = BuildOptions::default();
    let ta = Mesh::<BV>::from_trimesh(a.clone(), o).map_err(|e| e.to_string())?;
    let tb = Mesh::<BV>::from_trimesh(b.clone(), o).map_err(|e| e.to_string())?;
    let mut q = Proximity::<BV>::new(args.rotation);
    let mut r = BvRun {
        name: BV::NAME,
        distance: Vec::with_capacity(poses.len()),
        within: Vec::with_capacity(poses.len()),
        values: Vec::with_capacity(poses.len()),
        inside: Vec::with_capacity(poses.len()),
        counters: [0.0; 6],
    };
    // Warm-up: scratch sized, code and data in cache.
    if let Some(p) = poses.first() {
        q.distance(&ta, p, &tb).map_err(|e| e.to_string())?;
    }
    for p in poses {
        let (d, t) = args.clock.time(|| q.distance(&ta, p, &tb));
        let d = d.map_err(|e| e.to_string())?;
        r.distance.push(t);
        r.values.push(d.distance);
        let c = d.counters;
        r.counters[0] += c.nv as f64;
        r.counters[1] += c.np as f64;
        r.counters[2] += c.nu as f64;
        let (w, t) = args.clock.time(|| q.within(&ta, p, &tb, margin));
        r.inside.push(w.map_err(|e| e.to_string())?);
        r.within.push(t);
        let c = q.counters();
        r.counters[3] += c.nv as f64;
        r.counters[4] += c.np as f64;
        r.counters[5] += c.nu as f64;
    }
    for c in &mut r.counters {
        *c /= poses.len().max(1) as f64;
    }
    Ok(r)
}

struct PairRun {
    name: &'static str,
    tris: (usize, usize),
    margin: f64,
    brute_poses: usize,
    bvs: Vec<BvRun>,
    /// The C++ peers' distance runs, or why there are none.
    peers: Result<Vec<PeerDistance>, String>,
}

/// One C++ peer's distance query on one mesh pair.
struct PeerDistance {
    /// `coal obbrss`, ...
    name: String,
    /// Library and version (`coal 3.0.3`).
    version: String,
    /// Median and mean µs per query (wall clock, over poses × reps).
    median_us: f64,
    mean_us: f64,
}

/// Runs the peers' distance on the pair's poses and checks their distances
/// against `ours` (one per pose); an unbuilt harness is a note, not a failure.
fn run_peers(
    (name, fa, fb): (&str, &str, &str),
    poses: &[Affine3A],
    ours: &[f64],
    tolerance: f64,
    args: &Args,
    errors: &mut Vec<String>,
) -> Result<Vec<PeerDistance>, String> {
    let Some(dir) = peers::harness_dir() else {
        return Err("C++ peers not built (scripts/peers.sh builds them)".into());
    };
    let pose_file =
        std::env::temp_dir().join(format!("proxima-w5d-{}-{name}.poses", std::process::id()));
    peers::write_poses(&pose_file, poses)?;
    let (pa, pb) = (format!("{DATA}{fa}"), format!("{DATA}{fb}"));
    let mut out = Vec::new();
    for config in PEERS {
        eprintln!("  {name}: {} {} distance ...", config.0, config.1);
        let files = (pa.as_ref(), pb.as_ref());
        let r = peers::run_harness(&dir, config, files, &pose_file, "distance", args.peer_reps);
        let r = match r {
            Ok(r) if r.distances.len() == poses.len() => r,
            Ok(r) => {
                let e = format!("{} answers for {} poses", r.distances.len(), poses.len());
                errors.push(format!("{name}: {} {}: {e}", config.0, config.1));
                continue;
            }
            Err(e) => {
                errors.push(format!("{name}: {e}"));
                continue;
            }
        };
        for (i, (&(theirs, ..), &d)) in r.distances.iter().zip(ours).enumerate() {
            // Intersecting meshes: 0 here, at most the tolerance there (coal
            // may report a penetration as a negative distance).
            let ok = if d == 0.0 {
                theirs <= tolerance
            } else {
                (theirs - d).abs() <= tolerance
            };
            if !ok {
                errors.push(format!(
                    "{name} pose {i}: {} {} distance {theirs}, ours {d}",
                    config.0, config.1
                ));
            }
        }
        out.push(PeerDistance {
            name: format!("{} {}", config.0, config.1),
            version: r.lib,
            median_us: r.median_us,
            mean_us: r.mean_us,
        });
    }
    let _ = std::fs::remove_file(&pose_file);
    Ok(out)
}

fn load(file: &str) -> Result<TriMesh, String> {
    let path = format!("{DATA}{file}");
    proxima::io::load(&path).map_err(|e| format!("{path}: {e}"))
}

/// The minimum `triangle_distance` over every pair of `a` moved by `pose` and `b`.
fn brute(a: &TriMesh, pose: &Affine3A, b: &TriMesh) -> f64 {
    let tb: Vec<[Vec3; 3]> = (0..b.len()).map(|j| b.triangle(j)).collect();
    let mut best = f64::INFINITY;
    for i in 0..a.len() {
        let t = a.triangle(i).map(|v| pose.transform_point3(v));
        for u in &tb {
            best = best.min(triangle_distance(&t, u).distance);
        }
    }
    best
}

fn run_pair(
    (name, fa, fb): (&'static str, &str, &str),
    args: &Args,
    errors: &mut Vec<String>,
) -> Result<PairRun, String> {
    let (a, b) = (load(fa)?, load(fb)?);
    let poses = if name == "rob-env" {
        let text =
            std::fs::read_to_string(&args.poses).map_err(|e| format!("{}: {e}", args.poses))?;
        poses::parse(&args.poses, &text)?
    } else {
        poses::generate(&a, &b, args.n, args.seed)
    };
    let (lo, hi) = b.vertices().iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(l, h), &v| (l.min(v), h.max(v)),
    );
    let diagonal = (hi - lo).length() as f64;
    let margin = args.margin_frac * diagonal;
    let mut bvs = Vec::new();
    for bv in &args.bvs {
        eprintln!("  {name}: {bv} ...");
        let (p, m) = (&poses, margin);
        bvs.push(match bv.as_str() {
            "aabb" => measure::<Aabb>(&a, &b, p, m, args)?,
            "kdop14" => measure::<Kdop14>(&a, &b, p, m, args)?,
            "kdop18" => measure::<Kdop18>(&a, &b, p, m, args)?,
            "kdop26" => measure::<Kdop26>(&a, &b, p, m, args)?,
            "obb" => measure::<Obb>(&a, &b, p, m, args)?,
            _ => measure::<Sphere>(&a, &b, p, m, args)?,
        });
    }
    for r in &bvs {
        for (i, (&d, &w)) in r.values.iter().zip(&r.inside).enumerate() {
            if d.to_bits() != bvs[0].values[i].to_bits() {
                errors.push(format!(
                    "{name} pose {i}: {} distance {d}, {} {}",
                    r.name, bvs[0].name, bvs[0].values[i]
                ));
            }
            if w != (d <= margin) {
                errors.push(format!(
                    "{name} pose {i}: {} within({margin}) = {w} but distance {d}",
                    r.name
                ));
            }
        }
    }
    let brute_poses = args
        .brute
        .min(BRUTE_BUDGET / (a.len() * b.len()))
        .min(poses.len());
    if let Some(r) = bvs.first() {
        eprintln!("  {name}: brute force on {brute_poses} poses ...");
        for (i, pose) in poses.iter().take(brute_poses).enumerate() {
            let want = brute(&a, pose, &b);
            if want.to_bits() != r.values[i].to_bits() {
                errors.push(format!(
                    "{name} pose {i}: distance {} but brute force {want}",
                    r.values[i]
                ));
            }
        }
    }
    let peers = match bvs.first() {
        Some(r) if args.peers => {
            let tolerance = PEER_TOLERANCE * diagonal;
            run_peers((name, fa, fb), &poses, &r.values, tolerance, args, errors)
        }
        _ => Err("not run (--peers none)".into()),
    };
    Ok(PairRun {
        name,
        tris: (a.len(), b.len()),
        margin,
        brute_poses,
        bvs,
        peers,
    })
}

fn us(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}

fn mean(d: &[Duration]) -> Duration {
    d.iter().sum::<Duration>() / d.len().max(1) as u32
}

fn table(runs: &[PairRun], args: &Args) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "w5-distance, SAH trees (leaf 1), rotation={:?}, clock={} (times per query; distances checked equal for every BV on every pose, within checked against them)", args.rotation, args.clock.name());
    for p in runs {
        let Some(first) = p.bvs.first() else { continue };
        let zero = first.values.iter().filter(|&&d| d == 0.0).count();
        let inside = first.inside.iter().filter(|&&w| w).count();
        let _ = writeln!(
            s,
            "\n{} ({} x {} triangles, {} poses, brute-force checked on {}; distance 0 on {} poses, within {:.4} on {})",
            p.name, p.tris.0, p.tris.1, first.values.len(), p.brute_poses, zero, p.margin, inside
        );
        // Ratios: our medians over coal's distance median.
        let coal = p.peers.as_ref().ok().and_then(|v| {
            v.iter()
                .find(|r| r.name.starts_with("coal"))
                .map(|r| r.median_us)
        });
        let ratio = |t: f64| coal.map_or("-".to_string(), |c| format!("{:.2}", t / c));
        let _ = writeln!(
            s,
            "{:<12} {:>10} {:>10} {:>9} {:>8} {:>7} {:>10} {:>10} {:>9} {:>8} {:>7} {:>7}",
            "bv",
            "dist mean",
            "dist med",
            "Nv",
            "Np",
            "Nu",
            "within mn",
            "within md",
            "Nv",
            "Np",
            "d/coal",
            "w/coal"
        );
        for r in &p.bvs {
            let c = r.counters;
            let (dm, wm) = (us(median(&r.distance)), us(median(&r.within)));
            let _ = writeln!(
                s,
                "{:<12} {:>10.1} {:>10.1} {:>9.0} {:>8.0} {:>7.0} {:>10.1} {:>10.1} {:>9.0} {:>8.0} {:>7} {:>7}",
                r.name,
                us(mean(&r.distance)),
                dm,
                c[0],
                c[1],
                c[2],
                us(mean(&r.within)),
                wm,
                c[3],
                c[4],
                ratio(dm),
                ratio(wm)
            );
        }
        match &p.peers {
            Ok(v) => {
                for r in v {
                    let _ = writeln!(
                        s,
                        "{:<12} {:>10.1} {:>10.1}   ({}, distance, wall clock)",
                        r.name, r.mean_us, r.median_us, r.version
                    );
                }
            }
            Err(e) => {
                let _ = writeln!(s, "peers: {e}");
            }
        }
    }
    s
}

fn json(runs: &[PairRun], args: &Args) -> String {
    let mut s = format!(
        "{{\"workload\":\"w5-distance\",\"clock\":\"{}\",\"pairs\":[",
        args.clock.name()
    );
    for (i, p) in runs.iter().enumerate() {
        let _ = write!(
            s,
            "{}{{\"name\":\"{}\",\"triangles\":[{},{}],\"margin\":{},\"brute_poses\":{},\"bvs\":[",
            if i > 0 { "," } else { "" },
            p.name,
            p.tris.0,
            p.tris.1,
            p.margin,
            p.brute_poses
        );
        for (j, r) in p.bvs.iter().enumerate() {
            let c = r.counters;
            let _ = write!(s, "{}{{\"bv\":\"{}\",\"distance_mean_us\":{:.2},\"distance_median_us\":{:.2},\"within_mean_us\":{:.2},\"within_median_us\":{:.2},\"nv\":{:.1},\"np\":{:.1},\"nu\":{:.1},\"within_nv\":{:.1},\"within_np\":{:.1}}}", if j > 0 { "," } else { "" }, r.name, us(mean(&r.distance)), us(median(&r.distance)), us(mean(&r.within)), us(median(&r.within)), c[0], c[1], c[2], c[3], c[4]);
        }
        s.push_str("],\"peers\":[");
        for (j, r) in p.peers.iter().flatten().enumerate() {
            let _ = write!(s, "{}{{\"peer\":\"{}\",\"version\":\"{}\",\"distance_mean_us\":{:.2},\"distance_median_us\":{:.2}}}", if j > 0 { "," } else { "" }, r.name, r.version, r.mean_us, r.median_us);
        }
        s.push_str("]}");
    }
    s.push_str("]}\n");
    s
}

/// Entry point of `proxima-bench w5-distance ...` (`args` after the workload name).
pub fn main(args: impl Iterator<Item = String>) -> ExitCode {
    let args = match parse(args) {
        Ok(a) => a,
        Err(e) => {
            if !e.is_empty() {
                eprintln!("error: {e}");
            }
            eprintln!("{USAGE}");
            return ExitCode::from(2);
        }
    };
    let mut errors = Vec::new();
    let mut runs = Vec::new();
    for name in &args.pairs {
        let spec = *PAIRS
            .iter()
            .find(|p| p.0 == name)
            .expect("checked in parse");
        eprintln!("running {name} ...");
        match run_pair(spec, &args, &mut errors) {
            Ok(r) => runs.push(r),
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        }
    }
    print!(
        "{}",
        if args.json {
            json(&runs, &args)
        } else {
            table(&runs, &args)
        }
    );
    for e in &errors {
        eprintln!("DISAGREEMENT: {e}");
    }
    if errors.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}
