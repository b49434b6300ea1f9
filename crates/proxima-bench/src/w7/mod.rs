//! `proxima-bench w7 [--n N] [--queries Q] [--k 1,10,100] [--set points,spheres] [--check C] [--reps R] [--seed S] [--clock cpu|wall] [--only A,B] [--json]`
//!
//! W7 [sources: w4]: k nearest neighbours on a static set (issue #14). W4's set
//! (`N` spheres, radii in `[0.5, 2]`, centres uniform in a cube of side
//! `4·N^(1/3)`) as points (radius 0, the same centres) and as spheres, loaded
//! into every Proxima index (Morton-order inserts, as W4) and the peers
//! ([`peers`]: kiddo, rstar, parry3d). `Q` query points (9 in 10 uniform in
//! the cube, 1 in 10 outside it, up to one side away) ask for the `k` nearest
//! by surface distance (`max(0, |c - q| - r)`; the centre distance for points)
//! through `SpatialIndex::nearest_into` with one reused output buffer.
//!
//! Before timing, the answers to the first `C` queries of every structure are
//! checked against LooseKdTree's (which the library's oracle tests check
//! against brute force): same length, the same distances within `1e-6`
//! of `|c - q| + r` and the coordinates (ties may order ids differently), and every id returned at the
//! distance reported for it. A structure that disagrees is reported (exit 1)
//! and not timed. Then each batch runs `R` rounds round-robin; the table gives
//! build time, median µs per query, and the ratio to the best peer and to the
//! target peer (kiddo for points, rstar for spheres).

pub mod peers;

use crate::query_args::{self, fmt_ratio, json_num, us_per_query, Args};
use crate::registry::QUADRATIC_LIMIT;
use parry3d::partitioning::BvhBuildStrategy;
use proxima::broad::{AnyIndex, IndexKind, Nearest, Neighbor, SpatialIndex};
use proxima::geom::{overlap, Sphere};
use proxima::glam::Vec3;
use proxima_harness::workloads::{cube_side, Kind, Scene, Workload};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::fmt::Write;
use std::time::Duration;

const USAGE: &str = "usage: proxima-bench w7 [--n N] [--queries Q] [--k 1,10,100] [--set points,spheres] [--check C] [--reps R] [--seed S] [--clock cpu|wall] [--only A,B] [--json]";

/// A structure answering k-nearest queries over the set (object `i` = sphere `i`).
pub trait Knn {
    /// Answers the `k` nearest to `q`; returns how many were found (the timed
    /// call: each structure keeps its answer in its own form).
    fn run(&mut self, q: Vec3, k: usize) -> usize;
    /// The answer as `(id, distance)`, nearest first (the checked call).
    fn answer(&mut self, q: Vec3, k: usize) -> Vec<(u32, f32)>;
    /// Whether the structure answers this `k`.
    fn supports(&self, _k: usize) -> bool {
        true
    }
}

/// A Proxima index and its reused output buffer.
pub struct Ours {
    index: AnyIndex<u32>,
    out: Vec<Neighbor>,
}

impl Ours {
    /// The index of `kind` as W4 builds it (configured for W4's scene, loaded
    /// in Morton order). Point sets use the spheres' scene too: its cells
    /// (sized for radius 2) match the mean point spacing of 4, where a
    /// radius-0 hint would leave them unsized.
    pub fn build(kind: IndexKind, set: &[Sphere], scene: &Scene) -> Self {
        Ours {
            index: crate::w4::proxima(kind, set, scene, true).0,
            out: Vec::new(),
        }
    }
}

impl Knn for Ours {
    fn run(&mut self, q: Vec3, k: usize) -> usize {
        self.index
            .nearest_into(&Nearest::new(q, k), None, &mut self.out)
            .expect("finite query");
        self.out.len()
    }

