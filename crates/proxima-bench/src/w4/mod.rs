//! `proxima-bench w4 [--n N] [--queries Q] [--frusta F] [--reps R] [--threads K] [--seed S] [--clock cpu|wall] [--only A,B] [--order morton|input] [--json]`
//!
//! W4 [sources: w4]: queries on a static set. W1's spheres (radii in `[0.5, 2]`,
//! centres uniform in a cube of side `4·N^(1/3)`) are loaded once into every
//! structure (build timed; Proxima's indices are loaded by inserting in Morton
//! order of the centres, `--order input` for the generated order), then each
//! query kind runs as a batch ([`queries`]), `R` rounds in which the structures take
//! turns, one batch each (so load from elsewhere hits them alike); the table gives the median batch time per query, the hits per batch
//! (checked equal across all structures — exit 1 otherwise), bytes per object and
//! the time relative to the best peer for that kind.
//!
//! `--threads 1` (default) runs every batch on the calling thread, timed with its
//! CPU time (or `--clock wall`); `--threads K > 1` runs every batch on a K-thread
//! rayon pool (Proxima through `broad::par_query_counts`, the peers through a
//! `par_iter` over the same per-query calls), timed on the wall clock.

pub mod bvh_peer;
pub mod engine;
pub mod kiddo_peer;
pub mod parry_peer;
pub mod queries;
pub mod rstar_peer;

use crate::registry::QUADRATIC_LIMIT;
use crate::run::{median, num, Clock};
use engine::{Engine, Proxima};
use parry3d::partitioning::BvhBuildStrategy;
use proxima::broad::IndexKind;
use proxima_harness::workloads::{cube_side, Kind, Scene, Workload};
use queries::QueryKind;
use std::fmt::Write;
use std::time::Duration;

const USAGE: &str = "usage: proxima-bench w4 [--n N] [--queries Q] [--frusta F] [--reps R] [--threads K] [--seed S] [--clock cpu|wall] [--only A,B] [--order morton|input] [--json]";

/// W4's options.
#[derive(Clone, Debug)]
pub struct Args {
    /// Number of spheres.
    pub n: usize,
    /// Sphere, box and ray queries per batch.
    pub queries: usize,
    /// Frusta per batch.
    pub frusta: usize,
    /// Repetitions of every batch (the median is reported).
    pub reps: usize,
    /// Threads of the pool the batches run on (1 = the calling thread).
    pub threads: usize,
    /// Seed of the set and the queries.
    pub seed: u64,
    /// Clock for single-threaded runs.
    pub clock: Clock,
    /// JSON instead of the table.
    pub json: bool,
    /// Only these structures (all when empty).
    pub only: Vec<String>,
    /// Insert into Proxima's indices in Morton order (`--order morton`, the
    /// default) or in input order (`--order input`).
    pub morton: bool,
}

/// Parses the arguments after `w4`.
pub fn parse(mut it: impl Iterator<Item = String>) -> Result<Args, String> {
    let mut a = Args {
        n: 100_000,
        queries: 10_000,
        frusta: 200,
        reps: 5,
        threads: 1,
        seed: 1,
        clock: Clock::ThreadCpu,
        json: false,
        only: Vec::new(),
        morton: true,
    };
    while let Some(flag) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match flag.as_str() {
            "--n" => a.n = num(&value("--n")?)?,
            "--queries" => a.queries = num(&value("--queries")?)?,
            "--frusta" => a.frusta = num(&value("--frusta")?)?,
            "--reps" => a.reps = num(&value("--reps")?)?,
            "--threads" => a.threads = num(&value("--threads")?)?,
            "--seed" => a.seed = num(&value("--seed")?)?,
            "--clock" => a.clock = Clock::parse(&value("--clock")?)?,
            "--json" => a.json = true,
            "--order" => {
                a.morton = match value("--order")?.as_str() {
                    "morton" => true,
                    "input" => false,
                    other => return Err(format!("--order takes morton or input, not {other:?}")),
                }
            }
            "--only" => {
                a.only = value("--only")?
                    .split(',')
                    .filter(|s| !s.is_empty())
                    .map(String::from)
                    .collect()
            }
            "-h" | "--help" => return Err(String::new()),
            other => return Err(format!("unknown argument {other:?}")),
        }
    }
    if a.reps == 0 || a.threads == 0 || a.n == 0 {
        return Err("--n, --reps and --threads must be at least 1".into());
    }
    if a.threads > 1 {
        // The calling thread's CPU time would miss the pool's workers.
        a.clock = Clock::Wall;
    }
    Ok(a)
}

/// One structure: name, mode (how a peer is built: one entry per documented
/// way, `-` for Proxima's indices), whether it is a peer, and its build.
struct Entry {
    name: &'static str,
    mode: &'static str,
    peer: bool,
    quadratic: bool,
    build: Build,
}

