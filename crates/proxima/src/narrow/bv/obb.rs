//! Oriented bounding boxes (Gottschalk, Lin, Manocha: "OBBTree"; [sources: bv-kinds]).

// Index loops read like the matrix formulas they implement.
#![allow(clippy::needless_range_loop)]

use super::{clip_slab, positive, BoundingVolume};
use crate::geom::Ray;
use glam::{Affine3A, Mat3, Mat3A, Vec3, Vec3A, Vec3Swizzles};

/// An oriented box: `center + axes * u` for `|u_i| <= half[i]`, `axes` orthonormal
/// (columns). Fitted by principal component analysis (the triangle-area covariance of
/// OBBTree, or the point covariance), falling back to the world axes when the AABB is
/// smaller. Overlap is the 15-axis separating-axis test under the relative pose, so a
/// rotation costs nothing but the test itself ([sources: bvh-cost]: OBBs trade a costlier `Cv`
/// for a tight fit and free updates).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Obb {
    /// Centre.
    pub center: Vec3,
    /// Orthonormal axes (columns).
    pub axes: Mat3,
    /// Half-extents along the axes, `>= 0`.
    pub half: Vec3,
}

impl Obb {
    /// The box with the given axes that bounds `points` (non-empty). O(points).
    /// Finite for every finite point set bounded along the axes within the `f32`
    /// range (an extent wider than `f32::MAX` is halved before it is formed).
    pub fn with_axes(axes: Mat3, points: impl Iterator<Item = Vec3>) -> Obb {
        let at = axes.transpose();
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in points {
            let q = at * p;
            lo = lo.min(q);
            hi = hi.max(q);
        }
        let (mut mid, mut half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        if !(mid.is_finite() && half.is_finite()) {
            // The sum or difference overflowed (extents near `f32::MAX`): halving
            // first is exact at these magnitudes (it only rounds subnormals).
            (mid, half) = (lo * 0.5 + hi * 0.5, hi * 0.5 - lo * 0.5);
        }
        Obb {
            center: axes * mid,
            axes,
            half,
        }
    }

    /// This box moved by the motion `m`, seen in `o`'s frame: the matrix whose
    /// column `j` is this box's axis `j` (so `c.col(j)[i] = b_i · a_j`), and the
    /// centre offset. The common start of both separating-axis tests.
    #[inline(always)]
    fn in_frame_of(&self, m: &<Obb as BoundingVolume>::Motion, o: &Obb) -> (Mat3A, Vec3A) {
        let (rot, tr, _) = *m;
        let bt = Mat3A::from(o.axes).transpose();
        let c = bt * (rot * Mat3A::from(self.axes));
        let ca = rot * Vec3A::from(self.center) + tr;
        (c, bt * (ca - Vec3A::from(o.center)))
    }

    /// The 8 corners.
    pub fn corners(&self) -> [Vec3; 8] {
        let mut out = [Vec3::ZERO; 8];
        for (i, o) in out.iter_mut().enumerate() {
            let s = Vec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            *o = self.center + self.axes * (s * self.half);
        }
        out
    }

    fn volume(&self) -> f32 {
        self.half.x * self.half.y * self.half.z
    }

    /// PCA box of `points` for covariance `cov`, or the AABB if that is smaller.
    fn fit(cov: Mat3, points: &[Vec3]) -> Obb {
        let axes = eigenvectors(cov);
        let pca = Obb::with_axes(axes, points.iter().copied());
        let aabb = Obb::with_axes(Mat3::IDENTITY, points.iter().copied());
        if aabb.volume() <= pca.volume() {
            aabb
        } else {
            pca
        }
    }
}

/// Covariance of a point set.
fn point_covariance(points: &[Vec3]) -> Mat3 {
    let n = points.len() as f32;
    let mean = points.iter().copied().sum::<Vec3>() / n;
    let mut c = Mat3::ZERO;
    for &p in points {
        let d = p - mean;
        c += outer(d, d);
    }
    c * (1.0 / n)
}

#[inline]
fn outer(a: Vec3, b: Vec3) -> Mat3 {
    Mat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Eigenvectors (columns, right-handed, orthonormal) of a symmetric 3×3 matrix by
/// cyclic Jacobi rotations (in f64). Any orthonormal basis is a valid OBB frame, so
/// this never fails; it only affects tightness.
fn eigenvectors(m: Mat3) -> Mat3 {
    let mut a = [[0.0f64; 3]; 3];
    for (i, row) in a.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = m.col(j)[i] as f64;
        }
    }
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0f64]];
    for _sweep in 0..16 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let diag = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off <= 1e-12 * diag || off == 0.0 || !off.is_finite() {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A <- Jᵀ A J with the rotation J in the (p, q) plane.
            for k in 0..3 {
                let (akp, akq) = (a[k][p], a[k][q]);
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let (apk, aqk) = (a[p][k], a[q][k]);
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in v.iter_mut() {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let col = |j: usize| Vec3::new(v[0][j] as f32, v[1][j] as f32, v[2][j] as f32);
    // Re-orthonormalize in f32 (Gram–Schmidt) and make the frame right-handed.
    let x = col(0).normalize_or(Vec3::X);
    let y = (col(1) - x * x.dot(col(1))).normalize_or(x.any_orthonormal_vector());
    let z = x.cross(y);
    Mat3::from_cols(x, y, z)
}

impl BoundingVolume for Obb {
    /// Rotation, translation, slack.
    type Motion = (Mat3A, Vec3A, f32);

    const NAME: &'static str = "obb";
    const AXIS_ALIGNED: bool = false;

    fn from_points(points: &[Vec3]) -> Self {
        Obb::fit(point_covariance(points), points)
    }

    /// OBBTree's fit: the covariance of the triangles' surfaces (area-weighted, so
    /// that dense vertex clusters do not bias the axes); point covariance if the
    /// total area is zero.
    fn from_triangles(triangles: &[[Vec3; 3]]) -> Self {
        let pts: Vec<Vec3> = triangles.iter().flatten().copied().collect();
        let mut area = 0.0f32;
        let mut mean = Vec3::ZERO;
        let mut second = Mat3::ZERO;
        for &[p, q, r] in triangles {
            let a = (q - p).cross(r - p).length() * 0.5;
            let m = (p + q + r) / 3.0;
            area += a;
            mean += m * a;
            second += (outer(m, m) * 9.0 + outer(p, p) + outer(q, q) + outer(r, r)) * (a / 12.0);
        }
        if area.is_nan() || area <= 0.0 || !area.is_finite() {
            return Self::from_points(&pts);
        }
        mean /= area;
        let cov = second * (1.0 / area) - outer(mean, mean);
        Obb::fit(cov, &pts)
    }

    fn merge(&self, o: &Self) -> Self {
        let mut pts = [Vec3::ZERO; 16];
        pts[..8].copy_from_slice(&self.corners());
        pts[8..].copy_from_slice(&o.corners());
        let a = Obb::with_axes(self.axes, pts.iter().copied());
        let b = Obb::with_axes(o.axes, pts.iter().copied());
        let c = Self::from_points(&pts);
        [a, b, c]
            .into_iter()
            .min_by(|x, y| x.volume().total_cmp(&y.volume()))
            .unwrap_or(c)
    }

    fn refit_points(&self, points: &[Vec3]) -> Self {
        Obb::with_axes(self.axes, points.iter().copied())
    }

    fn refit_parent(&self, left: &Self, right: &Self) -> Self {
        Obb::with_axes(self.axes, left.corners().into_iter().chain(right.corners()))
    }

    fn transformed(&self, pose: &Affine3A) -> Self {
        Obb {
            center: pose.transform_point3(self.center),
            axes: Mat3::from(pose.matrix3) * self.axes,
            half: self.half,
        }
    }

    fn motion(pose: &Affine3A, slack: f32) -> Self::Motion {
        (pose.matrix3, pose.translation, slack)
    }

    /// The 15-axis separating-axis test (3 + 3 face normals, 9 edge cross products),
    /// every bound enlarged by the slack (which also covers near-parallel edges,
    /// whose cross product is almost zero).
    #[inline]
    fn overlaps(&self, m: &Self::Motion, o: &Self) -> bool {
        let slack = m.2;
        let (c, t) = self.in_frame_of(m, o);
        let (a, b) = (Vec3A::from(self.half), Vec3A::from(o.half));
        let c0 = c.x_axis;
        let c1 = c.y_axis;
        let c2 = c.z_axis;
        let a0 = c0.abs();
        let a1 = c1.abs();
        let a2 = c2.abs();
        // B's axes: |t_i| > b_i + sum_j a_j |c_ij|.
        let ra = a0 * a.x + a1 * a.y + a2 * a.z;
        if t.abs().cmpgt(b + ra + Vec3A::splat(slack)).any() {
            return false;
        }
        // A's axes: |t · c_j| > a_j + sum_i b_i |c_ij|.
        let tj = Vec3A::new(t.dot(c0), t.dot(c1), t.dot(c2));
        let rb = Vec3A::new(a0.dot(b), a1.dot(b), a2.dot(b));
        if tj.abs().cmpgt(a + rb + Vec3A::splat(slack)).any() {
            return false;
        }
        // Edge pairs L = b_i × a_j.
        let ab = [a0, a1, a2];
        let cc = [c0, c1, c2];
        for j in 0..3 {
            let (aj1, aj2) = ((j + 1) % 3, (j + 2) % 3);
            let (cj, absj) = (cc[j], ab[j]);
            // i = 0: L = b0 × a_j ; |t2 c1j - t1 c2j| > b1|c2j| + b2|c1j| + a_j1|c0,j2| + a_j2|c0,j1|
            for i in 0..3 {
                let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
                let lhs = (t[i2] * cj[i1] - t[i1] * cj[i2]).abs();
                let rhs_b = b[i1] * absj[i2] + b[i2] * absj[i1];
                let rhs_a = a[aj1] * ab[aj2][i] + a[aj2] * ab[aj1][i];
                if lhs > rhs_a + rhs_b + slack {
                    return false;
                }
            }
        }
        true
    }

    /// The largest gap over the 15 separating axes of [`BoundingVolume::overlaps`]
    /// (each a lower bound on the boxes' distance), the slack subtracted. The 9
    /// edge axes `b_i × a_j` are not unit (`sqrt(1 - (b_i · a_j)²)` for a true
    /// rotation): their gap is divided by the length, computed from the moved axes
    /// and slightly overestimated so that the bound stays a bound, and
    /// axes shorter than 0.05 (nearly parallel edges, where rounding dominates)
    /// are skipped.
    #[inline]
    fn distance_lower_bound(&self, m: &Self::Motion, o: &Self) -> f32 {
        let slack = m.2;
        let (c, t) = self.in_frame_of(m, o);
        let (a, b) = (Vec3A::from(self.half), Vec3A::from(o.half));
        let cc = [c.x_axis, c.y_axis, c.z_axis];
        let ab = cc.map(|v| v.abs());
        // B's axes, then A's: unit vectors.
        let ra = ab[0] * a.x + ab[1] * a.y + ab[2] * a.z;
        let tj = Vec3A::new(t.dot(cc[0]), t.dot(cc[1]), t.dot(cc[2]));
        let rb = Vec3A::new(ab[0].dot(b), ab[1].dot(b), ab[2].dot(b));
        let mut best = (t.abs() - b - ra).max(tj.abs() - a - rb).max_element() - slack;
        // Edge axes e_i × c_j (in B's frame), the three i at once per j: the
        // projection of t is (t × c_j)_i; B's radius b_i1 |c_j,i2| + b_i2 |c_j,i1|;
        // A's radius a_j1 |c_j2,i| + a_j2 |c_j1,i|; the squared length
        // |c_j|² - c_j,i² (exact for a pose that is not quite a rotation).
        let (by, bz) = (b.yzx(), b.zxy());
        for j in 0..3 {
            let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
            let cj = cc[j];
            let lhs = t.cross(cj).abs();
            let rhs = by * ab[j].zxy() + bz * ab[j].yzx() + ab[j2] * a[j1] + ab[j1] * a[j2];
            let len2 = Vec3A::splat(cj.length_squared()) - cj * cj;
            // Slack first, then the division: the smaller (sound) bound; axes
            // shorter than 0.05 (near-parallel edges) are skipped.
            let gap = lhs - rhs - Vec3A::splat(slack);
            let ok = gap.cmpgt(Vec3A::ZERO) & len2.cmpge(Vec3A::splat(0.0025));
            if ok.any() {
                // gap / |L| through its square: one square root for the three;
                // three where the square overflows (gaps beyond √f32::MAX).
                let q2 = Vec3A::select(ok, gap * gap / len2, Vec3A::ZERO).max_element();
                let q = if q2 <= f32::MAX {
                    q2.sqrt()
                } else {
                    (0..3)
                        .filter(|&i| ok.bitmask() & (1 << i) != 0)
                        .map(|i| gap[i] / len2[i].sqrt())
                        .fold(0.0f32, f32::max)
                        .min(f32::MAX)
                };
                best = best.max(q * (1.0 / 1.001));
            }
        }
        positive(best)
    }

    fn inflated(&self, slack: f32) -> Self {
        Obb {
            half: self.half + Vec3::splat(slack),
            ..*self
        }
    }

    #[inline]
    fn size(&self) -> f32 {
        2.0 * (self.half.x + self.half.y + self.half.z)
    }

    fn ray_entry(&self, ray: &Ray, slack: f32) -> Option<f32> {
        let at = self.axes.transpose();
        let o = at * (ray.origin - self.center);
        let d = at * ray.dir;
        let (mut t0, mut t1) = (0.0f32, ray.max_t);
        for k in 0..3 {
            if !clip_slab(
                o[k],
                d[k],
                -self.half[k] - slack,
                self.half[k] + slack,
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

    #[test]
    fn eigenvectors_of_a_diagonal_and_a_rotated_matrix() {
        let e = eigenvectors(Mat3::from_diagonal(Vec3::new(3.0, 1.0, 2.0)));
        assert!((e.determinant() - 1.0).abs() < 1e-5);
        let r = Mat3::from_rotation_y(0.4) * Mat3::from_rotation_x(0.3);
        let m = r * Mat3::from_diagonal(Vec3::new(5.0, 2.0, 0.5)) * r.transpose();
        let e = eigenvectors(m);
        // Each eigenvector is parallel to a column of r.
        for j in 0..3 {
            let best = (0..3)
                .map(|k| e.col(j).dot(r.col(k)).abs())
                .fold(0.0f32, f32::max);
            assert!(best > 0.999, "{best}");
        }
    }

    #[test]
    fn fitted_box_contains_its_points_and_sat_agrees_on_simple_cases() {
        let r = Mat3::from_rotation_z(0.7);
        let pts: Vec<Vec3> = (0..50)
            .map(|i| {
                let f = i as f32;
                r * Vec3::new(
                    (f * 0.37).sin() * 4.0,
                    (f * 0.91).cos(),
                    (f * 0.13).sin() * 0.2,
                )
            })
            .collect();
        let b = Obb::from_points(&pts);
        for &p in &pts {
            let q = b.axes.transpose() * (p - b.center);
            assert!(q.abs().cmple(b.half + Vec3::splat(1e-4)).all());
        }
        let id = Obb::motion(&Affine3A::IDENTITY, 0.0);
        let unit = Obb::with_axes(Mat3::IDENTITY, [Vec3::ZERO, Vec3::ONE].into_iter());
        // A unit cube rotated 45° about z, centred at x = 1.5 + √2/2 - tiny: touches.
        let rz = Mat3::from_rotation_z(std::f32::consts::FRAC_PI_4);
        let pose = |x: f32| {
            Obb::motion(
                &Affine3A::from_mat3_translation(rz, Vec3::new(x, 0.5, 0.5)),
                1e-5,
            )
        };
        let centred = Obb::with_axes(
            Mat3::IDENTITY,
            [Vec3::splat(-0.5), Vec3::splat(0.5)].into_iter(),
        );
        let h = std::f32::consts::FRAC_1_SQRT_2;
        assert!(centred.overlaps(&pose(1.0 + h - 1e-3), &unit));
        assert!(!centred.overlaps(&pose(1.0 + h + 1e-2), &unit));
        assert!(unit.overlaps(&id, &unit));
    }
}
