//! [`Ray`] (`origin + t·dir`, `t` in `[0, max_t]`) and [`Segment`] (queried as
//! the ray [`Segment::to_ray`], `t` in `[0, 1]`).

use crate::error::check_vec3;
use crate::{Error, Result};
use glam::Vec3;

/// The points `origin + t * dir` for `0 <= t <= max_t`.
///
/// `dir` need not be unit length: hit parameters `t` are in units of `dir`, so a
/// segment is the ray from `a` with `dir = b - a` and `max_t = 1`. `max_t` may be
/// `f32::INFINITY`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Direction (non-zero).
    pub dir: Vec3,
    /// Largest parameter considered, `>= 0`.
    pub max_t: f32,
}

impl Ray {
    /// An unbounded ray (`max_t = ∞`).
    pub const fn new(origin: Vec3, dir: Vec3) -> Self {
        Ray {
            origin,
            dir,
            max_t: f32::INFINITY,
        }
    }

    /// A ray limited to `0 <= t <= max_t`.
    pub const fn with_max_t(origin: Vec3, dir: Vec3, max_t: f32) -> Self {
        Ray { origin, dir, max_t }
    }

    /// Checks for a finite origin, a finite non-zero direction and `max_t >= 0`.
    pub fn validate(&self) -> Result<()> {
        check_vec3(self.origin, "ray origin")?;
        check_vec3(self.dir, "ray direction")?;
        if self.dir == Vec3::ZERO {
            return Err(Error::ZeroDirection);
        }
        if self.max_t.is_nan() || self.max_t < 0.0 {
            return Err(Error::InvalidRayLength);
        }
        Ok(())
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// The closed segment from `a` to `b`. Queries treat it as the ray from `a` with
/// `dir = b - a`, `max_t = 1`, so hit parameters run from 0 at `a` to 1 at `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Start point.
    pub a: Vec3,
    /// End point.
    pub b: Vec3,
}

impl Segment {
    /// A segment from `a` to `b`.
    pub const fn new(a: Vec3, b: Vec3) -> Self {
        Segment { a, b }
    }

    /// The equivalent ray (`dir = b - a`, `max_t = 1`). A segment with `a == b` gives a
    /// zero direction, which [`Ray::validate`] rejects.
    #[inline]
    pub fn to_ray(&self) -> Ray {
        Ray::with_max_t(self.a, self.b - self.a, 1.0)
    }
}
