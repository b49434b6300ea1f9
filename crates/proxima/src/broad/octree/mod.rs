//! The linear octree for dynamic scenes [sources: octree, octree-code].
//!
//! Cells are named by [`LocationCode`]s and found through a hash map from code to
//! node, so moving an object to the next cell is "compute the neighbour's code,
//! look it up" instead of a descent from the root. See [`LinearOctree`].

mod code;
mod insert;
mod nearest;
mod neighbors;
mod node;
mod pairs;
mod query;
mod ray;
mod stats;
mod update;
mod validate;

#[cfg(test)]
mod tests;

pub(crate) use code::MAX_DEPTH;
pub use code::{morton_order, Face, LocationCode};
pub use stats::OctreeStats;

use crate::arena::{Arena, Pool};

use crate::broad::filter::InertCount;
use crate::broad::walk::{walk_methods, Walk};
use crate::broad::{Filter, IndexKind, RayHit, SceneHint, Selection, SpatialIndex};
use crate::geom::{Aabb, Ray, Sphere};
use crate::{Error, Handle, Result};
use glam::Vec3;
use node::{Node, Obj};
use rustc_hash::FxHashMap;
use std::ops::ControlFlow;

/// Everything a [`LinearOctree`] is built from. [`OctreeConfig::new`] gives 48
/// objects per leaf, merge below 24, depth up to 16: on W1 at N = 100k, leaves
/// of up to 32 (the earlier default) made a frame (update all + all pairs)
/// about twice as fast as leaves of up to 8 (fewer nodes to visit; see
/// `examples/octree_w1.rs`). Leaves of up to 48 against 32 (three
/// alternations, 2026-11-30, with the kNN searches' leaf prefetch widened
/// from 16 to 24 lines in the same build; docs/bench/octree-leaf48.txt): W1
/// 100k frame −15 to −26%, W9 −24 to −37%, W7 kNN at 1M −22 to −33% (one
/// run; 10–20% between runs there), at 100k −9 to +1% (spheres at k ≤ 10 −5
/// to +6%), W8 sweeps −7 to +2% (ratios to parry3d in the same run), W4
/// queries −12 to +8% (rays 0 to +5%). 64 (one run against 48, within the
/// noise) was slower on W1 and W8 and faster on W9.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OctreeConfig {
    /// The box the root cell covers (any finite box; a degenerate one is
    /// widened to a unit cube). Objects outside it are still stored exactly.
    pub world: Aabb,
    /// A leaf splits into octants when it holds more than this many objects (and is
    /// shallower than `max_depth`). At least 1.
    pub max_per_leaf: u32,
    /// An inner node merges its subtree back into one leaf when the number of
    /// objects below it falls *below* this. Must not exceed `max_per_leaf`, so a
    /// freshly split node (more than `max_per_leaf` objects) is never merged at once:
    /// the gap between the two thresholds is the hysteresis that keeps an object
    /// oscillating across a border from splitting and merging every frame. `0`
    /// disables merging (emptied leaves are still deleted).
    pub merge_below: u32,
    /// Deepest level a leaf may have, at most [`LocationCode::MAX_DEPTH`] (21).
    /// Leaves at this depth hold any number of objects (coincident centres cannot
    /// be separated).
    pub max_depth: u32,
}

/// [`OctreeConfig::new`]'s `max_per_leaf`, named so that what is sized by
/// it (the kNN searches' whole-leaf prefetch, `nearest.rs`) follows it.
pub(super) const DEFAULT_MAX_PER_LEAF: u32 = 48;

impl OctreeConfig {
    /// The default tuning over `world`.
    pub fn new(world: Aabb) -> Self {
        OctreeConfig {
            world,
            max_per_leaf: DEFAULT_MAX_PER_LEAF,
            merge_below: DEFAULT_MAX_PER_LEAF / 2,
            max_depth: 16,
        }
    }

    /// The default tuning over the hint's world box.
    pub fn for_scene(hint: &SceneHint) -> Self {
        Self::new(hint.world)
    }

