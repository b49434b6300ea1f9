//! [`Frustum`]: six inward-facing planes (a camera's view volume), and the
//! [`Relation`] of a volume to such a convex region.

use crate::geom::{Aabb, Plane, Sphere};
use crate::{Error, Result};
use glam::Mat4;

/// How a volume relates to a convex region.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Relation {
    /// Entirely outside at least one plane.
    Outside,
    /// Neither outside a plane nor inside all.
    Intersecting,
    /// Inside every plane.
    Inside,
}

/// A view frustum: six inward-facing planes with unit normals, in the order left,
/// right, bottom, top, near, far.
///
/// Built from a view-projection matrix with glam's conventions: column-major, clip
/// space `-w <= x <= w`, `-w <= y <= w` and depth `0 <= z <= w` (as made by
/// `Mat4::perspective_rh`, `perspective_lh`, `orthographic_rh` … times a view
/// matrix). A point `p` is inside when `M * (p, 1)` satisfies those inequalities.
///
/// The sphere test is the classic per-plane one: a sphere is culled only when it
/// lies entirely outside one plane, so spheres near a frustum corner may be kept
/// although they miss the frustum. This is exactly the semantics of the `frustum`
/// line of `proxima replay`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frustum {
    /// Left, right, bottom, top, near, far; normals point inward.
    pub planes: [Plane; 6],
}

impl Frustum {
    /// Bit mask with one bit per plane: all six planes still to test.
    pub const ALL_PLANES: u8 = 0b11_1111;

    /// Extracts the planes of a view-projection matrix (Gribb–Hartmann). Fails on a
    /// non-finite entry.
    pub fn from_view_projection(m: Mat4) -> Result<Frustum> {
        if !m.is_finite() {
            return Err(Error::NonFinite {
                what: "view-projection matrix",
            });
        }
        let r0 = m.row(0);
        let r1 = m.row(1);
        let r2 = m.row(2);
        let r3 = m.row(3);
        let p = Plane::from_vec4_normalized;
        Ok(Frustum {
            planes: [
                p(r3 + r0),
                p(r3 - r0),
                p(r3 + r1),
                p(r3 - r1),
                p(r2),
                p(r3 - r2),
            ],
        })
    }

    /// The frustum from its planes (inward normals, unit length expected).
    pub fn from_planes(planes: [Plane; 6]) -> Frustum {
        Frustum { planes }
    }

    /// Checks that every plane is finite.
    pub fn validate(&self) -> Result<()> {
        for p in &self.planes {
            if !p.normal.is_finite() || !p.d.is_finite() {
                return Err(Error::NonFinite {
                    what: "frustum plane",
                });
            }
        }
        Ok(())
    }

    /// Closed frustum–sphere test; see [`overlap::frustum_sphere`](crate::geom::overlap::frustum_sphere).
    #[inline]
    pub fn classify_sphere(&self, s: &Sphere) -> Relation {
        crate::geom::overlap::frustum_sphere(self, s)
    }

    /// Frustum–box classification over the planes in `mask`; see
    /// [`overlap::frustum_aabb`](crate::geom::overlap::frustum_aabb).
    #[inline]
    pub fn classify_aabb(&self, b: &Aabb, mask: u8) -> (Relation, u8) {
        crate::geom::overlap::frustum_aabb(self, b, mask)
    }
}
