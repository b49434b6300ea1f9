//! k-DOPs (discrete orientation polytopes) with K = 14, 18, 26 [sources: kdop].

use super::{clip_slab, BoundingVolume};
use crate::geom::Ray;
use crate::{Error, Result};
use glam::{Affine3A, Mat3A, Vec3, Vec3A};

/// A k-DOP: the intersection of `K/2` slabs `min_i <= dot(axis_i, p) <= max_i` with
/// fixed integer axes, as in the source (Klosowski et al.) [sources: kdop]:
/// - `K = 14`: the 3 coordinate axes and the 4 corner diagonals `(1,1,1)`,
///   `(1,-1,1)`, `(1,1,-1)`, `(1,-1,-1)` (cut the 8 corners of the AABB);
/// - `K = 18`: the 3 coordinate axes and the 6 edge diagonals `(1,1,0)`, `(1,0,1)`,
///   `(0,1,1)`, `(1,-1,0)`, `(1,0,-1)`, `(0,1,-1)` (cut the 12 edges);
/// - `K = 26`: all 13.
///
/// Stored as `K` numbers: the `K/2` minima then the `K/2` maxima. Two k-DOPs overlap
/// iff every slab interval overlaps: `K` float comparisons. A translation `t` shifts
/// slab `i` by `dot(axis_i, t)`; a rotation needs a refit (see
/// [`BoundingVolume::AXIS_ALIGNED`]). Other values of `K` are rejected at compile
/// time: every method evaluates a constant assertion on `K`, so using one with an
/// unsupported `K` is a build error, never a panic:
///
/// ```compile_fail
/// let _ = proxima::narrow::Kdop::<10>::empty();
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kdop<const K: usize> {
    /// `d[i]` is the minimum along axis `i`, `d[i + K/2]` the maximum.
    pub d: [f32; K],
}

/// The 14-DOP (coordinate axes + corner diagonals).
pub type Kdop14 = Kdop<14>;
/// The 18-DOP (coordinate axes + edge diagonals).
pub type Kdop18 = Kdop<18>;
/// The 26-DOP (all 13 axes).
pub type Kdop26 = Kdop<26>;

/// The 13 axes, in the order of [`project13`].
const AXES: [[f32; 3]; 13] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, 0.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [1.0, -1.0, 0.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, -1.0],
];

/// Projections of `p` on the 13 axes, written as sums (no multiplications by ±1, 0).
#[inline(always)]
fn project13(p: Vec3) -> [f32; 13] {
    let (x, y, z) = (p.x, p.y, p.z);
    [
        x,
        y,
        z,
        x + y + z,
        x - y + z,
        x + y - z,
        x - y - z,
        x + y,
        x + z,
        y + z,
        x - y,
        x - z,
        y - z,
    ]
}

/// `Rᵀ axis_k` for axis `k` of [`AXES`], given `rows = Rᵀ` (whose columns are the
/// rows of `R`): `Rᵀ (a, b, c) = a·row0 + b·row1 + c·row2` with `a, b, c` in
/// `{-1, 0, 1}`, written as sums.
#[inline(always)]
fn rotated_axis(rows: &Mat3A, k: usize) -> Vec3A {
    let (x, y, z) = (rows.x_axis, rows.y_axis, rows.z_axis);
    match k {
        0 => x,
        1 => y,
        2 => z,
        3 => x + y + z,
        4 => x - y + z,
        5 => x + y - z,
        6 => x - y - z,
        7 => x + y,
        8 => x + z,
        9 => y + z,
        10 => x - y,
        11 => x - z,
        _ => y - z,
    }
}

/// `min` without NaN handling (inputs are finite): one instruction.
#[inline(always)]
fn fmin(a: f32, b: f32) -> f32 {
    if b < a {
        b
    } else {
        a
    }
}

/// `max` without NaN handling (inputs are finite).
#[inline(always)]
fn fmax(a: f32, b: f32) -> f32 {
    if b > a {
        b
    } else {
        a
    }
}

impl<const K: usize> Kdop<K> {
    const H: usize = K / 2;

    /// Evaluated (at compile time) by every method: `K` must be 14, 18 or 26.
    const SUPPORTED: () = assert!(
        K == 14 || K == 18 || K == 26,
        "Kdop supports K = 14, 18 or 26"
    );

    /// Index into [`AXES`] of slab `i` (`i < K/2`).
    #[inline(always)]
    const fn axis_index(i: usize) -> usize {
        let () = Self::SUPPORTED;
        match K {
            14 | 26 => i,
            18 => {
                if i < 3 {
                    i
                } else {
                    i + 4
                }
            }
            _ => panic!("Kdop supports K = 14, 18 or 26"),
        }
    }

