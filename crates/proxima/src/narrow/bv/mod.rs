//! Bounding volumes for mesh BVHs behind one trait, [`BoundingVolume`] [sources: bv-kinds, bvh-cost]:
//! its impls for [`Aabb`](crate::geom::Aabb) and [`Sphere`](crate::geom::Sphere),
//! and the [`Kdop`] and [`Obb`] types, one file each.

mod aabb;
mod kdop;
mod obb;
mod sphere;

pub use kdop::{Kdop, Kdop14, Kdop18, Kdop26};
pub use obb::Obb;
pub(crate) use sphere::enclosing_radius;

use crate::geom::Ray;
use glam::{Affine3A, Vec3};
use std::fmt::Debug;

/// A bounding volume usable in a [`Bvh`](crate::narrow::Bvh).
///
/// The seed compares spheres, AABBs, OBBs and k-DOPs through the cost model
/// `T = Nv*Cv + Np*Cp + Nu*Cu`: a tighter volume lowers `Nv` (volume tests) and `Np`
/// (triangle tests), a cheaper one lowers `Cv`, and one that is cheap to update under
/// motion lowers `Nu*Cu`. Every volume implements this trait, so a
/// [`Bvh`](crate::narrow::Bvh) and the collision queries are written once.
///
/// Two families:
/// - *axis-aligned* volumes ([`Aabb`](crate::geom::Aabb), [`Kdop`]): their slab
///   normals are fixed in the world. A translation shifts the slab intervals (no node
///   update); a rotation needs the moving tree refit ([`BoundingVolume::AXIS_ALIGNED`]).
/// - *oriented* volumes ([`Obb`], [`Sphere`](crate::geom::Sphere)): the test takes
///   the relative pose directly.
///
/// Robustness: volumes are fitted from `f32` points, and the triangle test receives
/// `f32` points transformed by the pose, so every overlap test accepts an absolute
/// `slack` that covers the rounding of projections, transforms and shifts (computed
/// per query from the coordinate magnitudes). The tests are therefore conservative:
/// they never reject a pair whose triangles intersect.
///
/// "Moving frame" below is the frame of the mesh that carries a pose (the first
/// mesh of a collision query); the pose maps it into the frame of the other mesh.
pub trait BoundingVolume: Copy + Debug + Send + Sync + 'static {
    /// A relative pose prepared once per query for [`BoundingVolume::overlaps`]
    /// (for k-DOPs: the per-slab shifts `dot(axis_i, t)`; for OBBs: the matrix).
    type Motion: Copy + Debug;

    /// Short name (`"aabb"`, `"kdop18"`, `"obb"`, `"sphere"`).
    const NAME: &'static str;

    /// True for volumes whose slab normals are fixed in the world (AABB, k-DOPs):
    /// [`BoundingVolume::motion`] then reads only the translation of the pose, and a
    /// rotated pose is handled by refitting the moving tree [sources: bvh-rotate] or by
    /// [`BoundingVolume::transformed`].
    const AXIS_ALIGNED: bool;

    /// The volume fitted to a non-empty set of points. O(points).
    fn from_points(points: &[Vec3]) -> Self;

    /// The volume fitted to a non-empty set of triangles. Defaults to the fit of
    /// their corners; [`Obb`] overrides it with the triangle-area covariance.
    fn from_triangles(triangles: &[[Vec3; 3]]) -> Self {
        let pts: Vec<Vec3> = triangles.iter().flatten().copied().collect();
        Self::from_points(&pts)
    }

    /// A volume containing both (exact for AABB and k-DOPs, conservative otherwise).
    fn merge(&self, other: &Self) -> Self;

    /// Refit to new points after deformation: same as [`BoundingVolume::from_points`]
    /// except that an [`Obb`] keeps its axes (so a refit is O(points), no PCA).
    fn refit_points(&self, points: &[Vec3]) -> Self {
        Self::from_points(points)
    }

    /// Refit of an internal node from its refitted children: [`BoundingVolume::merge`]
    /// by default; an [`Obb`] keeps its own axes and bounds the children's corners.
    fn refit_parent(&self, left: &Self, right: &Self) -> Self {
        left.merge(right)
    }

    /// A volume containing this one moved by `pose` (a rigid motion). Exact for
    /// [`Obb`] and spheres; for axis-aligned volumes a conservative bound (the
    /// k-DOP of the rotated box), the source's refit being the exact alternative
    /// [sources: bvh-rotate]. O(K). Collision's descent takes this one.
    fn transformed(&self, pose: &Affine3A) -> Self;

    /// Like [`BoundingVolume::transformed`], possibly tighter at a higher cost:
    /// the 18- and 26-DOP intersect the rotated box with the rotated boxes of
    /// their diagonal frames (about 4× the instructions). The distance descent
    /// takes this one (its lower bounds gain more than the update costs: W5
    /// distance, bunny × bunny −23% instructions); collision does not (W5
    /// collide, k-DOP18 first contact +50% time with it). Default: `transformed`.
    fn transformed_tight(&self, pose: &Affine3A) -> Self {
        self.transformed(pose)
    }

    /// Prepares `pose` (moving frame → other frame) and the rounding `slack`.
    fn motion(pose: &Affine3A, slack: f32) -> Self::Motion;

    /// Closed overlap of `self` (in the moving frame, moved by `motion`) with `other`
    /// (in the fixed frame), enlarged by the motion's slack. Conservative.
    fn overlaps(&self, motion: &Self::Motion, other: &Self) -> bool;

    /// The volume grown by `slack` on every side (k-DOPs: every slab interval).
    fn inflated(&self, slack: f32) -> Self;

    /// Closed overlap of two volumes in the same frame, without slack (the caller
    /// has [`inflated`](BoundingVolume::inflated) one of them).
    fn overlaps_fixed(&self, other: &Self) -> bool {
        self.overlaps(&Self::motion(&Affine3A::IDENTITY, 0.0), other)
    }

    /// How deeply `self` (in the moving frame, moved by `motion`) and `other`
    /// overlap: negative exactly when [`BoundingVolume::overlaps`] is false,
    /// otherwise a non-negative depth that the first-contact query uses to visit
    /// the more deeply overlapping pair first (pairs that overlap deeply are the
    /// likelier to hold intersecting triangles). The default, `0` or `-1`, orders
    /// nothing; k-DOPs and AABBs return the smallest overlap of their slab
    /// intervals. Cost: about that of [`BoundingVolume::overlaps`].
    #[inline]
    fn overlap_depth(&self, motion: &Self::Motion, other: &Self) -> f32 {
        if self.overlaps(motion, other) {
            0.0
        } else {
            -1.0
        }
    }

    /// [`BoundingVolume::overlap_depth`] of two volumes in the same frame, without
    /// slack (the caller has [`inflated`](BoundingVolume::inflated) one of them).
    #[inline]
    fn overlap_depth_fixed(&self, other: &Self) -> f32 {
        if self.overlaps_fixed(other) {
            0.0
        } else {
            -1.0
        }
    }

    /// A size measure used to decide which tree to descend (the larger volume).
    /// Invariant under rigid motion for oriented volumes.
    fn size(&self) -> f32;

    /// The entry parameter of `ray` into the volume enlarged by `slack`, clipped to
    /// `[0, ray.max_t]`, or `None` if the ray misses it. Conservative.
    fn ray_entry(&self, ray: &Ray, slack: f32) -> Option<f32>;

    /// A lower bound on the distance between `self` (in the moving frame, moved by
    /// `motion`) and `other` (in the fixed frame), `0` when they may overlap: the
    /// cut of the distance queries ([`Proximity`](crate::narrow::Proximity)).
    /// The motion's slack is subtracted, so the bound holds for the points the
    /// volumes were fitted to despite rounding. Never negative, never NaN for
    /// finite input. Cost: about that of [`BoundingVolume::overlaps`] (AABBs: the
    /// Euclidean gap of the coordinate slabs; k-DOPs: the largest Euclidean gap
    /// over the frames of mutually orthogonal slabs, the coordinate one and for
    /// the 18- and 26-DOP three of edge diagonals, and of the remaining slabs
    /// over their normalized axes; OBBs: the largest gap over the separating
    /// axes; spheres: exact).
    fn distance_lower_bound(&self, motion: &Self::Motion, other: &Self) -> f32;

    /// [`BoundingVolume::distance_lower_bound`] of two volumes in the same frame,
    /// without slack (the caller has [`inflated`](BoundingVolume::inflated) one of
    /// them).
    fn distance_lower_bound_fixed(&self, other: &Self) -> f32 {
        self.distance_lower_bound(&Self::motion(&Affine3A::IDENTITY, 0.0), other)
    }
}

