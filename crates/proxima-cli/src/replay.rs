//! `proxima replay TRACE [--index NAME|all] [--check] [--time]` [sources: cli, trace-format].
//!
//! Parses and checks the trace ([`proxima_harness::trace`]), runs it through one
//! index or several with the harness's replay engine ([`proxima_harness::replay`]),
//! prints one line per query, and with several indices compares every answer with
//! the brute-force oracle. Exit codes: 0 success, 1 an index disagrees with brute
//! force, 2 bad input (file, line, option).

use proxima_harness::indices::{self, BRUTE};
use proxima_harness::replay::{disagreement, query_lines, run_one, Answer, Run};
use proxima_harness::trace::{Kind, Trace};
use std::io::{self, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

/// Options of `proxima replay`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The trace file (format: docs/sources.md#trace-format).
    pub trace: PathBuf,
    /// Index to run (`brute`, … or `all`: every index, each compared with brute).
    #[arg(long, default_value = BRUTE)]
    pub index: String,
    /// Also run brute force and fail (exit 1) at the first answer that differs.
    #[arg(long)]
    pub check: bool,
    /// Print, per index, the total time per operation kind (`#` lines).
    #[arg(long)]
    pub time: bool,
}

/// Runs `proxima replay`.
pub fn main(args: &Args) -> ExitCode {
    let name = args.trace.display();
    let text = match std::fs::read(&args.trace) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("proxima replay: cannot read {name}: {e}");
            return ExitCode::from(2);
        }
    };
    let trace = match Trace::parse(&text) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("proxima replay: {name}: {e}");
            return ExitCode::from(2);
        }
    };
    drop(text);

    // The index whose answers are printed first, then those compared with brute.
    let chosen: Vec<&str> = if args.index == "all" {
        indices::NAMES.to_vec()
    } else if indices::NAMES.contains(&args.index.as_str()) {
        if args.check && args.index != BRUTE {
            vec![args.index.as_str(), BRUTE]
        } else {
            vec![args.index.as_str()]
        }
    } else {
        eprintln!(
            "proxima replay: unknown index '{}' (known: {}, all)",
            args.index,
            indices::NAMES.join(", ")
        );
        return ExitCode::from(2);
    };

    let hint = trace.scene_hint();
    let mut runs = Vec::with_capacity(chosen.len());
    for idx in &chosen {
        match run_one(idx, &hint, &trace) {
            Ok(r) => runs.push(r),
            Err(msg) => {
                eprintln!("proxima replay: {name}: {msg}");
                return ExitCode::from(1);
            }
        }
    }

    // With `all` brute's answers are printed; otherwise the chosen index's.
    let shown = if args.index == "all" {
        runs.iter().find(|r| r.name == BRUTE).unwrap_or(&runs[0])
    } else {
        &runs[0]
    };
    if let Err(e) = print(shown, &runs, args.time) {
        if e.kind() == io::ErrorKind::BrokenPipe {
            return ExitCode::SUCCESS;
        }
        eprintln!("proxima replay: cannot write output: {e}");
        return ExitCode::from(1);
    }

    let lines = query_lines(&trace);
    if let Some((i, r, brute)) = disagreement(&runs) {
        let show = |a: Option<&Answer>| a.map_or("nothing".into(), |a| format!("`{a}`"));
        eprintln!(
            "proxima replay: {name}: line {}: index {} answers {}, brute answers {}",
            lines.get(i).copied().unwrap_or(0),
            r.name,
            show(r.answers.get(i)),
            show(brute.answers.get(i)),
        );
        return ExitCode::from(1);
    }
    ExitCode::SUCCESS
}

fn print(shown: &Run, runs: &[Run], time: bool) -> io::Result<()> {
    let mut out = io::BufWriter::new(io::stdout().lock());
    for a in &shown.answers {
        writeln!(out, "{a}")?;
    }
    if time {
        writeln!(out, "# time: index kind ops total_ms us_per_op")?;
        for r in runs {
            let mut total = Duration::ZERO;
            for (k, (d, n)) in Kind::ALL.iter().zip(r.time) {
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
