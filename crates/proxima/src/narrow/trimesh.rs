//! [`TriMesh`]: validated triangle-mesh geometry (vertices and index triples).

use crate::{Error, Result};
use glam::Vec3;
use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};

/// A triangle mesh: shared vertices and triangles as vertex-index triples.
///
/// Validated on construction: at least one triangle, every index in range, every
/// coordinate finite. Zero-area triangles (repeated or collinear vertices) are
/// allowed; every algorithm in [`narrow`](crate::narrow) handles them.
///
/// This is the geometry alone; [`Mesh`](crate::narrow::Mesh) owns one together
/// with its trees. A [`Bvh`](crate::narrow::Bvh) built over a `TriMesh` reads
/// its vertices at query time, so it refuses any other mesh (even one with as
/// many vertices), and this one after [`TriMesh::set_vertices`] until it is
/// refit: a clone of the mesh, holding the same geometry, is accepted. O(1).
#[derive(Clone)]
pub struct TriMesh {
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    stamp: MeshStamp,
}

/// Which mesh and which version of its vertices a tree was built or refit over,
/// so that a tree given another mesh (or the same one, deformed and not refit)
/// fails instead of answering wrongly: `topology` is new for every
/// [`TriMesh::new`], `geometry` for every [`TriMesh::set_vertices`] too. A clone
/// keeps both (it holds the same triangles and vertices). O(1) to compare.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct MeshStamp {
    pub topology: u64,
    pub geometry: u64,
}

/// A number never handed out before in this process.
fn fresh() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

impl PartialEq for TriMesh {
    /// Equal geometry: the same vertices and triangles (wherever they came from).
    fn eq(&self, other: &Self) -> bool {
        self.vertices == other.vertices && self.triangles == other.triangles
    }
}

impl fmt::Debug for TriMesh {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TriMesh")
            .field("vertices", &self.vertices)
            .field("triangles", &self.triangles)
            .finish()
    }
}

impl TriMesh {
    /// Builds a mesh, checking it. O(vertices + triangles).
    pub fn new(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<TriMesh> {
        if triangles.is_empty() {
            return Err(Error::InvalidMesh("mesh has no triangles".into()));
        }
        if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidMesh(format!("vertex {i} is not finite")));
        }
        let n = vertices.len();
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&i| i as usize >= n) {
                return Err(Error::InvalidMesh(format!(
                    "triangle {t} uses vertex {bad}, but the mesh has {n} vertices"
                )));
            }
        }
        let id = fresh();
        Ok(TriMesh {
            vertices,
            triangles,
            stamp: MeshStamp {
                topology: id,
                geometry: id,
            },
        })
    }

    /// The mesh's identity and vertex version (see [`MeshStamp`]).
    #[inline]
    pub(crate) fn stamp(&self) -> MeshStamp {
        self.stamp
    }

    /// The vertices.
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The triangles (indices into [`TriMesh::vertices`]).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Always false: a valid mesh has at least one triangle.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The corners of triangle `i`, or [`Error::IndexOutOfRange`] (naming `i` and
    /// the triangle count) if `i >= len()`. O(1). The checked form of
    /// [`TriMesh::triangle`] for indices that come from user input.
    #[inline]
    pub fn get_triangle(&self, i: usize) -> Result<[Vec3; 3]> {
        if i >= self.triangles.len() {
            return Err(Error::IndexOutOfRange {
                what: "triangle",
                index: i,
                len: self.triangles.len(),
            });
        }
        Ok(self.triangle(i))
    }

    /// The corners of triangle `i`. O(1). Panics if `i >= len()`, like slice
    /// indexing: for indices from a loop over `0..len()` or from this crate's
    /// own results (BVH hits); use [`TriMesh::get_triangle`] for anything else.
    #[inline]
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[i];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }

    /// Replaces the vertex positions (same count), e.g. for a deformed mesh; the
    /// caller then refits its BVHs ([`Bvh::refit`](crate::narrow::Bvh::refit)),
    /// which refuse the mesh until then. ([`Mesh::set_vertices`](crate::narrow::Mesh::set_vertices)
    /// does both.) O(vertices). Fails, changing nothing, on a count mismatch or a
    /// non-finite coordinate.
    pub fn set_vertices(&mut self, vertices: &[Vec3]) -> Result<()> {
        if vertices.len() != self.vertices.len() {
            return Err(Error::InvalidMesh(format!(
                "expected {} vertices, got {}",
                self.vertices.len(),
                vertices.len()
            )));
        }
        if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidMesh(format!("vertex {i} is not finite")));
        }
        self.vertices.copy_from_slice(vertices);
        self.stamp.geometry = fresh();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation() {
        let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(TriMesh::new(v.clone(), vec![[0, 1, 2]]).is_ok());
        assert!(TriMesh::new(v.clone(), vec![]).is_err());
        assert!(TriMesh::new(v.clone(), vec![[0, 1, 3]]).is_err());
        let mut bad = v.clone();
        bad[1].y = f32::NAN;
        assert!(TriMesh::new(bad, vec![[0, 1, 2]]).is_err());
        // Degenerate triangles are allowed.
        assert!(TriMesh::new(v, vec![[0, 0, 0]]).is_ok());
    }

    #[test]
    fn get_triangle_out_of_range_is_an_error() {
        let m = TriMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]).unwrap();
        assert_eq!(m.get_triangle(0), Ok([Vec3::ZERO, Vec3::X, Vec3::Y]));
        let e = m.get_triangle(1).unwrap_err();
        assert_eq!(
            e,
            Error::IndexOutOfRange {
                what: "triangle",
                index: 1,
                len: 1
            }
        );
        assert_eq!(e.to_string(), "triangle index 1 out of range (there are 1)");
        assert!(m.get_triangle(usize::MAX).is_err());
    }
}