    /// Checks the ranges documented on the fields ([`Error::InvalidParameter`];
    /// the world box gives its own error).
    pub fn validate(&self) -> Result<()> {
        self.world.validate()?;
        let bad = |m: &str| Err(Error::InvalidParameter(format!("octree config: {m}")));
        if self.max_per_leaf == 0 {
            return bad("max_per_leaf must be at least 1");
        }
        if self.merge_below > self.max_per_leaf {
            return bad("merge_below must not exceed max_per_leaf (no hysteresis)");
        }
        if self.max_depth > MAX_DEPTH {
            return bad("max_depth must be at most 21 (a u64 location code)");
        }
        Ok(())
    }
}

/// A sparse linear octree over bounding spheres [sources: octree, octree-code].
///
/// **Structure.** The root cell is the cube centred on the world box whose side is
/// the box's longest extent (the source's cells are cubes; a flat world thus gets
/// cubic cells, not slabs). Every node is named by its [`LocationCode`]; a
/// [`FxHashMap`] from code to node index replaces pointers for random access (the
/// source's MAP), and nodes live in a pool with a free list. Inner nodes also keep
/// the indices of their children for top-down traversals. The tree is sparse: a
/// split creates only the octants that receive objects, and an object moving into
/// empty space creates the one leaf it needs. Emptied leaves are deleted.
///
/// **Objects.** An object belongs to the leaf containing its centre. A centre
/// outside the root cube is *clamped* onto the cube for placement only; its
/// *extent* is then its radius plus the (L∞) distance from the clamped point, so the
/// stored sphere still lies inside its leaf's loose box and every query stays
/// exact. Such objects cost loose bounds: their leaf and its ancestors grow by that
/// distance. Every node keeps the largest extent below it (conservative: never too
/// small), and queries test the cell grown by it, so objects larger than a cell are
/// handled without being stored twice.
///
/// **Split / merge.** A leaf holding more than
/// [`max_per_leaf`](OctreeConfig::max_per_leaf) objects splits (while depth allows);
/// a subtree whose object count falls below
/// [`merge_below`](OctreeConfig::merge_below) collapses into one leaf (hysteresis).
///
/// **Moves** ([`SpatialIndex::update`]): a centre that stays in its leaf costs no
/// lookup; a centre that moves to an adjacent cell (across a face, edge or corner)
/// goes through [`LocationCode::face_neighbor`] and a map lookup, then resolves a
/// neighbour at another depth by going up (larger leaf) or down toward the centre
/// (smaller leaves), as in [sources: octree-depths]; a long jump finds the leaf from the code
/// of the new centre by a binary search over depths (≈ log2(depth) map lookups).
/// The three paths are counted in [`LinearOctree::stats`].
///
/// **Queries** traverse nodes with loose boxes (each query shape classifies a box);
/// a subtree classified `Inside` (frustum, box) is reported without further tests,
/// and frustum plane masks skip planes that already contain a parent.
/// [`SpatialIndex::visit_pairs`] is a simultaneous traversal of the tree with
/// itself, pruned by loose boxes (on W1 at N = 100k about 4–5× faster than one
/// sphere query per object, measured with `examples/octree_w1.rs`). The first ray
/// hit is a front-to-back search. No query allocates.
///
/// Costs: insert/remove O(depth) (plus a split or merge of ≤ `max_per_leaf`
/// objects when one happens); a move within a leaf O(1), to an adjacent leaf O(1)
/// lookups plus O(distance to the common ancestor) count updates.
#[derive(Clone, Debug)]
pub struct LinearOctree<T> {
    config: OctreeConfig,
    world: Aabb,
    /// The root cell (a cube containing `world`).
    cube: Aabb,
    /// `2^21 / side`: world → integer coordinates at depth 21.
    scale: Vec3,
    /// Cell edge length at each depth (`side * 2^-d`, exact).
    cell_size: [f32; MAX_DEPTH as usize + 1],
    /// Added to every loose box to absorb f32 rounding of cell boxes and
    /// quantization (a few ulps of the world's coordinates).
    slack: f32,
    objects: Arena<Obj<T>>,
    nodes: Pool<Node>,
    /// Each leaf's items by octant, by node index: bit `s` of
    /// `octants[leaf][k]` is set when the item at slot `s < 64` has its
    /// (clamped) centre in octant `k` of the leaf's cell (the key's next
    /// three bits), so that a first-hit search scans only the items of the
    /// octants its cast reaches (`ray.rs`), as if the leaf were split but
    /// without the nodes. Kept by every change to a leaf's items (`validate`
    /// checks them). Zero for inner nodes and for leaves at `MAX_DEPTH` (no
    /// octants there); slots from 64 on are in no mask, and scans take all
    /// of them. Beside the nodes, not in them: inside (88 -> 152 bytes a
    /// node) W1's updates took 8-10% longer in three alternations.
    octants: Vec<[u64; 8]>,
    map: FxHashMap<u64, u32>,
    root: u32,
    /// Emptied item lists kept for new leaves, so steady-state moves do not
    /// allocate.
    spare: Vec<Vec<node::Item>>,
    /// Live nodes per depth (bounds the depth search of long jumps).
    per_depth: [u32; MAX_DEPTH as usize + 1],
    counters: stats::Counters,
    /// Inert objects stored: while there are some, the pair search leaves
    /// them out (see `pairs.rs`).
    inert: InertCount,
}

