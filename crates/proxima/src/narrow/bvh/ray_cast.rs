//! Ray and segment casts against a [`RayBvh`].

use super::ray::RayHit;
use super::ray_tree::{RayBvh, RayNode};
use crate::geom::{Ray, Segment};
use crate::narrow::bv::BoundingVolume;
use crate::narrow::ray_triangle::{RayFilter, WoopRay};
use crate::Result;
use glam::{Vec3, Vec3A};

/// Relative widening of the box entry and exit parameters: the subtraction, the
/// rounded reciprocal and the product each round by at most ε/2.
const WIDEN: f32 = 4.0 * f32::EPSILON;

/// Slots of the traversal stack kept on the machine stack (deeper trees spill).
const STACK: usize = 32;

/// A LIFO of `(node, entry t)` on the machine stack, spilling to the heap only for
/// trees deeper than [`STACK`].
struct Stack {
    items: [(u32, f32); STACK],
    len: usize,
    spill: Vec<(u32, f32)>,
}

impl Stack {
    #[inline(always)]
    fn new() -> Stack {
        Stack {
            items: [(0, 0.0); STACK],
            len: 0,
            spill: Vec::new(),
        }
    }

    #[inline(always)]
    fn push(&mut self, x: (u32, f32)) {
        if self.len < STACK {
            self.items[self.len] = x;
            self.len += 1;
        } else {
            self.spill.push(x);
        }
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<(u32, f32)> {
        if let Some(x) = self.spill.pop() {
            return Some(x);
        }
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        Some(self.items[self.len])
    }
}

/// Entry parameter of the ray into node `n` if it enters at or before `limit`:
/// slab test with the precomputed inverse direction `inv` (all finite), the
/// interval widened by [`WIDEN`] so rounding never culls a box the ray touches.
#[inline(always)]
fn entry_fast(n: &RayNode, o: Vec3A, inv: Vec3A, limit: f32) -> Option<f32> {
    let t0 = (Vec3A::from_vec4(n.lo) - o) * inv;
    let t1 = (Vec3A::from_vec4(n.hi) - o) * inv;
    let near = t0.min(t1).max_element().max(0.0) * (1.0 - WIDEN);
    let far = t0.max(t1).min_element() * (1.0 + WIDEN);
    (near <= far && near <= limit).then_some(near)
}

impl RayBvh {
    /// The closest hit of `ray` (smallest `t`, ties to the smaller triangle index):
    /// exactly [`Bvh::cast_ray`](crate::narrow::Bvh::cast_ray)'s answer, faster.
    /// O(log n) typical. Fails on an invalid ray.
    pub fn cast_ray(&self, ray: &Ray) -> Result<Option<RayHit>> {
        ray.validate()?;
        Ok(self.cast_valid(ray, false))
    }

    /// Whether `ray` hits the mesh: some hit (not necessarily the closest), found
    /// with an early exit. Fails on an invalid ray.
    pub fn ray_hits_any(&self, ray: &Ray) -> Result<Option<RayHit>> {
        ray.validate()?;
        Ok(self.cast_valid(ray, true))
    }

    /// [`RayBvh::cast_ray`] for the segment from `seg.a` (`t = 0`) to `seg.b` (`t = 1`).
    pub fn cast_segment(&self, seg: &Segment) -> Result<Option<RayHit>> {
        self.cast_ray(&seg.to_ray())
    }

    /// The cast of a validated ray.
    pub(crate) fn cast_valid(&self, ray: &Ray, any: bool) -> Option<RayHit> {
        let inv = Vec3A::ONE / Vec3A::from(ray.dir);
        if inv.is_finite() {
            let o = Vec3A::from(ray.origin);
            self.traverse(ray, any, |n, limit| entry_fast(n, o, inv, limit))
        } else {
            // A zero (or subnormal) direction component: the general slab clip,
            // which tests the origin against a slab the ray runs parallel to.
            self.traverse(ray, any, |n, limit| {
                n.aabb().ray_entry(ray, 0.0).filter(|&t| t <= limit)
            })
        }
    }

    /// Front-to-back descent: at each internal node both children are tested, the
    /// nearer is visited next and the farther stacked with its entry `t`; a node
    /// entered beyond the best hit so far is skipped.
    #[inline(always)]
    fn traverse(
        &self,
        ray: &Ray,
        any: bool,
        entry: impl Fn(&RayNode, f32) -> Option<f32>,
    ) -> Option<RayHit> {
        let filter = RayFilter::new(ray);
        let woop = WoopRay::new(ray);
        let mut best: Option<RayHit> = None;
        let mut limit = ray.max_t;
        let mut stack = Stack::new();
        let mut cur = match entry(&self.nodes[0], limit) {
            Some(_) => 0u32,
            None => return None,
        };
        loop {
            let n = &self.nodes[cur as usize];
            let count = n.count();
            if count == 0 {
                let c = n.link();
                let a = entry(&self.nodes[c as usize], limit);
                let b = entry(&self.nodes[c as usize + 1], limit);
                match (a, b) {
                    (Some(ta), Some(tb)) => {
                        if ta <= tb {
                            stack.push((c + 1, tb));
                            cur = c;
                        } else {
                            stack.push((c, ta));
                            cur = c + 1;
                        }
                        continue;
                    }
                    (Some(_), None) => {
                        cur = c;
                        continue;
                    }
                    (None, Some(_)) => {
                        cur = c + 1;
                        continue;
                    }
                    (None, None) => {}
                }
            } else {
                let s = n.link() as usize;
                for k in s..s + count as usize {
                    let t = &self.tris[k];
                    let e1 = t.v[0] - t.v[1];
                    let e2 = t.v[2] - t.v[0];
                    if !filter.may_hit(t.v[0], e1, e2, Vec3A::from_vec4(t.ng), t.ng.w, limit) {
                        continue;
                    }
                    let Some(h) = woop.hit(&t.v.map(Vec3::from)) else {
                        continue;
                    };
                    let id = self.ids[k];
                    if best.map_or(true, |b| h.t < b.t || (h.t == b.t && id < b.triangle)) {
                        best = Some(RayHit {
                            triangle: id,
                            t: h.t,
                            u: h.u,
                            v: h.v,
                        });
                        if any {
                            return best;
                        }
                        limit = h.t;
                    }
                }
            }
            // Next stacked node still entered no later than the best hit.
            loop {
                match stack.pop() {
                    None => return best,
                    Some((i, t)) if t <= limit => {
                        cur = i;
                        break;
                    }
                    Some(_) => {}
                }
            }
        }
    }
}
