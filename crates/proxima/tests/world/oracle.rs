//! Random operation sequences, the world against the brute-force world after
//! every query, `validate()` after every operation.

use super::brute::{BShape, BruteWorld, ContactMap};
use super::{grid_pose, meshes, nudge, random_pose, MeshData};
use proxima::broad::{Filter, IndexKind};
use proxima::geom::{overlap, Aabb, Frustum, Ray, Relation};
use proxima::glam::{Mat4, Vec3};
use proxima::narrow::{BoundingVolume, Kdop14, Kdop18, Kdop26, Obb, RotationUpdate};
use proxima::world::{ContactReport, Shape, World, WorldConfig};
use proxima::Handle;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::sync::Arc;

/// The world under test, the oracle, and the shapes both are built from.
pub struct Sim<BV: BoundingVolume> {
    pub world: World<u64, BV>,
    pub brute: BruteWorld,
    pub live: Vec<Handle>,
    pub shapes: Vec<(Shape<BV>, BShape)>,
    pub rng: Pcg64,
    next_id: u64,
    /// Queries compared, by kind: contacts, first contacts, rays, spheres, culls.
    pub compared: [usize; 5],
    /// Object pairs in contact seen over all `contacts` queries.
    pub contact_pairs: usize,
}

impl<BV: BoundingVolume> Sim<BV> {
    pub fn new(config: WorldConfig, seed: u64) -> Self {
        let mut rng = Pcg64::seed_from_u64(seed);
        let mut shapes: Vec<(Shape<BV>, BShape)> = meshes(&mut rng)
            .into_iter()
            .map(|m: Arc<MeshData>| (Shape::from(m.mesh::<BV>()), BShape::Mesh(m)))
            .collect();
        for r in [0.15f32, 0.4, 0.0] {
            shapes.push((Shape::sphere(r).unwrap(), BShape::Ball(r)));
        }
        Sim {
            world: World::new(config).unwrap(),
            brute: BruteWorld::default(),
            live: Vec::new(),
            shapes,
            rng,
            next_id: 0,
            compared: [0; 5],
            contact_pairs: 0,
        }
    }

    fn filter(&mut self) -> Filter {
        if self.rng.gen_bool(0.7) {
            Filter::ALL
        } else {
            Filter::new(self.rng.gen_range(0..4), self.rng.gen_range(0..4))
        }
    }

    fn pick(&mut self) -> Option<Handle> {
        (!self.live.is_empty()).then(|| self.live[self.rng.gen_range(0..self.live.len())])
    }

    pub fn insert(&mut self) {
        let k = self.rng.gen_range(0..self.shapes.len());
        let pose = match self.rng.gen_range(0..10) {
            0..=5 => random_pose(&mut self.rng, 2.0),
            6 | 7 => grid_pose(&mut self.rng, 3),
            _ => match self.pick() {
                Some(h) => nudge(&mut self.rng, &self.world.pose(h).unwrap(), 0.7),
                None => random_pose(&mut self.rng, 2.0),
            },
        };
        let filter = self.filter();
        let id = self.next_id;
        self.next_id += 1;
        let (shape, bshape) = self.shapes[k].clone();
        let h = self
            .world
            .insert_with_filter(shape, pose, id, filter)
            .unwrap();
        self.brute.insert(h, bshape, pose, filter);
        self.live.push(h);
    }

    fn set_pose(&mut self) {
        let Some(h) = self.pick() else { return };
        let old = self.world.pose(h).unwrap();
        let pose = match self.rng.gen_range(0..20) {
            0..=9 => nudge(&mut self.rng, &old, 0.05),
            10..=13 => random_pose(&mut self.rng, 2.0),
            14..=16 => old,
            _ => grid_pose(&mut self.rng, 3),
        };
        self.world.set_pose(h, pose).unwrap();
        self.brute.objects.get_mut(&h).unwrap().pose = pose;
    }

    fn set_poses(&mut self) {
        let n = self.rng.gen_range(1..=self.live.len().max(1));
        let mut batch = Vec::new();
        for _ in 0..n {
            let Some(h) = self.pick() else { return };
            let pose = nudge(&mut self.rng, &self.world.pose(h).unwrap(), 0.05);
            batch.push((h, pose));
        }
        self.world.set_poses(&batch).unwrap();
        for (h, p) in batch {
            self.brute.objects.get_mut(&h).unwrap().pose = p;
        }
    }

    fn remove(&mut self) {
        let Some(h) = self.pick() else { return };
        let id = *self.world.get(h).unwrap();
        assert_eq!(self.world.remove(h).unwrap(), id);
        self.brute.remove(h);
        self.live.retain(|&x| x != h);
        assert_eq!(self.world.get(h).unwrap_err(), proxima::Error::StaleHandle);
    }

