//! The generic broad-phase oracle [sources: index-trait]: long seeded random
//! sequences of inserts, moves, removals and queries run on an index and on
//! `BruteForce` side by side ([`run`]); every answer must be identical and
//! `validate()` must pass after every operation. The library's suites
//! (`tests/oracle`, `tests/loose_kd*.rs`) run it on every index and
//! configuration, and [`make_index`] is the one way they build an index of a kind.
//!
//! The scenes here are shapes for operation sequences (random moves, jumps,
//! resizes, bad input), not the benchmark workloads of [`crate::workloads`].

use proxima::broad::{
    AnyIndex, BruteForce, Filter, IndexKind, LooseKdConfig, LooseKdTree, Metric, Nearest, Neighbor,
    Query, RayHit, SceneHint, SpatialIndex, SpatialIndexExt,
};
use proxima::geom::{Aabb, Frustum, Ray, Segment, Sphere, SphereSweep};
use proxima::glam::{vec3, Mat4, Vec3};
use proxima::Handle;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::collections::HashMap;
use std::ops::ControlFlow;

/// The kinds of scene the suite draws from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scene {
    /// W1: uniform centres in a cube, radii 0.5..2.
    Uniform,
    /// W2: a 1000 x 1000 x 10 slab.
    Flat,
    /// W3: a few tight Gaussian clusters.
    Clustered,
    /// Radii from 0 to 200 (many larger than the index's `r_max`).
    WideRadii,
    /// A quarter of the centres outside the world box, some far outside.
    Outside,
    /// Many spheres at one point (and zero radii).
    OnePoint,
}

/// Every [`Scene`], in declaration order.
pub const ALL_SCENES: [Scene; 6] = [
    Scene::Uniform,
    Scene::Flat,
    Scene::Clustered,
    Scene::WideRadii,
    Scene::Outside,
    Scene::OnePoint,
];

/// What an index constructor is told about the scene: the world box and the
/// typical largest radius (objects may still exceed either).
#[derive(Clone, Copy, Debug)]
pub struct SceneParams {
    /// The world box.
    pub world: Aabb,
    /// The typical largest radius.
    pub r_max: f32,
}

impl SceneParams {
    /// The same as the library's hint ([`SceneHint::new`]).
    pub fn hint(&self) -> SceneHint {
        SceneHint::new(self.world, self.r_max)
    }
}

/// The index of `kind` the test suites run for `hint`: each config's
/// `for_scene`, except a denser loose k-d tree (density 0.5: deeper nodes, so
/// more splits, merges and moves between nodes per operation). A suite that
/// wants another configuration of one kind matches on that kind first and
/// falls back to this.
pub fn make_index<T: Send + Sync>(kind: IndexKind, hint: &SceneHint) -> AnyIndex<T> {
    match kind {
        IndexKind::LooseKd => LooseKdTree::with_config(LooseKdConfig {
            density: 0.5,
            ..LooseKdConfig::for_scene(hint)
        })
        .unwrap_or_else(|e| panic!("{kind}: {e}"))
        .into(),
        _ => kind.build(hint).unwrap_or_else(|e| panic!("{kind}: {e}")),
    }
}

struct Gen {
    scene: Scene,
    world: Aabb,
    clusters: Vec<Vec3>,
    rng: Pcg64,
}

impl Gen {
    fn new(scene: Scene, seed: u64) -> Gen {
        let mut rng = Pcg64::seed_from_u64(seed);
        let world = match scene {
            Scene::Flat => Aabb::new(Vec3::ZERO, vec3(1000.0, 1000.0, 10.0)),
            _ => Aabb::new(Vec3::ZERO, Vec3::splat(100.0)),
        };
        let clusters = (0..4)
            .map(|_| {
                vec3(
                    rng.gen_range(10.0..90.0),
                    rng.gen_range(10.0..90.0),
                    rng.gen_range(10.0..90.0),
                )
            })
            .collect();
        Gen {
            scene,
            world,
            clusters,
            rng,
        }
    }

    fn params(&self) -> SceneParams {
        SceneParams {
            world: self.world,
            r_max: 2.0,
        }
    }

