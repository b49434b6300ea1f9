//! [`Aabb`]: the closed axis-aligned box (query shape, node bound, 6-DOP).

use crate::error::check_vec3;
use crate::geom::Sphere;
use crate::{Error, Result};
use glam::Vec3;

/// An axis-aligned box `[min, max]` (closed). Also the 6-DOP bounding volume.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Aabb {
    /// A box from its corners; not validated (see [`Aabb::validate`]).
    #[inline]
    pub const fn new(min: Vec3, max: Vec3) -> Self {
        Aabb { min, max }
    }

    /// The inverted box that is the identity of [`Aabb::union`]; contains nothing.
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// Checks for finite corners with `min <= max` on every axis.
    pub fn validate(&self) -> Result<()> {
        check_vec3(self.min, "AABB min")?;
        check_vec3(self.max, "AABB max")?;
        if self.min.cmple(self.max).all() {
            Ok(())
        } else {
            Err(Error::InvertedAabb)
        }
    }

    /// Centre point (halves first, so it does not overflow for any finite box).
    #[inline]
    pub fn center(&self) -> Vec3 {
        self.min * 0.5 + self.max * 0.5
    }

    /// `max - min`.
    #[inline]
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// Half of [`Aabb::extent`] (halves first, so it does not overflow for any
    /// finite box).
    #[inline]
    pub fn half_extent(&self) -> Vec3 {
        self.max * 0.5 - self.min * 0.5
    }

    /// The box grown by `d` on every side.
    #[inline]
    pub fn grown(&self, d: f32) -> Aabb {
        Aabb::new(self.min - Vec3::splat(d), self.max + Vec3::splat(d))
    }

    /// Smallest box containing both.
    #[inline]
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb::new(self.min.min(o.min), self.max.max(o.max))
    }

    /// True if `p` is inside or on the boundary.
    #[inline]
    pub fn contains_point(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// True if `o` lies entirely inside (boundary included).
    #[inline]
    pub fn contains_aabb(&self, o: &Aabb) -> bool {
        o.min.cmpge(self.min).all() && o.max.cmple(self.max).all()
    }

    /// True if the whole sphere lies inside (boundary included).
    #[inline]
    pub fn contains_sphere(&self, s: &Sphere) -> bool {
        self.contains_aabb(&s.aabb())
    }

    /// Closed box–box overlap; see [`overlap::aabb_aabb`](crate::geom::overlap::aabb_aabb).
    #[inline]
    pub fn intersects_aabb(&self, o: &Aabb) -> bool {
        crate::geom::overlap::aabb_aabb(self, o)
    }

    /// Index of the longest axis (0 = x, 1 = y, 2 = z; ties go to the lower index).
    #[inline]
    pub fn longest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    /// Squared distance from `p` to the box (0 inside).
    #[inline]
    pub fn distance_squared_to_point(&self, p: Vec3) -> f32 {
        let q = p.clamp(self.min, self.max);
        (p - q).length_squared()
    }
}
