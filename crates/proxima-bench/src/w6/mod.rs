//! W6, rays vs one mesh [sources: w6]: `proxima-bench w6 [--mesh NAME,NAME]
//! [--rays R] [--threads 1,2] [--repeats N] [--leaf L] [--seed S] [--only A,B]
//! [--clock cpu|wall] [--json] [--no-embree] [--rays-out DIR]` (`--rays-out`
//! writes each mesh's rays to `DIR/MESH.rays` in the harness's format).
//!
//! For each mesh of `shared/data` (or `--mesh`), R rays ([`rays::rays`]) go through
//! every structure ([`structures::entries`]): build time, median time per ray over
//! the repeats on one thread (thread CPU time by default; the structures take
//! turns, one batch each per round, so load from elsewhere hits them alike), the same batch on a
//! rayon pool of each `--threads` size (wall time: several threads), hits, and the
//! ratio to obvhs. In the same run every answer is checked ([`check`]): Proxima's
//! structures must agree exactly with each other and with brute force (on a subset,
//! and on every ray a peer disagrees on); peers may differ on grazing rays (their
//! `f32` Möller tests are not watertight), and those rays are counted.
//!
//! Embree runs in the same run when `scripts/peers.sh` built its harness
//! ([`embree`]; a note otherwise): its answers are checked like a peer's (hit/miss
//! equal, `t` within 1e-5 relative, another triangle allowed at an equal `t`), and
//! its fastest mode on one thread and on K threads (each `--threads` value) and its
//! build time (Embree's own threads) sit in the table; `vs embree` divides our time
//! per ray by its fastest one-thread mode, `par vs embree` our batch on the most
//! threads by its fastest mode on as many.

pub mod bvh_peer;
pub mod caster;
pub mod check;
pub mod embree;
pub mod obvhs_peer;
pub mod parry_mesh_peer;
pub mod rays;
pub mod structures;

use crate::run::{median, num, Clock};
use check::{Tol, Verdict, Verifier};
use proxima::geom::Ray;
use proxima::narrow::{BuildOptions, SplitRule, TriMesh};
use std::fmt::Write;
use std::process::ExitCode;
use std::time::Duration;

const USAGE: &str = "usage: proxima-bench w6 [--mesh NAME,NAME] [--rays R] [--threads 1,2] [--repeats N] [--leaf L] [--seed S] [--only A,B] [--clock cpu|wall] [--json] [--no-embree] [--rays-out DIR]";

/// The Embree row's name.
pub const EMBREE: &str = "embree";
/// Relative tolerance on Embree's `t` (the brief's; its `f32` Möller test vs our
/// exact one).
const EMBREE_T_TOL: f32 = 1e-5;

/// The default meshes (`shared/data`).
pub const MESHES: [&str; 5] = [
    "bunny.obj",
    "teapot.obj",
    "env.obj",
    "SKINbody.stl",
    "BONERibcage.stl",
];

/// Rays brute force runs on (it costs a full mesh pass per ray).
const BRUTE_RAYS: usize = 500;

struct Args {
    meshes: Vec<String>,
    rays: usize,
    threads: Vec<usize>,
    repeats: usize,
    leaf: usize,
    seed: u64,
    only: Vec<String>,
    clock: Clock,
    json: bool,
    embree: bool,
    rays_out: Option<String>,
}

fn list(s: &str) -> Vec<String> {
    s.split(',')
        .filter(|s| !s.is_empty())
        .map(String::from)
        .collect()
}

fn parse(mut it: impl Iterator<Item = String>) -> Result<Args, String> {
    let mut a = Args {
        meshes: MESHES.iter().map(|s| s.to_string()).collect(),
        rays: 100_000,
        threads: vec![1, 2],
        repeats: 5,
        leaf: 4,
        seed: 1,
        only: Vec::new(),
        clock: Clock::ThreadCpu,
        json: false,
        embree: true,
        rays_out: None,
    };
    while let Some(flag) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match flag.as_str() {
            "--mesh" => a.meshes = list(&value("--mesh")?),
            "--rays" => a.rays = num(&value("--rays")?)?,
            "--threads" => {
                a.threads = list(&value("--threads")?)
                    .iter()
                    .map(|s| num(s))
                    .collect::<Result<_, _>>()?
            }
            "--repeats" => a.repeats = num(&value("--repeats")?)?,
            "--leaf" => a.leaf = num(&value("--leaf")?)?,
            "--seed" => a.seed = num(&value("--seed")?)?,
            "--only" => a.only = list(&value("--only")?),
            "--clock" => a.clock = Clock::parse(&value("--clock")?)?,
            "--json" => a.json = true,
            "--no-embree" => a.embree = false,
            "--rays-out" => a.rays_out = Some(value("--rays-out")?),
            "-h" | "--help" => return Err(String::new()),
            o => return Err(format!("unknown argument {o:?}")),
        }
    }
    if a.rays == 0 || a.repeats == 0 || a.leaf == 0 || a.threads.contains(&0) {
        return Err("--rays, --repeats, --leaf and thread counts must be at least 1".into());
    }
    Ok(a)
}

