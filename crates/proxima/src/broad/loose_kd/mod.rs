//! The loose k-d tree over bounding spheres [sources: kd-tree] (the source's C++
//! class `SPHERE_SET_TREE`: `Push`, `Pop`, `Move`, `Clear`, `TestIntersection`).
//!
//! Files, one concern each: `node.rs` (node layout, box derivation, conservative
//! regions, the per-node object vectors), `insert.rs` (the placement rule, node
//! creation, placing and swap-removing objects),
//! `update.rs` (removal and moves with climbing), `query.rs` (selection queries and
//! the front-to-back ray search), `pairs.rs` (node-vs-node self collision),
//! `pairs_par.rs` (the same walk split into rayon tasks, feature `parallel`),
//! `validate.rs`, `stats.rs`, `visit.rs` (read-only node walk for pictures).

mod insert;
mod nearest;
mod node;
mod pairs;
#[cfg(feature = "parallel")]
mod pairs_par;
mod query;
mod stats;
mod store;
mod update;
mod validate;
mod visit;

#[cfg(test)]
mod tests;

pub use stats::{KdStats, Placement};
pub use visit::KdNodeView;

use crate::arena::{Arena, Pool};

use crate::broad::filter::InertCount;
use crate::broad::walk::{walk_methods, Walk};
use crate::broad::{Filter, IndexKind, RayHit, SceneHint, Selection, SpatialIndex};
use crate::geom::{Aabb, Ray, Sphere};
use crate::{Error, Handle, Result};
use node::{Node, NIL};
use std::ops::ControlFlow;
use store::Store;

/// Largest accepted depth cap (it also sizes the fixed traversal stacks).
pub(crate) const MAX_DEPTH_LIMIT: u8 = LooseKdConfig::MAX_DEPTH_LIMIT;

/// Everything a [`LooseKdTree`] is built from. [`LooseKdConfig::new`] takes the
/// world box and `R_max` and sets the tuning to its defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LooseKdConfig {
    /// The box the tree subdivides (finite, not inverted). Objects outside it
    /// are still stored exactly; see [`LooseKdTree`] for what they cost.
    pub world: Aabb,
    /// `R_max` (finite, `> 0`): spheres with at least this radius stay at the
    /// root; the border zones are at most this wide.
    pub r_max: f32,
    /// The density `d` in `(0, 1]`: higher gives narrower border zones and a
    /// deeper tree. Default [`LooseKdConfig::DEFAULT_DENSITY`].
    pub density: f32,
    /// The depth cap, `1..=`[`LooseKdConfig::MAX_DEPTH_LIMIT`] (the root is
    /// depth 0). Default [`LooseKdConfig::DEFAULT_MAX_DEPTH`].
    pub max_depth: u8,
}

impl LooseKdConfig {
    /// A good density for scenes of many similar spheres moving a little per frame
    /// [sources: w1]: measured with the W1 frame (update all + all pairs). With the
    /// objects in one depth-first array (`store.rs`), 0.15 beat 0.2 at N = 100k
    /// (frame ~5–10% faster, 138 instead of 200 bytes per object, build twice as
    /// fast) and at 10k (~5–10%); 0.12 and 0.1 were 20–40% slower at 100k, 0.3 and
    /// 0.4 1.5–2× slower. The trade-off is scene-dependent: on W2 (flat world)
    /// 0.15 was also ~20% faster, but on W3 (tight clusters, ~7 pairs per object) its
    /// pair search was ~20–30% slower than with 0.2; pass a higher density for such
    /// scenes. Lower densities widen the border zones (more spheres stop
    /// high in the tree, more cross tests); higher ones deepen the tree (more nodes
    /// to walk and more moves that change node).
    pub const DEFAULT_DENSITY: f32 = 0.15;

    /// Largest accepted depth cap (it also sizes the fixed traversal stacks).
    pub const MAX_DEPTH_LIMIT: u8 = 64;

    /// The largest depth cap [`LooseKdConfig::new`] chooses
    /// ([`LooseKdConfig::depth_for`]): deep enough for worlds ~10⁴ times wider than
    /// `R_max` on every axis, shallow enough that spheres of radius zero piled on
    /// one point stop after 40 levels instead of recursing until `f32` runs out of
    /// bits.
    pub const DEFAULT_MAX_DEPTH: u8 = 40;

