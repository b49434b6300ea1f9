//! [`ParallelPairs`] for the dense grid: runs of rows of cells split across rayon's
//! threads (a few runs per thread, each at least a few xy layers so that the
//! scan's look-ahead stays small beside the run), then the large objects one
//! task each.

use super::UniformGrid3d;
use crate::broad::ParallelPairs;
use rayon::prelude::*;
use std::ops::ControlFlow;

/// Tasks per thread: enough to balance uneven cells across threads.
const TASKS_PER_THREAD: u32 = 4;

/// Each task also gathers the spheres of one xy layer of rows beyond its run
/// (the look-ahead of the pair scan), so a run is at least this many layers.
const MIN_LAYERS_PER_TASK: u32 = 4;

impl<T: Send + Sync> ParallelPairs<T> for UniformGrid3d<T> {
    /// Each task runs the sequential half-shell search over its own run of rows
    /// (every pair is owned by the cell of its first object, so runs never report
    /// the same pair), folding into its accumulator; the large objects' pairs are
    /// folded the same way, one object per task.
    fn par_fold_pairs<A, I, F, R>(&self, init: I, fold: F, reduce: R) -> A
    where
        A: Send,
        I: Fn() -> A + Sync + Send,
        F: Fn(A, crate::Handle, &T, crate::Handle, &T) -> A + Sync + Send,
        R: Fn(A, A) -> A + Sync + Send,
    {
        let rows = self.row_count();
        let ny = self.geom.dims[1];
        let threads = rayon::current_num_threads() as u32;
        let per_task = rows
            .div_ceil(TASKS_PER_THREAD * threads)
            .max(MIN_LAYERS_PER_TASK * ny)
            .max(1);
        let tasks = rows.div_ceil(per_task);
        let gridded = (0..tasks)
            .into_par_iter()
            .fold(&init, |acc, t| {
                let w0 = t * per_task;
                let w1 = (w0 + per_task).min(rows);
                let mut acc = Some(acc);
                let _ = self.pair_rows(w0, w1, &mut |ha, va, hb, vb| {
                    acc = acc.take().map(|a| fold(a, ha, va, hb, vb));
                    ControlFlow::Continue(())
                });
                acc.expect("accumulator is always put back")
            })
            .reduce(&init, &reduce);
        let large = (0..self.large.len())
            .into_par_iter()
            .fold(&init, |acc, i| {
                let mut acc = Some(acc);
                let _ = self.large_pairs(i, &mut |ha, va, hb, vb| {
                    acc = acc.take().map(|a| fold(a, ha, va, hb, vb));
                    ControlFlow::Continue(())
                });
                acc.expect("accumulator is always put back")
            })
            .reduce(&init, &reduce);
        reduce(gridded, large)
    }
}

#[cfg(test)]
mod tests {
    use crate::broad::Grid3dConfig;
    use crate::broad::SpatialIndexExt;
    use crate::broad::{BruteForce, ParallelPairs, SpatialIndex, UniformGrid3d};
    use crate::geom::{Aabb, Sphere};
    use glam::{vec3, Vec3};
    use rand::{Rng, SeedableRng};

    #[test]
    fn parallel_pairs_equal_sequential_and_brute_force() {
        let w = Aabb::new(Vec3::ZERO, Vec3::splat(60.0));
        let mut g = UniformGrid3d::with_config(Grid3dConfig {
            world: w,
            cell_size: 4.0,
        })
        .unwrap();
        let mut b = BruteForce::new();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let mut handles = Vec::new();
        for i in 0..3000u32 {
            let c = vec3(
                rng.gen_range(-5.0..65.0),
                rng.gen_range(-5.0..65.0),
                rng.gen_range(-5.0..65.0),
            );
            let r = if i % 300 == 0 {
                9.0
            } else {
                rng.gen_range(0.5..1.96)
            };
            handles.push((
                g.insert(Sphere::new(c, r), i).unwrap(),
                b.insert(Sphere::new(c, r), i).unwrap(),
            ));
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let to_ids = |p: Vec<(crate::Handle, crate::Handle)>, idx: &dyn SpatialIndexIds| {
            let mut v: Vec<(u32, u32)> = p
                .into_iter()
                .map(|(x, y)| {
                    let (a, b) = (idx.id(x), idx.id(y));
                    (a.min(b), a.max(b))
                })
                .collect();
            v.sort_unstable();
            v
        };
        for round in 0..3 {
            let par = pool.install(|| g.par_pairs());
            let mut seq = g.pairs();
            seq.sort_unstable();
            assert_eq!(par, seq);
            assert_eq!(pool.install(|| g.par_count_pairs()), seq.len() as u64);
            let brute = pool.install(|| b.par_pairs());
            assert!(brute.len() > 1000, "round {round}: {}", brute.len());
            assert_eq!(to_ids(par, &g), to_ids(brute, &b));
            // Move everything a little and check again.
            for &(hg, hb) in &handles {
                let (s, _) = g.get(hg).unwrap();
                let s = Sphere::new(s.center + vec3(0.7, -0.4, 0.3), s.radius);
                g.update(hg, s).unwrap();
                b.update(hb, s).unwrap();
            }
        }
        g.validate().unwrap();
    }

    /// Payload id of a handle, for comparing indices with different handles.
    trait SpatialIndexIds {
        fn id(&self, h: crate::Handle) -> u32;
    }
    impl<I: SpatialIndex<u32>> SpatialIndexIds for I {
        fn id(&self, h: crate::Handle) -> u32 {
            *self.get(h).unwrap().1
        }
    }
}