/// How an entry builds its structure over a set of spheres.
enum Build {
    /// A Proxima index (Morton or input insertion order).
    Index(IndexKind),
    /// A peer's bulk build.
    Peer(fn(&[proxima::geom::Sphere], &Scene, bool) -> Box<dyn Engine>),
}

impl Build {
    fn run(&self, s: &[proxima::geom::Sphere], scene: &Scene, morton: bool) -> Box<dyn Engine> {
        match self {
            Build::Index(kind) => Box::new(proxima(*kind, s, scene, morton)),
            Build::Peer(build) => build(s, scene, morton),
        }
    }
}

/// Insertion order of Proxima's indices: Morton order of the centres (their bulk
/// load; the peers' bulk builds sort spatially too) or the input order.
fn order(s: &[proxima::geom::Sphere], morton: bool) -> Vec<u32> {
    if morton {
        engine::morton_order(s)
    } else {
        (0..s.len() as u32).collect()
    }
}

/// Proxima's index of `kind` as W4 builds it: configured by the library for
/// the scene's hint, bulk-loaded in the given order.
pub(crate) fn proxima(
    kind: IndexKind,
    s: &[proxima::geom::Sphere],
    scene: &Scene,
    morton: bool,
) -> Proxima {
    let index = kind
        .build(&scene.hint())
        .unwrap_or_else(|e| panic!("{kind}: {e}"));
    Proxima::build(index, s, &order(s, morton))
}

fn entries() -> Vec<Entry> {
    // Proxima's indices in the table's order; O(n²) brute force is skipped on
    // large sets.
    let ours = [
        IndexKind::Brute,
        IndexKind::LooseKd,
        IndexKind::Octree,
        IndexKind::HashGrid,
        IndexKind::Grid3d,
        IndexKind::Grid2d,
    ]
    .map(|kind| Entry {
        name: kind.type_name(),
        mode: crate::registry::NO_MODE,
        peer: false,
        quadratic: kind == IndexKind::Brute,
        build: Build::Index(kind),
    });
    let peers = [
        // Every documented build of a peer is its own row; the ratios take the
        // fastest (queries run on the tree each build makes).
        Entry {
            name: "parry3d",
            mode: "binned",
            peer: true,
            quadratic: false,
            build: Build::Peer(|s, _, _| {
                Box::new(parry_peer::ParryQuery::build(s, BvhBuildStrategy::Binned))
            }),
        },
        Entry {
            name: "parry3d",
            mode: "ploc",
            peer: true,
            quadratic: false,
            build: Build::Peer(|s, _, _| {
                Box::new(parry_peer::ParryQuery::build(s, BvhBuildStrategy::Ploc))
            }),
        },
        Entry {
            name: "rstar",
            mode: "bulk_load",
            peer: true,
            quadratic: false,
            build: Build::Peer(|s, _, _| Box::new(rstar_peer::RstarQuery::build(s))),
        },
        Entry {
            name: "rstar",
            mode: "insert",
            peer: true,
            quadratic: false,
            build: Build::Peer(|s, _, _| Box::new(rstar_peer::RstarQuery::build_by_inserts(s))),
        },
        Entry {
            name: "kiddo",
            mode: "immutable",
            peer: true,
            quadratic: false,
            build: Build::Peer(|s, _, _| Box::new(kiddo_peer::KiddoQuery::build(s))),
        },
        Entry {
            name: "bvh",
            mode: "sah",
            peer: true,
            quadratic: false,
            build: Build::Peer(|s, _, _| Box::new(bvh_peer::BvhQuery::build(s))),
        },
    ];
    ours.into_iter().chain(peers).collect()
}

/// One structure on one kind.
#[derive(Clone, Debug)]
pub struct Row {
    /// Structure.
    pub name: &'static str,
    /// How it was built (`-` for Proxima's indices).
    pub mode: &'static str,
    /// A peer crate?
    pub peer: bool,
    /// Build time (once, shared by the kinds).
    pub build: Duration,
    /// Median batch time, or `None` when the kind is not supported.
    pub batch: Option<Duration>,
    /// Hits per batch.
    pub hits: u64,
    /// Bytes per object.
    pub bytes_per_object: f64,
}

/// Sum of counts and a position-weighted checksum, so two structures agree only
/// if they agree query by query (up to a vanishing chance of collision).
fn digest(counts: &[usize]) -> (u64, u64) {
    let total = counts.iter().map(|&c| c as u64).sum();
    let check = counts.iter().enumerate().fold(0u64, |h, (i, &c)| {
        h.wrapping_mul(0x100_0000_01b3)
            .wrapping_add((c as u64) ^ ((i as u64) << 32))
    });
    (total, check)
}

