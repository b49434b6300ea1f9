//! `proxima world TRACE [--index NAME] [--bv NAME] [--first] [--check] [--time]`
//! [sources: cli, world-trace].
//!
//! Parses and checks the trace ([`proxima_harness::world_trace`]), runs it on a collision
//! world ([`proxima_harness::world_replay`]) and prints one line per query; with `--check`
//! also on the brute-force world ([`proxima_harness::world_oracle`]), failing at the first
//! answer that differs. Exit codes: 0 success, 1 the world disagrees with the
//! brute-force world, 2 bad input (file, line, option).

use proxima::broad::IndexKind;
use proxima::world::WorldConfig;
use proxima_harness::world_replay::{first_difference, run_bv, run_oracle, WorldRun, BVS};
use proxima_harness::world_trace::{WorldKind, WorldTrace};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

/// Options of `proxima world`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The trace file (format: docs/sources.md#world-trace).
    pub trace: PathBuf,
    /// Broad-phase index (`brute`, `loose-kd`, `octree`, `grid2d`, `hashgrid`,
    /// `grid3d`); by default the world's own choice.
    #[arg(long)]
    pub index: Option<String>,
    /// Bounding volume of the mesh trees.
    #[arg(long, default_value = "kdop18")]
    pub bv: String,
    /// Contacts in first-contact mode: `contacts P` (object pairs only).
    #[arg(long)]
    pub first: bool,
    /// Also run the brute-force world and fail (exit 1) at the first answer that
    /// differs.
    #[arg(long)]
    pub check: bool,
    /// Print the total time per operation kind (`#` lines).
    #[arg(long)]
    pub time: bool,
}

/// Reads and parses a trace file; the error is the one line to print.
pub fn load(path: &Path) -> Result<WorldTrace, String> {
    let name = path.display();
    let text = std::fs::read(path).map_err(|e| format!("cannot read {name}: {e}"))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    WorldTrace::parse(&text, dir).map_err(|e| format!("{name}: {e}"))
}

/// Runs `proxima world`.
pub fn main(args: &Args) -> ExitCode {
    let name = args.trace.display();
    let index = match args.index.as_deref().map(str::parse::<IndexKind>) {
        None => None,
        Some(Ok(k)) => Some(k),
        Some(Err(e)) => {
            eprintln!("proxima world: {e}");
            return ExitCode::from(2);
        }
    };
    if !BVS.contains(&args.bv.as_str()) {
        eprintln!(
            "proxima world: unknown bounding volume '{}' (known: {})",
            args.bv,
            BVS.join(", ")
        );
        return ExitCode::from(2);
    }
    let trace = match load(&args.trace) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("proxima world: {e}");
            return ExitCode::from(2);
        }
    };
    let config = WorldConfig {
        index,
        ..WorldConfig::default()
    };
    let run = match run_bv(&args.bv, &trace, config, args.first) {
        Ok(r) => r,
        Err((pos, msg)) => {
            let line = trace.lines.get(pos).copied().unwrap_or(0);
            eprintln!("proxima world: {name}: line {line}: {msg}");
            return ExitCode::from(2);
        }
    };
    let oracle = args.check.then(|| run_oracle(&trace, args.first));
    let mut runs = vec![&run];
    runs.extend(oracle.as_ref());
    if let Err(e) = print(&run, &runs, args.time) {
        if e.kind() == io::ErrorKind::BrokenPipe {
            return ExitCode::SUCCESS;
        }
        eprintln!("proxima world: cannot write output: {e}");
        return ExitCode::from(1);
    }
    if let Some(oracle) = &oracle {
        if let Some(i) = first_difference(&oracle.answers, &run.answers) {
            let show = |a: Option<&proxima_harness::world_replay::WorldAnswer>| {
                a.map_or("nothing".into(), |a| format!("`{a}`"))
            };
            eprintln!(
                "proxima world: {name}: line {}: the world answers {}, the brute-force world {}",
                trace.query_lines().get(i).copied().unwrap_or(0),
                show(run.answers.get(i)),
                show(oracle.answers.get(i)),
            );
            return ExitCode::from(1);
        }
    }
    ExitCode::SUCCESS
}

fn print(shown: &WorldRun, runs: &[&WorldRun], time: bool) -> io::Result<()> {
    let mut out = io::BufWriter::new(io::stdout().lock());
    for a in &shown.answers {
        writeln!(out, "{a}")?;
    }
    if time {
        writeln!(out, "# time: index kind ops total_ms us_per_op")?;
        for r in runs {
            let mut total = Duration::ZERO;
            for (k, (d, n)) in WorldKind::ALL.iter().zip(r.time) {
                if n > 0 {
                    let ms = d.as_secs_f64() * 1e3;
                    let us = ms * 1e3 / n as f64;
                    writeln!(
                        out,
                        "# {:<10} {:<8} {n:>8} {ms:>10.3} {us:>10.3}",
                        r.name,
                        k.name()
                    )?;
                    total += d;
                }
            }
            let ms = total.as_secs_f64() * 1e3;
            writeln!(out, "# {:<10} {:<8} {:>8} {ms:>10.3}", r.name, "total", "")?;
        }
    }
    out.flush()
}
