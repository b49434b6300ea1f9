use crate::{Error, Result};
use glam::Vec3;

/// A triangle mesh: shared vertices and triangles as vertex-index triples.
///
/// Validated on construction: at least one triangle, every index in range, every
/// coordinate finite. Zero-area triangles (repeated or collinear vertices) are
/// allowed; every algorithm in [`narrow`](crate::narrow) handles them.
#[derive(Clone, Debug, PartialEq)]
pub struct TriMesh {
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
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
        Ok(TriMesh {
            vertices,
            triangles,
        })
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
    /// caller then refits its BVH. Fails, changing nothing, on a count mismatch or a
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
