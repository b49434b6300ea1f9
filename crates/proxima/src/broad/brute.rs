//! The brute-force index: a flat list scanned by every query. It is the oracle the
//! other indices are tested against, and the baseline of the benchmarks.

use crate::arena::Arena;
use crate::broad::nearest::{self, Nearest, Neighbor};
use crate::broad::walk::{walk_methods, Walk};
use crate::broad::{Filter, IndexKind, Selection, SpatialIndex};
use crate::geom::{overlap, Sphere};
use crate::{Handle, Result};
use std::ops::ControlFlow;

/// Stores spheres in a generational arena and answers every query by testing each one.
///
/// Insert, remove and update are O(1); queries are O(n); pairs are O(n²); k
/// nearest is one scan and a selection of the `k` smallest, O(n + k log k). Its
/// answers are the definition of right for every other index (same closed tests
/// and distances from [`geom::overlap`](crate::geom::overlap)).
#[derive(Clone, Debug)]
pub struct BruteForce<T> {
    items: Arena<(Sphere, Filter, T)>,
}

impl<T> Default for BruteForce<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T> BruteForce<T> {
    /// An empty index. Brute force has nothing to tune, so it has no config
    /// struct (the one exception to the constructor pattern of the other
    /// indices).
    pub fn new() -> Self {
        BruteForce {
            items: Arena::new(),
        }
    }
}

impl<T: Send + Sync> SpatialIndex<T> for BruteForce<T> {
    fn insert_with_filter(&mut self, sphere: Sphere, filter: Filter, value: T) -> Result<Handle> {
        sphere.validate()?;
        self.items.insert((sphere, filter, value))
    }

    fn remove(&mut self, handle: Handle) -> Result<T> {
        self.items.remove(handle).map(|(_, _, v)| v)
    }

    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()> {
        sphere.validate()?;
        self.items.get_mut(handle)?.0 = sphere;
        Ok(())
    }

    fn get(&self, handle: Handle) -> Result<(Sphere, &T)> {
        self.items.get(handle).map(|(s, _, v)| (*s, v))
    }

    fn get_mut(&mut self, handle: Handle) -> Result<&mut T> {
        self.items.get_mut(handle).map(|(_, _, v)| v)
    }

    fn filter(&self, handle: Handle) -> Result<Filter> {
        self.items.get(handle).map(|(_, f, _)| *f)
    }

    fn set_filter(&mut self, handle: Handle, filter: Filter) -> Result<()> {
        self.items.get_mut(handle)?.1 = filter;
        Ok(())
    }

    fn len(&self) -> usize {
        self.items.len()
    }

    fn clear(&mut self) {
        self.items.clear();
    }

    fn for_each(&self, f: &mut dyn FnMut(Handle, &Sphere, &T)) {
        for (h, (s, _, v)) in self.items.iter() {
            f(h, s, v);
        }
    }

    walk_methods!(T);

    fn validate(&self) -> Result<()> {
        self.items.validate()
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>() + self.items.heap_bytes()
    }

    fn kind(&self) -> IndexKind {
        IndexKind::Brute
    }
}

impl<T> BruteForce<T> {
    /// The objects that can interact with something: the pair searches'
    /// candidates (inert ones, [`Filter::is_inert`], never enter them). O(n).
    fn interacting(&self) -> Vec<(Handle, &(Sphere, Filter, T))> {
        self.items
            .iter()
            .filter(|(_, (_, f, _))| !f.is_inert())
            .collect()
    }
}

impl<T> Walk<T> for BruteForce<T> {
    fn walk<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for (h, (s, _, v)) in self.items.iter() {
            if query.selects(s) {
                f(h, s, v)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// The stored filter is at hand in the scan: test it there, before the
    /// shape.
    fn walk_filtered<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        filter: Option<Filter>,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let Some(q) = filter else {
            return self.walk(query, f);
        };
        for (h, (s, of, v)) in self.items.iter() {
            if q.interacts(*of) && query.selects(s) {
                f(h, s, v)?;
            }
        }
        ControlFlow::Continue(())
    }

    fn filter_of(&self, h: Handle) -> Filter {
        self.items.get(h).expect("a live handle").1
    }

    fn object_count(&self) -> usize {
        self.items.len()
    }

    /// One scan: every admitted object's distance, then the `k` smallest.
    fn knn_into(&self, q: &Nearest, filter: Option<Filter>, out: &mut Vec<Neighbor>) {
        out.clear();
        for (h, (s, of, _)) in self.items.iter() {
            if filter.is_none_or(|f| f.interacts(*of)) {
                let distance = q.metric.distance(q.point, s);
                if distance <= q.max_distance {
                    out.push(Neighbor {
                        handle: h,
                        distance,
                    });
                }
            }
        }
        nearest::finish(out, q.k);
    }

    fn walk_pairs(
        &self,
        mut f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let all = self.interacting();
        for (i, (ha, (sa, fa, va))) in all.iter().enumerate() {
            for (hb, (sb, fb, vb)) in &all[i + 1..] {
                if fa.interacts(*fb) && overlap::sphere_sphere(sa, sb) {
                    f(*ha, va, *hb, vb)?;
                }
            }
        }
        ControlFlow::Continue(())
    }
}

/// Each object against every later one, the outer loop split over rayon's threads.
/// Cost O(n²) divided by the thread count: the parallel oracle.
#[cfg(feature = "parallel")]
impl<T: Send + Sync> super::ParallelPairs<T> for BruteForce<T> {
    fn par_fold_pairs<A, I, F, R>(&self, init: I, fold: F, reduce: R) -> A
    where
        A: Send,
        I: Fn() -> A + Sync + Send,
        F: Fn(A, Handle, &T, Handle, &T) -> A + Sync + Send,
        R: Fn(A, A) -> A + Sync + Send,
    {
        use rayon::prelude::*;
        let all = self.interacting();
        (0..all.len())
            .into_par_iter()
            .fold(&init, |mut acc, i| {
                let (ha, (sa, fa, va)) = all[i];
                for (hb, (sb, fb, vb)) in &all[i + 1..] {
                    if fa.interacts(*fb) && overlap::sphere_sphere(sa, sb) {
                        acc = fold(acc, ha, va, *hb, vb);
                    }
                }
                acc
            })
            .reduce(&init, &reduce)
    }
}

#[cfg(all(test, feature = "parallel"))]
mod parallel_tests {
    use super::*;
    use crate::broad::{ParallelPairs, SpatialIndexExt};
    use glam::Vec3;

    #[test]
    fn parallel_pairs_equal_sequential_pairs() {
        let mut b = BruteForce::new();
        // A lattice of overlapping and touching spheres plus a removed one.
        for i in 0..400u32 {
            let p = Vec3::new((i % 20) as f32, (i / 20) as f32 * 0.9, (i % 7) as f32);
            b.insert(Sphere::new(p, 0.5 + (i % 3) as f32 * 0.1), i)
                .unwrap();
        }
        let h = b.insert(Sphere::new(Vec3::ZERO, 3.0), 999).unwrap();
        b.remove(h).unwrap();
        let mut seq = b.pairs();
        seq.sort_unstable();
        assert!(
            seq.len() > 100,
            "the scene must have pairs to compare: {}",
            seq.len()
        );
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let par = pool.install(|| b.par_pairs());
        assert_eq!(par, seq);
        assert_eq!(pool.install(|| b.par_count_pairs()), seq.len() as u64);
    }
}
