//! Exact symmetries: vertex orders, argument order, signed axis permutations.

use glam::Vec3;

pub type Tri = [Vec3; 3];

/// The 6 orders of a triangle's corners.
pub fn orders(t: &Tri) -> [Tri; 6] {
    let [a, b, c] = *t;
    [
        [a, b, c],
        [b, c, a],
        [c, a, b],
        [a, c, b],
        [c, b, a],
        [b, a, c],
    ]
}

/// One of the 48 signed axis permutations (exact on every float).
pub fn axis_map(p: Vec3, m: usize) -> Vec3 {
    const PERMS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [1, 2, 0],
        [2, 0, 1],
        [0, 2, 1],
        [2, 1, 0],
        [1, 0, 2],
    ];
    let perm = PERMS[m % 6];
    let signs = m / 6;
    let v = p.to_array();
    let s = |i: usize| if signs & (1 << i) != 0 { -1.0 } else { 1.0 };
    Vec3::new(s(0) * v[perm[0]], s(1) * v[perm[1]], s(2) * v[perm[2]])
}

/// Every variant of the pair under vertex orders, argument order and (if
/// `axes`) the 48 axis maps.
pub fn variants(a: &Tri, b: &Tri, axes: bool) -> Vec<(Tri, Tri)> {
    let maps = if axes { 48 } else { 1 };
    let mut out = Vec::with_capacity(72 * maps);
    for m in 0..maps {
        let (am, bm) = (a.map(|p| axis_map(p, m)), b.map(|p| axis_map(p, m)));
        for oa in orders(&am) {
            for ob in orders(&bm) {
                out.push((oa, ob));
                out.push((ob, oa));
            }
        }
    }
    out
}