    fn uniform_in(&mut self, b: &Aabb) -> Vec3 {
        vec3(
            self.rng.gen_range(b.min.x..=b.max.x),
            self.rng.gen_range(b.min.y..=b.max.y),
            self.rng.gen_range(b.min.z..=b.max.z),
        )
    }

    fn gauss(&mut self) -> f32 {
        // Sum of uniforms: close enough to a Gaussian for scene shapes.
        (0..4)
            .map(|_| self.rng.gen_range(-1.0f32..1.0))
            .sum::<f32>()
    }

    fn center(&mut self) -> Vec3 {
        let w = self.world;
        match self.scene {
            Scene::Uniform | Scene::Flat | Scene::WideRadii => self.uniform_in(&w),
            Scene::Clustered => {
                let c = self.clusters[self.rng.gen_range(0..self.clusters.len())];
                c + vec3(self.gauss(), self.gauss(), self.gauss()) * 2.0
            }
            Scene::Outside => {
                if self.rng.gen_bool(0.25) {
                    let far = if self.rng.gen_bool(0.2) { 1e4 } else { 150.0 };
                    self.uniform_in(&Aabb::new(Vec3::splat(-far), Vec3::splat(far)))
                } else {
                    self.uniform_in(&w)
                }
            }
            Scene::OnePoint => {
                if self.rng.gen_bool(0.8) {
                    vec3(37.5, 37.5, 37.5)
                } else {
                    self.uniform_in(&w)
                }
            }
        }
    }

    fn radius(&mut self) -> f32 {
        match self.scene {
            Scene::WideRadii => {
                if self.rng.gen_bool(0.1) {
                    0.0
                } else {
                    self.rng.gen_range(0.0f32..1.0).powi(3) * 200.0
                }
            }
            Scene::OnePoint => {
                if self.rng.gen_bool(0.5) {
                    0.0
                } else {
                    self.rng.gen_range(0.0..2.0)
                }
            }
            _ => self.rng.gen_range(0.5..2.0),
        }
    }

    fn sphere(&mut self) -> Sphere {
        Sphere::new(self.center(), self.radius())
    }

    fn query_sphere(&mut self) -> Sphere {
        let c = self.center();
        let r = self.rng.gen_range(0.0f32..1.0).powi(2) * 30.0;
        Sphere::new(c, r)
    }

    fn query_aabb(&mut self) -> Aabb {
        let c = self.center();
        let h = vec3(
            self.rng.gen_range(0.0..20.0),
            self.rng.gen_range(0.0..20.0),
            self.rng.gen_range(0.0..20.0),
        );
        Aabb::new(c - h, c + h)
    }

    fn direction(&mut self) -> Vec3 {
        loop {
            let mut d = vec3(
                self.rng.gen_range(-1.0..1.0),
                self.rng.gen_range(-1.0..1.0),
                self.rng.gen_range(-1.0..1.0),
            );
            // Axis-aligned rays exercise the zero-component paths.
            if self.rng.gen_bool(0.15) {
                let keep = self.rng.gen_range(0..3);
                for a in 0..3 {
                    if a != keep {
                        d[a] = 0.0;
                    }
                }
            }
            if d.length_squared() > 1e-4 {
                return d * self.rng.gen_range(0.5..3.0);
            }
        }
    }

    fn ray(&mut self) -> Ray {
        let o = self.center();
        let d = self.direction();
        let max_t = if self.rng.gen_bool(0.3) {
            f32::INFINITY
        } else {
            self.rng.gen_range(0.0..100.0)
        };
        Ray::with_max_t(o, d, max_t)
    }

    fn frustum(&mut self) -> Frustum {
        let eye = self.center();
        let target = self.center();
        let dir = if (target - eye).length_squared() < 1e-3 {
            Vec3::X
        } else {
            target - eye
        };
        let up = if dir.cross(Vec3::Z).length_squared() < 1e-6 {
            Vec3::Y
        } else {
            Vec3::Z
        };
        let view = Mat4::look_to_rh(eye, dir, up);
        let proj = if self.rng.gen_bool(0.8) {
            Mat4::perspective_rh(
                self.rng.gen_range(0.3..2.0),
                self.rng.gen_range(0.5..2.0),
                self.rng.gen_range(0.1..5.0),
                self.rng.gen_range(10.0..200.0),
            )
        } else {
            let s = self.rng.gen_range(5.0..50.0);
            Mat4::orthographic_rh(-s, s, -s, s, 0.0, self.rng.gen_range(10.0..200.0))
        };
        Frustum::from_view_projection(proj * view).unwrap()
    }
}

