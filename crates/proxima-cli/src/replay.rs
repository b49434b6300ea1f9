//! `proxima replay TRACE [--index NAME|all] [--check] [--time]` [sources: cli, trace-format].
//!
//! Parses and checks the trace (see [`crate::trace`]), runs it through one index or
//! several, prints one line per query, and with several indices compares every
//! answer with the brute-force oracle. Exit codes: 0 success, 1 an index disagrees
//! with brute force, 2 bad input (file, line, option).

use crate::indices::{self, SceneHint, BRUTE};
use crate::trace::{Kind, Op, Query, Trace};
use proxima::broad::{AnyIndex, IndexKind, SpatialIndex, SpatialIndexExt};
use proxima::geom::Sphere;
use proxima::Handle;
use std::fmt;
use std::io::{self, Write};
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

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

/// The answer to one query line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Answer {
    /// Number of overlapping pairs.
    Pairs(usize),
    /// Number of spheres overlapping the query sphere.
    Sphere(usize),
    /// Number of spheres overlapping the box.
    Aabb(usize),
    /// Number of spheres hit and the user id of the first (smallest entry `t`, ties
    /// by smaller id), if any.
    Ray(usize, Option<u64>),
    /// Number of spheres kept by the frustum.
    Frustum(usize),
}

impl fmt::Display for Answer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Answer::Pairs(n) => write!(f, "pairs {n}"),
            Answer::Sphere(n) => write!(f, "sphere {n}"),
            Answer::Aabb(n) => write!(f, "aabb {n}"),
            Answer::Ray(n, Some(id)) => write!(f, "ray {n} {id}"),
            Answer::Ray(n, None) => write!(f, "ray {n} -"),
            Answer::Frustum(n) => write!(f, "frustum {n}"),
        }
    }
}

/// What one index produced over a trace.
#[derive(Debug)]
pub struct Run {
    /// Index name.
    pub name: &'static str,
    /// One answer per query line, in trace order.
    pub answers: Vec<Answer>,
    /// Total time and count per operation kind, in [`Kind::ALL`] order.
    pub time: [(Duration, usize); 8],
}

/// Runs a parsed trace on an index. An error is `(op position, message)`: the trace
/// was checked, so it means the index rejected a valid operation.
struct Replay<'a> {
    trace: &'a Trace,
}

impl Replay<'_> {
    /// Replays the trace on the empty `index` called `name`.
    fn run(&self, name: &'static str, mut index: AnyIndex<u64>) -> Result<Run, (usize, String)> {
        let t = self.trace;
        let mut handles: Vec<Option<Handle>> = vec![None; t.ids.len()];
        let mut answers = Vec::with_capacity(t.query_count());
        let mut time = [(Duration::ZERO, 0usize); 8];
        for (pos, op) in t.ops.iter().enumerate() {
            let start = Instant::now();
            let res = apply(&mut index, &mut handles, &t.ids, op);
            let k = op.kind() as usize;
            time[k].0 += start.elapsed();
            time[k].1 += 1;
            match res {
                Ok(Some(a)) => answers.push(a),
                Ok(None) => {}
                Err(e) => return Err((pos, format!("index {name}: {e}"))),
            }
        }
        Ok(Run {
            name,
            answers,
            time,
        })
    }
}

/// Applies one operation; queries return their answer.
fn apply(
    index: &mut AnyIndex<u64>,
    handles: &mut [Option<Handle>],
    ids: &[u64],
    op: &Op,
) -> proxima::Result<Option<Answer>> {
    // The parser guarantees liveness; a missing handle would be a parser bug.
    let live = |h: Option<Handle>| h.ok_or(proxima::Error::StaleHandle);
    let mut n = 0usize;
    Ok(Some(match op {
        Op::Insert { slot, sphere } => {
            let s = *slot as usize;
            handles[s] = Some(index.insert(*sphere, ids[s])?);
            return Ok(None);
        }
        Op::Move { slot, sphere } => {
            index.update(live(handles[*slot as usize])?, *sphere)?;
            return Ok(None);
        }
        Op::Remove { slot } => {
            index.remove(live(handles[*slot as usize].take())?)?;
            return Ok(None);
        }
        Op::Query(Query::Pairs) => {
            let _ = index.for_each_pair(|_, _, _, _| {
                n += 1;
                ControlFlow::Continue(())
            });
            Answer::Pairs(n)
        }
        Op::Query(Query::Sphere(s)) => {
            let _ = index.for_each_in(*s, counter(&mut n))?;
            Answer::Sphere(n)
        }
        Op::Query(Query::Aabb(b)) => {
            let _ = index.for_each_in(*b, counter(&mut n))?;
            Answer::Aabb(n)
        }
        Op::Query(Query::Frustum(fr)) => {
            let _ = index.for_each_in(**fr, counter(&mut n))?;
            Answer::Frustum(n)
        }
        Op::Query(Query::Ray(ray)) => {
            // Sorted by entry t; among equal smallest t the smaller *user* id wins.
            let hits = index.ray_hits(ray)?;
            let mut first = None;
            if let Some(t0) = hits.first().map(|h| h.t) {
                for h in hits.iter().take_while(|h| h.t == t0) {
                    let id = *index.get(h.handle)?.1;
                    first = Some(first.map_or(id, |f: u64| f.min(id)));
                }
            }
            Answer::Ray(hits.len(), first)
        }
    }))
}

