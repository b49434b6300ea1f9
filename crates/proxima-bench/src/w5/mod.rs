//! W5 mesh vs mesh [sources: w5, bvh]: each mesh pair at many relative poses,
//! through every bounding-volume type with SAH trees, beside the peers: parry3d's
//! `TriMesh`, and the C++ libraries FCL 0.7 and coal 3.0 with their OBBRSS and
//! OBB trees ([`peers`], when `scripts/peers.sh` has built their harness).
//!
//! `proxima-bench w5 [--poses FILE] [--pairs rob-env,bunny,...] [--n N] [--seed S]
//! [--brute K] [--rotation auto|refit|conservative] [--clock cpu|wall]
//! [--peers auto|none] [--peer-reps R] [--write-poses DIR] [--json]`
//!
//! - `rob-env` (FCL's test: rob.obj moving, env.obj fixed) uses the pose file
//!   (default `data/rob-env-1000.poses`, FCL's distribution); `skin-ribcage`
//!   (SKINbody moving around and into BONERibcage) 100 poses of
//!   [`poses::generate_nested`]; the other pairs 300 poses of
//!   [`poses::generate`] (`--n` sets the count of every generated pair).
//! - Per bounding volume: build time of each tree, mean and median time per
//!   all-pairs and per first-contact query and their ratios to the fastest peer
//!   of the run (each statistic its own fastest), the mean cost counters
//!   `Nv/Np/Nu` of the all-pairs query, the intersecting triangle pairs summed
//!   over poses, and the poses with a contact. The same for every peer (the C++
//!   peers' times are the harness's wall-clock figures over poses × `--peer-reps`).
//! - `--write-poses DIR` also writes each pair's poses to `DIR/PAIR.poses` (for
//!   `proxima collide --poses` and the peers' harness, e.g. under callgrind).
//! - Checked in the same run (exit code 1 otherwise): every bounding volume finds
//!   the same number of pairs on every pose; first contact hits iff all pairs is
//!   non-empty; on the first `--brute` poses (fewer on big pairs, so that at most
//!   ~10^8 triangle tests run; none on a pair above that) the pair sets equal brute force with the exact
//!   test; every disagreement with parry is confirmed ours by the exact test; the
//!   C++ peers find the same pairs and hits on every pose except for extra pairs
//!   within their touching tolerance ([`peers::run_config`]).

pub mod check;
pub mod ours;
pub mod peers;
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

const USAGE: &str = "usage: proxima-bench w5 [--poses FILE] [--pairs rob-env,bunny,teapot,hand-forearm,skin-ribcage] [--n N] [--seed S] [--brute K] [--rotation auto|refit|conservative] [--clock cpu|wall] [--peers auto|none] [--peer-reps R] [--write-poses DIR] [--json]";

/// The mesh pairs: name, moving mesh, fixed mesh (files in `shared/data/`).
const PAIRS: [(&str, &str, &str); 5] = [
    ("rob-env", "rob.obj", "env.obj"),
    ("bunny", "bunny.obj", "bunny.obj"),
    ("teapot", "teapot.obj", "teapot.obj"),
    ("hand-forearm", "hand_3finger.stl", "forearm.stl"),
    ("skin-ribcage", "SKINbody.stl", "BONERibcage.stl"),
];
const DEFAULT_PAIRS: &str = "rob-env,bunny,teapot,hand-forearm,skin-ribcage";
/// Generated poses per pair (without `--n`): 300, and 100 for the big pair.
fn default_n(pair: &str) -> usize {
    if pair == "skin-ribcage" {
        100
    } else {
        300
    }
}
const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/");
const DEFAULT_POSES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data/rob-env-1000.poses");
/// Cap on brute-force triangle tests per mesh pair.
const BRUTE_BUDGET: usize = 100_000_000;

struct Args {
    poses: String,
    write_poses: Option<String>,
    pairs: Vec<String>,
    n: Option<usize>,
    seed: u64,
    brute: usize,
    rotation: RotationUpdate,
    clock: Clock,
    peers: bool,
    peer_reps: usize,
    json: bool,
}