/// Runs W4; returns the rows per kind and the disagreements (empty when all agree).
pub fn run(a: &Args) -> (Vec<(QueryKind, Vec<Row>)>, Vec<String>) {
    let w = Workload::new(Kind::W1, a.n, a.seed);
    let scene = w.scene();
    let batches = queries::generate(cube_side(a.n), a.queries, a.frusta, a.seed);
    let pool = (a.threads > 1).then(|| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(a.threads)
            .build()
            .expect("thread pool")
    });
    let mut rows: Vec<(QueryKind, Vec<Row>)> =
        QueryKind::ALL.iter().map(|&k| (k, Vec::new())).collect();
    let mut reference: Vec<Option<(u64, u64, &'static str)>> = vec![None; QueryKind::ALL.len()];
    let mut errors = Vec::new();
    // Build every structure first, then time them round-robin (per round and
    // kind, one batch each): load from elsewhere on the machine then hits every
    // structure alike, so the ratios of one run are steadier.
    let mut built = Vec::new();
    for e in entries() {
        let wanted = a.only.is_empty() || a.only.iter().any(|o| o.eq_ignore_ascii_case(e.name));
        if !wanted || (e.quadratic && a.n > QUADRATIC_LIMIT) {
            continue;
        }
        eprintln!("building {} ...", e.name);
        let (engine, build) = a.clock.time(|| e.build.run(&w.spheres, &scene, a.morton));
        built.push((e, engine, build));
    }
    // times[kind][structure]
    let mut times = vec![vec![Vec::with_capacity(a.reps); built.len()]; rows.len()];
    let mut hits = vec![vec![0u64; built.len()]; rows.len()];
    for round in 0..a.reps {
        eprintln!("round {} of {} ...", round + 1, a.reps);
        for (k, (kind, _)) in rows.iter().enumerate() {
            for (i, (e, engine, _)) in built.iter().enumerate() {
                if !engine.supports(*kind) {
                    continue;
                }
                // One thread: on this thread, so its CPU clock sees the work
                // (`install` would hand it to a pool worker).
                let (counts, t) = a.clock.time(|| match &pool {
                    Some(p) => p.install(|| engine.counts(&batches, *kind, true)),
                    None => engine.counts(&batches, *kind, false),
                });
                times[k][i].push(t);
                let (total, check) = digest(&counts.expect("supported kind"));
                hits[k][i] = total;
                match reference[k] {
                    None => reference[k] = Some((total, check, e.name)),
                    Some((t0, c0, who)) if (t0, c0) != (total, check) => errors.push(format!(
                        "HIT MISMATCH on {} queries: {who} found {t0} hits, {} found {total}{}",
                        kind.name(),
                        e.name,
                        if t0 == total {
                            " (same total, different per-query counts)"
                        } else {
                            ""
                        }
                    )),
                    _ => {}
                }
            }
        }
    }
    for (k, (kind, out)) in rows.iter_mut().enumerate() {
        for (i, (e, engine, build)) in built.iter().enumerate() {
            out.push(Row {
                name: e.name,
                mode: e.mode,
                peer: e.peer,
                build: *build,
                batch: engine.supports(*kind).then(|| median(&times[k][i])),
                hits: hits[k][i],
                bytes_per_object: engine.memory_bytes() as f64 / a.n as f64,
            });
        }
    }
    errors.dedup();
    (rows, errors)
}

fn us_per_query(d: Duration, n: usize) -> f64 {
    d.as_secs_f64() * 1e6 / n.max(1) as f64
}

/// The peers the target (at most 0.8x their time) is set against.
pub const TARGET_PEERS: [&str; 2] = ["parry3d", "rstar"];

/// The batch time of `r` over the best time among the peers `keep` accepts, for
/// the same kind.
fn ratio_to(r: &Row, rows: &[Row], keep: impl Fn(&Row) -> bool) -> Option<f64> {
    let best = rows
        .iter()
        .filter(|p| p.peer && keep(p))
        .filter_map(|p| p.batch)
        .min()?;
    Some(r.batch?.as_secs_f64() / best.as_secs_f64().max(1e-12))
}

/// Over the best peer.
fn ratio(r: &Row, rows: &[Row]) -> Option<f64> {
    ratio_to(r, rows, |_| true)
}

/// Over the better of parry3d and rstar (the target's reference).
fn ratio_target(r: &Row, rows: &[Row]) -> Option<f64> {
    ratio_to(r, rows, |p| TARGET_PEERS.contains(&p.name))
}

