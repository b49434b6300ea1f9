//! The brute-force world of `proxima world --check` [sources: world]: every
//! object pair, every triangle pair (`triangles_intersect` on the posed `f32`
//! vertices), every triangle for rays (`ray_triangle`) and spheres
//! (`sphere_triangle`). It shares no code with `proxima::world` and applies the
//! same definition of a mesh pair's frame: the mesh with more triangles (on a
//! tie, the object added later) is moved into the other's frame by
//! `pose_fixed⁻¹ · pose_moving`, computed in `f32`.
//!
//! Two shortcuts keep it affordable without changing an answer. An object pair
//! is skipped when the world boxes of the two meshes' local boxes, moved by
//! their poses and grown by a margin far above the rounding of either frame
//! (`1e-3` of the coordinates' magnitude), are disjoint: posed meshes that
//! share a point have overlapping boxes; a ray skips an object whose grown box
//! it misses (the conservative `ray_aabb`). Triangle pairs are found by sweeping
//! the triangles' boxes along x (sort and sweep), then deciding every pair of
//! overlapping boxes exactly; those boxes are of the very `f32` corners the
//! exact test receives, and two triangles that share a point have overlapping
//! boxes. Hundreds of objects and meshes of tens of thousands of triangles stay
//! affordable.

use crate::world_replay::WorldAnswer;
use crate::world_trace::{WorldOp, WorldTrace};
use proxima::geom::overlap::ray_aabb;
use proxima::geom::{Aabb, Ray};
use proxima::glam::{Affine3A, BVec3, Vec3};
use proxima::narrow::{ray_triangle, sphere_triangle, triangles_intersect};
use std::collections::HashSet;

/// A live object: mesh, pose, insertion number.
#[derive(Clone, Copy, Debug)]
struct Obj {
    mesh: u32,
    pose: Affine3A,
    seq: u64,
}

/// A triangle with its box.
#[derive(Clone, Copy, Debug)]
struct Boxed {
    tri: [Vec3; 3],
    lo: Vec3,
    hi: Vec3,
    id: u32,
}

impl Boxed {
    fn new(tri: [Vec3; 3], id: u32) -> Boxed {
        Boxed {
            tri,
            lo: tri[0].min(tri[1]).min(tri[2]),
            hi: tri[0].max(tri[1]).max(tri[2]),
            id,
        }
    }
}

/// The brute-force world over a trace's meshes.
pub struct BruteWorld<'t> {
    trace: &'t WorldTrace,
    /// Each mesh's triangles in its own frame, sorted by `lo.x`.
    local: Vec<Vec<Boxed>>,
    /// Each mesh's box in its own frame.
    bounds: Vec<(Vec3, Vec3)>,
    objects: Vec<Option<Obj>>,
    ignored: HashSet<(u32, u32)>,
    seq: u64,
    first: bool,
}

