//! The hash grid's unit tests: constructors, key boxes, moves between cells
//! and the oversized list, and queries, pairs and rays against brute force on
//! small scenes with oversized, far and huge objects.

use super::*;
use crate::broad::test_util::check_ray;
use crate::broad::{BruteForce, SpatialIndex, SpatialIndexExt};
use crate::geom::{Aabb, Ray, Segment, Sphere};
use glam::{vec3, Vec3};
use std::ops::ControlFlow;

#[test]
fn constructor_checks() {
    assert_eq!(HashGrid::<()>::new(2.0).unwrap().cell_size(), 4.0);
    assert!(HashGrid::<()>::new(0.0).is_err());
    assert!(HashGrid::<()>::new(-1.0).is_err());
    assert!(HashGrid::<()>::new(f32::NAN).is_err());
    assert!(HashGrid::<()>::with_config(HashGridConfig {
        cell_size: f32::INFINITY
    })
    .is_err());
    assert!(HashGrid::<()>::with_config(HashGridConfig { cell_size: 1e-45 }).is_err());
}

#[test]
fn objects_move_between_cells_and_the_oversized_list() {
    let mut g = HashGrid::with_config(HashGridConfig { cell_size: 4.0 }).unwrap();
    let h = g
        .insert(Sphere::new(vec3(2.0, 2.0, 2.0), 1.0), 'a')
        .unwrap();
    assert_eq!((g.cell_count(), g.reference_count()), (1, 1));
    g.update(h, Sphere::new(vec3(2.5, 1.5, 2.0), 1.2)).unwrap();
    assert_eq!((g.cell_count(), g.reference_count()), (1, 1));
    g.update(h, Sphere::new(vec3(4.0, 4.0, 4.0), 1.0)).unwrap();
    assert_eq!((g.cell_count(), g.reference_count()), (8, 8));
    g.validate().unwrap();
    g.update(h, Sphere::new(Vec3::ZERO, 100.0)).unwrap();
    assert_eq!((g.cell_count(), g.oversized_count()), (0, 1));
    let h2 = g.insert(Sphere::new(Vec3::ONE, 1e3), 'b').unwrap();
    g.update(h, Sphere::new(Vec3::ZERO, 200.0)).unwrap();
    g.validate().unwrap();
    g.update(h, Sphere::new(vec3(1e4 + 2.0, 2.0, 2.0), 0.5))
        .unwrap();
    assert_eq!((g.cell_count(), g.oversized_count()), (1, 1));
    g.validate().unwrap();
    assert_eq!(g.pairs().len(), 0);
    assert_eq!(g.remove(h2), Ok('b'));
    assert_eq!(g.remove(h), Ok('a'));
    assert_eq!((g.cell_count(), g.oversized_count()), (0, 0));
    g.validate().unwrap();
    assert!(g.remove(h).is_err());
}

#[test]
fn key_boxes() {
    let k = lattice(4.0);
    assert_eq!(k.coord(-0.5, 0), -1);
    assert_eq!(k.coord(7.9, 0), 1);
    assert_eq!(k.coord(f32::NAN, 0), -LIMIT);
    assert_eq!(k.coord(1e30, 0), LIMIT);
    assert_eq!(k.coord(-1e30, 0), -LIMIT);
    let b = k.sphere_box(&Sphere::new(vec3(6.0, 6.0, -6.0), 1.0), 3);
    assert_eq!(b, KeyBox::single([1, 1, -2]));
    assert_eq!(b.volume(), 1);
    // Touching a cell face from inside reaches across it (padding).
    let b = k.sphere_box(&Sphere::new(vec3(6.0, 6.0, 6.0), 2.0), 3);
    assert_eq!(
        b,
        KeyBox {
            lo: [0, 0, 0],
            hi: [2, 2, 2]
        }
    );
    assert_eq!(b.volume(), 27);
    let mut n = 0;
    b.for_each(|key| {
        assert!(b.contains(key));
        n += 1;
    });
    assert_eq!(n, 27);
    let huge = k.sphere_box(&Sphere::new(Vec3::ZERO, 1e35), 3);
    assert_eq!(huge, k.limits);
    assert_eq!(huge.volume(), u64::MAX);
    assert!(KeyBox::EMPTY.is_empty());
    assert_eq!(KeyBox::EMPTY.volume(), 0);
    let mut e = KeyBox::EMPTY;
    e.include([3, -4, 5]);
    e.include([1, 2, 3]);
    assert_eq!(
        e,
        KeyBox {
            lo: [1, -4, 3],
            hi: [3, 2, 5]
        }
    );
    assert!(e
        .intersect(&KeyBox {
            lo: [4; 3],
            hi: [9; 3]
        })
        .is_empty());
    let nan = Aabb::new(Vec3::splat(f32::NAN), Vec3::ZERO);
    assert_eq!(k.aabb_box(&nan, 3), k.limits);
}

/// Sorted payloads of the objects `q` selects (duplicates kept).
fn values(i: &impl SpatialIndex<u32>, q: &Sphere) -> Vec<u32> {
    let mut v = Vec::new();
    let _ = i.for_each_in(*q, |_, _, x| {
        v.push(*x);
        ControlFlow::Continue(())
    });
    v.sort_unstable();
    v
}