impl<T> LinearOctree<T> {
    /// An empty octree over `world` (any finite box; a degenerate one is widened to
    /// a unit cube) with the default tuning ([`OctreeConfig::new`]). Errors on a
    /// non-finite or inverted box.
    pub fn new(world: Aabb) -> Result<Self> {
        Self::with_config(OctreeConfig::new(world))
    }

    /// An empty octree as `config` says. Errors as [`OctreeConfig::validate`].
    pub fn with_config(config: OctreeConfig) -> Result<Self> {
        config.validate()?;
        let world = config.world;
        let mut side = world.extent().max_element();
        if side <= 0.0 {
            side = 1.0;
        }
        let half = Vec3::splat(side * 0.5);
        let c = world.center();
        let cube = Aabb::new(c - half, c + half);
        if !cube.min.is_finite() || !cube.max.is_finite() {
            return Err(Error::NonFinite { what: "world box" });
        }
        let mut cell_size = [0.0; MAX_DEPTH as usize + 1];
        for (d, s) in cell_size.iter_mut().enumerate() {
            *s = (cube.max.x - cube.min.x) * (1.0 / (1u32 << d) as f32);
        }
        let scale = Vec3::splat((1u32 << MAX_DEPTH) as f32 / cell_size[0]);
        let magnitude = cube.min.abs().max(cube.max.abs()).max_element();
        let slack = magnitude * f32::EPSILON * 64.0;
        let mut t = LinearOctree {
            config,
            world,
            cube,
            scale,
            cell_size,
            slack,
            objects: Arena::new(),
            nodes: Pool::default(),
            octants: Vec::new(),
            map: FxHashMap::default(),
            root: 0,
            spare: Vec::new(),
            per_depth: [0; MAX_DEPTH as usize + 1],
            counters: Default::default(),
            inert: InertCount::default(),
        };
        t.root = t.new_node(LocationCode::ROOT, node::NONE);
        Ok(t)
    }

    /// The configuration in use.
    pub fn config(&self) -> &OctreeConfig {
        &self.config
    }

    /// The world box of the config.
    pub fn world(&self) -> &Aabb {
        &self.world
    }

    /// The root cell: the cube the location codes divide.
    pub fn root_cell(&self) -> &Aabb {
        &self.cube
    }

    /// The box of cell `code` (see [`LocationCode::cell_box`]).
    pub fn cell_box(&self, code: LocationCode) -> Aabb {
        self.cell_of(code.coords(), code.depth())
    }

    /// The code of the leaf holding object `h`.
    pub fn leaf_of(&self, h: Handle) -> Result<LocationCode> {
        let o = self.objects.get(h)?;
        Ok(self.nodes[o.leaf].code)
    }

