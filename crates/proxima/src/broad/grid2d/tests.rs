//! The 2D grid's unit tests: constructors, cell ranges, and queries, pairs and
//! rays against brute force on small scenes with objects in many cells and
//! outside the rectangle.

use super::*;
use crate::broad::test_util::check_ray;
use crate::broad::{BruteForce, SpatialIndex, SpatialIndexExt};
use crate::geom::{Ray, Segment, Sphere};
use glam::{vec3, Vec3};
use std::ops::ControlFlow;

#[test]
fn constructor_checks_and_defaults() {
    let w = Aabb::new(Vec3::ZERO, vec3(1000.0, 1000.0, 10.0));
    let g: UniformGrid2d<()> = UniformGrid2d::new(w, 2.0).unwrap();
    assert_eq!(g.cell_size(), 4.0);
    assert_eq!(g.dims(), [250, 250]);
    // A tiny radius over a large world is capped at about DEFAULT_MAX_CELLS cells.
    let g: UniformGrid2d<()> = UniformGrid2d::new(w, 1e-3).unwrap();
    assert!(g.dims()[0] as usize * g.dims()[1] as usize <= DEFAULT_MAX_CELLS);
    let g: UniformGrid2d<()> = UniformGrid2d::new(w, 0.0).unwrap();
    assert_eq!(g.dims(), [256, 256]);
    assert!(UniformGrid2d::<()>::new(w, -1.0).is_err());
    assert!(UniformGrid2d::<()>::new(w, f32::INFINITY).is_err());
    assert!(UniformGrid2d::<()>::with_config(Grid2dConfig {
        world: w,
        cell_size: 0.0
    })
    .is_err());
    let bad = Aabb::new(Vec3::ONE, Vec3::ZERO);
    assert!(UniformGrid2d::<()>::new(bad, 1.0).is_err());
}

#[test]
fn update_within_the_same_cells_touches_no_cell() {
    let w = Aabb::new(Vec3::ZERO, vec3(100.0, 100.0, 1.0));
    let mut g = UniformGrid2d::with_config(Grid2dConfig {
        world: w,
        cell_size: 10.0,
    })
    .unwrap();
    let h = g
        .insert(Sphere::new(vec3(15.0, 15.0, 0.0), 1.0), 'a')
        .unwrap();
    assert_eq!(g.reference_count(), 1);
    g.update(h, Sphere::new(vec3(16.0, 14.0, 0.5), 2.0))
        .unwrap();
    assert_eq!(g.reference_count(), 1);
    g.validate().unwrap();
    // Across a border: now 2 cells.
    g.update(h, Sphere::new(vec3(19.5, 14.0, 0.5), 2.0))
        .unwrap();
    assert_eq!(g.reference_count(), 2);
    g.validate().unwrap();
    assert_eq!(g.remove(h), Ok('a'));
    assert_eq!(g.reference_count(), 0);
    g.validate().unwrap();
    assert!(g.update(h, Sphere::new(Vec3::ZERO, 1.0)).is_err());
}

#[test]
fn dimensions_and_bad_parameters() {
    let g = lattice(&Aabb::new(Vec3::ZERO, vec3(100.0, 50.0, 1.0)), 10.0).unwrap();
    assert_eq!(g.limits.hi, [9, 4, 0]);
    let w = Aabb::new(Vec3::ZERO, Vec3::ONE);
    assert!(lattice(&w, 0.0).is_err());
    assert!(lattice(&w, -1.0).is_err());
    assert!(lattice(&w, f32::NAN).is_err());
    assert!(lattice(&w, 1e-9).is_err(), "too many cells");
    assert!(lattice(&Aabb::new(Vec3::ONE, Vec3::ZERO), 1.0).is_err());
    // A degenerate rectangle still has one cell.
    let flat = lattice(&Aabb::new(Vec3::ZERO, Vec3::ZERO), 1.0).unwrap();
    assert_eq!(flat.limits.hi, [0, 0, 0]);
}

/// The lattice of the old `cells.rs` tests: 100 × 50 in cells of 10.
fn geom() -> Lattice {
    lattice(&Aabb::new(Vec3::ZERO, vec3(100.0, 50.0, 1.0)), 10.0).unwrap()
}

