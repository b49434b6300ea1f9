//! The brute-force world: every object pair, every triangle pair, every
//! triangle for rays and spheres, with the exact primitive tests of the library
//! (`triangles_intersect`, `sphere_triangle`, `ray_triangle`, the sphere tests),
//! each checked against exact arithmetic in its own suite. It shares no code
//! with `proxima::world`; it applies the same definition: a mesh pair is tested
//! in the frame of the mesh with fewer triangles (on a tie, of the object
//! inserted first), the other moved by `pose_fixed⁻¹ · pose_moving` in `f32`.
//!
//! Box pre-checks (comparisons of the very `f32` corners that the exact tests
//! receive) change no answer: a shared point lies in both boxes.

use super::MeshData;
use proxima::broad::Filter;
use proxima::geom::{overlap, Ray, Sphere};
use proxima::glam::{Affine3A, Vec3};
use proxima::narrow::{ray_triangle, sphere_triangle, triangles_intersect};
use proxima::Handle;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub enum BShape {
    Mesh(Arc<MeshData>),
    Ball(f32),
}

#[derive(Clone, Debug)]
pub struct BObj {
    pub shape: BShape,
    pub pose: Affine3A,
    pub filter: Filter,
    pub seq: u64,
}

/// Contacts keyed by `(a, b)` with `a < b`, each with its sorted primitive pairs
/// `(primitive of a, primitive of b)`.
pub type ContactMap = BTreeMap<(Handle, Handle), Vec<(u32, u32)>>;

#[derive(Clone, Debug, Default)]
pub struct BruteWorld {
    pub objects: BTreeMap<Handle, BObj>,
    pub ignored: BTreeSet<(Handle, Handle)>,
    seq: u64,
}

fn key(a: Handle, b: Handle) -> (Handle, Handle) {
    if a < b {
        (a, b)
    } else {
        (b, a)
    }
}

fn bounds(t: &[Vec3; 3]) -> (Vec3, Vec3) {
    (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]))
}

fn boxes_meet(a: &(Vec3, Vec3), b: &(Vec3, Vec3)) -> bool {
    a.0.cmple(b.1).all() && b.0.cmple(a.1).all()
}

impl BruteWorld {
    pub fn insert(&mut self, h: Handle, shape: BShape, pose: Affine3A, filter: Filter) {
        let seq = self.seq;
        self.seq += 1;
        self.objects.insert(
            h,
            BObj {
                shape,
                pose,
                filter,
                seq,
            },
        );
    }

    pub fn remove(&mut self, h: Handle) {
        self.objects.remove(&h);
        self.ignored.retain(|&(a, b)| a != h && b != h);
    }

    /// Every contact of the world.
    pub fn contacts(&self) -> ContactMap {
        let mut out = ContactMap::new();
        let objs: Vec<(&Handle, &BObj)> = self.objects.iter().collect();
        for i in 0..objs.len() {
            for j in i + 1..objs.len() {
                let ((&ha, a), (&hb, b)) = (objs[i], objs[j]);
                if !a.filter.interacts(b.filter) || self.ignored.contains(&key(ha, hb)) {
                    continue;
                }
                let pairs = pair(a, b);
                if !pairs.is_empty() {
                    out.insert((ha, hb), pairs);
                }
            }
        }
        out
    }

    /// The first hit: `(t, handle, triangle)` smallest.
    pub fn ray_cast(&self, ray: &Ray, filter: Filter) -> Option<(Handle, u32, f32)> {
        self.ray_hits(ray, filter).into_iter().next()
    }

    /// Every object hit with its first hit, sorted by `(t, handle)`.
    pub fn ray_hits(&self, ray: &Ray, filter: Filter) -> Vec<(Handle, u32, f32)> {
        let mut out = Vec::new();
        for (&h, o) in &self.objects {
            if !filter.interacts(o.filter) {
                continue;
            }
            let hit = match &o.shape {
                BShape::Mesh(m) => {
                    let inv = o.pose.inverse();
                    let local = Ray::with_max_t(
                        inv.transform_point3(ray.origin),
                        inv.transform_vector3(ray.dir),
                        ray.max_t,
                    );
                    let mut best: Option<(f32, u32)> = None;
                    for k in 0..m.triangles.len() {
                        if let Some(hit) = ray_triangle(&local, &m.triangle(k)) {
                            if best.is_none_or(|b| (hit.t, k as u32) < b) {
                                best = Some((hit.t, k as u32));
                            }
                        }
                    }
                    best
                }
                BShape::Ball(r) => {
                    overlap::ray_sphere(ray, &Sphere::new(o.pose.translation.into(), *r))
                        .map(|t| (t, 0))
                }
            };
            if let Some((t, tri)) = hit {
                out.push((h, tri, t));
            }
        }
        out.sort_by(|a, b| (a.2, a.0, a.1).partial_cmp(&(b.2, b.0, b.1)).unwrap());
        out
    }

