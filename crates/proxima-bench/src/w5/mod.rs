//! W5 mesh vs mesh [sources: w5, bvh]: each mesh pair at many relative poses,
//! through every bounding-volume type with SAH trees, and parry3d's `TriMesh` as
//! the peer.
//!
//! `proxima-bench w5 [--poses FILE] [--pairs rob-env,bunny,...] [--n N] [--seed S]
//! [--brute K] [--rotation auto|refit|conservative] [--clock cpu|wall] [--json]`
//!
//! - `rob-env` (FCL's test: rob.obj moving, env.obj fixed) uses the pose file
//!   (default `data/rob-env-1000.poses`, FCL's distribution); the other pairs use
//!   `--n` generated poses ([`poses::generate`]).
//! - Per bounding volume: build time of both trees, mean and median time per
//!   all-pairs and per first-contact query, the mean cost counters `Nv/Np/Nu` of
//!   the all-pairs query, the intersecting triangle pairs summed over poses, and
//!   the poses with a contact.
//! - Checked in the same run (exit code 1 otherwise): every bounding volume finds
//!   the same number of pairs on every pose; first contact hits iff all pairs is
//!   non-empty; on the first `--brute` poses (fewer on big pairs, so that at most
//!   ~10^8 triangle tests run; none on a pair above that) the pair sets equal brute force with the exact
//!   test; every disagreement with parry is confirmed ours by the exact test.

pub mod check;
pub mod ours;
pub mod poses;

use crate::parry_mesh::{self, ParryMeshes};
use crate::run::{median, Clock};
use check::Disagreements;
use ours::BvRun;
use proxima::geom::{Aabb, Sphere};
use proxima::glam::Affine3A;
use proxima::narrow::{Kdop14, Kdop18, Kdop26, Mesh, Obb, RotationUpdate, TriMesh};
use std::fmt::Write as _;
use std::process::ExitCode;
use std::time::Duration;

const USAGE: &str = "usage: proxima-bench w5 [--poses FILE] [--pairs rob-env,bunny,teapot,hand-forearm,skin-ribcage] [--n N] [--seed S] [--brute K] [--rotation auto|refit|conservative] [--clock cpu|wall] [--json]";

/// The mesh pairs: name, moving mesh, fixed mesh (files in `shared/data/`).
const PAIRS: [(&str, &str, &str); 5] = [
    ("rob-env", "rob.obj", "env.obj"),
    ("bunny", "bunny.obj", "bunny.obj"),
    ("teapot", "teapot.obj", "teapot.obj"),
    ("hand-forearm", "hand_3finger.stl", "forearm.stl"),
    ("skin-ribcage", "SKINbody.stl", "BONERibcage.stl"),
];
const DEFAULT_PAIRS: &str = "rob-env,bunny,teapot,hand-forearm";
const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/");
const DEFAULT_POSES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data/rob-env-1000.poses");
/// Cap on brute-force triangle tests per mesh pair.
const BRUTE_BUDGET: usize = 100_000_000;

struct Args {
    poses: String,
    pairs: Vec<String>,
    n: usize,
    seed: u64,
    brute: usize,
    rotation: RotationUpdate,
    clock: Clock,
    json: bool,
}

fn parse(mut it: impl Iterator<Item = String>) -> Result<Args, String> {
    let mut a = Args {
        poses: DEFAULT_POSES.into(),
        pairs: DEFAULT_PAIRS.split(',').map(String::from).collect(),
        n: 200,
        seed: 5,
        brute: 20,
        rotation: RotationUpdate::Auto,
        clock: Clock::ThreadCpu,
        json: false,
    };
    let num = |s: String| {
        s.replace('_', "")
            .parse::<u64>()
            .map_err(|_| format!("not a number: {s:?}"))
    };
    while let Some(flag) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match flag.as_str() {
            "--poses" => a.poses = value("--poses")?,
            "--pairs" => {
                a.pairs = value("--pairs")?
                    .split(',')
                    .filter(|s| !s.is_empty())
                    .map(String::from)
                    .collect();
                if let Some(p) = a
                    .pairs
                    .iter()
                    .find(|p| !PAIRS.iter().any(|q| q.0 == p.as_str()))
                {
                    return Err(format!("unknown mesh pair {p:?}"));
                }
            }
            "--n" => a.n = num(value("--n")?)? as usize,
            "--seed" => a.seed = num(value("--seed")?)?,
            "--brute" => a.brute = num(value("--brute")?)? as usize,
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
            "--json" => a.json = true,
            "-h" | "--help" => return Err(String::new()),
            o => return Err(format!("unknown argument {o:?}")),
        }
    }
    Ok(a)
}

/// parry's figures on one mesh pair.
struct ParryRun {
    build: Duration,
    all: Vec<Duration>,
    first: Vec<Duration>,
    pair_total: u64,
    hits: usize,
    d: Disagreements,
}

/// Everything measured on one mesh pair.
struct PairRun {
    name: &'static str,
    tris: (usize, usize),
    poses: usize,
    brute_poses: usize,
    bvs: Vec<BvRun>,
    parry: ParryRun,
}

