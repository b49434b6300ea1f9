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