    fn answer(&mut self, q: Vec3, k: usize) -> Vec<(u32, f32)> {
        self.run(q, k);
        self.out
            .iter()
            .map(|n| (*self.index.get(n.handle).expect("live").1, n.distance))
            .collect()
    }
}

/// Builds one structure over the set (`true`: the set is points).
type Build = Box<dyn Fn(&[Sphere], &Scene, bool) -> Box<dyn Knn>>;

/// One structure of the table: name, build mode (`-` for ours), peer or not,
/// which sets it takes and how it is built.
struct Entry {
    name: &'static str,
    mode: &'static str,
    peer: bool,
    points_only: bool,
    build: Build,
}

/// The reference every answer is checked against (always built).
const REFERENCE: IndexKind = IndexKind::LooseKd;

fn entries(a: &Args) -> Vec<Entry> {
    let n = a.n;
    let mut out: Vec<Entry> = [
        IndexKind::LooseKd,
        IndexKind::Brute,
        IndexKind::Octree,
        IndexKind::HashGrid,
        IndexKind::Grid3d,
        IndexKind::Grid2d,
    ]
    .into_iter()
    .filter(|&k| {
        k == REFERENCE
            || (a.wants(k.type_name()) && (k != IndexKind::Brute || n <= QUADRATIC_LIMIT))
    })
    .map(|kind| Entry {
        name: kind.type_name(),
        mode: crate::registry::NO_MODE,
        peer: false,
        points_only: false,
        build: Box::new(move |s: &[Sphere], scene: &Scene, _| {
            Box::new(Ours::build(kind, s, scene)) as Box<dyn Knn>
        }),
    })
    .collect();
    out.push(Entry {
        name: "kiddo",
        mode: "immutable",
        peer: true,
        points_only: true,
        build: Box::new(|s, _, _| Box::new(peers::KiddoKnn::build(s))),
    });
    out.push(Entry {
        name: "rstar",
        mode: "bulk_load",
        peer: true,
        points_only: false,
        build: Box::new(|s, _, points| {
            if points {
                Box::new(peers::RstarKnn::points(s))
            } else {
                Box::new(peers::RstarKnn::spheres(s))
            }
        }),
    });
    for (mode, strategy) in [
        ("binned", BvhBuildStrategy::Binned),
        ("ploc", BvhBuildStrategy::Ploc),
    ] {
        out.push(Entry {
            name: "parry3d",
            mode,
            peer: true,
            points_only: false,
            build: Box::new(move |s, _, _| Box::new(peers::ParryKnn::build(s, strategy))),
        });
    }
    out.retain(|e| !e.peer || a.wants(e.name));
    out
}

/// W7's query points: 9 in 10 uniform in the cube of side `side`, 1 in 10
/// uniform in the box one side larger on every face but outside the cube.
pub fn query_points(side: f32, q: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = Pcg64::seed_from_u64(seed ^ 0x5737_0000_0007);
    let mut point = |lo: f32, hi: f32| {
        Vec3::new(
            rng.gen_range(lo..=hi),
            rng.gen_range(lo..=hi),
            rng.gen_range(lo..=hi),
        )
    };
    (0..q)
        .map(|i| {
            if i % 10 != 9 {
                return point(0.0, side);
            }
            loop {
                let p = point(-side, 2.0 * side);
                if p.cmplt(Vec3::ZERO).any() || p.cmpgt(Vec3::splat(side)).any() {
                    return p;
                }
            }
        })
        .collect()
}