    /// Cells per `R_max` at [`LooseKdConfig::depth_for`]'s cap (1: cells about
    /// `R_max` wide before the slack levels).
    pub const CELLS_PER_R_MAX: f32 = 1.0;

    /// Levels [`LooseKdConfig::depth_for`] adds to its count: the loose children
    /// overlap, so a child is a little more than half its parent, and the slack
    /// takes the cells below `R_max / 2` on every axis.
    pub const DEPTH_SLACK: u8 = 3;

    /// The default tuning over `world` for spheres up to radius `r_max`, with
    /// the depth cap of [`LooseKdConfig::depth_for`].
    pub fn new(world: Aabb, r_max: f32) -> Self {
        LooseKdConfig {
            world,
            r_max,
            density: Self::DEFAULT_DENSITY,
            max_depth: Self::depth_for(&world, r_max),
        }
    }

    /// The default tuning over the hint's world box and `r_max`.
    pub fn for_scene(hint: &SceneHint) -> Self {
        Self::new(hint.world, hint.r_max)
    }

    /// The depth cap for a scene: the levels that split every axis of `world`
    /// down to cells about `R_max` wide (splits halve the longest axis:
    /// `ceil(log2(extent / R_max))` per axis), plus
    /// [`LooseKdConfig::DEPTH_SLACK`], within `1..=`[`LooseKdConfig::DEFAULT_MAX_DEPTH`].
    ///
    /// Why: a sphere stops at the first node where `r >= h` (the border zone
    /// `h = min(R_max, density · extent / 4)` shrinks with the cell), so a
    /// sphere far smaller than `R_max` — a point: never — descends to the cap,
    /// one node per level once it is alone. With a fixed cap of 40, 100k
    /// radius-0 points took 4.7 s to build and 17.7 µs per nearest query (W7).
    /// At this cap the cells are already below `R_max / 2`, where the border
    /// zone is under 2% of `R_max` at the default density: only spheres that
    /// small stop at the cap, where the tree still separates objects spaced
    /// about `R_max` apart. The cap is the seed's own rule (a sphere at the
    /// cap stays there) [sources: kd-insert]. O(1).
    pub fn depth_for(world: &Aabb, r_max: f32) -> u8 {
        let cell = r_max / Self::CELLS_PER_R_MAX;
        let e = world.extent();
        if !cell.is_finite() || cell <= 0.0 || !e.is_finite() {
            // `validate` rejects such a configuration anyway.
            return Self::DEFAULT_MAX_DEPTH;
        }
        let mut d = Self::DEPTH_SLACK as f32;
        for a in 0..3 {
            let ratio = e[a] / cell;
            if ratio > 1.0 {
                d += ratio.log2().ceil();
            }
        }
        d.min(Self::DEFAULT_MAX_DEPTH as f32) as u8
    }

    /// Checks the ranges documented on the fields ([`Error::InvalidParameter`];
    /// the world box gives its own error).
    pub fn validate(&self) -> Result<()> {
        self.world.validate()?;
        let (r_max, density, max_depth) = (self.r_max, self.density, self.max_depth);
        if !r_max.is_finite() || r_max <= 0.0 {
            return Err(Error::InvalidParameter(format!(
                "r_max must be finite and > 0, got {r_max}"
            )));
        }
        if !(density > 0.0 && density <= 1.0) {
            return Err(Error::InvalidParameter(format!(
                "density must be in (0, 1], got {density}"
            )));
        }
        if max_depth == 0 || max_depth > Self::MAX_DEPTH_LIMIT {
            return Err(Error::InvalidParameter(format!(
                "max_depth must be in 1..={}, got {max_depth}",
                Self::MAX_DEPTH_LIMIT
            )));
        }
        Ok(())
    }
}

/// Where a stored object is: its node and its position in the node's range of
/// the object array. The handle arena holds only this; the object itself is in
/// the array (`store.rs`).
#[derive(Clone, Copy, Debug)]
struct Loc {
    node: u32,
    pos: u32,
}