    /// Slab axis `i`, not normalized, or [`Error::IndexOutOfRange`] unless
    /// `i < K/2`. O(1).
    #[inline]
    pub fn axis(i: usize) -> Result<Vec3> {
        Self::check_slab(i)?;
        Ok(Self::slab_axis(i))
    }

    #[inline]
    fn slab_axis(i: usize) -> Vec3 {
        Vec3::from_array(AXES[Self::axis_index(i)])
    }

    fn check_slab(i: usize) -> Result<()> {
        if i < Self::H {
            Ok(())
        } else {
            Err(Error::IndexOutOfRange {
                what: "k-DOP slab",
                index: i,
                len: Self::H,
            })
        }
    }

    /// `1 / |axis_i|`: 1 for the coordinate axes, `1/√3` for the corner
    /// diagonals, `1/√2` for the edge diagonals (slab widths in length units).
    #[inline(always)]
    const fn inv_len(i: usize) -> f32 {
        match Self::axis_index(i) {
            0..=2 => 1.0,
            3..=6 => 0.577_350_26,
            _ => std::f32::consts::FRAC_1_SQRT_2,
        }
    }

    /// The empty k-DOP (every interval inverted), identity of [`BoundingVolume::merge`].
    #[inline]
    pub fn empty() -> Self {
        let () = Self::SUPPORTED;
        let mut d = [f32::INFINITY; K];
        for v in d.iter_mut().skip(Self::H) {
            *v = f32::NEG_INFINITY;
        }
        Kdop { d }
    }

    /// Grows the k-DOP to contain `p`. O(K).
    #[inline]
    pub fn add_point(&mut self, p: Vec3) {
        let () = Self::SUPPORTED;
        let pr = project13(p);
        for i in 0..Self::H {
            let v = pr[Self::axis_index(i)];
            self.d[i] = fmin(self.d[i], v);
            self.d[i + Self::H] = fmax(self.d[i + Self::H], v);
        }
    }

    /// The slab interval along axis `i`, or [`Error::IndexOutOfRange`] unless
    /// `i < K/2`. O(1).
    #[inline]
    pub fn interval(&self, i: usize) -> Result<(f32, f32)> {
        Self::check_slab(i)?;
        Ok((self.d[i], self.d[i + Self::H]))
    }

    /// True if `p` satisfies every slab (closed).
    pub fn contains_point(&self, p: Vec3) -> bool {
        let pr = project13(p);
        (0..Self::H).all(|i| {
            let v = pr[Self::axis_index(i)];
            self.d[i] <= v && v <= self.d[i + Self::H]
        })
    }
}

impl<const K: usize> BoundingVolume for Kdop<K> {
    /// The slab shifts `dot(axis_i, t)` minus/plus the slack, laid out like a k-DOP:
    /// the moved interval is `[min_i + m.d[i], max_i + m.d[i + K/2]]`.
    type Motion = Kdop<K>;

