//! An independent exact oracle for points on a dyadic grid, in integer arithmetic:
//! A ∩ B ≠ ∅ iff 0 ∈ A − B = conv{a_i − b_j} (9 points), and by Carathéodory's
//! theorem iff 0 lies in a closed simplex spanned by an affinely independent subset
//! of at most 4 of those points. All 255 subsets are tried. No predicate, projection
//! or case analysis of the library is involved.

use glam::Vec3;

type I = i128;
type V = [I; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: V, b: V) -> I {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn det(a: V, b: V, c: V) -> I {
    dot(a, cross(b, c))
}

/// Grid coordinates scaled to integers; `None` if a coordinate is not a multiple
/// of `1/scale` or too large for the i128 arithmetic below.
pub fn to_int(t: &[Vec3; 3], scale: f32) -> Option<[V; 3]> {
    let mut out = [[0; 3]; 3];
    for (i, p) in t.iter().enumerate() {
        for k in 0..3 {
            let s = p[k] * scale;
            if s.fract() != 0.0 || s.abs() > 1.0e6 {
                return None;
            }
            out[i][k] = s as I;
        }
    }
    Some(out)
}

fn simplex_contains_origin(s: &[V]) -> bool {
    match s.len() {
        1 => s[0] == [0; 3],
        2 => s[0] != s[1] && cross(s[0], s[1]) == [0; 3] && dot(s[0], s[1]) <= 0,
        3 => {
            let n = cross(sub(s[1], s[0]), sub(s[2], s[0]));
            n != [0; 3]
                && dot(n, s[0]) == 0
                && dot(cross(s[0], s[1]), n) >= 0
                && dot(cross(s[1], s[2]), n) >= 0
                && dot(cross(s[2], s[0]), n) >= 0
        }
        _ => {
            // orient(a,b,c,x) = det(b-a, c-a, x-a); the origin must be on the closed
            // side of each face that holds the opposite vertex.
            let o = |a: V, b: V, c: V, x: V| det(sub(b, a), sub(c, a), sub(x, a)).signum();
            let z = [0; 3];
            if o(s[0], s[1], s[2], s[3]) == 0 {
                return false;
            }
            [(0, 1, 2, 3), (1, 2, 3, 0), (2, 3, 0, 1), (3, 0, 1, 2)]
                .iter()
                .all(|&(a, b, c, d)| {
                    let sd = o(s[a], s[b], s[c], s[d]);
                    let s0 = o(s[a], s[b], s[c], z);
                    s0 == 0 || s0 == sd
                })
        }
    }
}

/// The oracle on integer coordinates.
pub fn intersect_int(a: &[V; 3], b: &[V; 3]) -> bool {
    let mut d = Vec::with_capacity(9);
    for p in a {
        for q in b {
            d.push(sub(*p, *q));
        }
    }
    let n = d.len();
    for mask in 1u32..(1 << n) {
        if mask.count_ones() > 4 {
            continue;
        }
        let s: Vec<V> = (0..n)
            .filter(|i| mask & (1 << i) != 0)
            .map(|i| d[i])
            .collect();
        if simplex_contains_origin(&s) {
            return true;
        }
    }
    false
}

/// The oracle for triangles whose coordinates are multiples of `1/scale`.
pub fn intersect(a: &[Vec3; 3], b: &[Vec3; 3], scale: f32) -> Option<bool> {
    Some(intersect_int(&to_int(a, scale)?, &to_int(b, scale)?))
}