/// The distance between the boxes `[lo_a, hi_a]` and `[lo_b, hi_b]` (`0` if they
/// overlap): the Euclidean norm of the per-axis gaps (the AABB's lower bound).
/// Where the `f32` squares overflow (gaps beyond `√f32::MAX ≈ 1.8e19`), in `f64`
/// ([`f32_below`]).
#[inline(always)]
pub(crate) fn box_gap(lo_a: Vec3, hi_a: Vec3, lo_b: Vec3, hi_b: Vec3) -> f32 {
    let g = (lo_b - hi_a).max(lo_a - hi_b).max(Vec3::ZERO).length();
    if g <= f32::MAX {
        g
    } else {
        wide_gap(|i| (lo_a[i], hi_a[i], lo_b[i], hi_b[i]), 3, |_| 1.0)
    }
}

/// A lower bound computed in `f64` as an `f32` lower bound: rounded down, at
/// most `f32::MAX`, `0` for NaN (an undefined gap bounds nothing).
pub(crate) fn f32_below(x: f64) -> f32 {
    if x.is_nan() || x <= 0.0 {
        return 0.0;
    }
    let f = (x as f32).min(f32::MAX);
    if f as f64 > x {
        f32::from_bits(f.to_bits() - 1)
    } else {
        f
    }
}