/// What one structure measured on one mesh.
pub struct Row {
    /// Structure name.
    pub name: &'static str,
    /// Peer crate.
    pub peer: bool,
    /// Rays cast.
    pub rays: usize,
    /// Build time.
    pub build: Duration,
    /// Median time per ray, one thread.
    pub per_ray: Duration,
    /// Median wall time per ray of the parallel batch, per thread count.
    pub par: Vec<(usize, Duration)>,
    /// Rays that hit.
    pub hits: usize,
    /// The agreement check.
    pub verdict: Verdict,
    /// For Embree: its modes' times per ray, one line.
    pub note: Option<String>,
}

fn per_ray(d: Duration, n: usize) -> Duration {
    d / n.max(1) as u32
}

/// Embree's row (its harness on the mesh file `path`, once per thread count), or
/// `None` when its harness is not built or `--only` leaves it out.
fn embree_row(
    a: &Args,
    path: &str,
    rays: &[Ray],
    verifier: &mut Verifier,
) -> Result<Option<Row>, String> {
    if !a.embree || !(a.only.is_empty() || a.only.iter().any(|o| o == EMBREE)) {
        return Ok(None);
    }
    let Some(bin) = embree::find() else {
        eprintln!("  embree: no harness (scripts/peers.sh builds it); column left out");
        return Ok(None);
    };
    eprintln!("  {EMBREE} ({}) ...", bin.display());
    let cpu = a.clock == Clock::ThreadCpu;
    let mut first: Option<embree::EmbreeRun> = None;
    let mut par = Vec::new();
    let mut notes = Vec::new();
    for &k in &a.threads {
        let r = embree::run(&bin, path, rays, k, a.repeats, cpu)?;
        let many = r.best_many().ok_or("w6_rays: no modes")?;
        par.push((k, many.many));
        notes.push(format!("{k}T {}", many.name));
        if first.is_none() {
            first = Some(r);
        }
    }
    let Some(r) = first else { return Ok(None) };
    let best = r.best_one().ok_or("w6_rays: no modes")?;
    let modes: Vec<String> = r
        .modes
        .iter()
        .map(|m| format!("{} {:.3}/{:.3}", m.name, us(m.one), us(m.many)))
        .collect();
    let verdict = verifier.check_within(EMBREE, true, &r.answers, Tol::Relative(EMBREE_T_TOL))?;
    Ok(Some(Row {
        name: EMBREE,
        peer: true,
        rays: rays.len(),
        build: r.build,
        per_ray: best.one,
        par,
        hits: r.answers.iter().filter(|h| h.is_some()).count(),
        verdict,
        note: Some(format!(
            "{}: fastest on 1 thread: {}; on K threads: {}; us/ray 1T/{}T per mode: {}; build on Embree's own threads",
            r.lib,
            best.name,
            notes.join(", "),
            r.threads,
            modes.join(", ")
        )),
    }))
}

