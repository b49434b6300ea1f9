//! [`AnyIndex`]: one type for whichever built-in index was chosen at run time,
//! with static dispatch inside each call.

use super::walk::{self, Walk};
use super::{
    BruteForce, Filter, Grid2dConfig, Grid3dConfig, HashGrid, HashGridConfig, IndexKind,
    LinearOctree, LooseKdConfig, LooseKdTree, Nearest, Neighbor, OctreeConfig, Query, RayHit,
    SceneHint, SpatialIndex, SweepHit, UniformGrid2d, UniformGrid3d,
};
use crate::geom::{Ray, Sphere, SphereSweep};
use crate::{Handle, Result};
use std::ops::ControlFlow;

/// Any of the six built-in indices, chosen at run time ([`IndexKind::build`],
/// [`AnyIndex::new`], or `From` an index built with its own config).
///
/// It implements [`SpatialIndex`] by delegating: one `match` per call, then the
/// index's own code. Its inherent [`for_each_in`](AnyIndex::for_each_in),
/// [`for_each_pair`](AnyIndex::for_each_pair), [`pairs`](AnyIndex::pairs) and
/// [`count_pairs`](AnyIndex::count_pairs) mean the same as the
/// [`SpatialIndexExt`](super::SpatialIndexExt) methods of those names but pass
/// the closure itself to the index's walk, so a pair search or a query with many
/// hits makes no dynamic call per object; its
/// [`update_many`](AnyIndex::update_many) matches once per batch, so a frame's
/// moves run the index's own update inlined in one loop. The variants are public so that a
/// caller can reach an index's own methods (statistics, node views).
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum AnyIndex<T> {
    /// [`IndexKind::Brute`].
    Brute(BruteForce<T>),
    /// [`IndexKind::LooseKd`].
    LooseKd(LooseKdTree<T>),
    /// [`IndexKind::Octree`].
    Octree(LinearOctree<T>),
    /// [`IndexKind::Grid2d`].
    Grid2d(UniformGrid2d<T>),
    /// [`IndexKind::HashGrid`].
    HashGrid(HashGrid<T>),
    /// [`IndexKind::Grid3d`].
    Grid3d(UniformGrid3d<T>),
}

/// `$body` with `$i` bound to the index inside `$any`, whatever its kind.
macro_rules! each {
    ($any:expr, $i:ident => $body:expr) => {
        match $any {
            AnyIndex::Brute($i) => $body,
            AnyIndex::LooseKd($i) => $body,
            AnyIndex::Octree($i) => $body,
            AnyIndex::Grid2d($i) => $body,
            AnyIndex::HashGrid($i) => $body,
            AnyIndex::Grid3d($i) => $body,
        }
    };
}

impl<T> AnyIndex<T> {
    /// An empty index of `kind`, configured by its config's `for_scene(hint)`.
    /// Errors when the hint's numbers are unusable for that kind (see each
    /// config).
    pub fn new(kind: IndexKind, hint: &SceneHint) -> Result<Self> {
        Ok(match kind {
            IndexKind::Brute => BruteForce::new().into(),
            IndexKind::LooseKd => LooseKdTree::with_config(LooseKdConfig::for_scene(hint))?.into(),
            IndexKind::Octree => LinearOctree::with_config(OctreeConfig::for_scene(hint))?.into(),
            IndexKind::Grid2d => UniformGrid2d::with_config(Grid2dConfig::for_scene(hint))?.into(),
            IndexKind::HashGrid => HashGrid::with_config(HashGridConfig::for_scene(hint))?.into(),
            IndexKind::Grid3d => UniformGrid3d::with_config(Grid3dConfig::for_scene(hint))?.into(),
        })
    }

    /// [`SpatialIndex::visit`] (unfiltered) with a closure, statically
    /// dispatched: the index's walk for the query's shape runs with `f`
    /// inlined.
    pub fn for_each_in(
        &self,
        query: impl Into<Query>,
        f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        let query = query.into();
        each!(self, i => walk::visit(i, &query, None, f))
    }

    /// [`SpatialIndex::visit_pairs`] with a closure, statically dispatched (the
    /// pair search's inner loop calls `f` directly).
    pub fn for_each_pair(
        &self,
        f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        each!(self, i => i.walk_pairs(f))
    }

    /// [`SpatialIndexExt::update_many`](super::SpatialIndexExt::update_many)
    /// with one `match` per batch instead of one per object.
    pub fn update_many(&mut self, moves: impl IntoIterator<Item = (Handle, Sphere)>) -> Result<()>
    where
        T: Send + Sync,
    {
        let moves = moves.into_iter();
        each!(self, i => {
            for (h, s) in moves {
                i.update(h, s)?;
            }
            Ok(())
        })
    }

    /// Every overlapping pair once, as `(a, b)` with `a < b`, in no particular
    /// order.
    pub fn pairs(&self) -> Vec<(Handle, Handle)> {
        let mut out = Vec::new();
        let _ = self.for_each_pair(|a, _, b, _| {
            out.push(if a < b { (a, b) } else { (b, a) });
            ControlFlow::Continue(())
        });
        out
    }

    /// Number of overlapping pairs.
    pub fn count_pairs(&self) -> u64 {
        let mut n = 0;
        let _ = self.for_each_pair(|_, _, _, _| {
            n += 1;
            ControlFlow::Continue(())
        });
        n
    }
}