/// The slab-gap lower bound in `f64`, for where the `f32` one overflowed: slab
/// `i < n` has the intervals `(lo_a, hi_a, lo_b, hi_b) = slab(i)` and the axis
/// scale `scale(i)` (`1 / |axis|`); the Euclidean norm of the three coordinate
/// slabs' gaps, or the largest scaled gap of the others. A NaN gap (infinite
/// ends) counts as none. Cold: only gaps beyond `√f32::MAX ≈ 1.8e19` come here.
#[cold]
#[inline(never)]
pub(crate) fn wide_gap(
    slab: impl Fn(usize) -> (f32, f32, f32, f32),
    n: usize,
    scale: impl Fn(usize) -> f32,
) -> f32 {
    let gap = |i: usize| {
        let (lo_a, hi_a, lo_b, hi_b) = slab(i);
        let g = (lo_b as f64 - hi_a as f64).max(lo_a as f64 - hi_b as f64);
        if g > 0.0 {
            g * scale(i) as f64
        } else {
            0.0
        }
    };
    let sq: f64 = (0..3).map(|i| gap(i) * gap(i)).sum();
    f32_below((3..n).map(gap).fold(sq.sqrt(), f64::max))
}

/// `x` if positive, else `+0.0` (also for NaN and `-0.0`): lower bounds stay
/// non-negative, so their bit patterns sort like their values.
#[inline(always)]
pub(crate) fn positive(x: f32) -> f32 {
    if x > 0.0 {
        x
    } else {
        0.0
    }
}

/// Clips the ray interval `[t0, t1]` by the slab `lo <= o + t*d <= hi` (one axis of
/// a k-DOP or a box). Returns false if the interval becomes empty. A zero `d` keeps
/// the interval iff the origin is inside the slab.
#[inline]
pub(crate) fn clip_slab(o: f32, d: f32, lo: f32, hi: f32, t0: &mut f32, t1: &mut f32) -> bool {
    if d == 0.0 {
        return o >= lo && o <= hi;
    }
    let inv = 1.0 / d;
    let (mut ta, mut tb) = ((lo - o) * inv, (hi - o) * inv);
    if ta > tb {
        std::mem::swap(&mut ta, &mut tb);
    }
    // Widen by a relative epsilon: the division rounds.
    let w = (ta.abs().max(tb.abs())) * (4.0 * f32::EPSILON);
    *t0 = t0.max(ta - w);
    *t1 = t1.min(tb + w);
    *t0 <= *t1
}

/// The rounding slack of one collision query: an absolute distance that covers the
/// rounding of projections, pose transforms and interval shifts for coordinates of
/// magnitude at most `scale` (a bound on `|x| + |y| + |z|` of every point involved)
/// and of a rotation matrix whose `RᵀR` differs from identity by at most `dev`.
#[inline]
pub(crate) fn slack_for(scale: f32, dev: f32) -> f32 {
    scale * (64.0 * f32::EPSILON + 4.0 * dev)
}