/// Why `got` is not a correct answer where `want` (the reference) is, or
/// `None` when it is: same length, distinct ids, and at every rank the
/// reported distance equals the reference's and the true distance of the id
/// returned, within `1e-6` of the magnitudes involved (`|c - q| + r` and the
/// coordinates: `f32` peers round both). Ties may order ids
/// differently.
pub fn disagreement(
    set: &[Sphere],
    q: Vec3,
    want: &[(u32, f32)],
    got: &[(u32, f32)],
) -> Option<String> {
    if want.len() != got.len() {
        return Some(format!("{} results, reference {}", got.len(), want.len()));
    }
    let mut ids: Vec<u32> = got.iter().map(|g| g.0).collect();
    ids.sort_unstable();
    if ids.windows(2).any(|w| w[0] == w[1]) {
        return Some("an id returned twice".into());
    }
    for (rank, (w, g)) in want.iter().zip(got).enumerate() {
        let Some(s) = set.get(g.0 as usize) else {
            return Some(format!("rank {rank}: unknown id {}", g.0));
        };
        // f32 peers round coordinates of this size (parry's projected point).
        let coords = q.abs().max(s.center.abs()).max_element();
        let tol = 1e-6 * (s.center.distance(q) + s.radius).max(coords).max(1.0);
        let true_d = overlap::point_sphere_distance(q, s);
        if (w.1 - g.1).abs() > tol || (true_d - g.1).abs() > tol {
            return Some(format!(
                "rank {rank}: id {} at {} (its distance {true_d}), reference id {} at {}",
                g.0, g.1, w.0, w.1
            ));
        }
    }
    None
}

/// One structure on one set and `k`.
#[derive(Clone, Debug)]
pub struct Row {
    /// `points` or `spheres`.
    pub set: &'static str,
    /// Neighbours asked for.
    pub k: usize,
    /// Structure.
    pub name: &'static str,
    /// How a peer is built (`-` for ours).
    pub mode: &'static str,
    /// A peer crate?
    pub peer: bool,
    /// Build time.
    pub build: Duration,
    /// Median batch time; `None` when not supported or not timed.
    pub batch: Option<Duration>,
}

/// Runs W7; returns the rows and the disagreements found by the check.
pub fn run(a: &Args) -> (Vec<Row>, Vec<String>) {
    let w = Workload::new(Kind::W1, a.n, a.seed);
    let scene = w.scene();
    let queries = query_points(cube_side(a.n), a.queries, a.seed);
    let checked = &queries[..a.check.min(queries.len())];
    let mut rows = Vec::new();
    let mut errors = Vec::new();
    for set_name in ["points", "spheres"] {
        if !a.sets.iter().any(|s| s == set_name) {
            continue;
        }
        let points = set_name == "points";
        let set: Vec<Sphere> = w
            .spheres
            .iter()
            .map(|s| Sphere::new(s.center, if points { 0.0 } else { s.radius }))
            .collect();
        let mut built = Vec::new();
        for e in entries(a) {
            if points || !e.points_only {
                eprintln!("{set_name}: building {} {} ...", e.name, e.mode);
                let (s, t) = a.clock.time(|| (e.build)(&set, &scene, points));
                built.push((e, s, t, true));
            }
        }
        // Check every structure against the reference (entry 0) on each k.
        for &k in &a.ks {
            let want: Vec<_> = checked.iter().map(|&q| built[0].1.answer(q, k)).collect();
            for (e, s, _, ok) in built.iter_mut().skip(1) {
                if !s.supports(k) {
                    continue;
                }
                for (i, &q) in checked.iter().enumerate() {
                    if let Some(why) = disagreement(&set, q, &want[i], &s.answer(q, k)) {
                        errors.push(format!(
                            "W7 {set_name} k={k}: {} {} disagrees on query {i} {q}: {why}",
                            e.name, e.mode
                        ));
                        *ok = false;
                        break;
                    }
                }
            }
        }
        let runs: Vec<Vec<bool>> = (a.ks.iter())
            .map(|&k| built.iter().map(|b| b.3 && b.1.supports(k)).collect())
            .collect();
        let mut sink = 0usize;
        let times = query_args::time_round_robin(
            a.clock,
            a.reps,
            a.ks.len(),
            built.len(),
            |k, i| runs[k][i],
            |k, i| {
                let s = &mut built[i].1;
                for &q in &queries {
                    sink += s.run(q, a.ks[k]);
                }
            },
        );
        std::hint::black_box(sink);
        for (k, &kk) in a.ks.iter().enumerate() {
            for (i, (e, _, build, _)) in built.iter().enumerate() {
                rows.push(Row {
                    set: if points { "points" } else { "spheres" },
                    k: kk,
                    name: e.name,
                    mode: e.mode,
                    peer: e.peer,
                    build: *build,
                    batch: times[k][i],
                });
            }
        }
    }
    (rows, errors)
}

