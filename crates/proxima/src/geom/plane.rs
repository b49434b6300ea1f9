//! [`Plane`]: an oriented plane, the building block of a frustum.

use glam::{Vec3, Vec4};

/// A plane `normal · p + d = 0`; the positive side (`normal · p + d >= 0`) is "inside".
///
/// Planes made by [`Plane::from_vec4_normalized`] have a unit normal, so
/// [`Plane::signed_distance`] is a true distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Normal (unit length for normalized planes).
    pub normal: Vec3,
    /// Offset.
    pub d: f32,
}

impl Plane {
    /// A plane from its normal and offset (not normalized).
    pub const fn new(normal: Vec3, d: f32) -> Self {
        Plane { normal, d }
    }

    /// The plane `(x, y, z) · p + w = 0`, scaled so the normal has unit length. A
    /// zero normal is left as is: such a plane is everywhere inside (`w >= 0`) or
    /// everywhere outside (`w < 0`), which the signed distance still expresses.
    pub fn from_vec4_normalized(v: Vec4) -> Self {
        let n = v.truncate();
        let len = n.length();
        if len > 0.0 && len.is_finite() {
            Plane::new(n / len, v.w / len)
        } else {
            Plane::new(n, v.w)
        }
    }

    /// `normal · p + d`: positive inside, negative outside.
    #[inline]
    pub fn signed_distance(&self, p: Vec3) -> f32 {
        self.normal.dot(p) + self.d
    }
}
