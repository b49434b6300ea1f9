//! [`SphereSweep`]: a sphere moving in a straight line (continuous collision,
//! shape casts) [sources: index-queries].

use crate::error::{check_radius, check_vec3};
use crate::geom::Aabb;
use crate::Result;
use glam::Vec3;

/// A sphere of radius `radius` whose centre moves in a straight line from
/// `from` (time `t = 0`) to `to` (`t = 1`).
///
/// It touches a stored sphere `(c, r)` iff the distance from `c` to the segment
/// `[from, to]` is at most `r + radius` (closed), decided exactly by
/// [`overlap::sweep_sphere`](crate::geom::overlap::sweep_sphere), which also
/// gives the time of first contact. The segment is the one between the two
/// end points as given: nothing rounds `to - from`. `from == to` is allowed
/// (a sphere at rest: it touches what it overlaps, at `t = 0`), and
/// `radius == 0` is the exact segment query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereSweep {
    /// Where the centre starts (`t = 0`).
    pub from: Vec3,
    /// Where the centre ends (`t = 1`).
    pub to: Vec3,
    /// Radius of the moving sphere, `>= 0`.
    pub radius: f32,
}

impl SphereSweep {
    /// A sweep; not validated (see [`SphereSweep::validate`]).
    pub const fn new(from: Vec3, to: Vec3, radius: f32) -> Self {
        SphereSweep { from, to, radius }
    }

    /// Checks for finite end points and a finite, non-negative radius.
    pub fn validate(&self) -> Result<()> {
        check_vec3(self.from, "sweep start")?;
        check_vec3(self.to, "sweep end")?;
        check_radius(self.radius, "sweep radius")
    }

    /// The centre at time `t` (`from + t (to - from)`, rounded to `f32`).
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.from + (self.to - self.from) * t
    }

    /// A box containing the whole swept volume (the segment grown by the
    /// radius), rounded outward to `f32`, so every sphere the sweep touches
    /// intersects it. O(1).
    pub fn aabb(&self) -> Aabb {
        let r = -(self.radius as f64);
        let lo = self.from.min(self.to);
        let hi = self.from.max(self.to);
        Aabb::new(
            Vec3::from([0, 1, 2].map(|i| super::overlap::sum_floor(lo[i], r))),
            Vec3::from([0, 1, 2].map(|i| -super::overlap::sum_floor(-hi[i], r))),
        )
    }
}