fn mean(d: &[Duration]) -> Duration {
    d.iter().sum::<Duration>() / d.len().max(1) as u32
}

fn us(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}

fn load(file: &str) -> Result<TriMesh, String> {
    let path = format!("{DATA}{file}");
    proxima::io::load(&path).map_err(|e| format!("{path}: {e}"))
}

/// Runs one mesh pair; `errors` collects every failed check.
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
    let brute_poses = args
        .brute
        .min(BRUTE_BUDGET / (a.len() * b.len()))
        .min(poses.len());
    let (c, k, r) = (args.clock, brute_poses, args.rotation);
    let mut bvs = Vec::new();
    for bv in ["aabb", "kdop14", "kdop18", "kdop26", "obb", "sphere"] {
        eprintln!("  {name}: {bv} ...");
        bvs.push(match bv {
            "aabb" => ours::measure::<Aabb>(&a, &b, &poses, c, k, r)?,
            "kdop14" => ours::measure::<Kdop14>(&a, &b, &poses, c, k, r)?,
            "kdop18" => ours::measure::<Kdop18>(&a, &b, &poses, c, k, r)?,
            "kdop26" => ours::measure::<Kdop26>(&a, &b, &poses, c, k, r)?,
            "obb" => ours::measure::<Obb>(&a, &b, &poses, c, k, r)?,
            _ => ours::measure::<Sphere>(&a, &b, &poses, c, k, r)?,
        });
    }
    // Every volume: same count on every pose, first contact consistent.
    let reference = &bvs[0];
    for r in &bvs {
        for (i, (&n, &hit)) in r.counts.iter().zip(&r.hits).enumerate() {
            if n != reference.counts[i] {
                errors.push(format!(
                    "{name} pose {i}: {} finds {n} pairs, {} finds {}",
                    r.name, reference.name, reference.counts[i]
                ));
            }
            if hit != (n > 0) {
                errors.push(format!(
                    "{name} pose {i}: {} first contact {hit} but {n} pairs",
                    r.name
                ));
            }
        }
    }
    // Brute force on a sample of poses.
    eprintln!("  {name}: brute force on {brute_poses} poses ...");
    for (i, pose) in poses.iter().take(brute_poses).enumerate() {
        let want = check::brute_pairs(&a, pose, &b);
        for r in &bvs {
            if r.sample[i] != want {
                errors.push(format!(
                    "{name} pose {i}: {} pairs differ from brute force ({} vs {})",
                    r.name,
                    r.sample[i].len(),
                    want.len()
                ));
            }
        }
    }
    eprintln!("  {name}: parry3d ...");
    let parry = run_parry(&a, &b, &poses, reference, args.clock)?;
    if parry.d.unverified > 0 {
        errors.push(format!(
            "{name}: {} disagreements with parry not confirmed by the exact test",
            parry.d.unverified
        ));
    }
    Ok(PairRun {
        name,
        tris: (a.len(), b.len()),
        poses: poses.len(),
        brute_poses,
        bvs,
        parry,
    })
}

fn run_parry(
    a: &TriMesh,
    b: &TriMesh,
    poses: &[Affine3A],
    ours: &BvRun,
    clock: Clock,
) -> Result<ParryRun, String> {
    let (meshes, build) = clock.time(|| ParryMeshes::build(a, b));
    let meshes = meshes?;
    let mut r = ParryRun {
        build,
        all: Vec::new(),
        first: Vec::new(),
        pair_total: 0,
        hits: 0,
        d: Disagreements::default(),
    };
    // Our pairs per pose again (sorted), for the pair-level comparison: taken
    // from the exact oracle of the collider, untimed.
    let opts = proxima::narrow::BuildOptions::default();
    let ma = Mesh::<Obb>::from_trimesh(a.clone(), opts).map_err(|e| e.to_string())?;
    let mb = Mesh::<Obb>::from_trimesh(b.clone(), opts).map_err(|e| e.to_string())?;
    let mut col = proxima::narrow::Collider::<Obb>::default();
    for (i, p) in poses.iter().enumerate() {
        let pp = parry_mesh::pose(p);
        let (hit, t) = clock.time(|| meshes.intersects(&pp));
        let hit = hit?;
        r.first.push(t);
        r.hits += hit as usize;
        let (mut pairs, t) = clock.time(|| meshes.all_pairs(&pp));
        r.all.push(t);
        r.pair_total += pairs.len() as u64;
        pairs.sort_unstable();
        let mut mine = col.all_pairs(&ma, p, &mb).map_err(|e| e.to_string())?.pairs;
        mine.sort_unstable();
        if mine.len() as u64 != ours.counts[i] {
            return Err(format!("pose {i}: OBB recount differs"));
        }
        for (i, j) in check::compare_pairs(a, p, b, &mine, &pairs, &mut r.d) {
            let gap = meshes.triangle_distance(&pp, i, j);
            r.d.parry_only_max_gap = r.d.parry_only_max_gap.max(gap);
            r.d.parry_only_apart += (gap > 0.0) as usize;
        }
        if hit != ours.hits[i] {
            r.d.bool_poses += 1;
            // Ours says contact: its pairs are exact-test positives (checked in
            // compare_pairs). Ours says none: brute force must agree.
            if !ours.hits[i] && !check::brute_pairs(a, p, b).is_empty() {
                r.d.unverified += 1;
            }
        }
    }
    Ok(r)
}

