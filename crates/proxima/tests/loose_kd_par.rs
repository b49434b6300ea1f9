//! `LooseKdTree`'s parallel pair finding against its sequential one and, through
//! the generic oracle harness, against `BruteForce`: every scene of the oracle
//! suite at several densities, with the parallel search run in a 2-thread pool
//! each time the harness asks for the pairs. Needs the `parallel` feature
//! (`cargo test -p proxima --features parallel --test loose_kd_par`).
#![cfg(feature = "parallel")]

use proxima::broad::{
    BruteForce, IndexKind, LooseKdConfig, LooseKdTree, ParallelPairs, Query, RayHit, SpatialIndex,
    SpatialIndexExt,
};
use proxima::geom::{Ray, Sphere};
use proxima::glam::Vec3;
use proxima::{Handle, Result};
use proxima_harness::oracle::{run, SceneParams, ALL_SCENES};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::ops::ControlFlow;

/// A `LooseKdTree` whose `visit_pairs` also runs `par_pairs` and
/// `par_count_pairs` in a 2-thread pool and checks them against the sequential
/// pairs; everything else is delegated.
struct ParCheck {
    tree: LooseKdTree<u64>,
    pool: rayon::ThreadPool,
}

impl ParCheck {
    fn new(tree: LooseKdTree<u64>) -> Self {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        ParCheck { tree, pool }
    }
}

impl SpatialIndex<u64> for ParCheck {
    fn insert(&mut self, sphere: Sphere, value: u64) -> Result<Handle> {
        self.tree.insert(sphere, value)
    }
    fn remove(&mut self, handle: Handle) -> Result<u64> {
        self.tree.remove(handle)
    }
    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()> {
        self.tree.update(handle, sphere)
    }
    fn get(&self, handle: Handle) -> Result<(Sphere, &u64)> {
        self.tree.get(handle)
    }
    fn get_mut(&mut self, handle: Handle) -> Result<&mut u64> {
        self.tree.get_mut(handle)
    }
    fn len(&self) -> usize {
        self.tree.len()
    }
    fn clear(&mut self) {
        self.tree.clear()
    }
    fn for_each(&self, f: &mut dyn FnMut(Handle, &Sphere, &u64)) {
        self.tree.for_each(f)
    }
    fn visit(
        &self,
        query: &Query,
        f: &mut dyn FnMut(Handle, &Sphere, &u64) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        self.tree.visit(query, f)
    }
    fn visit_pairs(
        &self,
        f: &mut dyn FnMut(Handle, &u64, Handle, &u64) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let mut seq: Vec<(Handle, Handle)> = self
            .tree
            .pairs()
            .into_iter()
            .map(|(a, b)| (a.min(b), a.max(b)))
            .collect();
        seq.sort_unstable();
        let par = self.pool.install(|| self.tree.par_pairs());
        assert_eq!(par, seq, "parallel pairs differ from sequential pairs");
        let count = self.pool.install(|| self.tree.par_count_pairs());
        assert_eq!(count, seq.len() as u64);
        self.tree.visit_pairs(f)
    }
    fn ray_first(&self, ray: &Ray) -> Result<Option<RayHit>> {
        self.tree.ray_first(ray)
    }
    fn validate(&self) -> Result<()> {
        self.tree.validate()
    }
    fn memory_bytes(&self) -> usize {
        self.tree.memory_bytes()
    }
    fn kind(&self) -> IndexKind {
        self.tree.kind()
    }
}

#[test]
fn oracle_scenes_in_a_2_thread_pool() {
    for scene in ALL_SCENES {
        for (seed, density) in [(1u64, 0.5), (2, LooseKdConfig::DEFAULT_DENSITY), (3, 1.0)] {
            run(scene, seed, 3000, |p: &SceneParams| {
                ParCheck::new(
                    LooseKdTree::with_config(LooseKdConfig {
                        density,
                        ..LooseKdConfig::new(p.world, p.r_max)
                    })
                    .unwrap(),
                )
            });
        }
    }
}

/// Large W1-like scenes (deep trees, so the search really splits into tasks):
/// parallel = sequential = brute force, and the per-task folds add up.
#[test]
fn large_uniform_scenes_match_brute_force() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    for (seed, n) in [(1u64, 3000usize), (2, 8000)] {
        let mut rng = Pcg64::seed_from_u64(seed);
        let side = 4.0 * (n as f32).cbrt();
        let world = proxima::geom::Aabb::new(Vec3::splat(-2.0), Vec3::splat(side + 2.0));
        let mut tree = LooseKdTree::new(world, 2.0).unwrap();
        let mut brute = BruteForce::new();
        let mut handles = Vec::new();
        for i in 0..n as u64 {
            let c = Vec3::new(
                rng.gen_range(0.0..side),
                rng.gen_range(0.0..side),
                rng.gen_range(0.0..side),
            );
            let s = Sphere::new(c, rng.gen_range(0.5..=2.0));
            handles.push((tree.insert(s, i).unwrap(), brute.insert(s, i).unwrap()));
        }
        for frame in 0..3 {
            let ids = |v: Vec<(Handle, Handle)>, get: &dyn Fn(Handle) -> u64| {
                let mut v: Vec<(u64, u64)> = v
                    .into_iter()
                    .map(|(a, b)| {
                        let (a, b) = (get(a), get(b));
                        (a.min(b), a.max(b))
                    })
                    .collect();
                v.sort_unstable();
                v
            };
            let want = ids(brute.pairs(), &|h| *brute.get(h).unwrap().1);
            assert!(
                want.len() > n / 4,
                "too few pairs to compare: {}",
                want.len()
            );
            let tget = |h| *tree.get(h).unwrap().1;
            assert_eq!(ids(tree.pairs(), &tget), want, "sequential, frame {frame}");
            let par = pool.install(|| tree.par_pairs());
            assert_eq!(ids(par, &tget), want, "parallel, frame {frame}");
            for (ht, hb) in &handles {
                let (s, _) = brute.get(*hb).unwrap();
                let step = Vec3::new(
                    rng.gen_range(-0.2..0.2),
                    rng.gen_range(-0.2..0.2),
                    rng.gen_range(-0.2..0.2),
                );
                let s = Sphere::new(s.center + step, s.radius);
                tree.update(*ht, s).unwrap();
                brute.update(*hb, s).unwrap();
            }
        }
    }
}