impl<'t> BruteWorld<'t> {
    /// An empty brute-force world for `trace`; with `first`, contacts count
    /// object pairs only.
    pub fn new(trace: &'t WorldTrace, first: bool) -> Self {
        let local = trace
            .meshes
            .iter()
            .map(|m| {
                let mut v: Vec<Boxed> = (0..m.len())
                    .map(|i| Boxed::new(m.triangle(i), i as u32))
                    .collect();
                v.sort_by(|a, b| a.lo.x.total_cmp(&b.lo.x));
                v
            })
            .collect::<Vec<Vec<Boxed>>>();
        let bounds = local
            .iter()
            .map(|tris| {
                tris.iter()
                    .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), t| {
                        (lo.min(t.lo), hi.max(t.hi))
                    })
            })
            .collect();
        BruteWorld {
            trace,
            local,
            bounds,
            objects: vec![None; trace.ids.len()],
            ignored: HashSet::new(),
            seq: 0,
            first,
        }
    }

    /// Applies one operation; a query returns its answer.
    pub fn apply(&mut self, op: &WorldOp) -> Option<WorldAnswer> {
        match *op {
            WorldOp::Mesh { .. } => None,
            WorldOp::Add { slot, mesh } => {
                self.objects[slot as usize] = Some(Obj {
                    mesh,
                    pose: Affine3A::IDENTITY,
                    seq: self.seq,
                });
                self.seq += 1;
                None
            }
            WorldOp::Pose { slot, pose } => {
                if let Some(o) = &mut self.objects[slot as usize] {
                    o.pose = pose;
                }
                None
            }
            WorldOp::Remove { slot } => {
                self.objects[slot as usize] = None;
                self.ignored.retain(|&(a, b)| a != slot && b != slot);
                None
            }
            WorldOp::Ignore { a, b } => {
                self.ignored.insert((a.min(b), a.max(b)));
                None
            }
            WorldOp::Contacts => Some(self.contacts()),
            WorldOp::Ray(ray) => Some(WorldAnswer::Ray(self.ray(&ray))),
            WorldOp::Sphere(s) => Some(WorldAnswer::Sphere(self.sphere(s.center, s.radius))),
        }
    }

    fn live(&self) -> impl Iterator<Item = (u32, &Obj)> + '_ {
        self.objects
            .iter()
            .enumerate()
            .filter_map(|(i, o)| o.as_ref().map(|o| (i as u32, o)))
    }

    /// The world box of an object's posed local box, grown by the margin (see
    /// the module's documentation).
    fn world_box(&self, o: &Obj) -> (Vec3, Vec3) {
        let (lo, hi) = self.bounds[o.mesh as usize];
        let (mut wlo, mut whi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for i in 0..8 {
            let c = Vec3::select(BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0), hi, lo);
            let p = o.pose.transform_point3(c);
            (wlo, whi) = (wlo.min(p), whi.max(p));
        }
        let magnitude = wlo.abs().max(whi.abs()).max_element() + (whi - wlo).max_element();
        let m = Vec3::splat(1e-3 * magnitude + f32::MIN_POSITIVE);
        (wlo - m, whi + m)
    }

    fn contacts(&self) -> WorldAnswer {
        let live: Vec<(u32, &Obj)> = self.live().collect();
        let boxes: Vec<(Vec3, Vec3)> = live.iter().map(|(_, o)| self.world_box(o)).collect();
        let (mut pairs, mut tris) = (0, 0);
        for (i, &(sa, a)) in live.iter().enumerate() {
            for (j, &(sb, b)) in live.iter().enumerate().skip(i + 1) {
                if self.ignored.contains(&(sa.min(sb), sa.max(sb))) {
                    continue;
                }
                let ((alo, ahi), (blo, bhi)) = (boxes[i], boxes[j]);
                if !(alo.cmple(bhi).all() && blo.cmple(ahi).all()) {
                    continue;
                }
                let n = self.pair(a, b);
                pairs += (n > 0) as usize;
                tris += n;
            }
        }
        WorldAnswer::Contacts(pairs, (!self.first).then_some(tris))
    }

    /// The number of intersecting triangle pairs of two objects (with `first`,
    /// 0 or 1).
    fn pair(&self, a: &Obj, b: &Obj) -> usize {
        let len = |o: &Obj| self.local[o.mesh as usize].len();
        let (mv, fx) = if (len(a), a.seq) > (len(b), b.seq) {
            (a, b)
        } else {
            (b, a)
        };
        let rel = fx.pose.inverse() * mv.pose;
        let mut moved: Vec<Boxed> = self.local[mv.mesh as usize]
            .iter()
            .map(|t| Boxed::new(t.tri.map(|v| rel.transform_point3(v)), t.id))
            .collect();
        moved.sort_by(|x, y| x.lo.x.total_cmp(&y.lo.x));
        sweep(&moved, &self.local[fx.mesh as usize], self.first)
    }

    /// The first hit: smallest `t`, then smaller id, then smaller triangle.
    fn ray(&self, ray: &Ray) -> Option<(u64, u32)> {
        let mut best: Option<(f32, u64, u32)> = None;
        for (slot, o) in self.live() {
            let (lo, hi) = self.world_box(o);
            if ray_aabb(ray, &Aabb::new(lo, hi)).is_none() {
                continue;
            }
            let inv = o.pose.inverse();
            let local = Ray::with_max_t(
                inv.transform_point3(ray.origin),
                inv.transform_vector3(ray.dir),
                ray.max_t,
            );
            let id = self.trace.ids[slot as usize];
            for t in &self.local[o.mesh as usize] {
                if let Some(h) = ray_triangle(&local, &t.tri) {
                    let key = (h.t, id, t.id);
                    if best.is_none_or(|b| key < b) {
                        best = Some(key);
                    }
                }
            }
        }
        best.map(|(_, id, tri)| (id, tri))
    }

    /// The number of objects with a triangle within `r` of `c`.
    fn sphere(&self, c: Vec3, r: f32) -> usize {
        self.live()
            .filter(|(_, o)| {
                let cl = o.pose.inverse().transform_point3(c);
                self.local[o.mesh as usize]
                    .iter()
                    .any(|t| sphere_triangle(cl, r, &t.tri))
            })
            .count()
    }
}

