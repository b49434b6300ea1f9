//! `proxima-bench w1|w2|w3|w9 [--n N] [--frames F] [--seed S] [--only A,B] [--clock cpu|wall] [--threads K] [--inert F] [--json]`
//! `proxima-bench w5 …` (see `proxima_bench::w5`), `w5-distance …` (`proxima_bench::w5_distance`)
//! `proxima-bench w7 …` (k nearest, `proxima_bench::w7`), `w8 …` (sphere sweeps, `proxima_bench::w8`)
//! `proxima-bench world …` (see `proxima_bench::world`)
//! `proxima-bench chart FILE.json... --out FILE.svg [--metric NAME]`
//!
//! Runs one standard workload through every structure (Proxima's indices and the
//! peers) and prints a table: build time, median update and pair-finding time per
//! frame, pairs per frame (checked equal for every structure on every frame),
//! bytes per object and frame time relative to parry3d. O(n²) structures are
//! skipped above 20k objects. Times are the running thread's CPU time by default
//! (`--clock wall` for elapsed time): this machine is shared. `--threads K`
//! (default 1) counts pairs with the parallel search of the structures that
//! have one, in a K-thread pool; with K > 1 the clock is wall time. `--inert F`
//! (a fraction in [0, 1], default 0) puts that fraction of the objects in a
//! group that collides with nothing (`inert_filters`); pairs are then counted
//! among the others only, by every structure its own way (Proxima's indices
//! prune by filter inside the search, parry3d filters in its pair callback).

use proxima_bench::registry::{self, QUADRATIC_LIMIT};
use proxima_bench::report;
use proxima_bench::run::{measure_all_threads, num, Clock};
use proxima_harness::workloads::Kind;
use std::process::ExitCode;

const USAGE: &str =
    "usage: proxima-bench w1|w2|w3|w9 [--n N] [--frames F] [--seed S] [--only NAME,NAME] [--clock cpu|wall] [--threads K] [--inert F] [--json]\n       proxima-bench w4 [--help]\n       proxima-bench w5 [--help]\n       proxima-bench w5-distance [--help]\n       proxima-bench w6 [--help]\n       proxima-bench w7 [--help]\n       proxima-bench w8 [--help]\n       proxima-bench world [--help]\n       proxima-bench chart FILE.json... --out FILE.svg [--metric NAME] [--title T]";

struct Args {
    kind: Kind,
    n: usize,
    frames: usize,
    seed: u64,
    only: Vec<String>,
    clock: Clock,
    threads: usize,
    inert: f64,
    json: bool,
}

fn parse(mut it: impl Iterator<Item = String>) -> Result<Args, String> {
    let kind = it.next().ok_or("missing workload")?;
    let kind = Kind::parse(&kind).ok_or_else(|| format!("unknown workload {kind:?}"))?;
    let mut a = Args {
        kind,
        n: 100_000,
        frames: 20,
        seed: 1,
        only: Vec::new(),
        clock: Clock::ThreadCpu,
        threads: 1,
        inert: 0.0,
        json: false,
    };
    while let Some(flag) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match flag.as_str() {
            "--n" => a.n = num(&value("--n")?)?,
            "--frames" => a.frames = num(&value("--frames")?)?,
            "--seed" => a.seed = num(&value("--seed")?)?,
            "--only" => {
                a.only = value("--only")?
                    .split(',')
                    .filter(|s| !s.is_empty())
                    .map(String::from)
                    .collect()
            }
            "--clock" => a.clock = Clock::parse(&value("--clock")?)?,
            "--threads" => a.threads = num(&value("--threads")?)?,
            "--inert" => a.inert = num(&value("--inert")?)?,
            "--json" => a.json = true,
            "-h" | "--help" => return Err(String::new()),
            other => return Err(format!("unknown argument {other:?}")),
        }
    }
    if a.frames == 0 {
        return Err("--frames must be at least 1".into());
    }
    if !(0.0..=1.0).contains(&a.inert) {
        return Err(format!(
            "--inert takes a fraction in [0, 1], not {}",
            a.inert
        ));
    }
    if a.threads == 0 {
        return Err("--threads must be at least 1".into());
    }
    if a.threads > 1 {
        // The caller's thread CPU time would miss the pool's work.
        a.clock = Clock::Wall;
    }
    Ok(a)
}

fn main() -> ExitCode {
    let argv: Vec<String> = std::env::args().skip(1).collect();
    match argv.first().map(String::as_str) {
        Some("chart") => {
            return match proxima_bench::chart::main(&argv[1..]) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::from(2)
                }
            }
        }
        Some("w4") => return proxima_bench::w4::main(argv.into_iter().skip(1)),
        Some("w5") => return proxima_bench::w5::main(argv.into_iter().skip(1)),
        Some("w5-distance") => return proxima_bench::w5_distance::main(argv.into_iter().skip(1)),
        Some("w6") => return proxima_bench::w6::main(argv.into_iter().skip(1)),
        Some("w7") => return proxima_bench::w7::main(argv.into_iter().skip(1)),
        Some("w8") => return proxima_bench::w8::main(argv.into_iter().skip(1)),
        Some("world") => return proxima_bench::world::main(argv.into_iter().skip(1)),
        _ => {}
    }
    let args = match parse(argv.into_iter()) {
        Ok(a) => a,
        Err(e) => {
            if !e.is_empty() {
                eprintln!("error: {e}");
            }
            eprintln!("{USAGE}");
            return ExitCode::from(2);
        }
    };
    let entries = match registry::select(&args.only) {
        Ok(e) => e,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let skipped: Vec<_> = entries
        .iter()
        .filter(|e| !e.runs_on(args.n))
        .map(|e| e.name)
        .collect();
    let results = measure_all_threads(
        &entries,
        args.kind,
        args.n,
        args.seed,
        args.frames,
        args.clock,
        args.threads,
        args.inert,
        |e| eprintln!("running {} ...", e.name),
    );
    if args.json {
        // A filtered run names its workload `w1-inert0.5`, so that its rows
        // never mix with the unfiltered ones in a chart.
        let name = if args.inert > 0.0 {
            format!("{}-inert{}", args.kind.name(), args.inert)
        } else {
            args.kind.name().to_string()
        };
        print!(
            "{}",
            report::json(&name, args.seed, args.frames, args.clock, &results)
        );
    } else {
        println!(
            "{} n={} frames={} seed={} clock={} threads={} inert={} (medians per frame; pair counts checked equal on every frame)",
            args.kind.name(),
            args.n,
            args.frames,
            args.seed,
            args.clock.name(),
            args.threads,
            args.inert
        );
        print!("{}", report::table(&results));
        if !skipped.is_empty() {
            println!(
                "skipped (O(n^2) pairs above {QUADRATIC_LIMIT} objects): {}",
                skipped.join(", ")
            );
        }
    }
    ExitCode::SUCCESS
}