/// The loose k-d tree of [sources: kd-tree]: a binary, unbalanced tree built lazily over a
/// world box, whose two children overlap in a shared border zone so that every
/// sphere lives in exactly one node (never duplicated, never split).
///
/// # Structure [sources: kd-border, kd-insert, kd-move]
///
/// A node covers a box `B` and splits its longest axis `a` at the centre `m`, with
/// border half-width `h = min(R_max, extent_a(B) · d / 4)` (`d` = density). The
/// negative child covers `B` with `max_a = m + h`, the positive child `B` with
/// `min_a = m - h`. A sphere with `r >= h` is attached to the node; a smaller one
/// goes to the child on its centre's side (`c_a > m` → positive) and the rule
/// repeats. Since such a sphere has `r < h`, it lies entirely on its side of the
/// opposite child's border (`c_a - r > m - h`), so one comparison on the split axis
/// decides whether a query can reach a child. Nodes are created on first use and
/// freed when they hold nothing and have no children; the node count depends on the
/// world box, `R_max`, `d` and where the spheres are, not on their number.
///
/// **Placement invariant.** At every moment, each sphere sits exactly in the node
/// where inserting it afresh would put it (the tree is a function of the current
/// set of spheres, not of their history). The source's `Move` keeps a moved sphere in
/// its node while it stays inside the node's box `B`; this implementation instead
/// keeps it while the *placement rule* still routes it there (its centre is on the
/// same side of every ancestor's centre plane, `r` is still below every ancestor's
/// `h` and still `>= h` here). For a sphere inside the world this implies the
/// source's condition (a routed sphere lies inside `B`), so only the bookkeeping is
/// stricter: pruning, [`LooseKdTree::validate`] and the oracle tests all rely on
/// one exact invariant, and spheres outside the world box move as cheaply as
/// inside ones (the source's box test fails for them at every node, even the root).
///
/// # Costs
///
/// Memory: one node per occupied cell (`size_of` = 128 bytes, one cache-line-aligned
/// block); the objects (sphere, handle, payload) of all nodes share one array in
/// which each node owns a contiguous range with some spare room (up to ~1.5 spare or
/// dead positions per object, see `store.rs`; one 24-byte bound per 8
/// positions lets queries skip most of a node's objects; a move inside a node
/// does not update it but marks the node for full scans until the next
/// compaction or relocation of its range), plus one small arena slot per object
/// giving its node and position. Nodes live in a pooled arena with a free list; the
/// array and the nodes are periodically compacted into depth-first order, which is
/// the order the pair search and the queries read them in. Insert and a move that leaves the node's
/// cell are O(depth); a move inside the cell is O(1); removal is O(1) (swap with the
/// node's last object) plus freeing emptied ancestors. Depth is
/// capped ([`LooseKdConfig::max_depth`]): at the cap a
/// node takes every sphere routed to it, so zero-radius spheres on one point end up
/// in one node rather than recursing forever (queries then scan that node).
///
/// Spheres with `r >= R_max` are attached at the root: every query and the pair
/// search test them directly, so many of them make the tree degrade towards brute
/// force. Spheres outside the world box follow the same rule (the comparisons do
/// not need the box) but they stretch the *regions* used for ray, frustum and pair
/// pruning: the faces of node boxes that lie on the world boundary are replaced by
/// the bounds of everything stored (kept until the tree is next empty or cleared),
/// so far-away objects make boundary nodes look larger to those queries. Sphere
/// and box queries, which prune with the split planes only, are unaffected.
///
/// **Not the fastest for many small range queries on a static set.** Spheres
/// stop at every depth (where `r >= h`), so a small sphere or box query reads a
/// node and a range of objects at each level of its path: cache lines, not
/// arithmetic, bound it. On W4 (100 000 static spheres, `proxima-bench w4`, a
/// quiet run, BENCHMARKS.md) its sphere and box queries took 1.9× and 2.5× the
/// time of rstar's bulk-loaded R-tree, while its rays took 0.82–0.96× (since
/// casts test boxes with a bound prepared once per ray) and its frusta 0.9×.
/// For that use, [`UniformGrid3d`](super::UniformGrid3d) (0.9–1.0× rstar
/// on spheres and boxes) or [`LinearOctree`](super::LinearOctree) (frusta) fit
/// better; this tree is built for scenes that move (cheap updates, all pairs).
#[derive(Clone, Debug)]
pub struct LooseKdTree<T> {
    /// Handle → location; the objects themselves are in `store`.
    items: Arena<Loc>,
    nodes: Pool<Node>,
    /// The objects, each node's in its own contiguous range.
    store: Store<T>,
    /// Buffers of the pair search, reused between calls.
    scratch: pairs::PairScratch,
    /// Inert objects stored: while there are some, the pair search leaves
    /// them out (reading each object's filter as it collects spheres).
    inert: InertCount,
    root: u32,
    world: Aabb,
    r_max: f32,
    density: f32,
    max_depth: u8,
    /// World box ∪ the bounding box of every sphere stored since the tree was last
    /// empty: a bound for all stored spheres, used for the world-boundary faces of
    /// node regions.
    span: Aabb,
    /// Absolute slack added outward to every pruning bound, so that a conservative
    /// decision taken in `f32` can never disagree with the exact tests of
    /// `geom::overlap` by a rounding error (see `node::Node::region`).
    eps: f32,
}