/// The generators of the k-nearest, sweep and filter checks.
impl Gen {
    /// An object's or a query's filter: [`Filter::ALL`] half the time, else a
    /// few bits (so that both answers of `interacts` are common), sometimes
    /// inert (a zero group or mask).
    fn filter(&mut self) -> Filter {
        match self.rng.gen_range(0..16) {
            0..=7 => Filter::ALL,
            8 => Filter::new(self.rng.gen_range(0..2), self.rng.gen_range(0..8)),
            _ => Filter::new(1 << self.rng.gen_range(0..3), self.rng.gen_range(1..8)),
        }
    }

    /// A query's filter: none half the time.
    fn query_filter(&mut self) -> Option<Filter> {
        self.rng.gen_bool(0.5).then(|| self.filter())
    }

    /// A point far outside the world (1e7 or 3e37 away).
    fn far_point(&mut self) -> Vec3 {
        let d = self.direction().normalize();
        let far = if self.rng.gen_bool(0.7) { 1e7 } else { 3e37 };
        self.world.center() + d * far
    }

    /// A point on a quarter-unit grid in and around the world: differences of
    /// two such points are exact in `f32`.
    fn grid_point(&mut self) -> Vec3 {
        let c = self.center();
        (c * 4.0).round() / 4.0
    }

    /// A live object's sphere, if any.
    fn stored(&mut self, oracle: &BruteForce<u64>) -> Option<Sphere> {
        let mut all = Vec::new();
        oracle.for_each(&mut |_, s, _| all.push(*s));
        (!all.is_empty()).then(|| all[self.rng.gen_range(0..all.len())])
    }

    /// A k-nearest query: around the scene, at a stored centre (ties and
    /// zeros), or far outside; k from 0 to past the object count; either
    /// metric; sometimes a distance limit.
    fn nearest(&mut self, oracle: &BruteForce<u64>) -> Nearest {
        let point = match self.rng.gen_range(0..10) {
            0..=4 => self.center(),
            5 | 6 => self.stored(oracle).map_or(Vec3::ZERO, |s| s.center),
            7 => self.far_point(),
            _ => self.uniform_in(&self.world.clone()),
        };
        let k = match self.rng.gen_range(0..8) {
            0 => 1,
            1 => 8,
            2 => 64,
            3 => oracle.len() + self.rng.gen_range(1..10),
            4 => 0,
            _ => self.rng.gen_range(1..20),
        };
        let mut q = Nearest::new(point, k);
        if self.rng.gen_bool(0.3) {
            q = q.metric(Metric::Center);
        }
        if self.rng.gen_bool(0.3) {
            q = q.within(if self.rng.gen_bool(0.1) {
                0.0
            } else {
                self.rng.gen_range(0.0f32..1.0).powi(2) * 40.0
            });
        }
        q
    }

    /// A sphere sweep: across the scene, zero-length, starting inside a stored
    /// sphere, grazing one (near-tangent), on the quarter grid (exact
    /// direction), or from far away; radius 0 a quarter of the time.
    fn sweep(&mut self, oracle: &BruteForce<u64>) -> SphereSweep {
        let radius = match self.rng.gen_range(0..8) {
            0 | 1 => 0.0,
            2 => self.rng.gen_range(0.0..40.0),
            _ => self.rng.gen_range(0.0..3.0),
        };
        let stored = self.stored(oracle);
        let (from, to) = match (self.rng.gen_range(0..12), stored) {
            (0..=3, _) | (_, None) => (self.center(), self.center()),
            (4, _) => {
                let p = self.center();
                (p, p)
            }
            (5 | 6, Some(s)) => (s.center + self.direction() * 0.1 * s.radius, self.center()),
            (7 | 8, Some(s)) => {
                // Along an axis at distance r + R from the centre: tangent up
                // to the rounding of the end points.
                let (a, b) = match self.rng.gen_range(0..3) {
                    0 => (Vec3::X, Vec3::Y),
                    1 => (Vec3::Y, Vec3::Z),
                    _ => (Vec3::Z, Vec3::X),
                };
                let off = b * (s.radius + radius);
                let len = self.rng.gen_range(0.0..20.0);
                let back = self.rng.gen_range(-20.0..0.0);
                (s.center + off + a * back, s.center + off + a * len)
            }
            (9 | 10, _) => (self.grid_point(), self.grid_point()),
            _ => (self.far_point(), self.center()),
        };
        SphereSweep::new(from, to, radius)
    }
}