fn parse(mut it: impl Iterator<Item = String>) -> Result<Args, String> {
    let mut a = Args {
        poses: DEFAULT_POSES.into(),
        write_poses: None,
        pairs: DEFAULT_PAIRS.split(',').map(String::from).collect(),
        n: None,
        seed: 5,
        brute: 20,
        rotation: RotationUpdate::Auto,
        clock: Clock::ThreadCpu,
        peers: true,
        peer_reps: 1,
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
            "--write-poses" => a.write_poses = Some(value("--write-poses")?),
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
            "--n" => a.n = Some(num(value("--n")?)? as usize),
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
            "--peers" => {
                a.peers = match value("--peers")?.as_str() {
                    "auto" => true,
                    "none" => false,
                    o => return Err(format!("--peers takes auto or none, not {o:?}")),
                }
            }
            "--peer-reps" => a.peer_reps = num(value("--peer-reps")?)?.max(1) as usize,
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
    /// The C++ peers, or why they did not run.
    peers: Result<Vec<peers::PeerRun>, String>,
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
    let n = args.n.unwrap_or(default_n(name));
    let poses = match name {
        "rob-env" => {
            let text =
                std::fs::read_to_string(&args.poses).map_err(|e| format!("{}: {e}", args.poses))?;
            poses::parse(&args.poses, &text)?
        }
        "skin-ribcage" => poses::generate_nested(&a, &b, n, args.seed),
        _ => poses::generate(&a, &b, n, args.seed),
    };
    if let Some(dir) = &args.write_poses {
        let path = std::path::Path::new(dir).join(format!("{name}.poses"));
        peers::write_poses(&path, &poses)?;
        eprintln!("  {name}: wrote {}", path.display());
    }
    let brute_poses = args
        .brute
        .min(BRUTE_BUDGET / (a.len() * b.len()))
        .min(poses.len());
    let (c, k, r) = (
        ours::QueryClock::new(args.clock),
        brute_poses,
        args.rotation,
    );
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
    let parry = run_parry(&a, &b, &poses, reference, c)?;
    if parry.d.unverified > 0 {
        errors.push(format!(
            "{name}: {} disagreements with parry not confirmed by the exact test",
            parry.d.unverified
        ));
    }
    let peers = if args.peers {
        run_peers((name, fa, fb), args, (&a, &b, &poses), reference, errors)
    } else {
        Err("--peers none".into())
    };
    Ok(PairRun {
        name,
        tris: (a.len(), b.len()),
        poses: poses.len(),
        brute_poses,
        bvs,
        parry,
        peers,
    })
}

/// Runs every C++ peer configuration on the pair through its harness, or says why
/// not (not built: an `Err` note, not a failure).
fn run_peers(
    (name, fa, fb): (&str, &str, &str),
    args: &Args,
    meshes: (&TriMesh, &TriMesh, &[Affine3A]),
    ours: &BvRun,
    errors: &mut Vec<String>,
) -> Result<Vec<peers::PeerRun>, String> {
    let Some(dir) = peers::harness_dir() else {
        return Err("C++ peers not built (scripts/peers.sh builds them)".into());
    };
    let pose_file =
        std::env::temp_dir().join(format!("proxima-w5-{}-{name}.poses", std::process::id()));
    peers::write_poses(&pose_file, meshes.2)?;
    let (pa, pb) = (format!("{DATA}{fa}"), format!("{DATA}{fb}"));
    let mut out = Vec::new();
    let mut result = Ok(());
    for config in peers::CONFIGS {
        eprintln!("  {name}: {} {} ...", config.0, config.1);
        match peers::run_config(
            &dir,
            config,
            (pa.as_ref(), pb.as_ref()),
            &pose_file,
            args.peer_reps,
            meshes,
            (&ours.counts, &ours.hits),
            errors,
        ) {
            Ok(r) => out.push(r),
            Err(e) => {
                errors.push(format!("{name}: {e}"));
                result = Err(format!("failed: {e}"));
                break;
            }
        }
    }
    let _ = std::fs::remove_file(&pose_file);
    result.map(|()| out)
}

fn run_parry(
    a: &TriMesh,
    b: &TriMesh,
    poses: &[Affine3A],
    ours: &BvRun,
    qc: ours::QueryClock,
) -> Result<ParryRun, String> {
    let (meshes, build) = qc.clock.time(|| ParryMeshes::build(a, b));
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
        let (hit, t) = qc.time(|| meshes.intersects(&pp));
        let hit = hit?;
        r.first.push(t);
        r.hits += hit as usize;
        let (mut pairs, t) = qc.time(|| meshes.all_pairs(&pp));
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

/// A peer's figures in the table's terms: name, build µs per tree, all pairs
/// (median, mean µs), first contact (median, mean µs).
struct PeerFigures {
    name: String,
    build_us: (f64, f64),
    all: (f64, f64),
    first: (f64, f64),
}

/// Every peer of a pair: parry, then the C++ peers that ran.
fn peer_figures(p: &PairRun) -> Vec<PeerFigures> {
    let pr = &p.parry;
    let mut v = vec![PeerFigures {
        name: "parry3d".into(),
        // parry builds both meshes in one call: split evenly is not meaningful,
        // so the whole build is shown under the first and none under the second.
        build_us: (us(pr.build), 0.0),
        all: (us(median(&pr.all)), us(mean(&pr.all))),
        first: (us(median(&pr.first)), us(mean(&pr.first))),
    }];
    if let Ok(peers) = &p.peers {
        v.extend(peers.iter().map(|r| PeerFigures {
            name: r.name.clone(),
            build_us: r.build_us,
            all: r.all,
            first: r.first,
        }));
    }
    v
}

/// The fastest peer on one statistic: (value, name).
fn fastest(peers: &[PeerFigures], stat: impl Fn(&PeerFigures) -> f64) -> (f64, String) {
    peers
        .iter()
        .map(|p| (stat(p), p.name.clone()))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap_or((f64::NAN, String::new()))
}

/// The four denominators: all median, all mean, first median, first mean.
fn denominators(p: &PairRun) -> [(f64, String); 4] {
    let f = peer_figures(p);
    [
        fastest(&f, |x| x.all.0),
        fastest(&f, |x| x.all.1),
        fastest(&f, |x| x.first.0),
        fastest(&f, |x| x.first.1),
    ]
}

fn table(runs: &[PairRun], rotation: RotationUpdate, clock: Clock) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "w5 mesh vs mesh, SAH trees (leaf 1), rotation={:?}, clock={} for ours and parry3d, wall for the C++ peers (their harness); times in µs per query (the clock's own cost beyond a wall-clock reading removed); /best = ours over the fastest peer of this run on that statistic; pair counts checked equal for every BV on every pose", rotation, clock.name());
    for p in runs {
        let d = denominators(p);
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
            "fastest peers: all median {} ({:.1}), all mean {} ({:.1}), first median {} ({:.2}), first mean {} ({:.2})",
            d[0].1, d[0].0, d[1].1, d[1].0, d[2].1, d[2].0, d[3].1, d[3].0
        );
        let _ = writeln!(
            s,
            "{:<12} {:>9} {:>9} {:>9} {:>9} {:>6} {:>6} {:>9} {:>9} {:>6} {:>6} {:>8} {:>7} {:>6} {:>10}",
            "bv",
            "build A",
            "build B",
            "all med",
            "all mean",
            "/best",
            "/best",
            "1st med",
            "1st mean",
            "/best",
            "/best",
            "Nv",
            "Np",
            "Nu",
            "pairs"
        );
        for r in &p.bvs {
            let (am, aa) = (us(median(&r.all)), us(mean(&r.all)));
            let (fm, fa) = (us(median(&r.first)), us(mean(&r.first)));
            let _ = writeln!(
                s,
                "{:<12} {:>9.1} {:>9.1} {:>9.2} {:>9.2} {:>6.2} {:>6.2} {:>9.2} {:>9.2} {:>6.2} {:>6.2} {:>8.0} {:>7.0} {:>6.0} {:>10}",
                r.name,
                us(r.build.0),
                us(r.build.1),
                am,
                aa,
                am / d[0].0,
                aa / d[1].0,
                fm,
                fa,
                fm / d[2].0,
                fa / d[3].0,
                r.nv,
                r.np,
                r.nu,
                r.counts.iter().sum::<u64>()
            );
        }
        for f in peer_figures(p) {
            let (pairs, hits) = if f.name == "parry3d" {
                (p.parry.pair_total, p.parry.hits)
            } else {
                let r = p
                    .peers
                    .as_ref()
                    .ok()
                    .and_then(|v| v.iter().find(|r| r.name == f.name));
                r.map_or((0, 0), |r| {
                    (r.counts.iter().sum(), r.hits.iter().filter(|&&h| h).count())
                })
            };
            let _ = writeln!(
                s,
                "{:<12} {:>9.1} {:>9} {:>9.2} {:>9.2} {:>6} {:>6} {:>9.2} {:>9.2} {:>6} {:>6} {:>8} {:>7} {:>6} {:>10}  hits {}",
                f.name,
                f.build_us.0,
                if f.name == "parry3d" { "-".to_string() } else { format!("{:.1}", f.build_us.1) },
                f.all.0,
                f.all.1,
                "",
                "",
                f.first.0,
                f.first.1,
                "",
                "",
                "-",
                "-",
                "-",
                pairs,
                hits
            );
        }
        let pr = &p.parry;
        let _ = writeln!(s, "parry disagreements (each confirmed ours by the exact test): {} poses first-contact, {} pairs only parry ({} of them apart by parry's own distance query, largest gap {:.2e}), {} pairs only ours", pr.d.bool_poses, pr.d.parry_only, pr.d.parry_only_apart, pr.d.parry_only_max_gap, pr.d.ours_only);
        match &p.peers {
            Ok(v) => {
                for r in v {
                    let _ = writeln!(
                        s,
                        "{} ({}): answers equal to ours on every pose{}",
                        r.name,
                        r.version,
                        if r.tolerance_poses == 0 {
                            String::new()
                        } else {
                            format!(
                                " but {} where it adds {} pairs within its touching tolerance (checked)",
                                r.tolerance_poses, r.tolerance_pairs
                            )
                        }
                    );
                }
            }
            Err(note) => {
                let _ = writeln!(s, "C++ peers: {note}");
            }
        }
    }
    s
}