impl<T> LooseKdTree<T> {
    /// An empty tree over `world` for spheres up to radius `r_max`, with the
    /// default tuning ([`LooseKdConfig::new`]). Errors on a non-finite or
    /// inverted world box or a non-positive or non-finite `r_max`.
    ///
    /// Objects outside `world` or larger than `r_max` are still accepted and
    /// answered exactly; see the type's docs for what they cost.
    pub fn new(world: Aabb, r_max: f32) -> Result<Self> {
        Self::with_config(LooseKdConfig::new(world, r_max))
    }

    /// An empty tree as `config` says. Errors as [`LooseKdConfig::validate`].
    pub fn with_config(config: LooseKdConfig) -> Result<Self> {
        config.validate()?;
        let LooseKdConfig {
            world,
            r_max,
            density,
            max_depth,
        } = config;
        let mut t = LooseKdTree {
            items: Arena::new(),
            nodes: Pool::default(),
            store: Store::default(),
            scratch: Default::default(),
            inert: InertCount::default(),
            root: NIL,
            world,
            r_max,
            density,
            max_depth,
            span: world,
            eps: 0.0,
        };
        t.eps = node::slack(&t.span);
        Ok(t)
    }

    /// The world box the tree subdivides.
    pub fn world(&self) -> Aabb {
        self.world
    }

    /// The `R_max` parameter.
    pub fn r_max(&self) -> f32 {
        self.r_max
    }

    /// The density parameter.
    pub fn density(&self) -> f32 {
        self.density
    }

    /// The depth cap (root = 0).
    pub fn max_depth(&self) -> u8 {
        self.max_depth
    }

    /// Grows `span` (and the slack) to cover `s`. O(1).
    #[inline]
    fn cover(&mut self, s: &Sphere) {
        let b = s.aabb();
        if !self.span.contains_aabb(&b) {
            self.span = self.span.union(&b);
            self.eps = node::slack(&self.span);
        }
    }

    /// Position in the object array of the object at `loc`.
    #[inline]
    fn position(&self, loc: Loc) -> usize {
        (self.nodes[loc.node].start + loc.pos) as usize
    }

    /// Forgets the bounds of removed objects once nothing is stored.
    fn reset_span_if_empty(&mut self) {
        if self.items.is_empty() {
            self.span = self.world;
            self.eps = node::slack(&self.span);
        }
    }
}

impl<T: Send + Sync> SpatialIndex<T> for LooseKdTree<T> {
    /// `Push` [sources: kd-insert]: O(depth), creating the missing nodes on the way.
    fn insert_with_filter(&mut self, sphere: Sphere, filter: Filter, value: T) -> Result<Handle> {
        sphere.validate()?;
        // Before `cover` and `descend` change the tree: a full index stays as it was.
        self.items.check_room()?;
        self.cover(&sphere);
        let root = self.ensure_root();
        let node = self.descend(root, &sphere);
        let handle = self.items.insert(Loc { node, pos: 0 })?;
        self.put(node, sphere, handle, filter, value);
        self.maybe_compact();
        Ok(handle)
    }

    /// `Pop` [sources: kd-remove]: O(1) swap-remove from the node, then frees emptied nodes upwards.
    fn remove(&mut self, handle: Handle) -> Result<T> {
        let loc = *self.items.get(handle)?;
        let (_, _, _, value) = self.take(loc);
        self.prune_up(loc.node);
        self.items.remove(handle)?;
        self.reset_span_if_empty();
        self.maybe_compact();
        Ok(value)
    }

    /// `Move` [sources: kd-move]; see the type's docs for when the object changes node.
    /// Inline: a frame's update loop then holds the common in-node move.
    #[inline]
    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()> {
        sphere.validate()?;
        let loc = *self.items.get(handle)?;
        self.cover(&sphere);
        self.move_item(loc, sphere);
        Ok(())
    }

