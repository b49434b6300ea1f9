//! `proxima-bench w8 [--n N] [--queries Q] [--check C] [--reps R] [--seed S] [--clock cpu|wall] [--only A,B] [--json]`
//!
//! W8 [sources: w4]: sphere sweeps through a static set (issue #14). W4's set
//! (`N` spheres, radii in `[0.5, 2]`, centres uniform in a cube of side
//! `4·N^(1/3)`) is loaded into every Proxima index (as W4 builds them) and
//! into parry3d ([`parry_cast`]). `Q` sweeps: start uniform in the cube,
//! direction uniform, length uniform in `[5, 20]` (W4's bounded rays),
//! radius uniform in `[0.5, 2]` (the set's radii). Three kinds: `first`, the
//! first sphere touched and its time (`SpatialIndex::sweep_first`) as each
//! library returns it (our `Handle`, parry's leaf index: as W7 times
//! `nearest_into`); `first+id`, the same mapped to the sphere id (our
//! `get` of the handle, the lookup a caller makes; parry's leaf index is
//! the id here); and `hits`, every sphere touched, counted (`for_each_in`
//! a `SphereSweep`).
//!
//! Before timing, the first `C` sweeps of every structure are checked against
//! LooseKdTree's answers (which the library's oracle tests check against
//! brute force): the same first sphere at the same time within `1e-4` (or
//! another sphere our exact test touches at that time: a tie), and the same
//! set of spheres touched, up to grazes (spheres whose distance to the
//! segment is within `1e-4` relative of the summed radii, where parry's `f32`
//! cast and the exact test may differ). A structure that disagrees is
//! reported (exit 1) and not timed.

pub mod parry_cast;

use crate::query_args::{self, fmt_ratio, json_num, us_per_query, Args};
use crate::registry::QUADRATIC_LIMIT;
use crate::w4::engine::visit_count;
use proxima::broad::{AnyIndex, IndexKind, SpatialIndex};
use proxima::geom::{overlap, Sphere, SphereSweep};
use proxima_harness::workloads::{cube_side, unit_vector, Kind, Scene, Workload};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::fmt::Write;
use std::ops::ControlFlow;
use std::time::Duration;

const USAGE: &str = "usage: proxima-bench w8 [--n N] [--queries Q] [--check C] [--reps R] [--seed S] [--clock cpu|wall] [--only A,B] [--json]";

/// A structure answering sphere sweeps over the set (object `i` = sphere `i`).
pub trait Sweeper {
    /// The first sphere touched and its time in `[0, 1]` (the checked call).
    fn first(&self, s: &SphereSweep) -> Option<(u32, f32)>;
    /// The first contact as the library returns it (the timed call): its own
    /// key of the object touched — Proxima's `Handle`, parry's leaf index —
    /// and the time, not mapped to the sphere id. Mapping a key to the
    /// caller's data is the caller's step with either library (parry's leaf
    /// index is the id here only because the leaves are the input order), so
    /// neither is charged for it, as in W7. [`Sweeper::first`] is this,
    /// mapped.
    fn first_key(&self, s: &SphereSweep) -> Option<(u64, f32)>;
    /// How many spheres the sweep touches.
    fn count(&self, s: &SphereSweep) -> usize;
    /// The spheres the sweep touches, in any order (the checked call).
    fn hits(&self, s: &SphereSweep) -> Vec<u32>;
}

/// A Proxima index (payload = sphere id).
pub struct Ours(AnyIndex<u32>);

impl Sweeper for Ours {
    fn first(&self, s: &SphereSweep) -> Option<(u32, f32)> {
        let hit = self.0.sweep_first(s, None).expect("valid sweep")?;
        Some((*self.0.get(hit.handle).expect("live").1, hit.t))
    }

    fn first_key(&self, s: &SphereSweep) -> Option<(u64, f32)> {
        let hit = self.0.sweep_first(s, None).expect("valid sweep")?;
        let h = hit.handle;
        Some(((h.generation() as u64) << 32 | h.index() as u64, hit.t))
    }

    fn count(&self, s: &SphereSweep) -> usize {
        visit_count(&self.0, *s)
    }

    fn hits(&self, s: &SphereSweep) -> Vec<u32> {
        let mut out = Vec::new();
        let _ = self.0.for_each_in(*s, |_, _, &id| {
            out.push(id);
            ControlFlow::Continue(())
        });
        out
    }
}