impl<T: Send + Sync> SpatialIndex<T> for AnyIndex<T> {
    #[inline]
    fn insert(&mut self, sphere: Sphere, value: T) -> Result<Handle> {
        each!(self, i => i.insert(sphere, value))
    }
    #[inline]
    fn insert_with_filter(&mut self, sphere: Sphere, filter: Filter, value: T) -> Result<Handle> {
        each!(self, i => i.insert_with_filter(sphere, filter, value))
    }
    #[inline]
    fn remove(&mut self, handle: Handle) -> Result<T> {
        each!(self, i => i.remove(handle))
    }
    #[inline]
    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()> {
        each!(self, i => i.update(handle, sphere))
    }
    #[inline]
    fn get(&self, handle: Handle) -> Result<(Sphere, &T)> {
        each!(self, i => i.get(handle))
    }
    #[inline]
    fn get_mut(&mut self, handle: Handle) -> Result<&mut T> {
        each!(self, i => i.get_mut(handle))
    }
    fn filter(&self, handle: Handle) -> Result<Filter> {
        each!(self, i => i.filter(handle))
    }
    fn set_filter(&mut self, handle: Handle, filter: Filter) -> Result<()> {
        each!(self, i => i.set_filter(handle, filter))
    }
    fn len(&self) -> usize {
        each!(self, i => i.len())
    }
    fn clear(&mut self) {
        each!(self, i => i.clear())
    }
    fn for_each(&self, f: &mut dyn FnMut(Handle, &Sphere, &T)) {
        each!(self, i => i.for_each(f))
    }
    fn visit(
        &self,
        query: &Query,
        filter: Option<Filter>,
        f: &mut dyn FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        each!(self, i => walk::visit(i, query, filter, f))
    }
    fn visit_pairs(
        &self,
        f: &mut dyn FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        each!(self, i => i.walk_pairs(f))
    }
    fn ray_first(&self, ray: &Ray, filter: Option<Filter>) -> Result<Option<RayHit>> {
        ray.validate()?;
        Ok(each!(self, i => i.first_hit(ray, filter)))
    }
    fn sweep_first(&self, sweep: &SphereSweep, filter: Option<Filter>) -> Result<Option<SweepHit>> {
        sweep.validate()?;
        Ok(each!(self, i => i.first_sweep_hit(sweep, filter)))
    }
    fn nearest_into(
        &self,
        query: &Nearest,
        filter: Option<Filter>,
        out: &mut Vec<Neighbor>,
    ) -> Result<()> {
        out.clear();
        query.validate()?;
        each!(self, i => i.knn_into(query, filter, out));
        Ok(())
    }
    fn validate(&self) -> Result<()> {
        each!(self, i => SpatialIndex::validate(i))
    }
    fn memory_bytes(&self) -> usize {
        each!(self, i => i.memory_bytes())
    }
    fn kind(&self) -> IndexKind {
        match self {
            AnyIndex::Brute(_) => IndexKind::Brute,
            AnyIndex::LooseKd(_) => IndexKind::LooseKd,
            AnyIndex::Octree(_) => IndexKind::Octree,
            AnyIndex::Grid2d(_) => IndexKind::Grid2d,
            AnyIndex::HashGrid(_) => IndexKind::HashGrid,
            AnyIndex::Grid3d(_) => IndexKind::Grid3d,
        }
    }
}

/// `From` each index.
macro_rules! from_index {
    ($($variant:ident($ty:ident)),+ $(,)?) => {$(
        impl<T> From<$ty<T>> for AnyIndex<T> {
            fn from(index: $ty<T>) -> Self {
                AnyIndex::$variant(index)
            }
        }
    )+};
}
from_index!(
    Brute(BruteForce),
    LooseKd(LooseKdTree),
    Octree(LinearOctree),
    Grid2d(UniformGrid2d),
    HashGrid(HashGrid),
    Grid3d(UniformGrid3d),
);

/// Delegates to the index's parallel search where it has one (brute force, the
/// loose k-d tree, the dense 3D grid); the octree and the two multi-reference
/// grids fold their sequential pair search on the calling thread.
#[cfg(feature = "parallel")]
impl<T: Send + Sync> super::ParallelPairs<T> for AnyIndex<T> {
    fn par_fold_pairs<A, I, F, R>(&self, init: I, fold: F, reduce: R) -> A
    where
        A: Send,
        I: Fn() -> A + Sync + Send,
        F: Fn(A, Handle, &T, Handle, &T) -> A + Sync + Send,
        R: Fn(A, A) -> A + Sync + Send,
    {
        match self {
            AnyIndex::Brute(i) => i.par_fold_pairs(init, fold, reduce),
            AnyIndex::LooseKd(i) => i.par_fold_pairs(init, fold, reduce),
            AnyIndex::Grid3d(i) => i.par_fold_pairs(init, fold, reduce),
            AnyIndex::Octree(i) => fold_sequential(i, init, fold),
            AnyIndex::Grid2d(i) => fold_sequential(i, init, fold),
            AnyIndex::HashGrid(i) => fold_sequential(i, init, fold),
        }
    }
}

/// The fold of [`ParallelPairs::par_fold_pairs`](super::ParallelPairs) over an
/// index's sequential pair search, on the calling thread (one accumulator).
#[cfg(feature = "parallel")]
fn fold_sequential<T, W: Walk<T>, A>(
    index: &W,
    init: impl Fn() -> A,
    fold: impl Fn(A, Handle, &T, Handle, &T) -> A,
) -> A {
    // `fold` takes the accumulator by value: it moves through an Option.
    let mut acc = Some(init());
    let _ = index.walk_pairs(|a, va, b, vb| {
        acc = acc.take().map(|x| fold(x, a, va, b, vb));
        ControlFlow::Continue(())
    });
    acc.expect("the accumulator is put back after every pair")
}