/// The rows of the same set and `k` as `r`.
fn group<'a>(r: &'a Row, rows: &'a [Row]) -> impl Iterator<Item = &'a Row> {
    rows.iter().filter(move |p| p.set == r.set && p.k == r.k)
}

/// `r`'s batch time over the best of the peers `keep` accepts, same set and `k`.
fn ratio_to(r: &Row, rows: &[Row], keep: impl Fn(&Row) -> bool) -> Option<f64> {
    let best = group(r, rows)
        .filter(|p| p.peer && keep(p))
        .filter_map(|p| p.batch)
        .min()?;
    Some(r.batch?.as_secs_f64() / best.as_secs_f64().max(1e-12))
}

/// The peer the target is set against: kiddo for points, rstar for spheres.
pub fn target_peer(set: &str) -> &'static str {
    if set == "points" {
        "kiddo"
    } else {
        "rstar"
    }
}

/// The text tables, one per set and `k`.
pub fn table(a: &Args, rows: &[Row]) -> String {
    let mut out = String::new();
    let mut last = None;
    for r in rows {
        if last != Some((r.set, r.k)) {
            last = Some((r.set, r.k));
            let _ = writeln!(
                out,
                "\n{} k={}: {} queries per batch",
                r.set, r.k, a.queries
            );
            let _ = writeln!(
                out,
                "{:<14} {:<10} {:>9} {:>10} {:>12} {:>10}",
                "structure",
                "mode",
                "build ms",
                "us/query",
                "vs best peer",
                format!("vs {}", target_peer(r.set))
            );
        }
        let us = r.batch.map_or("n/a".into(), |t| {
            format!("{:.3}", us_per_query(t, a.queries))
        });
        let _ = writeln!(
            out,
            "{:<14} {:<10} {:>9.1} {:>10} {:>12} {:>10}",
            r.name,
            r.mode,
            r.build.as_secs_f64() * 1e3,
            us,
            fmt_ratio(ratio_to(r, rows, |_| true)),
            fmt_ratio(ratio_to(r, rows, |p| p.name == target_peer(r.set)))
        );
    }
    out
}

/// The same numbers as JSON.
pub fn json(a: &Args, rows: &[Row]) -> String {
    let mut out = format!(
        "{{\"workload\":\"w7\",\"n\":{},\"queries\":{},\"seed\":{},\"reps\":{},\"clock\":\"{}\",\"rows\":[",
        a.n,
        a.queries,
        a.seed,
        a.reps,
        a.clock.name()
    );
    for (j, r) in rows.iter().enumerate() {
        let _ = write!(
            out,
            "{}{{\"set\":\"{}\",\"k\":{},\"name\":\"{}\",\"mode\":\"{}\",\"peer\":{},\"build_ms\":{:.3},\"us_per_query\":{},\"ratio_to_best_peer\":{},\"ratio_to_target_peer\":{}}}",
            if j > 0 { "," } else { "" },
            r.set,
            r.k,
            r.name,
            r.mode,
            r.peer,
            r.build.as_secs_f64() * 1e3,
            json_num(r.batch.map(|t| us_per_query(t, a.queries))),
            json_num(ratio_to(r, rows, |_| true)),
            json_num(ratio_to(r, rows, |p| p.name == target_peer(r.set)))
        );
    }
    out.push_str("]}\n");
    out
}

