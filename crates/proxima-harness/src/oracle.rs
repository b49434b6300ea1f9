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
    AnyIndex, BruteForce, IndexKind, LooseKdConfig, LooseKdTree, SceneHint, SpatialIndex,
    SpatialIndexExt,
};
use proxima::geom::{Aabb, Frustum, Ray, Segment, Sphere};
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

/// Ids of the objects a query reports, sorted.
fn ids<I: SpatialIndex<u64>>(index: &I, handles: &[Handle]) -> Vec<u64> {
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

fn pair_ids<I: SpatialIndex<u64>>(index: &I) -> Vec<(u64, u64)> {
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
            let hi = index
                .insert(s, id)
                .unwrap_or_else(|e| panic!("{}: {e}", ctx()));
            let ho = oracle.insert(s, id).unwrap();
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
        }
        index
            .validate()
            .unwrap_or_else(|e| panic!("{}: validate: {e}", ctx()));
        assert_eq!(index.len(), oracle.len(), "{}: len", ctx());

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
                let fa = index.ray_first(&r).unwrap();
                let fb = oracle.ray_first(&r).unwrap();
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
        let (hi, _) = live.remove(&id).unwrap();
        assert_eq!(index.remove(hi), Ok(id));
        index.validate().unwrap();
    }
    assert!(index.is_empty());
    let h = index.insert(Sphere::new(Vec3::ONE, 1.0), 7).unwrap();
    index.clear();
    assert!(index.is_empty());
    assert!(index.get(h).is_err(), "handle survives clear");
    index.validate().unwrap();
}