fn run_mesh(a: &Args, path: &str, mesh: &TriMesh, out: &mut Vec<Row>) -> Result<(), String> {
    let rays = rays::rays(mesh, a.rays, a.seed);
    if let Some(dir) = &a.rays_out {
        // The ray set in the harness's format, to profile a peer on it alone.
        let stem = path.rsplit('/').next().unwrap_or(path);
        let file = format!("{dir}/{stem}.rays");
        std::fs::write(&file, embree::encode(&rays)).map_err(|e| format!("{file}: {e}"))?;
    }
    let brute_n = BRUTE_RAYS.min(rays.len());
    let opts = BuildOptions {
        split: SplitRule::Sah,
        leaf_size: a.leaf,
    };
    let mut verifier = Verifier::new(mesh, &rays);
    // Build everything first, then time the structures round-robin, one batch
    // each per round: a burst of load from elsewhere on the machine then lands on
    // every structure alike instead of on whichever was running, so the ratios
    // of one run are steadier than with each structure's repeats back to back.
    let mut built = Vec::new();
    for e in structures::entries() {
        if !a.only.is_empty() && !a.only.iter().any(|o| o == e.name) {
            continue;
        }
        eprintln!("  {} ...", e.name);
        let (s, build) = a.clock.time(|| (e.make)(mesh, opts));
        let set: &[Ray] = if e.subset { &rays[..brute_n] } else { &rays };
        built.push((e, s, build, set, Vec::with_capacity(a.repeats), Vec::new()));
    }
    for round in 0..a.repeats {
        for (e, s, _, set, times, res) in built.iter_mut() {
            // The subset (brute force) runs once: it is the check, not a peer.
            if e.subset && round > 0 {
                continue;
            }
            let (r, t) = a
                .clock
                .time(|| set.iter().map(|r| s.cast(r)).collect::<Vec<_>>());
            times.push(t);
            *res = r;
        }
    }
    for (e, s, build, set, times, res) in built {
        let mut par = Vec::new();
        if !e.subset {
            for &k in &a.threads {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(k)
                    .build()
                    .map_err(|e| e.to_string())?;
                let mut pt = Vec::with_capacity(a.repeats);
                for _ in 0..a.repeats {
                    let (r, t) = Clock::Wall.time(|| pool.install(|| s.cast_par(set)));
                    if r != res {
                        return Err(format!(
                            "{}: parallel batch differs from sequential",
                            e.name
                        ));
                    }
                    pt.push(t);
                }
                par.push((k, per_ray(median(&pt), set.len())));
            }
        }
        let verdict = verifier.check(e.name, e.peer, &res)?;
        out.push(Row {
            name: e.name,
            peer: e.peer,
            rays: set.len(),
            build,
            per_ray: per_ray(median(&times), set.len()),
            par,
            hits: res.iter().filter(|h| h.is_some()).count(),
            verdict,
            note: None,
        });
    }
    if let Some(row) = embree_row(a, path, &rays, &mut verifier)? {
        out.push(row);
    }
    Ok(())
}

fn us(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}

fn ratio_to(r: &Row, rows: &[Row], peer: &str) -> Option<f64> {
    let o = rows.iter().find(|x| x.name == peer)?;
    (o.per_ray > Duration::ZERO).then(|| us(r.per_ray) / us(o.per_ray))
}

fn ratio(r: &Row, rows: &[Row]) -> Option<f64> {
    ratio_to(r, rows, structures::OBVHS)
}

/// Our batch on `k` threads over Embree's fastest mode on as many.
fn par_ratio(r: &Row, rows: &[Row], k: usize) -> Option<f64> {
    let e = rows.iter().find(|x| x.name == EMBREE)?;
    let ours = r.par.iter().find(|p| p.0 == k)?.1;
    let theirs = e.par.iter().find(|p| p.0 == k)?.1;
    (theirs > Duration::ZERO).then(|| us(ours) / us(theirs))
}

fn fmt_ratio(x: Option<f64>) -> String {
    x.map_or("-".into(), |x| format!("{x:.2}x"))
}