/// The text tables, one per kind.
pub fn table(
    a: &Args,
    batches_len: impl Fn(QueryKind) -> usize,
    rows: &[(QueryKind, Vec<Row>)],
) -> String {
    let mut out = String::new();
    for (kind, rs) in rows {
        let q = batches_len(*kind);
        let _ = writeln!(out, "\n{} queries: {q} per batch", kind.name());
        let _ = writeln!(
            out,
            "{:<14} {:<10} {:>9} {:>10} {:>10} {:>12} {:>10} {:>12} {:>13}",
            "structure",
            "mode",
            "build ms",
            "us/query",
            "Mq/s",
            "hits/batch",
            "bytes/obj",
            "vs best peer",
            "vs parry|rstar"
        );
        for r in rs {
            match r.batch {
                Some(t) => {
                    let us = us_per_query(t, q);
                    let fmt = |x: Option<f64>| x.map_or("-".into(), |x| format!("{x:.2}x"));
                    let _ = writeln!(
                        out,
                        "{:<14} {:<10} {:>9.1} {:>10.3} {:>10.3} {:>12} {:>10.1} {:>12} {:>13}",
                        r.name,
                        r.mode,
                        r.build.as_secs_f64() * 1e3,
                        us,
                        1.0 / us.max(1e-12),
                        r.hits,
                        r.bytes_per_object,
                        fmt(ratio(r, rs)),
                        fmt(ratio_target(r, rs))
                    );
                }
                None => {
                    let _ = writeln!(
                        out,
                        "{:<14} {:<10} {:>9.1} {:>10} {:>10} {:>12} {:>10.1} {:>12}",
                        r.name,
                        r.mode,
                        r.build.as_secs_f64() * 1e3,
                        "n/a",
                        "-",
                        "-",
                        r.bytes_per_object,
                        "(no such query)"
                    );
                }
            }
        }
    }
    let _ = a;
    out
}

/// The same numbers as JSON.
pub fn json(
    a: &Args,
    batches_len: impl Fn(QueryKind) -> usize,
    rows: &[(QueryKind, Vec<Row>)],
) -> String {
    let mut out = format!(
        "{{\"workload\":\"w4\",\"n\":{},\"seed\":{},\"threads\":{},\"reps\":{},\"clock\":\"{}\",\"kinds\":[",
        a.n,
        a.seed,
        a.threads,
        a.reps,
        a.clock.name()
    );
    for (i, (kind, rs)) in rows.iter().enumerate() {
        let q = batches_len(*kind);
        let _ = write!(
            out,
            "{}{{\"kind\":\"{}\",\"queries\":{q},\"rows\":[",
            if i > 0 { "," } else { "" },
            kind.name()
        );
        for (j, r) in rs.iter().enumerate() {
            let num = |x: Option<f64>| x.map_or("null".to_string(), |v| format!("{v:.6}"));
            let _ = write!(
                out,
                "{}{{\"name\":\"{}\",\"mode\":\"{}\",\"peer\":{},\"build_ms\":{:.3},\"us_per_query\":{},\"hits\":{},\"bytes_per_object\":{:.1},\"ratio_to_best_peer\":{},\"ratio_to_parry_rstar\":{}}}",
                if j > 0 { "," } else { "" },
                r.name,
                r.mode,
                r.peer,
                r.build.as_secs_f64() * 1e3,
                num(r.batch.map(|t| us_per_query(t, q))),
                if r.batch.is_some() { r.hits.to_string() } else { "null".into() },
                r.bytes_per_object,
                num(ratio(r, rs)),
                num(ratio_target(r, rs))
            );
        }
        out.push_str("]}");
    }
    out.push_str("]}\n");
    out
}

/// `proxima-bench w4 ...`: exit 0, 1 on a hit mismatch, 2 on bad arguments.
pub fn main(args: impl Iterator<Item = String>) -> std::process::ExitCode {
    use std::process::ExitCode;
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
    let (rows, errors) = run(&a);
    let len = |k: QueryKind| match k {
        QueryKind::Frustum => a.frusta,
        _ => a.queries,
    };
    if a.json {
        print!("{}", json(&a, len, &rows));
    } else {
        println!(
            "w4 n={} queries={} frusta={} reps={} threads={} seed={} clock={} order={} (median batch time; hits checked equal across structures{})",
            a.n,
            a.queries,
            a.frusta,
            a.reps,
            a.threads,
            a.seed,
            a.clock.name(),
            if a.morton { "morton" } else { "input" },
            if a.n > QUADRATIC_LIMIT { "; BruteForce skipped above 20000" } else { "" }
        );
        print!("{}", table(&a, len, &rows));
        println!("kiddo stores points only: no box, ray or frustum query (n/a).");
    }
    for e in &errors {
        eprintln!("{e}");
    }
    if errors.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}