    fn ignore(&mut self) {
        let (Some(a), Some(b)) = (self.pick(), self.pick()) else {
            return;
        };
        if a == b {
            assert!(self.world.ignore(a, b).is_err());
            return;
        }
        let k = if a < b { (a, b) } else { (b, a) };
        if self.rng.gen_bool(0.7) {
            self.world.ignore(a, b).unwrap();
            self.brute.ignored.insert(k);
        } else {
            let was = self.world.unignore(b, a).unwrap();
            assert_eq!(was, self.brute.ignored.remove(&k));
        }
        assert_eq!(
            self.world.is_ignored(b, a).unwrap(),
            self.brute.ignored.contains(&k)
        );
        assert_eq!(self.world.ignored_len(), self.brute.ignored.len());
    }

    fn set_filter(&mut self) {
        let Some(h) = self.pick() else { return };
        let f = self.filter();
        self.world.set_filter(h, f).unwrap();
        self.brute.objects.get_mut(&h).unwrap().filter = f;
    }

    pub fn contacts(&mut self, first: bool) {
        let report = if first {
            self.world.contacts_first().unwrap()
        } else {
            self.world.contacts().unwrap()
        };
        let want = self.brute.contacts();
        check_report(&report, &want, first);
        self.compared[first as usize] += 1;
        self.contact_pairs += want.len();
    }

    fn ray(&mut self) {
        let o = Vec3::new(
            self.rng.gen_range(-4.0..4.0),
            self.rng.gen_range(-4.0..4.0),
            self.rng.gen_range(-4.0..4.0),
        );
        // Aim at an object's centre most of the time.
        let target = match self.pick() {
            Some(h) if self.rng.gen_bool(0.8) => self.world.pose(h).unwrap().translation.into(),
            _ => Vec3::ZERO,
        };
        let dir = (target - o) * self.rng.gen_range(0.3..2.0);
        if dir == Vec3::ZERO {
            return;
        }
        let max_t = if self.rng.gen_bool(0.5) {
            f32::INFINITY
        } else {
            self.rng.gen_range(0.0..2.0)
        };
        let ray = Ray::with_max_t(o, dir, max_t);
        let filter = self.filter();
        let got = self.world.ray_cast(&ray, filter).unwrap();
        let want = self.brute.ray_cast(&ray, filter);
        assert_eq!(
            got.map(|h| (h.object, h.triangle, h.t)),
            want,
            "ray {ray:?}"
        );
        let all: Vec<_> = self
            .world
            .ray_hits(&ray, filter)
            .unwrap()
            .into_iter()
            .map(|h| (h.object, h.triangle, h.t))
            .collect();
        assert_eq!(all, self.brute.ray_hits(&ray, filter), "ray hits {ray:?}");
        self.compared[2] += 1;
    }

    fn sphere(&mut self) {
        let c = match self.pick() {
            Some(h) if self.rng.gen_bool(0.7) => {
                let p: Vec3 = self.world.pose(h).unwrap().translation.into();
                p + Vec3::new(
                    self.rng.gen_range(-0.7..0.7),
                    self.rng.gen_range(-0.7..0.7),
                    self.rng.gen_range(-0.7..0.7),
                )
            }
            _ => Vec3::new(
                self.rng.gen_range(-3.0..3.0),
                self.rng.gen_range(-3.0..3.0),
                self.rng.gen_range(-3.0..3.0),
            ),
        };
        let r = self.rng.gen_range(0.0..0.8);
        let filter = self.filter();
        assert_eq!(
            self.world.overlap_sphere(c, r, filter).unwrap(),
            self.brute.overlap_sphere(c, r, filter),
            "sphere {c} {r}"
        );
        self.compared[3] += 1;
    }

    fn cull(&mut self) {
        let eye = Vec3::new(
            self.rng.gen_range(-6.0..6.0),
            self.rng.gen_range(-6.0..6.0),
            self.rng.gen_range(4.0..8.0),
        );
        let view = Mat4::look_at_rh(eye, Vec3::ZERO, Vec3::Y);
        let proj = Mat4::perspective_rh(self.rng.gen_range(0.3..1.2), 1.3, 0.5, 9.0);
        let f = Frustum::from_view_projection(proj * view).unwrap();
        let filter = self.filter();
        let want: Vec<Handle> = self
            .world
            .iter()
            .filter(|o| {
                filter.interacts(o.filter)
                    && overlap::frustum_sphere(&f, &o.bounding_sphere) != Relation::Outside
            })
            .map(|o| o.handle)
            .collect();
        assert_eq!(self.world.cull(&f, filter).unwrap(), want);
        self.compared[4] += 1;
    }