#[test]
fn sphere_ranges_are_clamped_and_padded() {
    let g = geom();
    let r = g.sphere_box(&Sphere::new(vec3(15.0, 15.0, 0.0), 1.0), 2);
    assert_eq!(r, KeyBox::single([1, 1, 0]));
    // Touching a cell border from inside reaches across it (padding).
    let r = g.sphere_box(&Sphere::new(vec3(15.0, 15.0, 0.0), 5.0), 2);
    assert_eq!(
        r,
        KeyBox {
            lo: [0, 0, 0],
            hi: [2, 2, 0]
        }
    );
    // Far outside: the border cells.
    let r = g.sphere_box(&Sphere::new(vec3(-1e4, 1e4, 0.0), 1.0), 2);
    assert_eq!(r, KeyBox::single([0, 4, 0]));
    // Huge: everything.
    let r = g.sphere_box(&Sphere::new(vec3(50.0, 25.0, 0.0), 1e30), 2);
    assert_eq!(r, g.limits);
    assert_eq!(r.volume(), 50);
    // Infinite and NaN query bounds stay conservative.
    let inf = Aabb::new(Vec3::splat(f32::NEG_INFINITY), Vec3::splat(f32::INFINITY));
    assert_eq!(g.aabb_box(&inf, 2), g.limits);
    let nan = Aabb::new(Vec3::splat(f32::NAN), Vec3::splat(f32::NAN));
    assert_eq!(g.aabb_box(&nan, 2), g.limits);
}

#[test]
fn coordinates_are_monotone() {
    let g = geom();
    let mut last = 0;
    let mut x = -20.0f32;
    while x < 120.0 {
        let c = g.coord(x, 0);
        assert!(c >= last);
        last = c;
        x += 0.37;
    }
    assert_eq!(last, 9);
    // z is flat: one cell whatever the coordinate.
    for z in [f32::NAN, -1e30, 0.0, 7.5, f32::INFINITY] {
        assert_eq!(g.coord(z, 2), 0);
    }
}

#[test]
fn an_object_in_many_cells_is_reported_once() {
    let w = Aabb::new(Vec3::ZERO, vec3(100.0, 100.0, 10.0));
    let mut g = UniformGrid2d::with_config(Grid2dConfig {
        world: w,
        cell_size: 5.0,
    })
    .unwrap();
    let big = g
        .insert(Sphere::new(vec3(50.0, 50.0, 5.0), 30.0), 0)
        .unwrap();
    let small = g
        .insert(Sphere::new(vec3(52.0, 52.0, 5.0), 1.0), 1)
        .unwrap();
    // An object far outside sits in a border cell and is still found.
    let far = g
        .insert(Sphere::new(vec3(-1e4, 50.0, 5.0), 1.0), 2)
        .unwrap();
    assert!(g.reference_count() > 100);
    for q in [
        Sphere::new(vec3(50.0, 50.0, 5.0), 40.0),
        Sphere::new(vec3(52.0, 52.0, 5.0), 0.5),
        Sphere::new(vec3(20.0, 50.0, 5.0), 3.0),
    ] {
        let mut seen = Vec::new();
        let _ = g.for_each_in(q, |h, _, _| {
            seen.push(h);
            ControlFlow::Continue(())
        });
        let n = seen.len();
        seen.sort();
        seen.dedup();
        assert_eq!(n, seen.len(), "reported twice");
        assert!(seen.contains(&big));
    }
    assert_eq!(g.within(vec3(-1e4, 50.0, 5.0), 0.0).unwrap(), vec![far]);
    // Wrong z: the grid ignores z, the exact test does not.
    assert!(!g
        .within(vec3(52.0, 52.0, 100.0), 1.0)
        .unwrap()
        .contains(&small));
    let b = Aabb::new(vec3(51.0, 51.0, 0.0), vec3(53.0, 53.0, 10.0));
    let mut hits = g.query(b).unwrap();
    hits.sort();
    assert_eq!(hits, {
        let mut v = vec![big, small];
        v.sort();
        v
    });
}

