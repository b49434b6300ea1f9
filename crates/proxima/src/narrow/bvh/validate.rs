//! Structural invariants of a BVH (for tests and debugging).

use super::tree::Bvh;
use crate::narrow::bv::{slack_for, BoundingVolume};
use crate::narrow::TriMesh;
use crate::{Error, Result};

impl<BV: BoundingVolume> Bvh<BV> {
    /// Checks the invariants against `mesh`, the mesh the tree was built over:
    /// pre-order layout (children after their parent, left child at `i + 1`),
    /// every node reached once, leaves non-empty with at most `leaf_size`
    /// triangles, the leaves' ranges partitioning the triangle order,
    /// `triangle_order` a permutation, and every triangle corner of the mesh inside
    /// its leaf's and every ancestor's volume (tested as a zero-size volume
    /// overlapping it, with a small tolerance). O(n log n).
    ///
    /// Fails with [`Error::Invalid`] naming the first broken invariant, or
    /// [`Error::MeshMismatch`] for another mesh.
    pub fn validate(&self, mesh: &TriMesh) -> Result<()> {
        let bad = |m: String| Err(Error::Invalid(m));
        self.check_mesh(mesh)?;
        let vertices = mesh.vertices();
        let n = self.nodes.len();
        let mut seen = vec![false; n];
        let mut covered = vec![false; self.tris.len()];
        let slack = slack_for(4.0 * self.coord_bound, 0.0);
        let still = BV::motion(&glam::Affine3A::IDENTITY, slack);
        // (node, ancestors' indices)
        let mut stack: Vec<(usize, Vec<usize>)> = vec![(0, Vec::new())];
        while let Some((i, anc)) = stack.pop() {
            if i >= n || seen[i] {
                return bad(format!("node {i} out of range or reached twice"));
            }
            seen[i] = true;
            let node = &self.nodes[i];
            let mut path = anc.clone();
            path.push(i);
            if node.is_leaf() {
                if node.count as usize > self.options.leaf_size {
                    return bad(format!("leaf {i} holds {} triangles", node.count));
                }
                for k in node.triangle_range() {
                    if k >= covered.len() || covered[k] {
                        return bad(format!("triangle slot {k} in two leaves"));
                    }
                    covered[k] = true;
                    for v in self.tris[k] {
                        let p = BV::from_points(&[vertices[v as usize]]);
                        for &a in &path {
                            if !p.overlaps(&still, &self.nodes[a].bv) {
                                return bad(format!("node {a} does not contain triangle slot {k}"));
                            }
                        }
                    }
                }
            } else {
                let (l, r) = node.children(i as u32);
                if l as usize != i + 1 || r as usize <= i + 1 {
                    return bad(format!("node {i} has children {l}, {r}"));
                }
                stack.push((r as usize, path.clone()));
                stack.push((l as usize, path));
            }
        }
        if let Some(i) = seen.iter().position(|s| !s) {
            return bad(format!("node {i} unreachable"));
        }
        if let Some(k) = covered.iter().position(|c| !c) {
            return bad(format!("triangle slot {k} in no leaf"));
        }
        let mut ids = self.ids.clone();
        ids.sort_unstable();
        if ids.iter().enumerate().any(|(i, &t)| t as usize != i) {
            return bad("triangle order is not a permutation".into());
        }
        Ok(())
    }
}