/// A query callback that counts what it is given.
fn counter(n: &mut usize) -> impl FnMut(Handle, &Sphere, &u64) -> ControlFlow<()> + '_ {
    move |_, _, _| {
        *n += 1;
        ControlFlow::Continue(())
    }
}

/// The position of the first answer where `other` differs from `reference` (a
/// missing answer counts as a difference), or `None` when they agree.
pub fn first_difference(reference: &[Answer], other: &[Answer]) -> Option<usize> {
    let n = reference.len().min(other.len());
    (0..n)
        .find(|&i| reference[i] != other[i])
        .or((reference.len() != other.len()).then_some(n))
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

/// The earliest query where some index differs from brute force: `(query position,
/// that index's run, brute's run)`. `None` when all agree or brute did not run.
pub fn disagreement(runs: &[Run]) -> Option<(usize, &Run, &Run)> {
    let brute = runs.iter().find(|r| r.name == BRUTE)?;
    runs.iter()
        .filter(|r| r.name != BRUTE)
        .filter_map(|r| first_difference(&brute.answers, &r.answers).map(|i| (i, r)))
        .min_by_key(|&(i, _)| i)
        .map(|(i, r)| (i, r, brute))
}

pub fn run_one(idx: &str, hint: &SceneHint, trace: &Trace) -> Result<Run, String> {
    let kind: IndexKind = idx.parse().map_err(|_| format!("unknown index '{idx}'"))?;
    let index = kind
        .build(hint)
        .map_err(|e| format!("index {idx} rejects the scene: {e}"))?;
    Replay { trace }
        .run(kind.name(), index)
        .map_err(|(pos, msg)| format!("line {}: {msg}", trace.lines[pos]))
}

/// Source line of each query, in order.
fn query_lines(trace: &Trace) -> Vec<u32> {
    trace
        .ops
        .iter()
        .zip(&trace.lines)
        .filter(|(op, _)| matches!(op, Op::Query(_)))
        .map(|(_, &l)| l)
        .collect()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn answers_print_in_trace_format() {
        assert_eq!(Answer::Pairs(3).to_string(), "pairs 3");
        assert_eq!(Answer::Ray(2, Some(7)).to_string(), "ray 2 7");
        assert_eq!(Answer::Ray(0, None).to_string(), "ray 0 -");
        assert_eq!(Answer::Frustum(0).to_string(), "frustum 0");
    }

    #[test]
    fn first_difference_finds_the_first_mismatch() {
        let a = [Answer::Pairs(1), Answer::Sphere(2), Answer::Ray(1, Some(5))];
        assert_eq!(first_difference(&a, &a), None);
        let b = [Answer::Pairs(1), Answer::Sphere(3), Answer::Ray(1, Some(4))];
        assert_eq!(first_difference(&a, &b), Some(1));
        let c = [Answer::Pairs(1), Answer::Sphere(2), Answer::Ray(1, Some(4))];
        assert_eq!(first_difference(&a, &c), Some(2));
        assert_eq!(first_difference(&a, &a[..2]), Some(2));
        assert_eq!(first_difference(&a[..1], &a), Some(1));
        assert_eq!(first_difference(&[], &[]), None);
    }

    fn run(name: &'static str, answers: Vec<Answer>) -> Run {
        Run {
            name,
            answers,
            time: Default::default(),
        }
    }

    #[test]
    fn disagreement_names_the_earliest_differing_index() {
        let truth = vec![Answer::Pairs(1), Answer::Sphere(2), Answer::Aabb(3)];
        let late = vec![Answer::Pairs(1), Answer::Sphere(2), Answer::Aabb(4)];
        let early = vec![Answer::Pairs(1), Answer::Sphere(9), Answer::Aabb(3)];
        let agree = [run(BRUTE, truth.clone()), run("x", truth.clone())];
        assert!(disagreement(&agree).is_none());
        let runs = [run("x", late), run(BRUTE, truth.clone()), run("y", early)];
        let (i, r, b) = disagreement(&runs).unwrap();
        assert_eq!((i, r.name, b.name), (1, "y", BRUTE));
        // Without brute there is nothing to compare with.
        assert!(disagreement(&runs[2..]).is_none());
    }
}
