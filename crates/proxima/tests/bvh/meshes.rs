//! Procedural meshes and random poses for the BVH tests.

use proxima::glam::{Affine3A, Quat, Vec3};
use proxima::narrow::TriMesh;
use rand::Rng;
use std::f32::consts::TAU;

/// A UV sphere (closed, with degenerate-free bands) of `nu × nv` quads.
pub fn uv_sphere(center: Vec3, r: f32, nu: u32, nv: u32) -> TriMesh {
    let mut v = Vec::new();
    for j in 0..=nv {
        let phi = std::f32::consts::PI * j as f32 / nv as f32;
        for i in 0..nu {
            let th = TAU * i as f32 / nu as f32;
            v.push(center + r * Vec3::new(phi.sin() * th.cos(), phi.sin() * th.sin(), phi.cos()));
        }
    }
    grid_triangles(v, nu, nv, true)
}

/// A torus of major radius `big`, minor `small`.
pub fn torus(big: f32, small: f32, nu: u32, nv: u32) -> TriMesh {
    let mut v = Vec::new();
    for j in 0..nv {
        let phi = TAU * j as f32 / nv as f32;
        for i in 0..nu {
            let th = TAU * i as f32 / nu as f32;
            let rr = big + small * phi.cos();
            v.push(Vec3::new(rr * th.cos(), rr * th.sin(), small * phi.sin()));
        }
    }
    let mut m = grid_triangles(v.clone(), nu, nv - 1, true);
    // Close the seam between the last and the first ring.
    let mut t = m.triangles().to_vec();
    let ring = |j: u32, i: u32| j * nu + (i % nu);
    for i in 0..nu {
        t.push([ring(nv - 1, i), ring(nv - 1, i + 1), ring(0, i + 1)]);
        t.push([ring(nv - 1, i), ring(0, i + 1), ring(0, i)]);
    }
    m = TriMesh::new(v, t).unwrap();
    m
}

/// A bumpy height field over `[-s, s]²` with `n × n` quads (an open surface).
pub fn terrain(s: f32, n: u32, seed: u64) -> TriMesh {
    use rand::SeedableRng;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut v = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let x = -s + 2.0 * s * i as f32 / n as f32;
            let y = -s + 2.0 * s * j as f32 / n as f32;
            let z = (x * 0.7).sin() * (y * 0.5).cos() * s * 0.1 + rng.gen_range(-0.02..0.02) * s;
            v.push(Vec3::new(x, y, z));
        }
    }
    let mut t = Vec::new();
    let id = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriMesh::new(v, t).unwrap()
}

fn grid_triangles(v: Vec<Vec3>, nu: u32, nv: u32, wrap: bool) -> TriMesh {
    let mut t = Vec::new();
    let id = |i: u32, j: u32| j * nu + if wrap { i % nu } else { i };
    for j in 0..nv {
        for i in 0..nu {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriMesh::new(v, t).unwrap()
}

/// A uniformly random rotation and a translation uniform in `[lo, hi]`.
pub fn random_pose(rng: &mut impl Rng, lo: Vec3, hi: Vec3) -> Affine3A {
    // Shoemake's uniform quaternion.
    let (u1, u2, u3): (f32, f32, f32) = (rng.gen(), rng.gen(), rng.gen());
    let q = Quat::from_xyzw(
        (1.0 - u1).sqrt() * (TAU * u2).sin(),
        (1.0 - u1).sqrt() * (TAU * u2).cos(),
        u1.sqrt() * (TAU * u3).sin(),
        u1.sqrt() * (TAU * u3).cos(),
    )
    .normalize();
    let t = Vec3::new(
        rng.gen_range(lo.x..=hi.x),
        rng.gen_range(lo.y..=hi.y),
        rng.gen_range(lo.z..=hi.z),
    );
    Affine3A::from_rotation_translation(q, t)
}