/// Handle of the index for the object the oracle names `ho` (same payload id).
fn index_handle(
    oracle: &BruteForce<u64>,
    live: &HashMap<u64, (Handle, Handle)>,
    ho: Handle,
) -> Handle {
    live[oracle.get(ho).unwrap().1].0
}

/// The first hit among `hits` (oracle handles) in the index's handle order:
/// smallest `t`, ties by the smaller index handle.
fn first_in_index(
    oracle: &BruteForce<u64>,
    live: &HashMap<u64, (Handle, Handle)>,
    hits: &[RayHit],
) -> Option<(Handle, u32)> {
    hits.iter()
        .map(|h| (h.t, index_handle(oracle, live, h.handle)))
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
        .map(|(t, h)| (h, t.to_bits()))
}

/// Hits as sorted (payload id, `t` bits).
fn hits_as_ids<I: SpatialIndex<u64> + ?Sized>(index: &I, hits: &[RayHit]) -> Vec<(u64, u32)> {
    let mut v: Vec<(u64, u32)> = hits
        .iter()
        .map(|h| (*index.get(h.handle).unwrap().1, h.t.to_bits()))
        .collect();
    v.sort_unstable();
    v
}

/// Ids of what a (possibly filtered) query reports, sorted.
fn visit_ids<I: SpatialIndex<u64> + ?Sized>(
    index: &I,
    q: &Query,
    filter: Option<Filter>,
) -> Vec<u64> {
    let mut v = Vec::new();
    let _ = index
        .visit(q, filter, &mut |_, _, &id| {
            v.push(id);
            ControlFlow::Continue(())
        })
        .unwrap();
    v.sort_unstable();
    v
}

/// The k-nearest answer the index must give, computed by the oracle: every
/// admitted object within the limit with the oracle's distance, re-keyed by
/// the index's handles (ties go to the smaller handle *of the index*), the
/// first `k`.
fn expected_nearest(
    oracle: &BruteForce<u64>,
    live: &HashMap<u64, (Handle, Handle)>,
    q: &Nearest,
    filter: Option<Filter>,
) -> Vec<(Handle, u32)> {
    let mut all = Vec::new();
    let everything = Nearest {
        k: usize::MAX,
        ..*q
    };
    oracle.nearest_into(&everything, filter, &mut all).unwrap();
    // The oracle's own answer with `k` is the prefix of its full ranking.
    let mut own = Vec::new();
    oracle.nearest_into(q, filter, &mut own).unwrap();
    assert_eq!(
        own[..],
        all[..own.len().min(all.len())],
        "oracle knn prefix"
    );
    assert_eq!(own.len(), q.k.min(all.len()), "oracle knn count");
    for w in all.windows(2) {
        assert!(Neighbor::order(&w[0], &w[1]).is_lt(), "oracle knn order");
    }
    let mut v: Vec<(Handle, f32)> = all
        .iter()
        .map(|n| (index_handle(oracle, live, n.handle), n.distance))
        .collect();
    v.sort_unstable_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    v.truncate(q.k);
    v.into_iter().map(|(h, d)| (h, d.to_bits())).collect()
}