/// Sort and sweep along x over two lists sorted by `lo.x`: every pair whose
/// boxes overlap is decided by `triangles_intersect`. Returns the number of
/// intersecting pairs (with `first`, stops at 1).
fn sweep(a: &[Boxed], b: &[Boxed], first: bool) -> usize {
    let (mut i, mut j) = (0, 0);
    let (mut active_a, mut active_b): (Vec<&Boxed>, Vec<&Boxed>) = (Vec::new(), Vec::new());
    let mut n = 0;
    while i < a.len() || j < b.len() {
        let take_a = j == b.len() || (i < a.len() && a[i].lo.x <= b[j].lo.x);
        let (t, mine, other) = if take_a {
            i += 1;
            (&a[i - 1], &mut active_a, &mut active_b)
        } else {
            j += 1;
            (&b[j - 1], &mut active_b, &mut active_a)
        };
        other.retain(|u| u.hi.x >= t.lo.x);
        for u in other.iter() {
            let meet = t.lo.cmple(u.hi).all() && u.lo.cmple(t.hi).all();
            if meet && triangles_intersect(&t.tri, &u.tri) {
                n += 1;
                if first {
                    return n;
                }
            }
        }
        mine.push(t);
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The sweep decides exactly the pairs a double loop over every triangle
    /// pair decides: small random triangles in a small box, many touching.
    #[test]
    fn sweep_equals_every_pair() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(13);
        for round in 0..200 {
            let mut tri = |id| {
                let c = Vec3::new(
                    rng.gen_range(0.0..2.0),
                    rng.gen_range(0.0..2.0),
                    rng.gen_range(0.0..2.0),
                );
                let mut p = || {
                    c + Vec3::new(
                        rng.gen_range(-0.4..0.4),
                        rng.gen_range(-0.4..0.4),
                        rng.gen_range(-0.4..0.4),
                    )
                };
                Boxed::new([p(), p(), p()], id)
            };
            let mut a: Vec<Boxed> = (0..20).map(&mut tri).collect();
            let mut b: Vec<Boxed> = (0..15).map(&mut tri).collect();
            // Shared corners and duplicated triangles: touching counts.
            b[0] = Boxed::new([a[0].tri[0], b[0].tri[1], b[0].tri[2]], 0);
            b[1] = a[1];
            let every = a
                .iter()
                .flat_map(|x| b.iter().map(move |y| (x, y)))
                .filter(|(x, y)| triangles_intersect(&x.tri, &y.tri))
                .count();
            for v in [&mut a, &mut b] {
                v.sort_by(|x, y| x.lo.x.total_cmp(&y.lo.x));
            }
            assert_eq!(sweep(&a, &b, false), every, "round {round}");
            assert_eq!(sweep(&a, &b, true), every.min(1), "round {round}");
        }
    }
}
