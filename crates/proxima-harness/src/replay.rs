//! The replay engine [sources: trace-format]: a parsed [`Trace`] run through one
//! index, one [`Answer`] per query line, and the comparison of every index's
//! answers with brute force's. `proxima replay` prints these answers (the CLI
//! keeps its options and printing); the `replay` fuzz target and the tests run the
//! same engine.

use crate::indices::BRUTE;
use crate::trace::{Kind, Op, Query, Trace};
use proxima::broad::{AnyIndex, IndexKind, SceneHint, SpatialIndex, SpatialIndexExt};
use proxima::geom::Sphere;
use proxima::Handle;
use std::fmt;
use std::ops::ControlFlow;
use std::time::{Duration, Instant};

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
    pub time: [(Duration, usize); Kind::ALL.len()],
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
        let mut time = [(Duration::ZERO, 0usize); Kind::ALL.len()];
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

/// Builds the index named `idx` for `hint` and replays `trace` on it. The error
/// is one line: an unknown name, a hint the index rejects, or `line N: index
/// NAME: what` when it rejects a checked operation (an index bug). O(the trace's
/// cost on that index).
pub fn run_one(idx: &str, hint: &SceneHint, trace: &Trace) -> Result<Run, String> {
    let kind: IndexKind = idx.parse().map_err(|_| format!("unknown index '{idx}'"))?;
    let index = kind
        .build(hint)
        .map_err(|e| format!("index {idx} rejects the scene: {e}"))?;
    Replay { trace }
        .run(kind.name(), index)
        .map_err(|(pos, msg)| format!("line {}: {msg}", trace.lines[pos]))
}

/// Source line of each query, in order (where to point at a disagreement).
pub fn query_lines(trace: &Trace) -> Vec<u32> {
    trace
        .ops
        .iter()
        .zip(&trace.lines)
        .filter(|(op, _)| matches!(op, Op::Query(_)))
        .map(|(_, &l)| l)
        .collect()
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