    /// True if `code` names a node of the tree; `Some(true)` for a leaf. One map
    /// lookup.
    pub fn node_kind(&self, code: LocationCode) -> Option<bool> {
        self.map.get(&code.raw()).map(|&i| self.nodes[i].leaf)
    }

    /// Calls `f(code, objects)` for every leaf, in no particular order.
    pub fn for_each_leaf(&self, mut f: impl FnMut(LocationCode, usize)) {
        for &i in self.map.values() {
            let n = &self.nodes[i];
            if n.leaf {
                f(n.code, n.items.len());
            }
        }
    }
}

impl<T: Send + Sync> SpatialIndex<T> for LinearOctree<T> {
    fn insert_with_filter(&mut self, sphere: Sphere, filter: Filter, value: T) -> Result<Handle> {
        sphere.validate()?;
        self.insert_valid(sphere, filter, value)
    }

    fn remove(&mut self, handle: Handle) -> Result<T> {
        self.remove_obj(handle)
    }

    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()> {
        sphere.validate()?;
        self.objects.get(handle)?;
        self.move_obj(handle, sphere);
        Ok(())
    }

    fn get(&self, handle: Handle) -> Result<(Sphere, &T)> {
        self.objects.get(handle).map(|o| (o.sphere, &o.value))
    }

    fn get_mut(&mut self, handle: Handle) -> Result<&mut T> {
        self.objects.get_mut(handle).map(|o| &mut o.value)
    }

    fn filter(&self, handle: Handle) -> Result<Filter> {
        self.objects.get(handle).map(|o| o.filter)
    }

    fn set_filter(&mut self, handle: Handle, filter: Filter) -> Result<()> {
        let o = self.objects.get_mut(handle)?;
        let old = std::mem::replace(&mut o.filter, filter);
        let leaf = o.leaf;
        self.inert.change(old, filter);
        self.widen_filters(leaf, filter);
        Ok(())
    }

    fn len(&self) -> usize {
        self.objects.len()
    }

    fn clear(&mut self) {
        self.clear_all();
    }

    fn for_each(&self, f: &mut dyn FnMut(Handle, &Sphere, &T)) {
        for (h, o) in self.objects.iter() {
            f(h, &o.sphere, &o.value);
        }
    }

    walk_methods!(T);

    fn validate(&self) -> Result<()> {
        self.validate_tree()
    }

    fn memory_bytes(&self) -> usize {
        self.memory()
    }

    fn kind(&self) -> IndexKind {
        IndexKind::Octree
    }
}

impl<T> Walk<T> for LinearOctree<T> {
    fn walk<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.visit_tree(query, (), &mut f)
    }

    /// The same walk, skipping every subtree whose filter bits (the OR of its
    /// objects' groups and masks) cannot interact with `filter`, and every
    /// object whose own filter does not.
    fn walk_filtered<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        filter: Option<Filter>,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        match filter {
            None => self.visit_tree(query, (), &mut f),
            Some(q) => self.visit_tree(query, q, &mut f),
        }
    }

    fn walk_pairs(
        &self,
        mut f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.pairs_tree(&mut f)
    }

    fn filter_of(&self, h: Handle) -> Filter {
        self.obj(h).filter
    }

    fn object_count(&self) -> usize {
        self.objects.len()
    }

    /// Branch and bound over the loose boxes (`nearest.rs`).
    fn knn_into(
        &self,
        query: &crate::broad::Nearest,
        filter: Option<Filter>,
        out: &mut Vec<crate::broad::Neighbor>,
    ) {
        self.nearest_tree(query, filter, out)
    }

    /// Front-to-back: children in the octant order of the ray's direction,
    /// subtrees entered after the best hit so far skipped.
    fn first_hit(&self, ray: &Ray, filter: Option<Filter>) -> Option<RayHit> {
        self.first_tree(ray, filter)
    }

    /// The same front-to-back search, pruning by the sweep's box entry.
    fn first_sweep_hit(
        &self,
        sweep: &crate::geom::SphereSweep,
        filter: Option<Filter>,
    ) -> Option<RayHit> {
        self.first_tree(sweep, filter)
    }
}
