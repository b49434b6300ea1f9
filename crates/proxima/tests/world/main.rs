//! The collision world against a brute-force world: long random sequences of
//! inserts, poses, removals, ignores, filter changes and queries, for every
//! index kind and several bounding volumes, `validate()` after every step;
//! coherence on and off; bad input.
//!
//! Every world here holds `u64` values: each other value type compiles the
//! whole world again (`World<u32, _>` and `World<u8>` beside `World<u64, _>`
//! cost 343 against 298 s of CPU to build this test, the largest unit of CI's
//! build), and the value type changes nothing the tests check.

mod brute;
mod coherence;
mod distance;
mod errors;
mod oracle;
#[cfg(feature = "parallel")]
mod par;

use proxima::glam::{Affine3A, Quat, Vec3};
use proxima::narrow::{BoundingVolume, Mesh, TriMesh};
use rand::Rng;
use std::sync::Arc;

/// A mesh as plain data (what the brute-force world reads).
#[derive(Clone, Debug)]
pub struct MeshData {
    pub vertices: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl MeshData {
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        self.triangles[i].map(|v| self.vertices[v as usize])
    }

    pub fn mesh<BV: BoundingVolume>(&self) -> Mesh<BV> {
        Mesh::new(self.vertices.clone(), self.triangles.clone()).unwrap()
    }
}

/// A unit cube centred on the origin (12 triangles): crates that rest face to
/// face at integer poses touch exactly.
pub fn crate_mesh() -> MeshData {
    let v: Vec<Vec3> = (0..8)
        .map(|i| {
            Vec3::new(
                (i & 1) as f32 - 0.5,
                (i >> 1 & 1) as f32 - 0.5,
                (i >> 2 & 1) as f32 - 0.5,
            )
        })
        .collect();
    let q = |a: u32, b: u32, c: u32, d: u32| [[a, b, c], [a, c, d]];
    let t = [
        q(0, 2, 3, 1),
        q(4, 5, 7, 6),
        q(0, 1, 5, 4),
        q(2, 6, 7, 3),
        q(0, 4, 6, 2),
        q(1, 3, 7, 5),
    ]
    .concat();
    MeshData {
        vertices: v,
        triangles: t,
    }
}

/// A tetrahedron.
pub fn tetra() -> MeshData {
    MeshData {
        vertices: vec![
            Vec3::new(-0.4, -0.3, -0.3),
            Vec3::new(0.5, -0.3, -0.2),
            Vec3::new(0.0, 0.5, -0.3),
            Vec3::new(0.0, 0.0, 0.5),
        ],
        triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    }
}

/// An icosahedron with jittered corners (20 triangles), about 0.6 across.
pub fn rock(rng: &mut impl Rng) -> MeshData {
    let p = (1.0 + 5f32.sqrt()) / 2.0;
    let mut v = vec![
        Vec3::new(-1.0, p, 0.0),
        Vec3::new(1.0, p, 0.0),
        Vec3::new(-1.0, -p, 0.0),
        Vec3::new(1.0, -p, 0.0),
        Vec3::new(0.0, -1.0, p),
        Vec3::new(0.0, 1.0, p),
        Vec3::new(0.0, -1.0, -p),
        Vec3::new(0.0, 1.0, -p),
        Vec3::new(p, 0.0, -1.0),
        Vec3::new(p, 0.0, 1.0),
        Vec3::new(-p, 0.0, -1.0),
        Vec3::new(-p, 0.0, 1.0),
    ];
    for x in &mut v {
        *x = *x * 0.3 * rng.gen_range(0.8..1.2);
    }
    let t = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    MeshData {
        vertices: v,
        triangles: t,
    }
}

/// An open, bumpy sheet (`2 n²` triangles) about 1.2 wide, with a degenerate
/// triangle added.
pub fn sheet(n: u32) -> MeshData {
    let mut v = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f32 / n as f32 - 0.5, j as f32 / n as f32 - 0.5);
            v.push(Vec3::new(
                x * 1.2,
                y * 1.2,
                0.15 * (x * 7.0).sin() * (y * 5.0).cos(),
            ));
        }
    }
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..n {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    t.push([id(0, 0), id(1, 0), id(1, 0)]);
    MeshData {
        vertices: v,
        triangles: t,
    }
}

/// `rob.obj` of the shared data (216 triangles), scaled to a longest side of
/// 1.2 and centred.
pub fn rob() -> MeshData {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/");
    let m: TriMesh = proxima::io::load(format!("{dir}rob.obj")).unwrap();
    let (lo, hi) = m.vertices().iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(l, h), v| (l.min(*v), h.max(*v)),
    );
    let (c, s) = ((lo + hi) * 0.5, 1.2 / (hi - lo).max_element());
    MeshData {
        vertices: m.vertices().iter().map(|v| (*v - c) * s).collect(),
        triangles: m.triangles().to_vec(),
    }
}

/// The meshes the random sequences draw from.
pub fn meshes(rng: &mut impl Rng) -> Vec<Arc<MeshData>> {
    vec![
        Arc::new(crate_mesh()),
        Arc::new(tetra()),
        Arc::new(rock(rng)),
        Arc::new(sheet(4)),
        Arc::new(rob()),
    ]
}

/// A random rigid pose with its centre in the cube `[-h, h]³`.
pub fn random_pose(rng: &mut impl Rng, h: f32) -> Affine3A {
    let q = Quat::from_xyzw(
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
    )
    .normalize();
    let t = Vec3::new(
        rng.gen_range(-h..h),
        rng.gen_range(-h..h),
        rng.gen_range(-h..h),
    );
    Affine3A::from_rotation_translation(q, t)
}

/// A pose that moves `pose` a little (a small rotation and step).
pub fn nudge(rng: &mut impl Rng, pose: &Affine3A, step: f32) -> Affine3A {
    let axis = Vec3::new(
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
    )
    .normalize_or(Vec3::Z);
    let r = Quat::from_axis_angle(axis, rng.gen_range(-step..step));
    let (_, q, t) = pose.to_scale_rotation_translation();
    let d = Vec3::new(
        rng.gen_range(-step..step),
        rng.gen_range(-step..step),
        rng.gen_range(-step..step),
    );
    Affine3A::from_rotation_translation((r * q).normalize(), t + d)
}

/// An exact pose: a rotation by a multiple of 90° about a coordinate axis and
/// a translation by halves (crates placed like this touch exactly).
pub fn grid_pose(rng: &mut impl Rng, h: i32) -> Affine3A {
    let quarter = std::f32::consts::FRAC_PI_2 * rng.gen_range(0..4) as f32;
    let rot = match rng.gen_range(0..3) {
        0 => proxima::glam::Mat3A::from_rotation_x(quarter),
        1 => proxima::glam::Mat3A::from_rotation_y(quarter),
        _ => proxima::glam::Mat3A::from_rotation_z(quarter),
    };
    // Round the matrix to its exact entries (0, ±1).
    let rot =
        proxima::glam::Mat3A::from_cols(rot.x_axis.round(), rot.y_axis.round(), rot.z_axis.round());
    let t = Vec3::new(
        rng.gen_range(-h..=h) as f32 * 0.5,
        rng.gen_range(-h..=h) as f32 * 0.5,
        rng.gen_range(-h..=h) as f32 * 0.5,
    );
    Affine3A::from_mat3_translation(rot.into(), t)
}