/// k nearest, sphere sweeps and filtered queries of every shape, compared
/// with the oracle (rotating, one or two per call).
fn check_queries<I: SpatialIndex<u64> + ?Sized>(
    index: &I,
    oracle: &BruteForce<u64>,
    live: &HashMap<u64, (Handle, Handle)>,
    g: &mut Gen,
    step: usize,
    ctx: &dyn Fn() -> String,
) {
    let filter = g.query_filter();
    match step % 4 {
        0 | 2 => {
            let q = g.nearest(oracle);
            let want = expected_nearest(oracle, live, &q, filter);
            // Stale contents must be cleared.
            let mut out: Vec<Neighbor> = live
                .values()
                .take(1)
                .map(|&(h, _)| Neighbor {
                    handle: h,
                    distance: -1.0,
                })
                .collect();
            index.nearest_into(&q, filter, &mut out).unwrap();
            let got: Vec<(Handle, u32)> = out
                .iter()
                .map(|n| (n.handle, n.distance.to_bits()))
                .collect();
            assert_eq!(got, want, "{}: nearest {q:?} filter {filter:?}", ctx());
            // The conveniences say the same.
            if q.metric == Metric::Surface {
                let conv = match (filter, q.max_distance.is_finite()) {
                    (None, false) => index.nearest(q.point, q.k),
                    (None, true) => index.nearest_within(q.point, q.k, q.max_distance),
                    (Some(f), false) => index.filtered(f).nearest(q.point, q.k),
                    (Some(f), true) => {
                        index
                            .filtered(f)
                            .nearest_within(q.point, q.k, q.max_distance)
                    }
                };
                assert_eq!(conv.unwrap(), out, "{}: nearest conveniences", ctx());
            }
        }
        1 => {
            let sw = g.sweep(oracle);
            let (hits_i, first_i) = match filter {
                None => (index.sweep_hits(&sw), index.sweep_first(&sw, None)),
                Some(f) => {
                    let v = index.filtered(f);
                    (v.sweep_hits(&sw), v.sweep_first(&sw))
                }
            };
            let (hits_i, first_i) = (hits_i.unwrap(), first_i.unwrap());
            let mut hits_o = Vec::new();
            let _ = oracle
                .visit(&Query::Sweep(sw), filter, &mut |h, s, _| {
                    let t = proxima::geom::overlap::sweep_sphere(&sw, s).expect("selected");
                    hits_o.push(RayHit { handle: h, t });
                    ControlFlow::Continue(())
                })
                .unwrap();
            assert_eq!(
                hits_as_ids(index, &hits_i),
                hits_as_ids(oracle, &hits_o),
                "{}: sweep hits {sw:?} filter {filter:?}",
                ctx()
            );
            for w in hits_i.windows(2) {
                assert!(
                    (w[0].t, w[0].handle) < (w[1].t, w[1].handle),
                    "{}: sweep hits order",
                    ctx()
                );
            }
            assert!(hits_i.iter().all(|h| (0.0..=1.0).contains(&h.t)));
            assert_eq!(
                first_i.map(|h| (h.handle, h.t.to_bits())),
                first_in_index(oracle, live, &hits_o),
                "{}: sweep first {sw:?} filter {filter:?}",
                ctx()
            );
            assert_eq!(
                first_i,
                hits_i.first().copied(),
                "{}: first = hits[0]",
                ctx()
            );
            if sw.from == sw.to {
                // At rest: what it overlaps, at t = 0.
                let q = Query::Sphere(Sphere::new(sw.from, sw.radius));
                let want = visit_ids(oracle, &q, filter);
                let got: Vec<u64> = hits_as_ids(index, &hits_i).iter().map(|x| x.0).collect();
                assert_eq!(got, want, "{}: zero-length sweep {sw:?}", ctx());
                assert!(hits_i.iter().all(|h| h.t == 0.0), "{}: t at rest", ctx());
            }
            let d = sw.to - sw.from;
            if sw.radius == 0.0 && sw.from != sw.to && sw.from + d == sw.to && sw.to - d == sw.from
            {
                // Radius 0 with an exact direction: the segment query, same t.
                let seg = Segment::new(sw.from, sw.to).to_ray();
                let want = match filter {
                    None => oracle.ray_hits(&seg),
                    Some(f) => oracle.filtered(f).ray_hits(&seg),
                };
                assert_eq!(
                    hits_as_ids(index, &hits_i),
                    hits_as_ids(oracle, &want.unwrap()),
                    "{}: radius-0 sweep = segment {sw:?}",
                    ctx()
                );
            }
        }
        _ => {
            // A filtered query of every other shape (unfiltered ones are
            // checked above), and the filtered first ray hit.
            let Some(f) = filter.or(Some(g.filter())) else {
                unreachable!()
            };
            let q = match g.rng.gen_range(0..4) {
                0 => Query::Sphere(g.query_sphere()),
                1 => Query::Aabb(g.query_aabb()),
                2 => Query::Ray(g.ray()),
                _ => Query::Frustum(g.frustum()),
            };
            let want = visit_ids(oracle, &q, Some(f));
            assert_eq!(
                visit_ids(index, &q, Some(f)),
                want,
                "{}: filtered {q:?} {f:?}",
                ctx()
            );
            let via_view = ids(index, &index.filtered(f).query(q).unwrap());
            assert_eq!(via_view, want, "{}: filtered view", ctx());
            let r = g.ray();
            let hits_o = oracle.filtered(f).ray_hits(&r).unwrap();
            assert_eq!(
                hits_as_ids(index, &index.filtered(f).ray_hits(&r).unwrap()),
                hits_as_ids(oracle, &hits_o),
                "{}: filtered ray hits {r:?} {f:?}",
                ctx()
            );
            let first = index.ray_first(&r, Some(f)).unwrap();
            assert_eq!(
                first.map(|h| (h.handle, h.t.to_bits())),
                first_in_index(oracle, live, &hits_o),
                "{}: filtered ray first {r:?} {f:?}",
                ctx()
            );
        }
    }
}