    fn get(&self, handle: Handle) -> Result<(Sphere, &T)> {
        let loc = self.items.get(handle)?;
        let p = (self.nodes[loc.node].start + loc.pos) as usize;
        Ok((self.store.sphere[p], self.store.at(p).1))
    }

    fn get_mut(&mut self, handle: Handle) -> Result<&mut T> {
        let loc = *self.items.get(handle)?;
        let p = (self.nodes[loc.node].start + loc.pos) as usize;
        let (_, _, v) = self.store.entry[p].as_mut().expect("live position");
        Ok(v)
    }

    fn filter(&self, handle: Handle) -> Result<Filter> {
        let loc = self.items.get(handle)?;
        Ok(self.store.full(self.position(*loc)).1)
    }

    fn set_filter(&mut self, handle: Handle, filter: Filter) -> Result<()> {
        let loc = *self.items.get(handle)?;
        let p = self.position(loc);
        let old = std::mem::replace(
            &mut self.store.entry[p].as_mut().expect("live position").1,
            filter,
        );
        self.inert.change(old, filter);
        self.widen_filters(loc.node, filter);
        Ok(())
    }

    fn len(&self) -> usize {
        self.items.len()
    }

    /// `Clear` [sources: kd-tree]: drops every node and object and releases the memory.
    fn clear(&mut self) {
        self.items.clear();
        self.nodes.clear();
        self.store = Store::default();
        self.scratch = Default::default();
        self.inert = InertCount::default();
        self.root = NIL;
        self.span = self.world;
        self.eps = node::slack(&self.span);
    }

    fn for_each(&self, f: &mut dyn FnMut(Handle, &Sphere, &T)) {
        for (_, loc) in self.items.iter() {
            let p = (self.nodes[loc.node].start + loc.pos) as usize;
            let (h, v) = self.store.at(p);
            f(h, &self.store.sphere[p], v);
        }
    }

    walk_methods!(T);

    fn validate(&self) -> Result<()> {
        self.validate_impl()
    }

    /// The struct plus the capacity of the handle arena, the node pool, the object
    /// array and the pair-search buffers. O(1).
    fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.items.heap_bytes()
            + self.nodes.heap_bytes()
            + self.store.heap_bytes()
            + self.scratch.heap_bytes()
    }

    fn kind(&self) -> IndexKind {
        IndexKind::LooseKd
    }
}

impl<T> Walk<T> for LooseKdTree<T> {
    fn walk<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.visit_impl(query, (), f)
    }

    /// The same walk, skipping every subtree whose filter bits (the OR of its
    /// objects' groups and masks) cannot interact with `filter`, and every
    /// object whose own filter does not.
    fn walk_filtered<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        filter: Option<Filter>,
        f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        match filter {
            None => self.visit_impl(query, (), f),
            Some(q) => self.visit_impl(query, q, f),
        }
    }

    /// Node-vs-node walk over the nodes' contiguous objects (see `pairs.rs`). Its
    /// buffers (20 bytes per carried object) are kept in the tree and reused, so
    /// repeated calls do not allocate once they have grown.
    fn walk_pairs(
        &self,
        f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.pairs_impl(f)
    }

    fn filter_of(&self, h: Handle) -> Filter {
        let loc = self.items.get(h).expect("a live handle");
        self.store.full(self.position(*loc)).1
    }

    fn object_count(&self) -> usize {
        self.items.len()
    }

    /// Branch and bound over the node regions (`nearest.rs`).
    fn knn_into(
        &self,
        query: &crate::broad::Nearest,
        filter: Option<Filter>,
        out: &mut Vec<crate::broad::Neighbor>,
    ) {
        self.nearest_impl(query, filter, out)
    }

    /// Front-to-back: nearer child first, subtrees whose region the ray enters
    /// after the best hit so far are skipped.
    fn first_hit(&self, ray: &Ray, filter: Option<Filter>) -> Option<RayHit> {
        self.first_impl(ray, filter)
    }

    /// The same front-to-back search, pruning by the sweep's box entry.
    fn first_sweep_hit(
        &self,
        sweep: &crate::geom::SphereSweep,
        filter: Option<Filter>,
    ) -> Option<RayHit> {
        self.first_impl(sweep, filter)
    }
}
