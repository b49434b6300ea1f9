//! Hand-made configurations with known answers: coplanar, touching, parallel,
//! nearly parallel and degenerate, each checked under all 72 vertex/argument
//! orders times 48 signed axis permutations, at three scales (exact powers of
//! two), against the expected answer and both references.

use crate::sym::{variants, Tri};
use crate::{carath, reference};
use glam::Vec3;
use proxima::narrow::triangles_intersect;

const E: f32 = 1.0 / 64.0;

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

fn tri(p: [[f32; 3]; 3]) -> Tri {
    p.map(Vec3::from_array)
}

/// A: the right triangle (0,0,0), (4,0,0), (0,4,0) in the plane z = 0.
fn base() -> Tri {
    [v(0.0, 0.0, 0.0), v(4.0, 0.0, 0.0), v(0.0, 4.0, 0.0)]
}

fn cases() -> Vec<(&'static str, Tri, Tri, bool)> {
    let a = base();
    let seg = |p: Vec3, q: Vec3| [p, q, p];
    let pt = |p: Vec3| [p, p, p];
    vec![
        // Coplanar.
        (
            "coplanar overlap",
            a,
            tri([[1., 1., 0.], [5., 1., 0.], [1., 5., 0.]]),
            true,
        ),
        (
            "coplanar disjoint",
            a,
            tri([[3., 3., 0.], [7., 3., 0.], [3., 7., 0.]]),
            false,
        ),
        (
            "coplanar shared edge",
            a,
            tri([[4., 0., 0.], [0., 4., 0.], [4., 4., 0.]]),
            true,
        ),
        (
            "coplanar vertex on edge",
            a,
            tri([[2., 2., 0.], [5., 2., 0.], [2., 5., 0.]]),
            true,
        ),
        (
            "coplanar vertex near edge",
            a,
            tri([[2. + E, 2., 0.], [5., 2., 0.], [2., 5., 0.]]),
            false,
        ),
        (
            "coplanar contained",
            a,
            tri([[0.5, 0.5, 0.], [1., 0.5, 0.], [0.5, 1., 0.]]),
            true,
        ),
        ("coplanar identical", a, a, true),
        (
            "coplanar vertex-vertex",
            a,
            tri([[4., 0., 0.], [8., 0., 0.], [4., -4., 0.]]),
            true,
        ),
        (
            "coplanar gap",
            a,
            tri([[4. + E, 0., 0.], [8., 0., 0.], [4., -4., 0.]]),
            false,
        ),
        (
            "coplanar edges cross, no vertex inside",
            a,
            tri([[-1., 1., 0.], [5., 1., 0.], [2., -2., 0.]]),
            true,
        ),
        // Parallel and nearly parallel.
        (
            "parallel planes",
            a,
            tri([[0., 0., 1.], [4., 0., 1.], [0., 4., 1.]]),
            false,
        ),
        (
            "parallel, one step apart",
            a,
            tri([[0., 0., E], [4., 0., E], [0., 4., E]]),
            false,
        ),
        (
            "nearly parallel, touching at a vertex",
            a,
            tri([[1., 1., 0.], [4., 0., E], [0., 4., E]]),
            true,
        ),
        (
            "nearly parallel, above",
            a,
            tri([[1., 1., E], [4., 0., 2. * E], [0., 4., E]]),
            false,
        ),
        (
            "nearly parallel, crossing",
            a,
            tri([[1., 1., -E], [4., 0., E], [0., 4., E]]),
            true,
        ),
        // Crossing and touching, not coplanar.
        (
            "crossing",
            a,
            tri([[1., 1., -1.], [1., 1., 1.], [1., -3., 0.]]),
            true,
        ),
        (
            "edge touches edge",
            a,
            tri([[1., 0., -1.], [1., 0., 1.], [1., -5., 0.]]),
            true,
        ),
        (
            "edge misses edge",
            a,
            tri([[1., -E, -1.], [1., -E, 1.], [1., -5., 0.]]),
            false,
        ),
        (
            "vertex on face",
            a,
            tri([[1., 1., 0.], [2., 1., 1.], [1., 2., 1.]]),
            true,
        ),
        (
            "vertex above face",
            a,
            tri([[1., 1., E], [2., 1., 1.], [1., 2., 1.]]),
            false,
        ),
        (
            "vertex on vertex",
            a,
            tri([[0., 0., 0.], [-1., -1., 1.], [-1., 1., -1.]]),
            true,
        ),
        (
            "edge in face",
            a,
            tri([[1., 1., 0.], [2., 1., 0.], [1., 1., 1.]]),
            true,
        ),
        (
            "edge on edge, other side",
            a,
            tri([[1., 0., 0.], [3., 0., 0.], [2., -1., 1.]]),
            true,
        ),
        (
            "pierce through vertex",
            a,
            tri([[0., 0., -1.], [0., 0., 1.], [-1., -1., 0.]]),
            true,
        ),
        // Degenerate second triangle.
        (
            "segment crossing face",
            a,
            seg(v(1., 1., -1.), v(1., 1., 1.)),
            true,
        ),
        (
            "collinear triple crossing",
            a,
            [v(1., 1., -1.), v(1., 1., 1.), v(1., 1., 0.)],
            true,
        ),
        (
            "segment beside",
            a,
            seg(v(5., 5., -1.), v(5., 5., 1.)),
            false,
        ),
        (
            "segment in plane crossing",
            a,
            seg(v(-1., 1., 0.), v(5., 1., 0.)),
            true,
        ),
        (
            "segment in plane outside",
            a,
            seg(v(-2., 1., 0.), v(-1., 1., 0.)),
            false,
        ),
        (
            "segment ending on face",
            a,
            seg(v(1., 1., 0.), v(1., 1., 1.)),
            true,
        ),
        (
            "segment ending above face",
            a,
            seg(v(1., 1., E), v(1., 1., 1.)),
            false,
        ),
        (
            "segment along edge",
            a,
            seg(v(3., 1., 0.), v(5., -1., 0.)),
            true,
        ),
        ("point inside", a, pt(v(1., 1., 0.)), true),
        ("point above", a, pt(v(1., 1., E)), false),
        ("point on edge", a, pt(v(2., 2., 0.)), true),
        ("point beside edge", a, pt(v(2. + E, 2., 0.)), false),
        ("point on vertex", a, pt(v(4., 0., 0.)), true),
        // Both degenerate.
        (
            "segments crossing",
            seg(v(0., 0., 0.), v(2., 0., 0.)),
            seg(v(1., -1., 0.), v(1., 1., 0.)),
            true,
        ),
        (
            "segments skew",
            seg(v(0., 0., 0.), v(2., 0., 0.)),
            seg(v(1., -1., E), v(1., 1., E)),
            false,
        ),
        (
            "segments collinear touching",
            seg(v(0., 0., 0.), v(2., 0., 0.)),
            seg(v(2., 0., 0.), v(3., 0., 0.)),
            true,
        ),
        (
            "segments collinear apart",
            seg(v(0., 0., 0.), v(2., 0., 0.)),
            seg(v(2. + E, 0., 0.), v(3., 0., 0.)),
            false,
        ),
        (
            "segments parallel",
            seg(v(0., 0., 0.), v(2., 0., 0.)),
            seg(v(0., 1., 0.), v(2., 1., 0.)),
            false,
        ),
        (
            "segments T",
            seg(v(0., 0., 0.), v(2., 0., 0.)),
            seg(v(1., 0., 0.), v(1., 3., 2.)),
            true,
        ),
        (
            "point on segment",
            seg(v(0., 0., 0.), v(2., 2., 2.)),
            pt(v(1., 1., 1.)),
            true,
        ),
        (
            "point off segment",
            seg(v(0., 0., 0.), v(2., 2., 2.)),
            pt(v(1., 1., 1. + E)),
            false,
        ),
        (
            "point beyond segment",
            seg(v(0., 0., 0.), v(2., 2., 2.)),
            pt(v(3., 3., 3.)),
            false,
        ),
        ("same points", pt(v(1., 2., 3.)), pt(v(1., 2., 3.)), true),
        (
            "different points",
            pt(v(1., 2., 3.)),
            pt(v(1., 2., 3. + E)),
            false,
        ),
    ]
}

#[test]
fn hand_made_cases_under_all_symmetries() {
    for (name, a, b, want) in cases() {
        for scale in [1.0f32, 2f32.powi(100), 2f32.powi(-100)] {
            let (a, b) = (a.map(|p| p * scale), b.map(|p| p * scale));
            if scale == 1.0 {
                assert_eq!(
                    carath::intersect(&a, &b, 64.0),
                    Some(want),
                    "{name}: carath"
                );
            }
            for (x, y) in variants(&a, &b, true) {
                assert_eq!(
                    triangles_intersect(&x, &y),
                    want,
                    "{name} (scale {scale}): {x:?} {y:?}"
                );
                assert_eq!(reference::intersect(&x, &y), want, "{name}: reference");
                assert_eq!(super::prepared(&x, &y), want, "{name}: prepared");
            }
        }
    }
}

#[test]
fn translation_does_not_change_answers() {
    // Translating by a grid vector is exact for these small coordinates.
    for (name, a, b, want) in cases() {
        for t in [v(64.0, -32.0, 0.5), v(-3.0, 7.0, 1024.0)] {
            assert_eq!(
                triangles_intersect(&a.map(|p| p + t), &b.map(|p| p + t)),
                want,
                "{name}"
            );
        }
    }
}
