//! Bounded property tests of `triangles_intersect`: agreement with the exact
//! reference and invariance under argument order, cyclic and reversed vertex order.
//! Coordinates on a small integer grid make touching and coplanar cases common.

use super::reference;
use proptest::prelude::*;
use proxima::glam::Vec3;
use proxima::narrow::triangles_intersect;

fn point() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        3 => (-3i8..=3, -3i8..=3, -3i8..=3).prop_map(|(x, y, z)| Vec3::new(x as f32, y as f32, z as f32)),
        1 => (-8.0f32..8.0, -8.0f32..8.0, -8.0f32..8.0).prop_map(|(x, y, z)| Vec3::new(x, y, z)),
    ]
}

fn tri() -> impl Strategy<Value = [Vec3; 3]> {
    [point(), point(), point()]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn matches_reference_and_is_symmetric(a in tri(), b in tri(), rot in 0usize..3, flip: bool) {
        let want = reference::intersect(&a, &b);
        prop_assert_eq!(triangles_intersect(&a, &b), want);
        prop_assert_eq!(triangles_intersect(&b, &a), want);
        prop_assert_eq!(super::prepared(&a, &b), want);
        prop_assert_eq!(super::prepared(&b, &a), want);
        let mut a2 = a;
        a2.rotate_left(rot);
        let mut b2 = b;
        if flip {
            b2.reverse();
        }
        prop_assert_eq!(triangles_intersect(&a2, &b2), want);
        prop_assert_eq!(triangles_intersect(&b2, &a2), want);
    }
}
