//! Refitting: bottom-up after deformation, and the source's exact refit of a rotated
//! tree [sources: bvh-rotate].

use super::tree::{coord_bound, Bvh};
use crate::narrow::bv::BoundingVolume;
use crate::narrow::TriMesh;
use crate::{Error, Result};
use glam::Vec3;

impl<BV: BoundingVolume> Bvh<BV> {
    /// Refits every volume to the current vertices of `mesh`, the mesh the tree
    /// was built over, after [`TriMesh::set_vertices`] deformed it (same
    /// triangles), keeping the topology: leaves from their triangles, then
    /// internal nodes from their children in one reverse (bottom-up) sweep. O(n).
    ///
    /// Exact for AABB and k-DOPs; OBBs keep their axes; spheres merge. The tree may
    /// become less efficient after large deformations (rebuild then), never wrong.
    /// Fails with [`Error::MeshMismatch`], changing nothing, on any other mesh.
    pub fn refit(&mut self, mesh: &TriMesh) -> Result<()> {
        if mesh.stamp().topology != self.mesh.topology {
            return Err(Error::MeshMismatch(
                "the BVH was built over another mesh".into(),
            ));
        }
        let vertices = mesh.vertices();
        let mut pts: Vec<Vec3> = Vec::new();
        for i in (0..self.nodes.len()).rev() {
            let n = self.nodes[i];
            let bv = if n.is_leaf() {
                pts.clear();
                for t in &self.tris[n.triangle_range()] {
                    pts.extend(t.iter().map(|&v| vertices[v as usize]));
                }
                n.bv.refit_points(&pts)
            } else {
                let (l, r) = n.children(i as u32);
                n.bv.refit_parent(&self.nodes[l as usize].bv, &self.nodes[r as usize].bv)
            };
            self.nodes[i].bv = bv;
        }
        self.coord_bound = coord_bound(vertices);
        self.mesh = mesh.stamp();
        Ok(())
    }

    /// The source's rotation update [sources: bvh-rotate]: every node's volume recomputed from the
    /// transformed vertices `world` (leaves from their triangles, internal nodes by
    /// merging), written to `out[i]` for node `i`. Exact for AABB and k-DOPs (the
    /// k-DOP of a union is the merge of the k-DOPs). Leaves are enlarged by `slack`
    /// (so every ancestor is too: the merge of enlarged volumes is the enlarged
    /// merge). Returns the number of node updates (`Nu`, all nodes). O(n).
    pub(crate) fn world_volumes(&self, world: &[Vec3], slack: f32, out: &mut Vec<BV>) -> u64 {
        out.clear();
        out.extend(self.nodes.iter().map(|n| n.bv));
        for i in (0..self.nodes.len()).rev() {
            let n = &self.nodes[i];
            out[i] = if n.is_leaf() {
                // Per triangle, merged: exact for k-DOPs, no scratch buffer.
                let mut tris = self.tris[n.triangle_range()].iter();
                let corners = |t: &[u32; 3]| t.map(|v| world[v as usize]);
                let mut bv = BV::from_points(&corners(tris.next().expect("leaf is non-empty")));
                for t in tris {
                    bv = bv.merge(&BV::from_points(&corners(t)));
                }
                bv.inflated(slack)
            } else {
                let (l, r) = n.children(i as u32);
                out[l as usize].merge(&out[r as usize])
            };
        }
        self.nodes.len() as u64
    }
}