/// `proxima-bench w7 ...`: exit 0, 1 when a structure disagrees, 2 on bad arguments.
pub fn main(args: impl Iterator<Item = String>) -> std::process::ExitCode {
    query_args::main(args, true, 10_000, USAGE, |a| {
        let (rows, errors) = run(a);
        if a.json {
            return (json(a, &rows), errors);
        }
        let mut out = format!(
            "w7 n={} queries={} checked={} reps={} seed={} clock={} (median batch time; answers checked against LooseKdTree before timing{})\n",
                a.n,
                a.queries,
                a.check.min(a.queries),
                a.reps,
                a.seed,
                a.clock.name(),
            if a.n > QUADRATIC_LIMIT { "; BruteForce skipped above 20000" } else { "" }
        );
        out.push_str(&table(a, &rows));
        out.push_str("kiddo: points only; parry3d: k = 1 only (Bvh::project_point has no k).\n");
        (out, errors)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small(sets: &str) -> Args {
        let argv = [
            "--n",
            "3000",
            "--queries",
            "300",
            "--check",
            "300",
            "--reps",
            "1",
            "--set",
            sets,
        ];
        query_args::parse(argv.iter().map(|s| s.to_string()), true, 10).expect("valid")
    }

    #[test]
    fn every_structure_agrees_on_a_small_set() {
        for sets in ["points", "spheres"] {
            let a = small(sets);
            let (rows, errors) = run(&a);
            assert!(errors.is_empty(), "{errors:?}");
            // Brute force runs on a small set, and every peer that applies.
            for name in ["BruteForce", "LooseKdTree", "rstar", "parry3d"] {
                assert!(
                    rows.iter().any(|r| r.name == name && r.batch.is_some()),
                    "{name}"
                );
            }
            let kiddo = rows.iter().any(|r| r.name == "kiddo" && r.batch.is_some());
            assert_eq!(kiddo, sets == "points");
            // parry answers k = 1 only.
            assert!(rows
                .iter()
                .all(|r| r.name != "parry3d" || (r.k == 1) == r.batch.is_some()));
        }
    }

    #[test]
    fn the_check_rejects_wrong_answers_and_accepts_ties() {
        let set = [
            Sphere::new(Vec3::new(1.0, 0.0, 0.0), 0.0),
            Sphere::new(Vec3::new(-1.0, 0.0, 0.0), 0.0),
            Sphere::new(Vec3::new(0.0, 3.0, 0.0), 1.0),
        ];
        let q = Vec3::ZERO;
        let want = [(0, 1.0), (1, 1.0), (2, 2.0)];
        assert_eq!(disagreement(&set, q, &want, &want), None);
        // A tie in another order is the same answer.
        assert_eq!(
            disagreement(&set, q, &want, &[(1, 1.0), (0, 1.0), (2, 2.0)]),
            None
        );
        // Too short, a wrong distance, a duplicate, an id at a distance it is not at.
        assert!(disagreement(&set, q, &want, &want[..2]).is_some());
        assert!(disagreement(&set, q, &want, &[(0, 1.0), (1, 1.0), (2, 2.001)]).is_some());
        assert!(disagreement(&set, q, &want, &[(0, 1.0), (0, 1.0), (2, 2.0)]).is_some());
        assert!(disagreement(&set, q, &want, &[(0, 1.0), (2, 1.0), (1, 2.0)]).is_some());
        assert!(disagreement(&set, q, &want, &[(0, 1.0), (1, 1.0), (7, 2.0)]).is_some());
    }

    #[test]
    fn query_points_are_mostly_inside_and_some_outside() {
        let side = 100.0;
        let q = query_points(side, 1000, 3);
        let inside = |p: &Vec3| p.cmpge(Vec3::ZERO).all() && p.cmple(Vec3::splat(side)).all();
        assert_eq!(q.iter().filter(|p| inside(p)).count(), 900);
        assert!(q.iter().all(|p| p.abs().max_element() <= 2.0 * side));
    }
}