    /// Every object's bounding sphere holds its posed vertices.
    fn check_spheres(&self) {
        for o in self.world.iter() {
            if let Shape::Mesh(m) = o.shape {
                let s = o.bounding_sphere;
                for v in m.trimesh().vertices() {
                    let p = o.pose.transform_point3(*v);
                    assert!(
                        (p.as_dvec3() - s.center.as_dvec3()).length() <= s.radius as f64,
                        "{p} outside {s:?}"
                    );
                }
            }
        }
    }

    /// One random operation, then `validate()`.
    pub fn step(&mut self, max_n: usize) {
        match self.rng.gen_range(0..100) {
            0..=13 if self.live.len() < max_n => self.insert(),
            0..=13 => self.remove(),
            14..=38 => self.set_pose(),
            39..=43 => self.set_poses(),
            44..=48 => self.remove(),
            49..=53 => self.ignore(),
            54..=57 => self.set_filter(),
            58..=77 => {
                let first = self.rng.gen_bool(0.4);
                self.contacts(first)
            }
            78..=87 => self.ray(),
            88..=94 => self.sphere(),
            95..=97 => self.cull(),
            _ => self.check_spheres(),
        }
        self.world.validate().unwrap();
        assert_eq!(self.world.len(), self.live.len());
    }
}

/// The report against the oracle: same pairs, and in all-pairs mode the same
/// primitive pairs; in first-contact mode one witness that the oracle has.
pub fn check_report(report: &ContactReport, want: &ContactMap, first: bool) {
    let keys: Vec<_> = report.pairs.iter().map(|c| (c.a, c.b)).collect();
    let want_keys: Vec<_> = want.keys().copied().collect();
    assert_eq!(keys, want_keys, "object pairs in contact");
    let mut end = 0;
    for c in &report.pairs {
        assert!(c.a < c.b);
        assert_eq!(c.triangles.start, end, "contiguous ranges");
        end = c.triangles.end;
        let got = report.triangles_of(c);
        let all = &want[&(c.a, c.b)];
        if first {
            assert_eq!(got.len(), 1);
            assert!(all.contains(&got[0]), "witness {:?} not in {all:?}", got[0]);
        } else {
            assert_eq!(got, &all[..], "pair {:?}", (c.a, c.b));
        }
    }
    assert_eq!(end, report.triangles.len());
    let c = report.counters;
    assert!(c.filtered + c.narrow_pairs <= c.broad_pairs, "{c:?}");
    assert!(
        c.narrow_pairs + c.coherent_pairs >= report.pairs.len() as u64,
        "{c:?}"
    );
    assert!(c.cut_starts <= c.narrow_pairs, "{c:?}");
}

/// A long sequence: grow to `max_n` objects, then churn.
pub fn run<BV: BoundingVolume>(
    config: WorldConfig,
    seed: u64,
    steps: usize,
    max_n: usize,
) -> Sim<BV> {
    let mut sim = Sim::<BV>::new(config, seed);
    for _ in 0..steps {
        sim.step(max_n);
    }
    assert!(sim.compared.iter().all(|&n| n > 0), "{:?}", sim.compared);
    assert!(
        sim.contact_pairs > 0,
        "no contact ever: the scene is too sparse"
    );
    sim
}

fn config(kind: IndexKind, coherence: bool) -> WorldConfig {
    WorldConfig {
        index: Some(kind),
        coherence,
        ..WorldConfig::default()
    }
}

const STEPS: usize = 1500;

macro_rules! per_kind {
    ($($name:ident: $kind:ident, $other:ty;)+) => {$(
        #[test]
        fn $name() {
            run::<Kdop18>(config(IndexKind::$kind, true), 1, STEPS, 22);
            run::<Kdop18>(config(IndexKind::$kind, false), 2, STEPS, 14);
            run::<$other>(config(IndexKind::$kind, true), 3, STEPS, 18);
        }
    )+};
}

per_kind! {
    brute_force: Brute, proxima::geom::Aabb;
    loose_kd: LooseKd, Obb;
    octree: Octree, Kdop14;
    grid2d: Grid2d, proxima::geom::Sphere;
    hash_grid: HashGrid, Kdop26;
    grid3d: Grid3d, Obb;
}

#[test]
fn every_kind_is_covered() {
    // The macro above lists six kinds; a new kind must be added there.
    assert_eq!(IndexKind::ALL.len(), 6);
}

#[test]
fn default_index_bounds_refit_and_tiny_cuts() {
    run::<Kdop18>(WorldConfig::default(), 4, STEPS, 20);
    run::<Kdop18>(
        WorldConfig {
            bounds: Some(Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))),
            rotation: RotationUpdate::Refit,
            cut_limit: 3,
            ..WorldConfig::default()
        },
        5,
        STEPS,
        20,
    );
    run::<Obb>(
        WorldConfig {
            cut_limit: 0,
            index: Some(IndexKind::Octree),
            ..WorldConfig::default()
        },
        6,
        STEPS / 2,
        16,
    );
}
