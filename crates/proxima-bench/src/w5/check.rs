//! W5 oracles: brute-force all triangle pairs with the exact test, and the exact
//! verification of every disagreement with parry.

use proxima::glam::{Affine3A, Vec3};
use proxima::narrow::{triangles_intersect, TriMesh};

/// The corners of triangle `i` of `m` moved by `pose`, exactly as the collision
/// queries compute them (`transform_point3` of each vertex).
pub fn moved(m: &TriMesh, pose: &Affine3A, i: usize) -> [Vec3; 3] {
    m.triangle(i).map(|p| pose.transform_point3(p))
}

/// Every intersecting pair `(i, j)`, by testing all `|a| * |b|` pairs with the
/// exact (unprepared) `triangles_intersect`. Sorted.
pub fn brute_pairs(a: &TriMesh, pose: &Affine3A, b: &TriMesh) -> Vec<(u32, u32)> {
    let tb: Vec<[Vec3; 3]> = (0..b.len()).map(|j| b.triangle(j)).collect();
    let mut out = Vec::new();
    for i in 0..a.len() {
        let ta = moved(a, pose, i);
        for (j, t) in tb.iter().enumerate() {
            if triangles_intersect(&ta, t) {
                out.push((i as u32, j as u32));
            }
        }
    }
    out
}

/// What an exact check says about parry's answers on one pose.
#[derive(Clone, Copy, Debug, Default)]
pub struct Disagreements {
    /// Poses where parry's boolean differs from our first-contact answer.
    pub bool_poses: usize,
    /// Triangle pairs only parry reports (all-pairs mode).
    pub parry_only: usize,
    /// Triangle pairs only we report.
    pub ours_only: usize,
    /// Disagreements where our exact test did NOT confirm our answer (must be 0).
    pub unverified: usize,
    /// Largest distance (parry's own `query::distance`) between the triangles of
    /// a pair only parry reports: how far its tolerance reaches.
    pub parry_only_max_gap: f32,
    /// Pairs only parry reports that its own distance query puts apart (> 0).
    pub parry_only_apart: usize,
}

/// Compares parry's all pairs with ours (both sorted) on one pose, and checks each
/// pair in the symmetric difference with the exact test on our moved corners:
/// a pair only we report must intersect, a pair only parry reports must not.
/// Returns the pairs only parry reports.
pub fn compare_pairs(
    a: &TriMesh,
    pose: &Affine3A,
    b: &TriMesh,
    ours: &[(u32, u32)],
    parry: &[(u32, u32)],
    d: &mut Disagreements,
) -> Vec<(u32, u32)> {
    let exact = |&(i, j): &(u32, u32)| {
        triangles_intersect(&moved(a, pose, i as usize), &b.triangle(j as usize))
    };
    let mut only = Vec::new();
    for p in parry.iter().filter(|p| ours.binary_search(p).is_err()) {
        d.parry_only += 1;
        d.unverified += exact(p) as usize;
        only.push(*p);
    }
    for p in ours.iter().filter(|p| parry.binary_search(p).is_err()) {
        d.ours_only += 1;
        d.unverified += !exact(p) as usize;
    }
    only
}

/// The number of triangle pairs `(i, j)` that do not intersect (exact test) but
/// lie within `tol` of each other: the pairs a library with a touching tolerance
/// may report on top of ours. Candidates are the pairs whose boxes come within
/// `tol` (a sweep over `x`); their distance is parry's `query::distance` between
/// the two triangles, allowed the rounding of its `f32` evaluation
/// (`16 ε` times the largest coordinate). O((|a| + |b|) log + candidates).
pub fn near_pairs(a: &TriMesh, pose: &Affine3A, b: &TriMesh, tol: f32) -> usize {
    use parry3d::math::{Pose, Vector};
    use parry3d::shape::Triangle;
    let ta: Vec<[Vec3; 3]> = (0..a.len()).map(|i| moved(a, pose, i)).collect();
    let tb: Vec<[Vec3; 3]> = (0..b.len()).map(|j| b.triangle(j)).collect();
    let boxes = |t: &[[Vec3; 3]]| -> Vec<(Vec3, Vec3)> {
        t.iter()
            .map(|c| (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2])))
            .collect()
    };
    let (ba, bb) = (boxes(&ta), boxes(&tb));
    // One list of (min x, side, index), swept in order of min x.
    let mut events: Vec<(f32, bool, u32)> = ba
        .iter()
        .enumerate()
        .map(|(i, b)| (b.0.x, false, i as u32))
        .chain(bb.iter().enumerate().map(|(j, b)| (b.0.x, true, j as u32)))
        .collect();
    events.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    let (mut open_a, mut open_b): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
    let tri = |c: &[Vec3; 3]| {
        let v = |p: Vec3| Vector::new(p.x, p.y, p.z);
        Triangle::new(v(c[0]), v(c[1]), v(c[2]))
    };
    let mut n = 0;
    for (x, side_b, k) in events {
        let (open_self, open_other, own, other) = if side_b {
            (&mut open_b, &mut open_a, &bb, &ba)
        } else {
            (&mut open_a, &mut open_b, &ba, &bb)
        };
        open_other.retain(|&o| other[o as usize].1.x + tol >= x);
        let me = own[k as usize];
        for &o in open_other.iter() {
            let ob = other[o as usize];
            if !((me.0 - Vec3::splat(tol)).cmple(ob.1).all()
                && (ob.0 - Vec3::splat(tol)).cmple(me.1).all())
            {
                continue;
            }
            let (i, j) = if side_b { (o, k) } else { (k, o) };
            let (p, q) = (&ta[i as usize], &tb[j as usize]);
            if triangles_intersect(p, q) {
                continue;
            }
            let m = p
                .iter()
                .chain(q)
                .map(|v| v.abs().max_element())
                .fold(0.0f32, f32::max);
            let d = parry3d::query::distance(&Pose::IDENTITY, &tri(p), &Pose::IDENTITY, &tri(q))
                .map_or(f32::INFINITY, |d| d.distance);
            n += (d <= tol + 16.0 * f32::EPSILON * m) as usize;
        }
        open_self.push(k);
    }
    n
}