#[test]
fn huge_and_unbounded_queries_are_exact_and_once() {
    let mut g = HashGrid::with_config(HashGridConfig { cell_size: 2.0 }).unwrap();
    let mut b = BruteForce::new();
    let mut k = 0;
    for i in 0..20 {
        for j in 0..20 {
            let s = Sphere::new(
                vec3(i as f32 * 3.0, j as f32 * 2.5, (i * j % 7) as f32),
                1.5,
            );
            g.insert(s, k).unwrap();
            b.insert(s, k).unwrap();
            k += 1;
        }
    }
    for s in [
        Sphere::new(vec3(1e4, -1e4, 3e4), 1.0),
        Sphere::new(vec3(-3e38, 0.0, 0.0), 1.0),
        Sphere::new(Vec3::splat(20.0), 500.0), // oversized
    ] {
        g.insert(s, k).unwrap();
        b.insert(s, k).unwrap();
        k += 1;
    }
    g.validate().unwrap();
    for q in [
        Sphere::new(Vec3::ZERO, 1e6),
        Sphere::new(Vec3::ZERO, 3e38),
        Sphere::new(vec3(30.0, 25.0, 3.0), 4.0),
        Sphere::new(vec3(1e4, -1e4, 3e4), 0.0),
    ] {
        let got = values(&g, &q);
        let mut d = got.clone();
        d.dedup();
        assert_eq!(got.len(), d.len(), "reported twice");
        assert_eq!(got, values(&b, &q), "{q:?}");
    }
    let bx = Aabb::new(Vec3::splat(-3e38), Vec3::splat(3e38));
    assert_eq!(g.query(bx).unwrap().len(), b.len());
}

#[test]
fn pairs_are_reported_once() {
    let mut g = HashGrid::with_config(HashGridConfig { cell_size: 1.0 }).unwrap();
    // Two spheres sharing 3 x 3 x 3 cells (most of their 27 and 64).
    let a = g.insert(Sphere::new(Vec3::splat(5.0), 1.2), 0).unwrap();
    let b = g.insert(Sphere::new(Vec3::splat(5.5), 1.4), 1).unwrap();
    // Oversized, overlapping both and each other.
    let c = g.insert(Sphere::new(Vec3::ZERO, 9.0), 2).unwrap();
    let d = g.insert(Sphere::new(vec3(1.0, 0.0, 0.0), 20.0), 3).unwrap();
    // Far away, alone.
    let e = g.insert(Sphere::new(vec3(1e5, 0.0, 0.0), 0.5), 4).unwrap();
    assert_eq!(g.oversized_count(), 2);
    let mut p = g.pairs();
    p.sort();
    let mut want: Vec<_> = [(a, b), (a, c), (b, c), (a, d), (b, d), (c, d)]
        .into_iter()
        .map(|(x, y)| (x.min(y), x.max(y)))
        .collect();
    want.sort();
    assert_eq!(p, want);
    let _ = e;
}

fn sample() -> (HashGrid<u32>, BruteForce<u32>) {
    let mut g = HashGrid::with_config(HashGridConfig { cell_size: 3.0 }).unwrap();
    let mut b = BruteForce::new();
    let mut k = 0u32;
    let mut add = |s: Sphere| {
        g.insert(s, k).unwrap();
        b.insert(s, k).unwrap();
        k += 1;
    };
    for x in (0..=60).step_by(7) {
        for y in (0..=60).step_by(9) {
            for z in (0..=30).step_by(6) {
                add(Sphere::new(
                    vec3(x as f32, y as f32, z as f32),
                    0.5 + ((x + y + z) % 4) as f32 * 0.5,
                ));
            }
        }
    }
    add(Sphere::new(vec3(-1e4, 30.0, 15.0), 1.0));
    add(Sphere::new(vec3(30.0, 30.0, 15.0), 80.0)); // oversized
    add(Sphere::new(vec3(2e4, 2e4, -2e4), 0.0));
    (g, b)
}

#[test]
fn rays_match_the_oracle_in_every_direction() {
    let (g, b) = sample();
    let origins = [
        vec3(30.0, 30.0, 15.0),
        vec3(-20.0, 10.0, 5.0),
        vec3(6.0, 9.0, 12.0), // on cell faces
        vec3(-3e4, 30.0, 15.0),
        vec3(1e6, -1e6, 1e6),
    ];
    for o in origins {
        for k in 0..64 {
            let (t, p) = (k as f32 * 0.7, k as f32 * 0.31);
            let d = vec3(t.cos() * p.sin(), t.sin() * p.sin(), p.cos());
            for max_t in [f32::INFINITY, 50.0, 2.0, 0.0] {
                check_ray(&g, &b, &Ray::with_max_t(o, d, max_t));
            }
        }
        for d in [
            Vec3::X,
            -Vec3::Y,
            Vec3::Z,
            -Vec3::Z,
            vec3(1.0, 1.0, 1.0),
            vec3(0.0, 1.0, -1.0),
        ] {
            check_ray(&g, &b, &Ray::new(o, d));
            check_ray(&g, &b, &Ray::new(o, d * 1e-3));
        }
    }
    // Towards the far point, and a segment across everything.
    let o = vec3(30.0, 30.0, 15.0);
    check_ray(&g, &b, &Ray::new(o, vec3(2e4, 2e4, -2e4) - o));
    check_ray(
        &g,
        &b,
        &Segment::new(vec3(-5.0, -5.0, -5.0), vec3(65.0, 65.0, 35.0)).to_ray(),
    );
}

#[test]
fn vertical_rays() {
    let (g, b) = sample();
    for (x, y) in [(7.0, 9.0), (3.0, 3.0), (-1e4, 30.0), (0.0, 0.0)] {
        for dz in [1.0, -1.0] {
            check_ray(&g, &b, &Ray::new(vec3(x, y, -100.0), vec3(0.0, 0.0, dz)));
            check_ray(&g, &b, &Ray::new(vec3(x, y, 100.0), vec3(0.0, 0.0, dz)));
        }
    }
}
