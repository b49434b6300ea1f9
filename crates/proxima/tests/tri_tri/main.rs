//! Exactness tests of `proxima::narrow::triangles_intersect` against two
//! references: `reference` (`proxima_harness::tri_tri`: exact predicates, a
//! different decomposition, shared with the `tri_tri` fuzz target) and
//! `carath` (integer arithmetic, Carathéodory; grid inputs only). The same
//! checks run `PreparedTriangle::intersects` (the filtered test the BVH queries
//! use), which must give the exact answer too.

mod carath;
mod cases;
mod prop;
mod random;
mod sym;

use proxima_harness::tri_tri as reference;

/// The answer of the prepared (filtered) test, asserted equal in both orders.
fn prepared(a: &[proxima::glam::Vec3; 3], b: &[proxima::glam::Vec3; 3]) -> bool {
    use proxima::narrow::PreparedTriangle;
    let (pa, pb) = (PreparedTriangle::new(*a), PreparedTriangle::new(*b));
    let got = pa.intersects(&pb);
    assert_eq!(pb.intersects(&pa), got, "prepared order: {a:?} {b:?}");
    got
}
