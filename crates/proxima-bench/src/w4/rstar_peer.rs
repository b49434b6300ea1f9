//! Peer: rstar 0.13's R*-tree over the spheres' AABB envelopes, bulk loaded
//! (`RTree::bulk_load`, its OMT packing for static sets) or filled by one
//! `RTree::insert` per sphere (the R* insertion with forced reinsertion): one W4
//! row each. Sphere and box queries use
//! `locate_in_envelope_intersecting_int` with the query's bounding box; rays and
//! frusta a custom `SelectionFunction` that unpacks a node when
//! `Selection::classify_box` does not say `Outside` and a leaf when the exact test
//! selects it. Candidates are filtered by the exact closed test.

use super::engine::Engine;
use super::queries::{Batches, QueryKind};
use proxima::broad::Selection;
use proxima::geom::{Aabb, Frustum, Relation, Sphere};
use proxima::glam::Vec3;
use rstar::{RTree, RTreeObject, SelectionFunction, AABB};
use std::ops::ControlFlow;

/// A stored sphere with its envelope cached (rstar asks for it at every node).
#[derive(Clone, Copy, Debug)]
pub struct Item {
    sphere: Sphere,
    envelope: AABB<[f32; 3]>,
}

impl RTreeObject for Item {
    type Envelope = AABB<[f32; 3]>;
    fn envelope(&self) -> Self::Envelope {
        self.envelope
    }
}

fn envelope(b: &Aabb) -> AABB<[f32; 3]> {
    AABB::from_corners(b.min.to_array(), b.max.to_array())
}

/// Any [`Selection`] as an rstar selection function.
struct Select<'a, Q: ?Sized>(&'a Q);

impl<Q: Selection + ?Sized> SelectionFunction<Item> for Select<'_, Q> {
    fn should_unpack_parent(&self, e: &AABB<[f32; 3]>) -> bool {
        let b = Aabb::new(Vec3::from(e.lower()), Vec3::from(e.upper()));
        self.0.classify_box(&b, Frustum::ALL_PLANES).0 != Relation::Outside
    }
    fn should_unpack_leaf(&self, item: &Item) -> bool {
        self.0.selects(&item.sphere)
    }
}

fn items(spheres: &[Sphere]) -> impl Iterator<Item = Item> + '_ {
    spheres.iter().map(|s| Item {
        sphere: *s,
        envelope: envelope(&s.aabb()),
    })
}

/// The R*-tree.
pub struct RstarQuery {
    tree: RTree<Item>,
}

impl RstarQuery {
    /// Bulk load.
    pub fn build(spheres: &[Sphere]) -> Self {
        RstarQuery {
            tree: RTree::bulk_load(items(spheres).collect()),
        }
    }

    /// One `insert` per sphere, in input order, into an empty tree.
    pub fn build_by_inserts(spheres: &[Sphere]) -> Self {
        let mut tree = RTree::new();
        for item in items(spheres) {
            tree.insert(item);
        }
        RstarQuery { tree }
    }

    fn by_bounds<Q: Selection>(&self, q: &Q) -> usize {
        let mut n = 0;
        let _ = self.tree.locate_in_envelope_intersecting_int(
            envelope(&q.bounds().expect("bounded query")),
            |item| {
                n += usize::from(q.selects(&item.sphere));
                ControlFlow::<()>::Continue(())
            },
        );
        n
    }

    fn by_selection<Q: Selection>(&self, q: &Q) -> usize {
        self.tree.locate_with_selection_function(Select(q)).count()
    }
}

impl Engine for RstarQuery {
    fn count(&self, b: &Batches, kind: QueryKind, i: usize) -> Option<usize> {
        Some(match kind {
            QueryKind::Sphere => self.by_bounds(&b.spheres[i]),
            QueryKind::Aabb => self.by_bounds(&b.boxes[i]),
            QueryKind::Ray => self.by_selection(&b.rays[i]),
            QueryKind::Frustum => self.by_selection(&b.frusta[i]),
        })
    }

    fn supports(&self, _: QueryKind) -> bool {
        true
    }

    /// Estimate (rstar does not report its size): the items, plus one node per
    /// `MAX_SIZE / 2 = 3` children on average at every level above them (a node
    /// is a `Vec` of children and an envelope; a child is an enum the size of the
    /// larger of item and node).
    fn memory_bytes(&self) -> usize {
        let n = self.tree.size();
        let child = std::mem::size_of::<rstar::RTreeNode<Item>>();
        let node = std::mem::size_of::<rstar::ParentNode<Item>>();
        // n leaves' slots, plus n/3 + n/9 + ... ≈ n/2 inner nodes, each with a slot.
        n * child + (n / 2) * (node + child)
    }
}