#[test]
fn pairs_sharing_many_cells_are_reported_once() {
    let w = Aabb::new(Vec3::ZERO, vec3(100.0, 100.0, 10.0));
    let mut g = UniformGrid2d::with_config(Grid2dConfig {
        world: w,
        cell_size: 2.0,
    })
    .unwrap();
    let a = g
        .insert(Sphere::new(vec3(50.0, 50.0, 5.0), 10.0), 0)
        .unwrap();
    let b = g
        .insert(Sphere::new(vec3(55.0, 52.0, 5.0), 10.0), 1)
        .unwrap();
    // Same footprint, different z: shares every cell with `a` but no overlap.
    let c = g
        .insert(Sphere::new(vec3(50.0, 50.0, 40.0), 10.0), 2)
        .unwrap();
    // Far outside on both sides of a corner: clamped into the same border cell.
    let d = g
        .insert(Sphere::new(vec3(-1e4, -1e4, 5.0), 1.0), 3)
        .unwrap();
    let e = g
        .insert(Sphere::new(vec3(-1e4, -1e4 + 2.0, 5.0), 1.0), 4)
        .unwrap();
    let f = g
        .insert(Sphere::new(vec3(-5e3, -1e4, 5.0), 1.0), 5)
        .unwrap();
    let mut p = g.pairs();
    p.sort();
    let mut want = vec![(a.min(b), a.max(b)), (d.min(e), d.max(e))];
    want.sort();
    assert_eq!(p, want);
    let _ = (c, f);
}

fn sample() -> (UniformGrid2d<u32>, BruteForce<u32>) {
    let w = Aabb::new(Vec3::ZERO, vec3(100.0, 100.0, 10.0));
    let mut g = UniformGrid2d::with_config(Grid2dConfig {
        world: w,
        cell_size: 7.0,
    })
    .unwrap();
    let mut b = BruteForce::new();
    let mut k = 0u32;
    for x in (0..=100).step_by(9) {
        for y in (0..=100).step_by(11) {
            let s = Sphere::new(
                vec3(x as f32, y as f32, (x % 7) as f32),
                1.0 + (y % 3) as f32,
            );
            g.insert(s, k).unwrap();
            b.insert(s, k).unwrap();
            k += 1;
        }
    }
    // Outside the rectangle, and one huge.
    for s in [
        Sphere::new(vec3(-1e4, 50.0, 5.0), 1.0),
        Sphere::new(vec3(150.0, -30.0, 5.0), 2.0),
        Sphere::new(vec3(50.0, 50.0, 5.0), 60.0),
    ] {
        g.insert(s, k).unwrap();
        b.insert(s, k).unwrap();
        k += 1;
    }
    (g, b)
}

#[test]
fn vertical_rays() {
    let (g, b) = sample();
    for (x, y) in [
        (9.0, 11.0),
        (50.0, 50.0),
        (-1e4, 50.0),
        (7.0, 7.0),
        (500.0, 500.0),
    ] {
        for dz in [1.0, -1.0, 1e-3] {
            for max_t in [f32::INFINITY, 3.0, 0.0] {
                check_ray(
                    &g,
                    &b,
                    &Ray::with_max_t(vec3(x, y, 5.0), vec3(0.0, 0.0, dz), max_t),
                );
            }
        }
    }
}

#[test]
fn rays_in_every_direction_match_the_oracle() {
    let (g, b) = sample();
    let origins = [
        vec3(50.0, 50.0, 5.0),
        vec3(-30.0, 20.0, 5.0),
        vec3(130.0, 140.0, 2.0),
        vec3(7.0, 14.0, 5.0), // on grid lines
        vec3(-2e4, 50.0, 5.0),
    ];
    for o in origins {
        for k in 0..48 {
            let ang = k as f32 * std::f32::consts::TAU / 48.0;
            let d = vec3(ang.cos(), ang.sin(), 0.01 * (k % 5) as f32 - 0.02);
            for max_t in [f32::INFINITY, 40.0, 1.0] {
                check_ray(&g, &b, &Ray::with_max_t(o, d, max_t));
            }
        }
        // Axis-aligned directions, including along a grid line.
        for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, vec3(1.0, 1.0, 0.0)] {
            check_ray(&g, &b, &Ray::new(o, d));
        }
    }
    let s = Segment::new(vec3(-5.0, -5.0, 5.0), vec3(105.0, 95.0, 5.0));
    check_ray(&g, &b, &s.to_ray());
}
