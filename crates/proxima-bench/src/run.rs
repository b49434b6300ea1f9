//! Runs a workload through structures, timing build, update and pair finding, and
//! checking that every structure finds the same number of pairs on every frame.

use crate::registry::Entry;
use crate::structure::Structure;
use proxima::broad::Filter;
use proxima_harness::workloads::{Kind, Workload};
use std::time::{Duration, Instant};

/// What the timings measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clock {
    /// Elapsed real time (what criterion measures).
    Wall,
    /// CPU time of the running thread: excludes time the thread spent
    /// descheduled, so it stays meaningful on a shared, loaded machine. The
    /// benchmarked code is single-threaded, so on an idle machine both agree.
    ThreadCpu,
}

/// A command-line number (`100_000` allowed), for every workload's arguments.
pub fn num<T: std::str::FromStr>(s: &str) -> Result<T, String> {
    s.replace('_', "")
        .parse()
        .map_err(|_| format!("not a number: {s:?}"))
}

impl Clock {
    /// The clock named by a `--clock` value (`cpu` or `wall`); the error is the
    /// message every workload prints.
    pub fn parse(s: &str) -> Result<Clock, String> {
        match s {
            "cpu" => Ok(Clock::ThreadCpu),
            "wall" => Ok(Clock::Wall),
            other => Err(format!("--clock takes cpu or wall, not {other:?}")),
        }
    }

    /// `wall` or `cpu`.
    pub fn name(self) -> &'static str {
        match self {
            Clock::Wall => "wall",
            Clock::ThreadCpu => "cpu",
        }
    }

    /// Runs `f` and returns its result and how long it took on this clock.
    pub fn time<R>(self, f: impl FnOnce() -> R) -> (R, Duration) {
        match self {
            Clock::Wall => {
                let t = Instant::now();
                let r = f();
                (r, t.elapsed())
            }
            Clock::ThreadCpu => {
                let t = cpu_time::ThreadTime::now();
                let r = f();
                (r, t.elapsed())
            }
        }
    }
}

/// The pair count of every frame, as first reported; later structures must agree.
///
/// Frame `f` is the state after `f` calls of [`Workload::step`] on a fresh
/// workload of the same kind, size and seed, so counts are comparable across
/// structures however many frames each one runs (criterion runs a different
/// number of iterations for each).
#[derive(Debug, Default)]
pub struct PairLedger {
    counts: Vec<Option<(u64, &'static str)>>,
}

impl PairLedger {
    /// An empty ledger.
    pub fn new() -> Self {
        Self::default()
    }

    /// Records `count` for `frame` reported by `who`, or panics if another
    /// structure reported a different count for the same frame.
    pub fn check(&mut self, frame: u64, who: &'static str, count: u64) {
        let f = frame as usize;
        if self.counts.len() <= f {
            self.counts.resize(f + 1, None);
        }
        match self.counts[f] {
            None => self.counts[f] = Some((count, who)),
            Some((c, first)) => assert!(
                c == count,
                "PAIR COUNT MISMATCH at frame {frame}: {first} found {c} pairs, {who} found {count}"
            ),
        }
    }

    /// The recorded count of a frame, if any.
    pub fn get(&self, frame: u64) -> Option<u64> {
        self.counts
            .get(frame as usize)
            .copied()
            .flatten()
            .map(|(c, _)| c)
    }
}

/// The filters of `--inert F`: object `i` is inert with probability `F`
/// (decided by a hash of `i`, so the same objects in every structure and run),
/// in group 2 whose mask is empty — a group that collides with nothing; the
/// others are group 1 colliding with group 1. An empty list for `F <= 0` (no
/// filter set at all: the unfiltered run).
pub fn inert_filters(n: usize, inert: f64) -> Vec<Filter> {
    if inert <= 0.0 {
        return Vec::new();
    }
    (0..n as u64)
        .map(|i| {
            let u = (i.wrapping_add(1).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 11) as f64;
            if u / ((1u64 << 53) as f64) < inert {
                Filter::new(2, 0)
            } else {
                Filter::new(1, 1)
            }
        })
        .collect()
}

/// What one structure measured on one workload.
#[derive(Clone, Debug)]
pub struct Measurement {
    /// Structure name.
    pub name: &'static str,
    /// The peer's mode ([`Entry::mode`]; `-` for Proxima's indices).
    pub mode: &'static str,
    /// Whether this is a peer crate.
    pub peer: bool,
    /// Time to insert every object into the empty structure.
    pub build: Duration,
    /// Per-frame update times (move every object).
    pub update: Vec<Duration>,
    /// Per-frame pair-finding times.
    pub pairs: Vec<Duration>,
    /// Total pairs over all frames.
    pub pair_total: u64,
    /// `memory_bytes()` after the last frame.
    pub memory: usize,
    /// Number of objects.
    pub n: usize,
}

/// Median of a list of durations (zero when empty).
pub fn median(d: &[Duration]) -> Duration {
    if d.is_empty() {
        return Duration::ZERO;
    }
    let mut v = d.to_vec();
    v.sort();
    v[v.len() / 2]
}

impl Measurement {
    /// Median update time per frame.
    pub fn update_median(&self) -> Duration {
        median(&self.update)
    }

    /// Median pair-finding time per frame.
    pub fn pairs_median(&self) -> Duration {
        median(&self.pairs)
    }

    /// Median of per-frame (update + pairs) times.
    pub fn frame_median(&self) -> Duration {
        let f: Vec<_> = self
            .update
            .iter()
            .zip(&self.pairs)
            .map(|(u, p)| *u + *p)
            .collect();
        median(&f)
    }

