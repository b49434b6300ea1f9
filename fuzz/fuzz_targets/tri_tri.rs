//! `triangles_intersect` against the exact reference of the test suite
//! (`proxima_harness::tri_tri`, built from the `robust` predicates with a
//! different decomposition), and its
//! invariance under argument order and vertex order; and the prepared path used by
//! the BVH collision queries (`narrow::PreparedTriangle::intersects`, an `f64`
//! filter in front of the exact test) against the same reference.
#![no_main]

use proxima::glam::Vec3;
use proxima::narrow::{triangles_intersect, PreparedTriangle};
use proxima_harness::tri_tri as reference;

/// Coordinates on a small integer grid (many exact touches and coplanar cases)
/// or raw finite floats.
fn coord(b: &[u8], i: &mut usize) -> f32 {
    let byte = |i: &mut usize| {
        let x = b.get(*i).copied().unwrap_or(0);
        *i += 1;
        x
    };
    let tag = byte(i);
    if tag < 200 {
        (tag % 9) as f32 - 4.0
    } else if tag < 230 {
        (byte(i) as i32 - 128) as f32 * 0.125
    } else {
        let v = f32::from_le_bytes([byte(i), byte(i), byte(i), byte(i)]);
        if v.is_finite() {
            v
        } else {
            0.0
        }
    }
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let mut i = 0;
    let mut v = [Vec3::ZERO; 6];
    for p in &mut v {
        *p = Vec3::new(
            coord(data, &mut i),
            coord(data, &mut i),
            coord(data, &mut i),
        );
    }
    let a = [v[0], v[1], v[2]];
    let b = [v[3], v[4], v[5]];
    let want = reference::intersect(&a, &b);
    assert_eq!(triangles_intersect(&a, &b), want, "{a:?} {b:?}");
    assert_eq!(triangles_intersect(&b, &a), want, "swapped {a:?} {b:?}");
    let ra = [a[1], a[2], a[0]];
    let fb = [b[2], b[1], b[0]];
    assert_eq!(triangles_intersect(&ra, &fb), want, "reordered {a:?} {b:?}");
    let (pa, pb) = (PreparedTriangle::new(a), PreparedTriangle::new(b));
    assert_eq!(pa.intersects(&pb), want, "prepared {a:?} {b:?}");
    assert_eq!(pb.intersects(&pa), want, "prepared swapped {a:?} {b:?}");
    let (pra, pfb) = (PreparedTriangle::new(ra), PreparedTriangle::new(fb));
    assert_eq!(pra.intersects(&pfb), want, "prepared reordered {a:?} {b:?}");
});