/// Invalid k-nearest and sweep queries are errors, and leave the output empty.
fn check_bad_queries<I: SpatialIndex<u64> + ?Sized>(index: &I, ctx: &dyn Fn() -> String) {
    let mut some = None;
    index.for_each(&mut |h, _, _| some = Some(h));
    let mut out = Vec::new();
    for q in [
        Nearest::new(Vec3::new(f32::NAN, 0.0, 0.0), 3),
        Nearest::new(Vec3::splat(f32::INFINITY), 3),
        Nearest::new(Vec3::ZERO, 3).within(-1.0),
        Nearest::new(Vec3::ZERO, 3).within(f32::NAN),
    ] {
        out.extend(some.map(|handle| Neighbor {
            handle,
            distance: 0.0,
        }));
        assert!(
            index.nearest_into(&q, None, &mut out).is_err(),
            "{}: {q:?}",
            ctx()
        );
        assert!(out.is_empty(), "{}: output after an error", ctx());
    }
    for sw in [
        SphereSweep::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::ZERO, 1.0),
        SphereSweep::new(Vec3::ZERO, Vec3::splat(f32::INFINITY), 1.0),
        SphereSweep::new(Vec3::ZERO, Vec3::ONE, -1.0),
        SphereSweep::new(Vec3::ZERO, Vec3::ONE, f32::NAN),
    ] {
        assert!(index.sweep_first(&sw, None).is_err(), "{}: {sw:?}", ctx());
        assert!(index.sweep_hits(&sw).is_err(), "{}: {sw:?}", ctx());
        assert!(index
            .visit(&Query::Sweep(sw), None, &mut |_, _, _| {
                ControlFlow::Continue(())
            })
            .is_err());
    }
}

/// Ids of the objects a query reports, sorted.
fn ids<I: SpatialIndex<u64> + ?Sized>(index: &I, handles: &[Handle]) -> Vec<u64> {
    let mut v: Vec<u64> = handles.iter().map(|h| *index.get(*h).unwrap().1).collect();
    v.sort_unstable();
    v
}

/// Ids and entry `t` bits of every object a ray hits, sorted.
fn hit_ids<I: SpatialIndex<u64>>(index: &I, r: &Ray) -> Vec<(u64, u32)> {
    let mut v: Vec<(u64, u32)> = index
        .ray_hits(r)
        .unwrap()
        .iter()
        .map(|h| (*index.get(h.handle).unwrap().1, h.t.to_bits()))
        .collect();
    v.sort_unstable();
    v
}

/// The pairs of `index` as sorted `(smaller id, larger id)` (the payloads);
/// panics if a pair is reported twice.
pub fn pair_ids<I: SpatialIndex<u64>>(index: &I) -> Vec<(u64, u64)> {
    let mut v = Vec::new();
    let _ = index.for_each_pair(|_, a, _, b| {
        v.push(if a < b { (*a, *b) } else { (*b, *a) });
        ControlFlow::Continue(())
    });
    v.sort_unstable();
    let n = v.len();
    v.dedup();
    assert_eq!(n, v.len(), "a pair was reported twice");
    v
}

