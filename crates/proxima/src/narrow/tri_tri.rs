//! Exact, closed triangle–triangle intersection (the narrow-phase primitive test of
//! [sources: tri-tri]): Guigue–Devillers' orientation-only algorithm, with every sign from the
//! exact predicates of [`predicates`](super::predicates), and explicit coplanar and
//! degenerate branches.

use super::coplanar::{project3, triangles_2d};
use super::predicates::{orient3d, proper_axis};
use super::segment::{segment_proper_triangle, segments_intersect};
use glam::Vec3;

/// Whether the closed triangles `a` and `b` share at least one point (touching
/// counts).
///
/// Exact for every finite `f32` input, including coplanar, touching and degenerate
/// triangles (zero area, repeated or collinear corners, points), so the answer does
/// not depend on the order of the corners or of the arguments. Non-finite input
/// gives an unspecified answer, never a panic.
///
/// Algorithm (Guigue & Devillers 2003, "Fast and robust triangle-triangle overlap
/// test using orientation predicates"): after a bounding-box rejection, each
/// triangle's corners are classified against the other's plane with `orient3d`;
/// if neither triangle is strictly on one side, the two segments in which the
/// triangles cut the common line are compared with two more `orient3d` signs.
/// Coplanar pairs are tested in 2D on a coordinate plane that the plane maps to
/// bijectively; a degenerate triangle is treated as the union of its edges.
///
/// Cost: 6–8 filtered `orient3d` in the general case (a few dozen flops each), the
/// exact fallback only on (nearly) degenerate configurations.
pub fn triangles_intersect(a: &[Vec3; 3], b: &[Vec3; 3]) -> bool {
    if !boxes_overlap(a, b) {
        return false;
    }
    match (proper_axis(a), proper_axis(b)) {
        (Some(ka), Some(_)) => proper_pair(a, b, ka),
        (None, Some(kb)) => edges(a).any(|(p, q)| segment_proper_triangle(p, q, b, kb)),
        (Some(ka), None) => edges(b).any(|(p, q)| segment_proper_triangle(p, q, a, ka)),
        (None, None) => {
            edges(a).any(|(p, q)| edges(b).any(|(r, s)| segments_intersect(p, q, r, s)))
        }
    }
}

fn edges(t: &[Vec3; 3]) -> impl Iterator<Item = (Vec3, Vec3)> + '_ {
    (0..3).map(move |i| (t[i], t[(i + 1) % 3]))
}

/// Closed bounding boxes overlap: exact (comparisons only).
fn boxes_overlap(a: &[Vec3; 3], b: &[Vec3; 3]) -> bool {
    let (amin, amax) = (a[0].min(a[1]).min(a[2]), a[0].max(a[1]).max(a[2]));
    let (bmin, bmax) = (b[0].min(b[1]).min(b[2]), b[0].max(b[1]).max(b[2]));
    amin.cmple(bmax).all() && bmin.cmple(amax).all()
}

/// Both triangles non-degenerate; `ka` is a proper projection axis of `a`.
fn proper_pair(a: &[Vec3; 3], b: &[Vec3; 3], ka: usize) -> bool {
    let sb = b.map(|p| orient3d(a[0], a[1], a[2], p));
    if one_strict_side(sb) {
        return false;
    }
    if sb == [0; 3] {
        // Same plane; dropping `ka` maps it bijectively onto a coordinate plane.
        return triangles_2d(&project3(a, ka), &project3(b, ka));
    }
    let sa = a.map(|p| orient3d(b[0], b[1], b[2], p));
    if one_strict_side(sa) {
        return false;
    }
    guigue_devillers(*a, sa, *b, sb)
}

pub(crate) fn one_strict_side(s: [i8; 3]) -> bool {
    s == [1; 3] || s == [-1; 3]
}

/// The non-coplanar case: neither triangle lies strictly on one side of the other's
/// plane. `sa` classifies `a`'s corners against plane `b`, `sb` the reverse.
///
/// Each triangle is rotated so that its first corner is alone on its side
/// (`s >= 0` for it, `s <= 0` for the others after orienting the other triangle;
/// swapping two corners of a triangle flips its plane). Then `a` cuts the line
/// L = plane(a) ∩ plane(b) in the segment from edge `a0a1` to edge `a0a2`, and `b`
/// in the one from `b0b1` to `b0b2`. Where edge `a0a1` and edge `b0b1` hit L is
/// ordered by the sign of `orient3d(a0, a1, b0, b1)` (zero iff they hit L at the
/// same point: the two edge lines are transversal to the other plane and not
/// parallel), and likewise for the second ends; the segments overlap iff both
/// orderings allow it.
pub(crate) fn guigue_devillers(a: [Vec3; 3], sa: [i8; 3], b: [Vec3; 3], sb: [i8; 3]) -> bool {
    let (mut a, flip_b) = isolate(a, sa);
    let mut b = b;
    let mut sb = sb;
    if flip_b {
        b.swap(1, 2);
        sb.swap(1, 2);
    }
    let (b, flip_a) = isolate(b, sb);
    if flip_a {
        a.swap(1, 2);
    }
    orient3d(a[0], a[1], b[0], b[1]) <= 0 && orient3d(a[0], a[2], b[2], b[0]) <= 0
}

/// Rotates `t` so that its first corner is alone on its side of the other plane:
/// signs `(+, <=0, <=0)` or, when that is impossible, `(-, >=0, >=0)` (then the
/// other plane must be flipped, returned as `true`), or for `(0, +, +)` /
/// `(0, -, -)` the corner on the plane. Requires signs not all equal to one value.
fn isolate(t: [Vec3; 3], s: [i8; 3]) -> ([Vec3; 3], bool) {
    let rot = |i: usize| [t[i], t[(i + 1) % 3], t[(i + 2) % 3]];
    let others = |i: usize| [s[(i + 1) % 3], s[(i + 2) % 3]];
    if let Some(i) = (0..3).find(|&i| s[i] > 0 && others(i).iter().all(|&o| o <= 0)) {
        return (rot(i), false);
    }
    if let Some(i) = (0..3).find(|&i| s[i] < 0 && others(i).iter().all(|&o| o >= 0)) {
        return (rot(i), true);
    }
    // Remaining patterns: one zero and two equal non-zero signs.
    let i = (0..3).find(|&i| s[i] == 0).unwrap_or(0);
    (rot(i), others(i)[0] > 0)
}