    const NAME: &'static str = match K {
        14 => "kdop14",
        18 => "kdop18",
        26 => "kdop26",
        _ => "kdop",
    };

    const AXIS_ALIGNED: bool = true;

    fn from_points(points: &[Vec3]) -> Self {
        let mut k = Self::empty();
        for &p in points {
            k.add_point(p);
        }
        k
    }

    fn from_triangles(triangles: &[[Vec3; 3]]) -> Self {
        let mut k = Self::empty();
        for t in triangles {
            for &p in t {
                k.add_point(p);
            }
        }
        k
    }

    #[inline]
    fn merge(&self, o: &Self) -> Self {
        let mut d = self.d;
        for i in 0..Self::H {
            d[i] = fmin(d[i], o.d[i]);
            d[i + Self::H] = fmax(d[i + Self::H], o.d[i + Self::H]);
        }
        Kdop { d }
    }

    /// Bounds the rotated AABB part of the k-DOP (its first 3 slabs): along each
    /// axis `u`, the support of a box of centre `c` and half-extents `e` rotated by
    /// `R` is `u·(Rc + t) ± |Rᵀu|·e`. O(K), conservative.
    ///
    /// `Rᵀu` for the integer axes is a sum of rows of `R` (`rotated_axis`): no
    /// matrix product per slab (this runs once per visited node of a rotated
    /// moving tree).
    #[inline]
    fn transformed(&self, pose: &Affine3A) -> Self {
        let h = Self::H;
        let lo = Vec3A::new(self.d[0], self.d[1], self.d[2]);
        let hi = Vec3A::new(self.d[h], self.d[h + 1], self.d[h + 2]);
        let c = (lo + hi) * 0.5;
        let e = (hi - lo) * 0.5;
        let pc = project13(Vec3::from(pose.transform_point3a(c)));
        let rows = pose.matrix3.transpose();
        let mut d = [0.0; K];
        for i in 0..h {
            let k = Self::axis_index(i);
            let r = rotated_axis(&rows, k).abs().dot(e);
            d[i] = pc[k] - r;
            d[i + h] = pc[k] + r;
        }
        Kdop { d }
    }

    fn motion(pose: &Affine3A, slack: f32) -> Self::Motion {
        let s = project13(Vec3::from(pose.translation));
        let mut d = [0.0; K];
        for i in 0..Self::H {
            let v = s[Self::axis_index(i)];
            d[i] = v - slack;
            d[i + Self::H] = v + slack;
        }
        Kdop { d }
    }

    #[inline]
    fn overlaps(&self, m: &Self::Motion, o: &Self) -> bool {
        // Branch-free: K comparisons, as [sources: kdop] counts them.
        let mut sep = false;
        for i in 0..Self::H {
            sep |= self.d[i] + m.d[i] > o.d[i + Self::H];
            sep |= o.d[i] > self.d[i + Self::H] + m.d[i + Self::H];
        }
        !sep
    }

    /// The smallest overlap of the slab intervals, `min(max) - max(min)` per slab
    /// scaled by `1/|axis|`, or `-1` when a slab separates (the same comparisons
    /// as [`BoundingVolume::overlaps`]).
    #[inline]
    fn overlap_depth(&self, m: &Self::Motion, o: &Self) -> f32 {
        let h = Self::H;
        let (mut depth, mut sep) = (f32::INFINITY, false);
        for i in 0..h {
            let lo = fmax(self.d[i] + m.d[i], o.d[i]);
            let hi = fmin(self.d[i + h] + m.d[i + h], o.d[i + h]);
            sep |= lo > hi;
            depth = fmin(depth, (hi - lo) * Self::inv_len(i));
        }
        if sep {
            -1.0
        } else {
            depth
        }
    }

    #[inline]
    fn overlap_depth_fixed(&self, o: &Self) -> f32 {
        let h = Self::H;
        let (mut depth, mut sep) = (f32::INFINITY, false);
        for i in 0..h {
            let lo = fmax(self.d[i], o.d[i]);
            let hi = fmin(self.d[i + h], o.d[i + h]);
            sep |= lo > hi;
            depth = fmin(depth, (hi - lo) * Self::inv_len(i));
        }
        if sep {
            -1.0
        } else {
            depth
        }
    }

    fn inflated(&self, slack: f32) -> Self {
        let mut d = self.d;
        for i in 0..Self::H {
            d[i] -= slack;
            d[i + Self::H] += slack;
        }
        Kdop { d }
    }

    #[inline(always)]
    fn overlaps_fixed(&self, o: &Self) -> bool {
        let mut sep = false;
        for i in 0..Self::H {
            sep |= self.d[i] > o.d[i + Self::H];
            sep |= o.d[i] > self.d[i + Self::H];
        }
        !sep
    }

    #[inline]
    fn size(&self) -> f32 {
        (self.d[Self::H] - self.d[0])
            + (self.d[Self::H + 1] - self.d[1])
            + (self.d[Self::H + 2] - self.d[2])
    }

    fn ray_entry(&self, ray: &Ray, slack: f32) -> Option<f32> {
        let po = project13(ray.origin);
        let pd = project13(ray.dir);
        let (mut t0, mut t1) = (0.0f32, ray.max_t);
        for i in 0..Self::H {
            let a = Self::axis_index(i);
            if !clip_slab(
                po[a],
                pd[a],
                self.d[i] - slack,
                self.d[i + Self::H] + slack,
                &mut t0,
                &mut t1,
            ) {
                return None;
            }
        }
        Some(t0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat3;

    #[test]
    fn axes_are_distinct_and_cover_the_seed_lists() {
        assert_eq!(Kdop14::axis(3), Ok(Vec3::new(1.0, 1.0, 1.0)));
        assert_eq!(Kdop18::axis(3), Ok(Vec3::new(1.0, 1.0, 0.0)));
        assert_eq!(Kdop18::axis(8), Ok(Vec3::new(0.0, 1.0, -1.0)));
        assert_eq!(Kdop26::axis(12), Ok(Vec3::new(0.0, 1.0, -1.0)));
        // Out of range: a typed error, not a panic.
        assert!(matches!(
            Kdop14::axis(7),
            Err(crate::Error::IndexOutOfRange {
                index: 7,
                len: 7,
                ..
            })
        ));
        let mut k = Kdop18::empty();
        k.add_point(Vec3::ONE);
        assert_eq!(k.interval(0), Ok((1.0, 1.0)));
        assert!(k.interval(9).is_err());
        let p = Vec3::new(0.3, -1.7, 2.5);
        for (i, axis) in AXES.iter().enumerate() {
            assert_eq!(project13(p)[i], Vec3::from_array(*axis).dot(p));
        }
    }

    #[test]
    fn fit_contains_points_and_translation_shift_matches_refit() {
        let pts = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 2.0, 0.5),
            Vec3::new(-1.0, 0.5, 3.0),
        ];
        let k = Kdop18::from_points(&pts);
        assert!(pts.iter().all(|&p| k.contains_point(p)));
        let t = Vec3::new(5.0, -2.0, 1.0);
        let moved: Vec<Vec3> = pts.iter().map(|&p| p + t).collect();
        let km = Kdop18::from_points(&moved);
        let m = Kdop18::motion(&Affine3A::from_translation(t), 0.0);
        for i in 0..9 {
            assert!((k.d[i] + m.d[i] - km.d[i]).abs() < 1e-5);
            assert!((k.d[i + 9] + m.d[i + 9] - km.d[i + 9]).abs() < 1e-5);
        }
        // Touching k-DOPs overlap (closed); separated ones do not.
        let a = Kdop14::from_points(&[Vec3::ZERO, Vec3::ONE]);
        let b = Kdop14::from_points(&[Vec3::ONE, Vec3::splat(2.0)]);
        let id = Kdop14::motion(&Affine3A::IDENTITY, 0.0);
        assert!(a.overlaps(&id, &b));
        let tri = Kdop14::from_points(&[Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z]);
        let corner = Kdop14::from_points(&[Vec3::new(0.9, 0.9, 0.9)]);
        // Inside the AABB of the corner tetrahedron, outside its x+y+z <= 1 slab.
        assert!(!tri.overlaps(&id, &corner));
        let aabb_only = crate::geom::Aabb::from_points(&[Vec3::ZERO, Vec3::ONE]);
        assert!(aabb_only.overlaps(
            &crate::geom::Aabb::motion(&Affine3A::IDENTITY, 0.0),
            &crate::geom::Aabb::from_points(&[Vec3::new(0.9, 0.9, 0.9)])
        ));
    }

    #[test]
    fn transformed_bounds_the_rotated_box_part() {
        let pts = [
            Vec3::new(0.3, -1.0, 2.0),
            Vec3::new(1.5, 0.2, -0.7),
            Vec3::new(-0.4, 0.9, 0.1),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let q = glam::Quat::from_axis_angle(Vec3::new(0.3, -0.8, 0.5).normalize(), 1.1);
        let pose = Affine3A::from_rotation_translation(q, Vec3::new(4.0, -2.0, 0.5));
        fn check<const K: usize>(pts: &[Vec3], pose: &Affine3A) {
            let k = Kdop::<K>::from_points(pts);
            let t = k.transformed(pose);
            // Every rotated point (and every rotated corner of the AABB part) inside.
            let (lo, hi) = (
                Vec3::new(k.d[0], k.d[1], k.d[2]),
                Vec3::new(k.d[K / 2], k.d[K / 2 + 1], k.d[K / 2 + 2]),
            );
            let corners = (0..8).map(|c| {
                Vec3::select(glam::BVec3::new(c & 1 != 0, c & 2 != 0, c & 4 != 0), hi, lo)
            });
            for p in pts.iter().copied().chain(corners) {
                assert!(t.inflated(1e-5).contains_point(pose.transform_point3(p)));
            }
            // And each slab is the support of the rotated box: `u·(Rc + t) ± |Rᵀu|·e`
            // with `Rᵀu` as a matrix product.
            let (c, e) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
            for i in 0..K / 2 {
                let u = Kdop::<K>::axis(i).unwrap();
                let m = u.dot(pose.transform_point3(c));
                let r = (Mat3::from(pose.matrix3).transpose() * u).abs().dot(e);
                assert!((t.d[i] - (m - r)).abs() < 1e-5, "{K} {i}");
                assert!((t.d[i + K / 2] - (m + r)).abs() < 1e-5, "{K} {i}");
            }
        }
        check::<14>(&pts, &pose);
        check::<18>(&pts, &pose);
        check::<26>(&pts, &pose);
    }
}
