//! Pair searches pruned by collision filters, against brute force: every index
//! kind, long random operation sequences in which many objects are inert
//! (group or mask zero: they never enter a pair search) and filters change
//! often through `set_filter` (objects turning inert and back), in two filter
//! layouts — random bits, and bits by region (so that whole subtrees or cells
//! share bits and the trees' per-node OR pruning has work to do). With the
//! `parallel` feature the parallel pair search is checked too.

use proxima::broad::{AnyIndex, BruteForce, Filter, IndexKind, SceneHint, SpatialIndex};
use proxima::geom::{Aabb, Sphere};
use proxima::glam::{vec3, Vec3};
use proxima::Handle;
use proxima_harness::oracle::{make_index, pair_ids};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::collections::HashMap;

/// Operations per index kind, layout and seed.
const OPS: usize = 2500;

/// How filters are drawn.
#[derive(Clone, Copy, Debug)]
enum Layout {
    /// Independent of position: 45% inert, 20% [`Filter::ALL`], the rest a
    /// few random bits.
    Random,
    /// By position: the objects left of the middle in group 1 colliding with
    /// group 1, the others group 2 with group 2, a third inert, a few ALL.
    Regions,
}

struct Scene {
    rng: Pcg64,
    world: Aabb,
    layout: Layout,
}

impl Scene {
    fn filter(&mut self, center: Vec3) -> Filter {
        let roll = self.rng.gen_range(0..20);
        match self.layout {
            Layout::Random => match roll {
                0..=2 => Filter::new(0, self.rng.gen_range(0..16)),
                3..=5 => Filter::new(self.rng.gen_range(0..16), 0),
                6..=8 => Filter::new(0, 0),
                9..=12 => Filter::ALL,
                _ => Filter::new(self.rng.gen_range(1..16), self.rng.gen_range(1..16)),
            },
            Layout::Regions => match roll {
                0..=6 => Filter::new(0, if roll % 2 == 0 { 0 } else { 3 }),
                7 => Filter::ALL,
                _ if center.x < 15.0 => Filter::new(1, 1),
                _ => Filter::new(2, 2),
            },
        }
    }

    fn center(&mut self) -> Vec3 {
        // A few outside the world box.
        let (lo, hi) = if self.rng.gen_bool(0.05) {
            (-10.0, 40.0)
        } else {
            (0.0, 30.0)
        };
        vec3(
            self.rng.gen_range(lo..hi),
            self.rng.gen_range(lo..hi),
            self.rng.gen_range(lo..hi),
        )
    }

    fn radius(&mut self) -> f32 {
        match self.rng.gen_range(0..40) {
            // A few large ones: the grids' large/oversized lists, tree roots.
            0 => self.rng.gen_range(5.0..15.0),
            1 => 0.0,
            _ => self.rng.gen_range(0.5..4.0),
        }
    }

    fn sphere(&mut self) -> Sphere {
        let c = self.center();
        Sphere::new(c, self.radius())
    }
}

#[cfg(feature = "parallel")]
fn par_pair_ids(index: &AnyIndex<u64>, pool: &rayon::ThreadPool) -> Vec<(u64, u64)> {
    use proxima::broad::ParallelPairs;
    let pairs = pool.install(|| index.par_pairs());
    let id = |h: Handle| *index.get(h).unwrap().1;
    let mut v: Vec<_> = pairs
        .into_iter()
        .map(|(a, b)| {
            let (a, b) = (id(a), id(b));
            (a.min(b), a.max(b))
        })
        .collect();
    v.sort_unstable();
    v
}

/// Totals over a run, so that the test proves it compared something.
#[derive(Default)]
struct Seen {
    checks: usize,
    pairs: usize,
    inert_at_checks: usize,
    objects_at_checks: usize,
    non_interacting_overlaps: usize,
}

