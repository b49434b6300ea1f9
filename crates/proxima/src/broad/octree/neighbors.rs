//! Face neighbours across depths [sources: octree-depths]: the same-depth neighbour code
//! is computed arithmetically; if the map does not hold it, the neighbour is a
//! larger leaf (go up) or empty space, and if it is an inner node, the neighbours
//! are its smaller leaves touching the shared face (go down).

use super::code::{Face, LocationCode};
use super::node::NONE;
use super::LinearOctree;

impl<T> LinearOctree<T> {
    /// Calls `f` with every leaf across face `face` of cell `code`: the leaves whose
    /// cells overlap the same-depth neighbour cell `code.face_neighbor(face)` and
    /// touch the face it shares with `code`. That is one leaf at the same or a
    /// smaller depth (larger cell), or the leaves of the neighbour's subtree on the
    /// facing side; none at the world border or where the neighbour cell is empty
    /// space (the tree is sparse).
    ///
    /// Cost: one map lookup if the neighbour is a node (plus the facing leaves),
    /// else one lookup per level climbed.
    pub fn for_each_face_neighbor(
        &self,
        code: LocationCode,
        face: Face,
        mut f: impl FnMut(LocationCode),
    ) {
        let Some(n) = code.face_neighbor(face) else {
            return;
        };
        if let Some(&i) = self.map.get(&n.raw()) {
            self.facing_leaves(i, face, &mut f);
            return;
        }
        let mut c = n;
        while let Some(p) = c.parent() {
            if let Some(&i) = self.map.get(&p.raw()) {
                // The first existing ancestor: a leaf covers the neighbour cell; an
                // inner node means the cell lies in an empty octant.
                if self.nodes[i].leaf {
                    f(self.nodes[i].code);
                }
                return;
            }
            c = p;
        }
    }

    /// The leaves across `face` of `code`, collected (see
    /// [`LinearOctree::for_each_face_neighbor`]).
    pub fn face_neighbors(&self, code: LocationCode, face: Face) -> Vec<LocationCode> {
        let mut out = Vec::new();
        self.for_each_face_neighbor(code, face, |c| out.push(c));
        out
    }

    /// Leaves below node `i` on the side facing back across `face` (for `+x`, the
    /// children with the low x half).
    fn facing_leaves(&self, i: u32, face: Face, f: &mut impl FnMut(LocationCode)) {
        let n = &self.nodes[i];
        if n.leaf {
            f(n.code);
            return;
        }
        let bit = 1usize << face.axis();
        let want = if face.is_positive() { 0 } else { bit };
        for (k, &c) in n.children.iter().enumerate() {
            if c != NONE && k & bit == want {
                self.facing_leaves(c, face, f);
            }
        }
    }
}
