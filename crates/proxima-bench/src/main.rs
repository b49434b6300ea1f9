//! `proxima-bench w1|w2|w3 [--n N] [--frames F] [--seed S] [--only A,B] [--clock cpu|wall] [--json]`
//!
//! Runs one standard workload through every structure (Proxima's indices and the
//! peers) and prints a table: build time, median update and pair-finding time per
//! frame, pairs per frame (checked equal for every structure on every frame),
//! bytes per object and frame time relative to parry3d. O(n²) structures are
//! skipped above 20k objects. Times are the running thread's CPU time by default
//! (`--clock wall` for elapsed time): this machine is shared.

use proxima_bench::registry::{self, QUADRATIC_LIMIT};
use proxima_bench::report;
use proxima_bench::run::{measure_all, Clock};
use proxima_bench::workloads::Kind;
use std::process::ExitCode;

const USAGE: &str =
    "usage: proxima-bench w1|w2|w3 [--n N] [--frames F] [--seed S] [--only NAME,NAME] [--clock cpu|wall] [--json]";

struct Args {
    kind: Kind,
    n: usize,
    frames: usize,
    seed: u64,
    only: Vec<String>,
    clock: Clock,
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
            "--clock" => {
                a.clock = match value("--clock")?.as_str() {
                    "cpu" => Clock::ThreadCpu,
                    "wall" => Clock::Wall,
                    other => return Err(format!("--clock takes cpu or wall, not {other:?}")),
                }
            }
            "--json" => a.json = true,
            "-h" | "--help" => return Err(String::new()),
            other => return Err(format!("unknown argument {other:?}")),
        }
    }
    if a.frames == 0 {
        return Err("--frames must be at least 1".into());
    }
    Ok(a)
}

fn num<T: std::str::FromStr>(s: &str) -> Result<T, String> {
    s.replace('_', "")
        .parse()
        .map_err(|_| format!("not a number: {s:?}"))
}

fn main() -> ExitCode {
    if std::env::args().nth(1).as_deref() == Some("w4") {
        return proxima_bench::w4::main(std::env::args().skip(2));
    }
    let args = match parse(std::env::args().skip(1)) {
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
    let results = measure_all(
        &entries,
        args.kind,
        args.n,
        args.seed,
        args.frames,
        args.clock,
        |e| eprintln!("running {} ...", e.name),
    );
    if args.json {
        print!(
            "{}",
            report::json(
                args.kind.name(),
                args.seed,
                args.frames,
                args.clock,
                &results
            )
        );
    } else {
        println!(
            "{} n={} frames={} seed={} clock={} (medians per frame; pair counts checked equal on every frame)",
            args.kind.name(),
            args.n,
            args.frames,
            args.seed,
            args.clock.name()
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