/// Runs `ops` random operations on `make(params)` and on `BruteForce`, comparing
/// after each. Panics with the operation number and seed on the first difference.
/// O(ops × (the index's cost + brute force's O(live) per query)), pairs every
/// 21 operations.
pub fn run<I, F>(scene: Scene, seed: u64, ops: usize, make: F)
where
    I: SpatialIndex<u64>,
    F: Fn(&SceneParams) -> I,
{
    let mut g = Gen::new(scene, seed);
    let mut index = make(&g.params());
    let mut oracle: BruteForce<u64> = BruteForce::new();
    // id -> (handle in index, handle in oracle)
    let mut live: HashMap<u64, (Handle, Handle)> = HashMap::new();
    let mut order: Vec<u64> = Vec::new();
    let mut next_id = 1u64;
    let mut removed: Vec<Handle> = Vec::new();
    let target = match scene {
        Scene::OnePoint => 300,
        _ => 400,
    };

    for step in 0..ops {
        let ctx = || format!("scene {scene:?} seed {seed} step {step}");
        let roll = g.rng.gen_range(0..100);
        let fill = live.len() < target;
        if live.is_empty() || (roll < 30 && fill) || roll < 8 {
            let s = g.sphere();
            let id = next_id;
            next_id += 1;
            // Half the objects keep the default filter (plain `insert`).
            let f = g.filter();
            let hi = if f == Filter::ALL {
                index.insert(s, id)
            } else {
                index.insert_with_filter(s, f, id)
            }
            .unwrap_or_else(|e| panic!("{}: {e}", ctx()));
            let ho = oracle.insert_with_filter(s, f, id).unwrap();
            assert_eq!(index.filter(hi), Ok(f), "{}: filter after insert", ctx());
            live.insert(id, (hi, ho));
            order.push(id);
        } else if roll < 60 {
            // Move: mostly small steps, some long jumps and resizes.
            let k = g.rng.gen_range(0..order.len());
            let id = order[k];
            let (hi, ho) = live[&id];
            let (old, _) = oracle.get(ho).unwrap();
            let s = match g.rng.gen_range(0..10) {
                0..=5 => {
                    let step = vec3(
                        g.rng.gen_range(-1.0..1.0),
                        g.rng.gen_range(-1.0..1.0),
                        g.rng.gen_range(-1.0..1.0),
                    );
                    Sphere::new(old.center + step, old.radius)
                }
                6..=7 => Sphere::new(g.center(), old.radius),
                _ => g.sphere(),
            };
            index
                .update(hi, s)
                .unwrap_or_else(|e| panic!("{}: {e}", ctx()));
            oracle.update(ho, s).unwrap();
            assert_eq!(index.get(hi).unwrap().0, s, "{}: get after update", ctx());
            // Moves keep the filter.
            assert_eq!(index.filter(hi), oracle.filter(ho), "{}: filter", ctx());
            if g.rng.gen_bool(0.15) {
                let f = g.filter();
                index.set_filter(hi, f).unwrap();
                oracle.set_filter(ho, f).unwrap();
                assert_eq!(index.filter(hi), Ok(f), "{}: set_filter", ctx());
            }
        } else if roll < 72 {
            let k = g.rng.gen_range(0..order.len());
            let id = order.swap_remove(k);
            let (hi, ho) = live.remove(&id).unwrap();
            assert_eq!(index.remove(hi), Ok(id), "{}", ctx());
            oracle.remove(ho).unwrap();
            removed.push(hi);
        } else if roll < 74 {
            // Bad input must be rejected and change nothing.
            let len = index.len();
            assert!(index
                .insert(Sphere::new(Vec3::new(f32::NAN, 0.0, 0.0), 1.0), 0)
                .is_err());
            assert!(index.insert(Sphere::new(Vec3::ZERO, -1.0), 0).is_err());
            if let Some(h) = removed.last() {
                assert!(index.remove(*h).is_err(), "{}: stale handle removed", ctx());
                assert!(index.update(*h, Sphere::new(Vec3::ZERO, 1.0)).is_err());
                assert!(index.filter(*h).is_err(), "{}: stale filter", ctx());
                assert!(index.set_filter(*h, Filter::ALL).is_err());
            }
            if let Some(id) = order.first() {
                let (hi, _) = live[id];
                let before = index.get(hi).unwrap().0;
                assert!(index
                    .update(hi, Sphere::new(Vec3::splat(f32::INFINITY), 1.0))
                    .is_err());
                assert_eq!(index.get(hi).unwrap().0, before);
            }
            assert_eq!(index.len(), len);
            check_bad_queries(&index, &ctx);
        }
        index
            .validate()
            .unwrap_or_else(|e| panic!("{}: validate: {e}", ctx()));
        assert_eq!(index.len(), oracle.len(), "{}: len", ctx());
        // k nearest, sweeps and filtered queries after every operation.
        check_queries(&index, &oracle, &live, &mut g, step, &ctx);

        // One query after every operation, rotating through the kinds.
        match step % 7 {
            0 => {
                let q = g.query_sphere();
                let a = ids(&index, &index.query(q).unwrap());
                let b = ids(&oracle, &oracle.query(q).unwrap());
                assert_eq!(a, b, "{}: sphere query {q:?}", ctx());
            }
            1 => {
                let q = g.query_aabb();
                let a = ids(&index, &index.query(q).unwrap());
                let b = ids(&oracle, &oracle.query(q).unwrap());
                assert_eq!(a, b, "{}: aabb query {q:?}", ctx());
            }
            2 | 3 => {
                let r = if step % 7 == 2 {
                    g.ray()
                } else {
                    let a = g.center();
                    let b = g.center();
                    if a == b {
                        g.ray()
                    } else {
                        Segment::new(a, b).to_ray()
                    }
                };
                assert_eq!(
                    hit_ids(&index, &r),
                    hit_ids(&oracle, &r),
                    "{}: ray hits {r:?}",
                    ctx()
                );
                let fa = index.ray_first(&r, None).unwrap();
                let fb = oracle.ray_first(&r, None).unwrap();
                assert_eq!(
                    fa.map(|h| h.t),
                    fb.map(|h| h.t),
                    "{}: first hit t {r:?}",
                    ctx()
                );
                if let Some(h) = fa {
                    // The reported object really is hit at that t.
                    let (s, _) = index.get(h.handle).unwrap();
                    assert_eq!(proxima::geom::overlap::ray_sphere(&r, &s), Some(h.t));
                }
            }
            4 => {
                let f = g.frustum();
                let a = ids(&index, &index.query(f).unwrap());
                let b = ids(&oracle, &oracle.query(f).unwrap());
                assert_eq!(a, b, "{}: frustum query", ctx());
            }
            5 => {
                // Early stop: the callback's Break is honoured.
                if !index.is_empty() {
                    let big = Sphere::new(g.world.center(), 1e6);
                    let mut n = 0;
                    let r = index
                        .for_each_in(big, |_, _, _| {
                            n += 1;
                            ControlFlow::Break(())
                        })
                        .unwrap();
                    assert_eq!((n, r), (1, ControlFlow::Break(())), "{}", ctx());
                }
            }
            _ => {
                if step % 21 == 6 || step + 1 == ops {
                    assert_eq!(pair_ids(&index), pair_ids(&oracle), "{}: pairs", ctx());
                }
            }
        }
    }

    // Empty it, then check that it is reusable.
    for id in order.drain(..) {
        let (hi, ho) = live.remove(&id).unwrap();
        assert_eq!(index.remove(hi), Ok(id));
        oracle.remove(ho).unwrap();
        index.validate().unwrap();
    }
    assert!(index.is_empty());
    // The empty index answers every query with nothing.
    let ctx = || format!("scene {scene:?} seed {seed} emptied");
    for step in 0..8 {
        check_queries(&index, &oracle, &live, &mut g, step, &ctx);
    }
    assert!(index.nearest(Vec3::ZERO, 5).unwrap().is_empty());
    let h = index.insert(Sphere::new(Vec3::ONE, 1.0), 7).unwrap();
    index.clear();
    assert!(index.is_empty());
    assert!(index.get(h).is_err(), "handle survives clear");
    index.validate().unwrap();
}