/// W8's sweeps over the cube of side `side`.
pub fn sweeps(side: f32, q: usize, seed: u64) -> Vec<SphereSweep> {
    let mut rng = Pcg64::seed_from_u64(seed ^ 0x5738_0000_0008);
    (0..q)
        .map(|_| {
            let from = proxima::glam::Vec3::new(
                rng.gen_range(0.0..=side),
                rng.gen_range(0.0..=side),
                rng.gen_range(0.0..=side),
            );
            let d = unit_vector(&mut rng) * rng.gen_range(5.0..=20.0);
            SphereSweep::new(from, from + d, rng.gen_range(0.5..=2.0))
        })
        .collect()
}

/// Whether the sweep only grazes `s`: the distance from its centre to the
/// segment is within `1e-4` relative of the summed radii (computed in `f64`).
pub fn grazes(sw: &SphereSweep, s: &Sphere) -> bool {
    let d = |v: proxima::glam::Vec3| v.as_dvec3();
    let (a, b, c) = (d(sw.from), d(sw.to), d(s.center));
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((c - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let dist = (a + ab * t).distance(c);
    let rr = (sw.radius + s.radius) as f64;
    (dist - rr).abs() <= 1e-4 * (1.0 + rr)
}

/// Why `got` disagrees with the reference answer `want` on sweep `sw`, or
/// `None`: see the module's description of the check.
pub fn disagreement(
    set: &[Sphere],
    sw: &SphereSweep,
    want: (Option<(u32, f32)>, &[u32]),
    got: (Option<(u32, f32)>, &[u32]),
) -> Option<String> {
    const TOL: f32 = 1e-4;
    let sphere = |i: u32| set.get(i as usize);
    match (want.0, got.0) {
        (None, None) => {}
        (Some((w, tw)), Some((g, tg))) => {
            let exact = sphere(g).and_then(|s| overlap::sweep_sphere(sw, s));
            let tie = exact.is_some_and(|t| (t - tw).abs() <= TOL);
            if (tw - tg).abs() > TOL || (w != g && !tie) {
                return Some(format!("first hit {g} at {tg}, reference {w} at {tw}"));
            }
        }
        (w, g) => {
            let only = w.or(g).expect("one is Some").0;
            if !sphere(only).is_some_and(|s| grazes(sw, s)) {
                return Some(format!("first hit {g:?}, reference {w:?}"));
            }
        }
    }
    let (mut w, mut g) = (want.1.to_vec(), got.1.to_vec());
    w.sort_unstable();
    g.sort_unstable();
    let missing = w.iter().filter(|i| g.binary_search(i).is_err());
    let extra = g.iter().filter(|i| w.binary_search(i).is_err());
    for &i in missing.chain(extra) {
        if !sphere(i).is_some_and(|s| grazes(sw, s)) {
            return Some(format!("hit sets differ on sphere {i} (not a graze)"));
        }
    }
    None
}

/// The timed kinds: the first hit as each library returns it
/// ([`Sweeper::first_key`]), the same mapped to the sphere id
/// ([`Sweeper::first`]: our `get` of the handle; parry's leaf index is the
/// id), and every hit, counted.
pub const KINDS: [&str; 3] = ["first", "first+id", "hits"];

/// One structure on one kind.
#[derive(Clone, Debug)]
pub struct Row {
    /// `first`, `first+id` or `hits` ([`KINDS`]).
    pub kind: &'static str,
    /// Structure.
    pub name: &'static str,
    /// How a peer is built (`-` for ours).
    pub mode: &'static str,
    /// A peer crate?
    pub peer: bool,
    /// Build time.
    pub build: Duration,
    /// Median batch time; `None` when not timed (it disagreed).
    pub batch: Option<Duration>,
    /// Sweeps with a first hit (`first`, `first+id`) or hits in total
    /// (`hits`), per batch.
    pub hits: u64,
}

type Build = Box<dyn Fn(&[Sphere], &Scene) -> Box<dyn Sweeper>>;

/// The structures: name, mode, peer, build. LooseKdTree (the reference) first.
fn entries(a: &Args) -> Vec<(&'static str, &'static str, bool, Build)> {
    let mut out: Vec<(&'static str, &'static str, bool, Build)> = [
        IndexKind::LooseKd,
        IndexKind::Brute,
        IndexKind::Octree,
        IndexKind::HashGrid,
        IndexKind::Grid3d,
        IndexKind::Grid2d,
    ]
    .into_iter()
    .filter(|&k| {
        k == IndexKind::LooseKd
            || (a.wants(k.type_name()) && (k != IndexKind::Brute || a.n <= QUADRATIC_LIMIT))
    })
    .map(|kind| {
        let build: Build = Box::new(move |s: &[Sphere], scene: &Scene| {
            Box::new(Ours(crate::w4::proxima(kind, s, scene, true).0)) as Box<dyn Sweeper>
        });
        (kind.type_name(), crate::registry::NO_MODE, false, build)
    })
    .collect();
    if a.wants("parry3d") {
        let compound: Build = Box::new(|s, _| Box::new(parry_cast::ParryCast::compound(s)));
        let bvh: Build = Box::new(|s, _| Box::new(parry_cast::ParryCast::bvh(s)));
        out.push(("parry3d", "compound", true, compound));
        out.push(("parry3d", "bvh", true, bvh));
    }
    out
}

/// Runs W8; returns the rows and the disagreements found by the check.
pub fn run(a: &Args) -> (Vec<Row>, Vec<String>) {
    let w = Workload::new(Kind::W1, a.n, a.seed);
    let scene = w.scene();
    let batch = sweeps(cube_side(a.n), a.queries, a.seed);
    let checked = &batch[..a.check.min(batch.len())];
    let mut built = Vec::new();
    for (name, mode, peer, build) in entries(a) {
        eprintln!("building {name} {mode} ...");
        let (s, t) = a.clock.time(|| build(&w.spheres, &scene));
        built.push((name, mode, peer, s, t, true));
    }
    let mut errors = Vec::new();
    let answer = |s: &dyn Sweeper, sw: &SphereSweep| (s.first(sw), s.hits(sw));
    let want: Vec<_> = checked.iter().map(|sw| answer(&*built[0].3, sw)).collect();
    for (j, (name, mode, _, s, _, ok)) in built.iter_mut().enumerate() {
        for (i, sw) in checked.iter().enumerate() {
            // The timed call (`first_key`) answers what the checked one
            // does: the same time, or none for both.
            let (timed, mapped) = (s.first_key(sw), s.first(sw));
            if timed.map(|h| h.1) != mapped.map(|h| h.1) {
                errors.push(format!(
                    "W8: {name} {mode} first_key {timed:?} against first {mapped:?} on sweep {i}"
                ));
                *ok = false;
                break;
            }
            if j == 0 {
                continue;
            }
            let got = answer(&**s, sw);
            let reference = (want[i].0, &want[i].1[..]);
            if let Some(why) = disagreement(&w.spheres, sw, reference, (got.0, &got.1)) {
                errors.push(format!(
                    "W8: {name} {mode} disagrees on sweep {i} {sw:?}: {why}"
                ));
                *ok = false;
                break;
            }
        }
    }
    let mut hits = vec![vec![0u64; built.len()]; KINDS.len()];
    let times = query_args::time_round_robin(
        a.clock,
        a.reps,
        KINDS.len(),
        built.len(),
        |_, i| built[i].5,
        |k, i| {
            let s = &built[i].3;
            hits[k][i] = match k {
                // The native answer, kept (`first_key`).
                0 => batch
                    .iter()
                    .filter(|sw| std::hint::black_box(s.first_key(sw)).is_some())
                    .count() as u64,
                1 => batch
                    .iter()
                    .filter(|sw| std::hint::black_box(s.first(sw)).is_some())
                    .count() as u64,
                _ => batch.iter().map(|sw| s.count(sw) as u64).sum(),
            };
        },
    );
    let mut rows = Vec::new();
    for (k, kind) in KINDS.iter().enumerate() {
        for (i, (name, mode, peer, _, build, _)) in built.iter().enumerate() {
            rows.push(Row {
                kind,
                name,
                mode,
                peer: *peer,
                build: *build,
                batch: times[k][i],
                hits: hits[k][i],
            });
        }
    }
    (rows, errors)
}

/// `r`'s batch time over the best peer's on the same kind.
fn ratio(r: &Row, rows: &[Row]) -> Option<f64> {
    let best = rows
        .iter()
        .filter(|p| p.peer && p.kind == r.kind)
        .filter_map(|p| p.batch)
        .min()?;
    Some(r.batch?.as_secs_f64() / best.as_secs_f64().max(1e-12))
}

/// The text tables, one per kind.
pub fn table(a: &Args, rows: &[Row]) -> String {
    let mut out = String::new();
    for kind in KINDS {
        let _ = writeln!(out, "\n{kind}: {} sweeps per batch", a.queries);
        let _ = writeln!(
            out,
            "{:<14} {:<10} {:>9} {:>10} {:>12} {:>12}",
            "structure", "mode", "build ms", "us/query", "hits/batch", "vs parry3d"
        );
        for r in rows.iter().filter(|r| r.kind == kind) {
            let us = r.batch.map_or("n/a".into(), |t| {
                format!("{:.3}", us_per_query(t, a.queries))
            });
            let _ = writeln!(
                out,
                "{:<14} {:<10} {:>9.1} {:>10} {:>12} {:>12}",
                r.name,
                r.mode,
                r.build.as_secs_f64() * 1e3,
                us,
                r.hits,
                fmt_ratio(ratio(r, rows))
            );
        }
    }
    out
}

/// The same numbers as JSON.
pub fn json(a: &Args, rows: &[Row]) -> String {
    let mut out = format!(
        "{{\"workload\":\"w8\",\"n\":{},\"queries\":{},\"seed\":{},\"reps\":{},\"clock\":\"{}\",\"rows\":[",
        a.n,
        a.queries,
        a.seed,
        a.reps,
        a.clock.name()
    );
    for (j, r) in rows.iter().enumerate() {
        let _ = write!(
            out,
            "{}{{\"kind\":\"{}\",\"name\":\"{}\",\"mode\":\"{}\",\"peer\":{},\"build_ms\":{:.3},\"us_per_query\":{},\"hits\":{},\"ratio_to_best_peer\":{}}}",
            if j > 0 { "," } else { "" },
            r.kind,
            r.name,
            r.mode,
            r.peer,
            r.build.as_secs_f64() * 1e3,
            json_num(r.batch.map(|t| us_per_query(t, a.queries))),
            r.hits,
            json_num(ratio(r, rows))
        );
    }
    out.push_str("]}\n");
    out
}

/// `proxima-bench w8 ...`: exit 0, 1 when a structure disagrees, 2 on bad arguments.
pub fn main(args: impl Iterator<Item = String>) -> std::process::ExitCode {
    query_args::main(args, false, 100_000, USAGE, |a| {
        let (rows, errors) = run(a);
        if a.json {
            return (json(a, &rows), errors);
        }
        let mut out = format!(
            "w8 n={} sweeps={} checked={} reps={} seed={} clock={} (median batch time; answers checked against LooseKdTree before timing{})\n",
                a.n,
                a.queries,
                a.check.min(a.queries),
                a.reps,
                a.seed,
                a.clock.name(),
            if a.n > QUADRATIC_LIMIT { "; BruteForce skipped above 20000" } else { "" }
        );
        out.push_str(&table(a, &rows));
        (out, errors)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proxima::glam::Vec3;

    #[test]
    fn every_structure_agrees_on_a_small_set() {
        let argv = [
            "--n",
            "3000",
            "--queries",
            "2000",
            "--check",
            "2000",
            "--reps",
            "1",
        ];
        let a = query_args::parse(argv.iter().map(|s| s.to_string()), false, 10).expect("valid");
        let (rows, errors) = run(&a);
        assert!(errors.is_empty(), "{errors:?}");
        assert_eq!(rows.iter().filter(|r| r.batch.is_some()).count(), 3 * 8);
        // Both first-hit kinds find the same number of hits.
        for (a, b) in rows
            .iter()
            .filter(|r| r.kind == "first")
            .zip(rows.iter().filter(|r| r.kind == "first+id"))
        {
            assert_eq!((a.name, a.mode, a.hits), (b.name, b.mode, b.hits));
        }
        // Every structure finds the same hits in total, and some.
        let first = rows.iter().find(|r| r.kind == "hits").expect("rows").hits;
        assert!(first > 0);
        assert!(rows
            .iter()
            .filter(|r| r.kind == "hits" && !r.peer)
            .all(|r| r.hits == first));
    }

    #[test]
    fn the_check_rejects_wrong_answers_and_allows_grazes() {
        let set = [
            Sphere::new(Vec3::new(5.0, 0.0, 0.0), 1.0),
            Sphere::new(Vec3::new(5.0, 0.0, 2.0), 1.0),
            Sphere::new(Vec3::new(8.0, 0.0, 0.0), 1.0),
        ];
        // Radius 1 along x: touches 0 at t = 0.3, grazes 1 (distance 2 = 1 + 1)
        // at t = 0.5, touches 2 at t = 0.6.
        let sw = SphereSweep::new(Vec3::ZERO, Vec3::new(10.0, 0.0, 0.0), 1.0);
        assert!(grazes(&sw, &set[1]) && !grazes(&sw, &set[0]));
        let all = [0, 1, 2];
        let want = (Some((0, 0.3)), &all[..]);
        assert_eq!(disagreement(&set, &sw, want, want), None);
        // Missing the graze is allowed, missing a real hit is not.
        assert_eq!(
            disagreement(&set, &sw, want, (Some((0, 0.3)), &[0, 2])),
            None
        );
        assert!(disagreement(&set, &sw, want, (Some((0, 0.3)), &[0, 1])).is_some());
        // A wrong first sphere or time.
        assert!(disagreement(&set, &sw, want, (Some((2, 0.6)), &all)).is_some());
        assert!(disagreement(&set, &sw, want, (Some((0, 0.31)), &all)).is_some());
        assert!(disagreement(&set, &sw, want, (None, &all)).is_some());
    }
}