    /// The objects with a point within `r` of `c`, sorted.
    pub fn overlap_sphere(&self, c: Vec3, r: f32, filter: Filter) -> Vec<Handle> {
        let mut out = Vec::new();
        for (&h, o) in &self.objects {
            if !filter.interacts(o.filter) {
                continue;
            }
            let near = match &o.shape {
                BShape::Mesh(m) => {
                    let cl = o.pose.inverse().transform_point3(c);
                    (0..m.triangles.len()).any(|k| sphere_triangle(cl, r, &m.triangle(k)))
                }
                BShape::Ball(rb) => overlap::sphere_sphere(
                    &Sphere::new(c, r),
                    &Sphere::new(o.pose.translation.into(), *rb),
                ),
            };
            if near {
                out.push(h);
            }
        }
        out
    }
}

/// The primitive pairs of two objects, `(primitive of a, primitive of b)`,
/// sorted.
fn pair(a: &BObj, b: &BObj) -> Vec<(u32, u32)> {
    let mut out = match (&a.shape, &b.shape) {
        (BShape::Mesh(ma), BShape::Mesh(mb)) => {
            let a_moves = (ma.triangles.len(), a.seq) > (mb.triangles.len(), b.seq);
            if a_moves {
                mesh_pairs(ma, &a.pose, mb, &b.pose)
            } else {
                mesh_pairs(mb, &b.pose, ma, &a.pose)
                    .into_iter()
                    .map(|(x, y)| (y, x))
                    .collect()
            }
        }
        (BShape::Ball(r), BShape::Mesh(m)) => ball_mesh(a, *r, m, &b.pose)
            .into_iter()
            .map(|t| (0, t))
            .collect(),
        (BShape::Mesh(m), BShape::Ball(r)) => ball_mesh(b, *r, m, &a.pose)
            .into_iter()
            .map(|t| (t, 0))
            .collect(),
        (BShape::Ball(ra), BShape::Ball(rb)) => {
            let sa = Sphere::new(a.pose.translation.into(), *ra);
            let sb = Sphere::new(b.pose.translation.into(), *rb);
            if overlap::sphere_sphere(&sa, &sb) {
                vec![(0, 0)]
            } else {
                Vec::new()
            }
        }
    };
    out.sort_unstable();
    out
}

/// Every intersecting triangle pair of `mv` moved into the frame of `fx`.
fn mesh_pairs(
    mv: &MeshData,
    pose_mv: &Affine3A,
    fx: &MeshData,
    pose_fx: &Affine3A,
) -> Vec<(u32, u32)> {
    let rel = pose_fx.inverse() * *pose_mv;
    let moved: Vec<[Vec3; 3]> = (0..mv.triangles.len())
        .map(|i| mv.triangle(i).map(|v| rel.transform_point3(v)))
        .collect();
    let fixed: Vec<[Vec3; 3]> = (0..fx.triangles.len()).map(|j| fx.triangle(j)).collect();
    let fixed_boxes: Vec<_> = fixed.iter().map(bounds).collect();
    let all = |ts: &[[Vec3; 3]]| {
        ts.iter()
            .map(bounds)
            .fold((Vec3::MAX, Vec3::MIN), |(l, h), (a, b)| {
                (l.min(a), h.max(b))
            })
    };
    let mut out = Vec::new();
    if !boxes_meet(&all(&moved), &all(&fixed)) {
        return out;
    }
    for (i, t) in moved.iter().enumerate() {
        let bt = bounds(t);
        for (j, u) in fixed.iter().enumerate() {
            if boxes_meet(&bt, &fixed_boxes[j]) && triangles_intersect(t, u) {
                out.push((i as u32, j as u32));
            }
        }
    }
    out
}

/// The triangles of `m` (at `pose_m`) within `r` of the ball object's centre.
fn ball_mesh(ball: &BObj, r: f32, m: &MeshData, pose_m: &Affine3A) -> Vec<u32> {
    let c = pose_m
        .inverse()
        .transform_point3(ball.pose.translation.into());
    (0..m.triangles.len() as u32)
        .filter(|&k| sphere_triangle(c, r, &m.triangle(k as usize)))
        .collect()
}