fn json(runs: &[PairRun], clock: Clock) -> String {
    let mut s = format!(
        "{{\"workload\":\"w5\",\"clock\":\"{}\",\"peer_clock\":\"wall\",\"pairs\":[",
        clock.name()
    );
    for (i, p) in runs.iter().enumerate() {
        let pr = &p.parry;
        let d = denominators(p);
        let _ = write!(
            s,
            "{}{{\"name\":\"{}\",\"triangles\":[{},{}],\"poses\":{},\"brute_poses\":{},\"fastest_peer\":{{\"all_median\":\"{}\",\"all_mean\":\"{}\",\"first_median\":\"{}\",\"first_mean\":\"{}\"}},\"bvs\":[",
            if i > 0 { "," } else { "" },
            p.name,
            p.tris.0,
            p.tris.1,
            p.poses,
            p.brute_poses,
            d[0].1,
            d[1].1,
            d[2].1,
            d[3].1
        );
        for (j, r) in p.bvs.iter().enumerate() {
            let (am, aa) = (us(median(&r.all)), us(mean(&r.all)));
            let (fm, fa) = (us(median(&r.first)), us(mean(&r.first)));
            let _ = write!(s, "{}{{\"bv\":\"{}\",\"build_ms\":[{:.3},{:.3}],\"all_mean_us\":{:.3},\"all_median_us\":{:.3},\"first_mean_us\":{:.3},\"first_median_us\":{:.3},\"all_median_vs_best\":{:.4},\"all_mean_vs_best\":{:.4},\"first_median_vs_best\":{:.4},\"first_mean_vs_best\":{:.4},\"nv\":{:.1},\"np\":{:.1},\"nu\":{:.1},\"pairs\":{},\"hits\":{}}}", if j > 0 { "," } else { "" }, r.name, us(r.build.0) / 1e3, us(r.build.1) / 1e3, aa, am, fa, fm, am / d[0].0, aa / d[1].0, fm / d[2].0, fa / d[3].0, r.nv, r.np, r.nu, r.counts.iter().sum::<u64>(), r.hits.iter().filter(|&&h| h).count());
        }
        let _ = write!(s, "],\"parry\":{{\"build_ms\":{:.3},\"all_mean_us\":{:.3},\"all_median_us\":{:.3},\"first_mean_us\":{:.3},\"first_median_us\":{:.3},\"pairs\":{},\"hits\":{},\"bool_disagreements\":{},\"parry_only_pairs\":{},\"parry_only_max_gap\":{:e},\"ours_only_pairs\":{}}}", pr.build.as_secs_f64() * 1e3, us(mean(&pr.all)), us(median(&pr.all)), us(mean(&pr.first)), us(median(&pr.first)), pr.pair_total, pr.hits, pr.d.bool_poses, pr.d.parry_only, pr.d.parry_only_max_gap, pr.d.ours_only);
        match &p.peers {
            Ok(v) => {
                s.push_str(",\"peers\":[");
                for (j, r) in v.iter().enumerate() {
                    let _ = write!(s, "{}{{\"peer\":\"{}\",\"version\":\"{}\",\"build_ms\":[{:.3},{:.3}],\"all_median_us\":{:.3},\"all_mean_us\":{:.3},\"first_median_us\":{:.3},\"first_mean_us\":{:.3},\"pairs\":{},\"hits\":{},\"tolerance_poses\":{},\"tolerance_pairs\":{}}}", if j > 0 { "," } else { "" }, r.name, r.version, r.build_us.0 / 1e3, r.build_us.1 / 1e3, r.all.0, r.all.1, r.first.0, r.first.1, r.counts.iter().sum::<u64>(), r.hits.iter().filter(|&&h| h).count(), r.tolerance_poses, r.tolerance_pairs);
                }
                s.push_str("]}");
            }
            Err(note) => {
                let _ = write!(
                    s,
                    ",\"peers\":null,\"peers_note\":\"{}\"}}",
                    note.replace('"', "'")
                );
            }
        }
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