fn table(runs: &[PairRun], rotation: RotationUpdate, clock: Clock) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "w5 mesh vs mesh, SAH trees (leaf 1), rotation={:?}, clock={} (times per query; vs parry = our median / parry median; pair counts checked equal for every BV on every pose)", rotation, clock.name());
    for p in runs {
        let pr = &p.parry;
        let (pa, pf) = (median(&pr.all), median(&pr.first));
        let _ = writeln!(
            s,
            "\n{} ({} x {} triangles, {} poses, brute-force checked on {}; contact on {} poses)",
            p.name,
            p.tris.0,
            p.tris.1,
            p.poses,
            p.brute_poses,
            p.bvs[0].hits.iter().filter(|&&h| h).count()
        );
        let _ = writeln!(
            s,
            "{:<8} {:>9} {:>10} {:>10} {:>8} {:>10} {:>10} {:>8} {:>9} {:>8} {:>7} {:>10}",
            "bv",
            "build ms",
            "all mean",
            "all med",
            "vs parry",
            "first mean",
            "first med",
            "vs parry",
            "Nv",
            "Np",
            "Nu",
            "pairs"
        );
        for r in &p.bvs {
            let (am, fm) = (median(&r.all), median(&r.first));
            let _ = writeln!(s, "{:<8} {:>9.2} {:>10.1} {:>10.1} {:>8.2} {:>10.1} {:>10.1} {:>8.2} {:>9.0} {:>8.0} {:>7.0} {:>10}", r.name, r.build.as_secs_f64() * 1e3, us(mean(&r.all)), us(am), us(am) / us(pa), us(mean(&r.first)), us(fm), us(fm) / us(pf), r.nv, r.np, r.nu, r.counts.iter().sum::<u64>());
        }
        let _ = writeln!(s, "{:<8} {:>9.2} {:>10.1} {:>10.1} {:>8} {:>10.1} {:>10.1} {:>8} {:>9} {:>8} {:>7} {:>10}", "parry", pr.build.as_secs_f64() * 1e3, us(mean(&pr.all)), us(pa), "1.00", us(mean(&pr.first)), us(pf), "1.00", "-", "-", "-", pr.pair_total);
        let _ = writeln!(s, "parry disagreements (each confirmed ours by the exact test): {} poses first-contact, {} pairs only parry ({} of them apart by parry's own distance query, largest gap {:.2e}), {} pairs only ours", pr.d.bool_poses, pr.d.parry_only, pr.d.parry_only_apart, pr.d.parry_only_max_gap, pr.d.ours_only);
    }
    s
}

fn json(runs: &[PairRun], clock: Clock) -> String {
    let mut s = format!(
        "{{\"workload\":\"w5\",\"clock\":\"{}\",\"pairs\":[",
        clock.name()
    );
    for (i, p) in runs.iter().enumerate() {
        let pr = &p.parry;
        let _ = write!(
            s,
            "{}{{\"name\":\"{}\",\"triangles\":[{},{}],\"poses\":{},\"brute_poses\":{},\"bvs\":[",
            if i > 0 { "," } else { "" },
            p.name,
            p.tris.0,
            p.tris.1,
            p.poses,
            p.brute_poses
        );
        for (j, r) in p.bvs.iter().enumerate() {
            let _ = write!(s, "{}{{\"bv\":\"{}\",\"build_ms\":{:.3},\"all_mean_us\":{:.2},\"all_median_us\":{:.2},\"first_mean_us\":{:.2},\"first_median_us\":{:.2},\"nv\":{:.1},\"np\":{:.1},\"nu\":{:.1},\"pairs\":{},\"hits\":{}}}", if j > 0 { "," } else { "" }, r.name, r.build.as_secs_f64() * 1e3, us(mean(&r.all)), us(median(&r.all)), us(mean(&r.first)), us(median(&r.first)), r.nv, r.np, r.nu, r.counts.iter().sum::<u64>(), r.hits.iter().filter(|&&h| h).count());
        }
        let _ = write!(s, "],\"parry\":{{\"build_ms\":{:.3},\"all_mean_us\":{:.2},\"all_median_us\":{:.2},\"first_mean_us\":{:.2},\"first_median_us\":{:.2},\"pairs\":{},\"hits\":{},\"bool_disagreements\":{},\"parry_only_pairs\":{},\"parry_only_max_gap\":{:e},\"ours_only_pairs\":{}}}}}", pr.build.as_secs_f64() * 1e3, us(mean(&pr.all)), us(median(&pr.all)), us(mean(&pr.first)), us(median(&pr.first)), pr.pair_total, pr.hits, pr.d.bool_poses, pr.d.parry_only, pr.d.parry_only_max_gap, pr.d.ours_only);
    }
    s.push_str("]}\n");
    s
}

/// Entry point of `proxima-bench w5 ...` (`args` after the workload name).
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
            json(&runs, args.clock)
        } else {
            table(&runs, args.rotation, args.clock)
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