fn run(kind: IndexKind, layout: Layout, seed: u64) -> Seen {
    let world = Aabb::new(Vec3::ZERO, Vec3::splat(30.0));
    let mut g = Scene {
        rng: Pcg64::seed_from_u64(seed),
        world,
        layout,
    };
    let mut index: AnyIndex<u64> = make_index(kind, &SceneHint::new(g.world, 4.0));
    let mut oracle: BruteForce<u64> = BruteForce::new();
    let mut live: HashMap<u64, (Handle, Handle)> = HashMap::new();
    let mut order: Vec<u64> = Vec::new();
    let mut next = 1u64;
    let mut seen = Seen::default();
    #[cfg(feature = "parallel")]
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    for step in 0..OPS {
        let ctx = || format!("{kind:?} {layout:?} seed {seed} step {step}");
        let roll = g.rng.gen_range(0..100);
        if step == OPS / 2 {
            // Once per run: everything goes, and the index fills up again.
            index.clear();
            oracle.clear();
            live.clear();
            order.clear();
        } else if order.is_empty() || (roll < 35 && order.len() < 350) {
            let s = g.sphere();
            let f = g.filter(s.center);
            let hi = index.insert_with_filter(s, f, next).unwrap();
            let ho = oracle.insert_with_filter(s, f, next).unwrap();
            live.insert(next, (hi, ho));
            order.push(next);
            next += 1;
        } else if roll < 65 {
            let id = order[g.rng.gen_range(0..order.len())];
            let (hi, ho) = live[&id];
            let old = oracle.get(ho).unwrap().0;
            let s = if g.rng.gen_bool(0.7) {
                let d = vec3(
                    g.rng.gen_range(-2.0..2.0),
                    g.rng.gen_range(-2.0..2.0),
                    g.rng.gen_range(-2.0..2.0),
                );
                Sphere::new(old.center + d, old.radius)
            } else {
                g.sphere()
            };
            index.update(hi, s).unwrap();
            oracle.update(ho, s).unwrap();
        } else if roll < 85 {
            // Filter changes: inert to active and back, bits that leave the
            // trees' OR-ed bits stale (a superset).
            let id = order[g.rng.gen_range(0..order.len())];
            let (hi, ho) = live[&id];
            let c = oracle.get(ho).unwrap().0.center;
            let f = g.filter(c);
            index.set_filter(hi, f).unwrap();
            oracle.set_filter(ho, f).unwrap();
            assert_eq!(index.filter(hi), Ok(f), "{}", ctx());
        } else {
            let k = g.rng.gen_range(0..order.len());
            let id = order.swap_remove(k);
            let (hi, ho) = live.remove(&id).unwrap();
            assert_eq!(index.remove(hi), Ok(id), "{}", ctx());
            oracle.remove(ho).unwrap();
        }
        index
            .validate()
            .unwrap_or_else(|e| panic!("{}: validate: {e}", ctx()));
        if step % 5 == 0 || step + 1 == OPS {
            let want = pair_ids(&oracle);
            assert_eq!(pair_ids(&index), want, "{}: pairs", ctx());
            #[cfg(feature = "parallel")]
            assert_eq!(par_pair_ids(&index, &pool), want, "{}: par pairs", ctx());
            seen.checks += 1;
            seen.pairs += want.len();
            seen.objects_at_checks += oracle.len();
            let mut inert = 0;
            oracle.for_each(&mut |h, _, _| inert += oracle.filter(h).unwrap().is_inert() as usize);
            seen.inert_at_checks += inert;
            // Overlapping pairs the filters drop: the searches had to leave
            // these out.
            let all = oracle.len();
            let mut spheres = Vec::with_capacity(all);
            oracle.for_each(&mut |h, s, _| spheres.push((*s, oracle.filter(h).unwrap())));
            for (i, (a, fa)) in spheres.iter().enumerate() {
                for (b, fb) in &spheres[i + 1..] {
                    if !fa.interacts(*fb) && proxima::geom::overlap::sphere_sphere(a, b) {
                        seen.non_interacting_overlaps += 1;
                    }
                }
            }
        }
    }
    seen
}

fn check_kind(kind: IndexKind) {
    for layout in [Layout::Random, Layout::Regions] {
        for seed in [11u64, 12] {
            let seen = run(kind, layout, seed);
            // The run compared real work: many pairs, many inert objects, and
            // many overlaps that only the filters remove.
            assert!(
                seen.checks > 400,
                "{kind:?} {layout:?}: {} checks",
                seen.checks
            );
            assert!(
                seen.pairs > 10 * seen.checks,
                "{kind:?} {layout:?}: {} pairs",
                seen.pairs
            );
            assert!(
                3 * seen.inert_at_checks > seen.objects_at_checks,
                "{kind:?} {layout:?}: {} of {} inert",
                seen.inert_at_checks,
                seen.objects_at_checks
            );
            assert!(
                seen.non_interacting_overlaps > seen.pairs,
                "{kind:?} {layout:?}: {} dropped overlaps, {} pairs",
                seen.non_interacting_overlaps,
                seen.pairs
            );
        }
    }
}

/// Every kind (so a new kind is covered without a change here).
#[test]
fn every_kind_prunes_pairs_by_filter_exactly() {
    for kind in IndexKind::ALL {
        check_kind(kind);
    }
}