    /// Mean pairs per frame.
    pub fn pairs_per_frame(&self) -> f64 {
        self.pair_total as f64 / self.pairs.len().max(1) as f64
    }

    /// Bytes per stored object.
    pub fn bytes_per_object(&self) -> f64 {
        self.memory as f64 / self.n.max(1) as f64
    }
}

/// Runs `frames` frames of workload (`kind`, `n`, `seed`) through one structure:
/// build (timed), then per frame: step the workload (not timed), update every
/// object (timed), count pairs (timed, checked against `ledger`).
pub fn measure(
    entry: &Entry,
    kind: Kind,
    n: usize,
    seed: u64,
    frames: usize,
    clock: Clock,
    ledger: &mut PairLedger,
) -> Measurement {
    measure_threads(entry, kind, n, seed, frames, clock, 1, 0.0, ledger)
}

/// [`measure`] with `threads` threads for the pairs: with `threads > 1`, pairs
/// are counted by [`Structure::count_pairs_par`] in a pool of that many threads
/// (time it with [`Clock::Wall`]: the work runs on the pool's threads, not the
/// caller's). With `inert > 0`, the objects get [`inert_filters`] after the
/// build (not timed), and only interacting pairs are counted.
#[allow(clippy::too_many_arguments)]
pub fn measure_threads(
    entry: &Entry,
    kind: Kind,
    n: usize,
    seed: u64,
    frames: usize,
    clock: Clock,
    threads: usize,
    inert: f64,
    ledger: &mut PairLedger,
) -> Measurement {
    let pool = (threads > 1).then(|| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("building the benchmark's thread pool")
    });
    let mut w = Workload::new(kind, n, seed);
    let mut s: Box<dyn Structure> = entry.make(&w.scene());
    let ((), build) = clock.time(|| s.build(&w.spheres));
    let filters = inert_filters(n, inert);
    if !filters.is_empty() {
        s.set_filters(&filters);
    }
    let mut m = Measurement {
        name: entry.name,
        mode: entry.mode,
        peer: entry.peer,
        build,
        update: Vec::with_capacity(frames),
        pairs: Vec::with_capacity(frames),
        pair_total: 0,
        memory: 0,
        n,
    };
    for _ in 0..frames {
        w.step();
        let ((), t) = clock.time(|| s.update(&w.spheres));
        m.update.push(t);
        let (count, t) = clock.time(|| match &pool {
            Some(pool) => s.count_pairs_par(pool),
            None => s.count_pairs(),
        });
        m.pairs.push(t);
        ledger.check(w.frame(), entry.name, count);
        m.pair_total += count;
    }
    m.memory = s.memory_bytes();
    m
}

/// Runs every entry affordable at `n` (see [`Entry::runs_on`]) on the same
/// workload, in order, with one shared ledger: panics on any pair-count mismatch.
pub fn measure_all(
    entries: &[Entry],
    kind: Kind,
    n: usize,
    seed: u64,
    frames: usize,
    clock: Clock,
    progress: impl FnMut(&Entry),
) -> Vec<Measurement> {
    measure_all_threads(entries, kind, n, seed, frames, clock, 1, 0.0, progress)
}

/// [`measure_all`] with `threads` threads for the pairs and a fraction `inert`
/// of inert objects (see [`measure_threads`]).
#[allow(clippy::too_many_arguments)]
pub fn measure_all_threads(
    entries: &[Entry],
    kind: Kind,
    n: usize,
    seed: u64,
    frames: usize,
    clock: Clock,
    threads: usize,
    inert: f64,
    mut progress: impl FnMut(&Entry),
) -> Vec<Measurement> {
    let mut ledger = PairLedger::new();
    entries
        .iter()
        .filter(|e| e.runs_on(n))
        .map(|e| {
            progress(e);
            measure_threads(e, kind, n, seed, frames, clock, threads, inert, &mut ledger)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::registry;
    use proxima::geom::overlap;

    /// `--inert 0.5`: every structure (Proxima's six indices, parry3d in every
    /// mode) counts exactly the pairs of non-inert objects, frame after frame,
    /// as a direct all-pairs count with the filters says; and the filters
    /// matter (about a quarter of the unfiltered pairs are left).
    #[test]
    fn inert_objects_drop_out_of_every_structure_s_pairs() {
        let (n, frames, seed) = (1500, 4, 7);
        let f = inert_filters(n, 0.5);
        let inert = f.iter().filter(|f| f.is_inert()).count();
        assert!((600..900).contains(&inert), "{inert} of {n} inert");
        let entries = registry::entries();
        let all = measure_all_threads(
            &entries,
            Kind::W1,
            n,
            seed,
            frames,
            Clock::Wall,
            1,
            0.5,
            |_| {},
        );
        assert_eq!(all.len(), entries.len());
        let (mut want, mut unfiltered) = (0u64, 0u64);
        let mut w = Workload::new(Kind::W1, n, seed);
        for _ in 0..frames {
            w.step();
            let s = &w.spheres;
            for i in 0..n {
                for j in i + 1..n {
                    if overlap::sphere_sphere(&s[i], &s[j]) {
                        unfiltered += 1;
                        want += f[i].interacts(f[j]) as u64;
                    }
                }
            }
        }
        assert!(
            4 * want < 2 * unfiltered && 8 * want > unfiltered,
            "{want} of {unfiltered}"
        );
        for m in &all {
            assert_eq!(m.pair_total, want, "{} {}", m.name, m.mode);
        }
        assert!(inert_filters(n, 0.0).is_empty());
    }
}
