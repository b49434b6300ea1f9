//! [`Shape`]: what an object of the collision world is, shared by any number of
//! objects [sources: world].

use crate::geom::Sphere;
use crate::narrow::{BoundingVolume, Kdop18, Mesh};
use crate::{Error, Result};
use glam::Vec3;
use std::path::Path;
use std::sync::Arc;

/// The geometry of a collision-world object, in the object's own frame: a
/// triangle mesh with its trees, or a solid ball.
///
/// A mesh shape holds its [`Mesh`] in an [`Arc`]: cloning a shape costs one
/// reference count, and a thousand crates share one crate mesh and its trees
/// (instancing). A mesh is its surface: two meshes touch when some triangle of
/// one shares a point with some triangle of the other (a mesh entirely inside
/// another does not touch it). A ball is solid: every point within `radius` of
/// the object's origin.
#[derive(Clone, Debug)]
pub enum Shape<BV = Kdop18> {
    /// A shared triangle mesh (its collision tree, its lazily built ray tree).
    Mesh(Arc<Mesh<BV>>),
    /// A solid ball of this radius around the object's origin (its primitive is
    /// "triangle" 0 in contact and hit reports).
    Sphere(f32),
}

impl<BV: BoundingVolume> Shape<BV> {
    /// Loads a mesh file (OBJ, STL or PLY, see [`Mesh::load`]) and builds its
    /// collision tree: one call from a file to a shape. O(n log n) in the
    /// triangles. Fails with the loader's error (the file and line of a parse
    /// error).
    pub fn load(path: impl AsRef<Path>) -> Result<Shape<BV>> {
        Ok(Shape::Mesh(Arc::new(Mesh::load(path)?)))
    }

    /// A mesh shape sharing `mesh`. O(1).
    pub fn mesh(mesh: Arc<Mesh<BV>>) -> Shape<BV> {
        Shape::Mesh(mesh)
    }

    /// A solid ball shape. Fails with [`Error::NegativeRadius`] or
    /// [`Error::NonFinite`] on a bad radius.
    pub fn sphere(radius: f32) -> Result<Shape<BV>> {
        Sphere::new(Vec3::ZERO, radius).validate()?;
        Ok(Shape::Sphere(radius))
    }

    /// The mesh, for a mesh shape.
    pub fn as_mesh(&self) -> Option<&Arc<Mesh<BV>>> {
        match self {
            Shape::Mesh(m) => Some(m),
            Shape::Sphere(_) => None,
        }
    }

    /// A ball containing the shape in its own frame: the mesh's
    /// [`Mesh::bounding_sphere`] (around a point fixed in the mesh, so a rigid
    /// motion only moves it), or the ball itself. O(1).
    pub fn local_bounding_sphere(&self) -> Sphere {
        match self {
            Shape::Mesh(m) => m.bounding_sphere(),
            Shape::Sphere(r) => Sphere::new(Vec3::ZERO, *r),
        }
    }

    /// Number of primitives: triangles of a mesh, 1 for a ball. O(1).
    pub fn primitive_count(&self) -> usize {
        match self {
            Shape::Mesh(m) => m.trimesh().triangles().len(),
            Shape::Sphere(_) => 1,
        }
    }

    /// Checks a shape built by hand (a `Shape::Sphere` literal): the radius must
    /// be finite and non-negative. Mesh shapes are valid by construction.
    pub(crate) fn validate(&self) -> Result<()> {
        match self {
            Shape::Mesh(_) => Ok(()),
            Shape::Sphere(r) if r.is_finite() && *r >= 0.0 => Ok(()),
            Shape::Sphere(r) if r.is_finite() => Err(Error::NegativeRadius { radius: *r }),
            Shape::Sphere(_) => Err(Error::NonFinite {
                what: "sphere shape radius",
            }),
        }
    }
}

impl<BV> From<Mesh<BV>> for Shape<BV> {
    /// A shape owning `mesh` (in a new `Arc`; clone the shape to share it).
    fn from(mesh: Mesh<BV>) -> Self {
        Shape::Mesh(Arc::new(mesh))
    }
}

impl<BV> From<Arc<Mesh<BV>>> for Shape<BV> {
    fn from(mesh: Arc<Mesh<BV>>) -> Self {
        Shape::Mesh(mesh)
    }
}