fn table(rows: &[Row], threads: &[usize]) -> String {
    let mut s = String::new();
    let kmax = threads.iter().copied().max().unwrap_or(1);
    let embree = rows.iter().any(|r| r.name == EMBREE);
    let _ = write!(
        s,
        "{:<16} {:>9} {:>8} {:>9}",
        "structure", "build ms", "rays", "us/ray"
    );
    for k in threads {
        let _ = write!(s, " {:>9}", format!("par{k}T"));
    }
    let _ = write!(s, " {:>8} {:>9} {:>9}", "hits", "disagree", "vs obvhs");
    if embree {
        let _ = write!(s, " {:>9} {:>11}", "vs embree", format!("par{kmax}T vs e"));
    }
    let _ = writeln!(s);
    for r in rows {
        let _ = write!(
            s,
            "{:<16} {:>9.2} {:>8} {:>9.3}",
            r.name,
            r.build.as_secs_f64() * 1e3,
            r.rays,
            us(r.per_ray)
        );
        for k in threads {
            match r.par.iter().find(|p| p.0 == *k) {
                Some(p) => {
                    let _ = write!(s, " {:>9.3}", us(p.1));
                }
                None => {
                    let _ = write!(s, " {:>9}", "-");
                }
            }
        }
        let ratio = fmt_ratio(ratio(r, rows));
        let _ = write!(s, " {:>8} {:>9} {:>9}", r.hits, r.verdict.disagree, ratio);
        if embree {
            let e = fmt_ratio(ratio_to(r, rows, EMBREE));
            let _ = write!(s, " {:>9} {:>11}", e, fmt_ratio(par_ratio(r, rows, kmax)));
        }
        let _ = writeln!(s);
    }
    for r in rows {
        if let Some(n) = &r.note {
            let _ = writeln!(s, "  {}", n);
        }
    }
    for r in rows.iter().filter(|r| r.verdict.disagree > 0) {
        let _ = writeln!(s, "  {}: {}", r.name, r.verdict.explain());
    }
    s
}

fn json(mesh: &str, rows: &[Row], threads: &[usize], out: &mut String) {
    let kmax = threads.iter().copied().max().unwrap_or(1);
    let js = |x: Option<f64>| x.map_or("null".into(), |x| format!("{x:.4}"));
    for r in rows {
        let par: Vec<String> = r
            .par
            .iter()
            .map(|(k, d)| format!("\"{k}\": {:.4}", us(*d)))
            .collect();
        let _ = writeln!(
            out,
            "{{\"workload\": \"w6\", \"mesh\": \"{mesh}\", \"structure\": \"{}\", \"peer\": {}, \"rays\": {}, \"build_ms\": {:.4}, \"us_per_ray\": {:.4}, \"par_us_per_ray\": {{{}}}, \"hits\": {}, \"disagree\": {}, \"vs_obvhs\": {}, \"vs_embree\": {}, \"par_vs_embree\": {}, \"note\": {:?}}},",
            r.name,
            r.peer,
            r.rays,
            r.build.as_secs_f64() * 1e3,
            us(r.per_ray),
            par.join(", "),
            r.hits,
            r.verdict.disagree,
            js(ratio(r, rows)),
            js(ratio_to(r, rows, EMBREE)),
            js(par_ratio(r, rows, kmax)),
            r.note.as_deref().unwrap_or("")
        );
    }
}

fn data_dir() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/").to_string()
}

/// Runs W6 with the arguments after `w6`; the exit code is 1 on any disagreement
/// that is not explained (ours vs brute force, or a peer beyond its tolerance).
pub fn main(args: impl Iterator<Item = String>) -> ExitCode {
    let a = match parse(args) {
        Ok(a) => a,
        Err(e) => {
            if !e.is_empty() {
                eprintln!("error: {e}");
            }
            eprintln!("{USAGE}");
            return ExitCode::from(2);
        }
    };
    let mut js = String::from("[\n");
    for name in &a.meshes {
        let path = if name.contains('/') {
            name.clone()
        } else {
            format!("{}{name}", data_dir())
        };
        let mesh = match proxima::io::load(&path) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("error: {path}: {e}");
                return ExitCode::from(2);
            }
        };
        eprintln!("{name} ({} triangles):", mesh.len());
        let mut rows = Vec::new();
        if let Err(e) = run_mesh(&a, &path, &mesh, &mut rows) {
            eprintln!("W6 CHECK FAILED on {name}: {e}");
            return ExitCode::from(1);
        }
        if a.json {
            json(name, &rows, &a.threads, &mut js);
        } else {
            println!(
                "w6 {name} tris={} rays={} seed={} leaf={} clock={} (us/ray: median of {} on one thread; parKT: rayon batch on K threads, wall)",
                mesh.len(),
                a.rays,
                a.seed,
                a.leaf,
                a.clock.name(),
                a.repeats
            );
            print!("{}", table(&rows, &a.threads));
        }
    }
    if a.json {
        if js.ends_with(",\n") {
            js.truncate(js.len() - 2);
            js.push('\n');
        }
        js.push_str("]\n");
        print!("{js}");
    }
    ExitCode::SUCCESS
}
