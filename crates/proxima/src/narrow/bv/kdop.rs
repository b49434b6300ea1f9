//! k-DOPs (discrete orientation polytopes) with K = 14, 18, 26 [sources: kdop].

use super::{clip_slab, wide_gap, BoundingVolume};
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

    /// Triples of slabs with mutually orthogonal axes ("frames"): within a
    /// frame the slab gaps are the coordinates of a box gap in a rotated basis,
    /// so their Euclidean norm bounds the distance. The 18- and 26-DOP have four
    /// (the coordinate axes; each edge-diagonal pair `(1,±1,0)`, `(1,0,±1)`,
    /// `(0,1,±1)` with the remaining coordinate axis), the 14-DOP only the first.
    const FRAMES: &'static [[usize; 3]] = match K {
        18 => &[[0, 1, 2], [3, 6, 2], [4, 7, 1], [5, 8, 0]],
        26 => &[[0, 1, 2], [7, 10, 2], [8, 11, 1], [9, 12, 0]],
        _ => &[[0, 1, 2]],
    };

    /// The slabs in no frame (the corner diagonals of the 14- and 26-DOP), each
    /// bounding the distance alone.
    const SINGLES: std::ops::Range<usize> = match K {
        18 => 3..3,
        _ => 3..7,
    };

    /// The distance lower bound of `self` shifted by `m` (a [`BoundingVolume::motion`],
    /// or no shift) and `o`: the largest over the [`Kdop::FRAMES`] of the
    /// Euclidean norm of their three slab gaps (each divided by its axis'
    /// length; the first frame is the boxes' distance), and over the other
    /// slabs of their gap divided by their axis' length. Each is a lower bound
    /// on the distance of the contents (the distance of two sets is at least
    /// that of their boxes in any orthonormal basis); on W5's bunny × bunny
    /// the diagonal frames raise the bound of the pairs the descent visits
    /// (see `BENCHMARKS.md`, W5 distance). Written as plain loops over the
    /// slabs (no NaN-aware `max`, no zero shift added) because it runs once per
    /// volume pair; a result that overflowed or is NaN is computed again in
    /// `f64` ([`wide_gap`], with the coordinate frame and single slabs only).
    #[inline(always)]
    fn gap(&self, m: Option<&[f32; K]>, o: &Self) -> f32 {
        let h = Self::H;
        // Slab `i` of `self` (moved) and of `o`.
        let slab = |i: usize| {
            let (lo, hi) = match m {
                Some(m) => (self.d[i] + m[i], self.d[i + h] + m[i + h]),
                None => (self.d[i], self.d[i + h]),
            };
            (lo, hi, o.d[i], o.d[i + h])
        };
        // Squared scaled gaps (`0` where the slabs overlap; NaN stays NaN).
        let mut q = [0.0f32; K];
        let mut total = 0.0f32;
        for (i, qi) in q.iter_mut().enumerate().take(h) {
            let (lo, hi, lo_o, hi_o) = slab(i);
            let g = fmax(fmax(lo_o - hi, lo - hi_o), 0.0) * Self::inv_len(i);
            *qi = g * g;
            total += *qi;
        }
        let mut r2 = 0.0f32;
        for f in Self::FRAMES {
            r2 = fmax(r2, q[f[0]] + q[f[1]] + q[f[2]]);
        }
        for i in Self::SINGLES {
            r2 = fmax(r2, q[i]);
        }
        if total <= f32::MAX {
            r2.sqrt()
        } else {
            // Overflowed (gaps beyond √f32::MAX) or NaN (infinite interval ends).
            wide_gap(slab, h, Self::inv_len)
        }
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

    /// Bounds the rotated k-DOP by the intersection of its rotated frame boxes
    /// (the coordinate box, and for the 18- and 26-DOP the boxes of the three
    /// frames of orthogonal slabs `(1,±1,0)` and `z`, `(1,0,±1)` and `y`,
    /// `(0,1,±1)` and `x`, each containing the k-DOP) [sources: kdop]:
    /// along each axis `u`, the support of a box of centre `c` and half-extents
    /// `e_j` along the unit axes `v_j`, rotated by `R`, is
    /// `u·(Rc + t) ± Σ_j |(Rᵀu)·v_j|·e_j`. O(K) per frame, conservative. The
    /// diagonal frames cut the corners of the rotated coordinate box (W5
    /// bunny × bunny distance, k-DOP18: see `BENCHMARKS.md`, W5 distance).
    ///
    /// `Rᵀu` for the integer axes is a sum of rows of `R` (`rotated_axis`): no
    /// matrix product per slab (this runs once per visited node of a rotated
    /// moving tree).
    #[inline]
    fn transformed_tight(&self, pose: &Affine3A) -> Self {
        let h = Self::H;
        let rows = pose.matrix3.transpose();
        let ru: [Vec3A; K] = std::array::from_fn(|i| {
            if i < h {
                rotated_axis(&rows, Self::axis_index(i))
            } else {
                Vec3A::ZERO
            }
        });
        // The intersection of the frames' bounds: lows from -∞, highs from +∞.
        let mut d = [f32::INFINITY; K];
        for v in d.iter_mut().take(h) {
            *v = f32::NEG_INFINITY;
        }
        for f in Self::FRAMES {
            // Frame slab `j` is `lo_j <= a_j·p <= hi_j` with the integer axis
            // `a_j = |a_j| v_j`: centre `Σ_j (lo_j + hi_j)/2 · a_j / |a_j|²`,
            // half-extent `(hi_j - lo_j)/2 / |a_j|` along `v_j`; below, `w_j` is
            // `1/|a_j|²` and `(Rᵀu)·v_j · e_j = (Rᵀu)·a_j · (hi_j - lo_j)/2 · w_j`.
            let mut c = Vec3A::ZERO;
            let mut a = [Vec3A::ZERO; 3];
            let mut e = [0.0f32; 3];
            for j in 0..3 {
                let s = f[j];
                let w = Self::inv_len(s) * Self::inv_len(s);
                a[j] = Vec3A::from(Self::slab_axis(s));
                c += a[j] * ((self.d[s] + self.d[s + h]) * 0.5 * w);
                e[j] = (self.d[s + h] - self.d[s]) * 0.5 * w;
            }
            let pc = project13(Vec3::from(pose.transform_point3a(c)));
            for i in 0..h {
                let r = ru[i].dot(a[0]).abs() * e[0]
                    + ru[i].dot(a[1]).abs() * e[1]
                    + ru[i].dot(a[2]).abs() * e[2];
                let k = pc[Self::axis_index(i)];
                d[i] = fmax(d[i], k - r);
                d[i + h] = fmin(d[i + h], k + r);
            }
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

    #[inline]
    fn distance_lower_bound(&self, m: &Self::Motion, o: &Self) -> f32 {
        self.gap(Some(&m.d), o)
    }

    #[inline]
    fn distance_lower_bound_fixed(&self, o: &Self) -> f32 {
        self.gap(None, o)
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
    fn distance_bound_combines_orthogonal_slabs() {
        // A segment along (1,-1,0) and its copy moved by (1,1,1): the boxes
        // overlap in x and y, so the box bound is 1 (z) and the best single
        // edge-diagonal slab gives √2; the frame of (1,1,0), (1,-1,0) and z
        // gives the distance, √3 (the segments are parallel, the offset
        // orthogonal to them).
        let a = [Vec3::new(-1.0, 1.0, 0.0), Vec3::new(1.0, -1.0, 0.0)];
        let b = a.map(|p| p + Vec3::ONE);
        let truth = 3f32.sqrt();
        let m = |slack| Kdop18::motion(&Affine3A::IDENTITY, slack);
        let (ka, kb) = (Kdop18::from_points(&a), Kdop18::from_points(&b));
        assert!((ka.distance_lower_bound_fixed(&kb) - truth).abs() < 1e-6);
        assert!((ka.distance_lower_bound(&m(0.0), &kb) - truth).abs() < 1e-6);
        // The slack lowers it; the 26-DOP has the same frame.
        assert!(ka.distance_lower_bound(&m(0.01), &kb) < truth - 0.005);
        let (ka, kb) = (Kdop26::from_points(&a), Kdop26::from_points(&b));
        assert!((ka.distance_lower_bound_fixed(&kb) - truth).abs() < 1e-6);
    }

    #[test]
    fn transformed_bounds_the_rotated_frame_boxes() {
        let pts = [
            Vec3::new(0.3, -1.0, 2.0),
            Vec3::new(1.5, 0.2, -0.7),
            Vec3::new(-0.4, 0.9, 0.1),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let q = glam::Quat::from_axis_angle(Vec3::new(0.3, -0.8, 0.5).normalize(), 1.1);
        let pose = Affine3A::from_rotation_translation(q, Vec3::new(4.0, -2.0, 0.5));
        // Returns how much the diagonal frames tightened the coordinate box's
        // bound (summed over the slabs).
        fn check<const K: usize>(pts: &[Vec3], pose: &Affine3A) -> f32 {
            let h = K / 2;
            let k = Kdop::<K>::from_points(pts);
            let t = k.transformed_tight(pose);
            let cheap = k.transformed(pose);
            // Every rotated point inside both.
            for p in pts {
                assert!(t.inflated(1e-5).contains_point(pose.transform_point3(*p)));
                assert!(cheap
                    .inflated(1e-5)
                    .contains_point(pose.transform_point3(*p)));
            }
            // Each slab is the intersection over the frames of the support of the
            // rotated frame box, `u·(Rc + t) ± Σ_j |(Rᵀu)·v_j| e_j` with `Rᵀu` as
            // a matrix product and the unit axes `v_j`.
            let rt = Mat3::from(pose.matrix3).transpose();
            let (mut lo, mut hi) = ([f32::MIN; 13], [f32::MAX; 13]);
            let mut gain = 0.0;
            for (n, f) in Kdop::<K>::FRAMES.iter().enumerate() {
                let v = f.map(|s| Kdop::<K>::axis(s).unwrap().normalize());
                let len = f.map(|s| Kdop::<K>::axis(s).unwrap().length());
                let mid = |j: usize| (k.d[f[j]] + k.d[f[j] + h]) * 0.5 / len[j];
                let c = v[0] * mid(0) + v[1] * mid(1) + v[2] * mid(2);
                let e = |j: usize| (k.d[f[j] + h] - k.d[f[j]]) * 0.5 / len[j];
                for i in 0..h {
                    let u = Kdop::<K>::axis(i).unwrap();
                    let m = u.dot(pose.transform_point3(c));
                    let ru = rt * u;
                    let r = (0..3).map(|j| ru.dot(v[j]).abs() * e(j)).sum::<f32>();
                    if n > 0 {
                        gain += (lo[i].max(m - r) - lo[i]) + (hi[i] - hi[i].min(m + r));
                    }
                    lo[i] = lo[i].max(m - r);
                    hi[i] = hi[i].min(m + r);
                }
                // `transformed` is the coordinate frame's bound alone.
                if n == 0 {
                    for i in 0..h {
                        assert!((cheap.d[i] - lo[i]).abs() < 1e-5, "{K} {i}");
                        assert!((cheap.d[i + h] - hi[i]).abs() < 1e-5, "{K} {i}");
                    }
                }
            }
            for i in 0..h {
                assert!((t.d[i] - lo[i]).abs() < 1e-5, "{K} {i}");
                assert!((t.d[i + h] - hi[i]).abs() < 1e-5, "{K} {i}");
            }
            gain
        }
        assert_eq!(check::<14>(&pts, &pose), 0.0);
        // The diagonal frames cut the rotated coordinate box here.
        assert!(check::<18>(&pts, &pose) > 0.1);
        assert!(check::<26>(&pts, &pose) > 0.1);
    }
}
