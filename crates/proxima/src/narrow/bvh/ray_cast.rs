//! Ray and segment casts against a [`RayBvh`].

use super::ray::RayHit;
use super::ray_tree::{RayBvh, RayNode, LEAF};
use crate::geom::{Ray, Segment};
use crate::narrow::bv::BoundingVolume;
use crate::narrow::ray_triangle::{RayFilter, WoopRay};
use crate::Result;
use glam::{Vec3, Vec3A, Vec4};

/// Relative widening of the box entry and exit parameters: the subtraction, the
/// rounded reciprocal and the product each round by at most ε/2.
const WIDEN: f32 = 4.0 * f32::EPSILON;

/// Slots of the traversal stack kept on the machine stack (deeper trees spill).
const STACK: usize = 16;

/// A LIFO of `(node, entry t)` on the machine stack, spilling to the heap only for
/// trees deeper than [`STACK`].
pub(crate) struct Stack {
    items: [(u32, f32); STACK],
    len: usize,
    spill: Vec<(u32, f32)>,
}

impl Stack {
    #[inline(always)]
    pub(crate) fn new() -> Stack {
        Stack {
            items: [(0, 0.0); STACK],
            len: 0,
            spill: Vec::new(),
        }
    }

    #[inline(always)]
    pub(crate) fn push(&mut self, x: (u32, f32)) {
        if self.len < STACK {
            self.items[self.len] = x;
            self.len += 1;
        } else {
            self.spill.push(x);
        }
    }

    #[inline(always)]
    pub(crate) fn pop(&mut self) -> Option<(u32, f32)> {
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

/// The ray in the form the 4-wide slab test wants: origin and inverse direction
/// splatted per axis, and which side of each slab the ray enters by.
struct Slabs {
    o: [Vec4; 3],
    inv: [Vec4; 3],
    /// `neg[a]`: the direction is negative on axis `a` (enters by the max side).
    neg: [bool; 3],
}

/// Entry parameters of the ray into the four lanes of `n` and the mask of lanes it
/// enters at or before `limit`: slab test with the precomputed inverse direction
/// (all finite) and the near/far side of each slab chosen once per ray by the
/// direction's signs, the interval widened by [`WIDEN`] so rounding never culls a
/// box the ray touches. Only vertical SIMD operations.
#[inline(always)]
fn entry4(n: &RayNode, s: &Slabs, limit: f32) -> (Vec4, u32) {
    let mut near = Vec4::ZERO;
    let mut far = Vec4::splat(limit);
    for a in 0..3 {
        let (np, fp) = if s.neg[a] {
            (n.hi[a], n.lo[a])
        } else {
            (n.lo[a], n.hi[a])
        };
        near = near.max((np - s.o[a]) * s.inv[a]);
        far = far.min((fp - s.o[a]) * s.inv[a]);
    }
    let near = near * (1.0 - WIDEN);
    // `limit` was in `far` before widening: a box entered exactly at the best
    // hit is kept (a tie may go to a smaller triangle index).
    let far = far * (1.0 + WIDEN);
    (near, near.cmple(far).bitmask() & ((1u32 << n.len) - 1))
}

/// [`entry4`] for a ray with a zero or subnormal direction component: the general
/// slab clip of each lane, which tests the origin against a slab the ray runs
/// parallel to.
fn entry4_general(n: &RayNode, ray: &Ray, limit: f32) -> (Vec4, u32) {
    let mut near = Vec4::ZERO;
    let mut mask = 0;
    for k in 0..n.len as usize {
        if let Some(t) = n.lane(k).ray_entry(ray, 0.0).filter(|&t| t <= limit) {
            near[k] = t;
            mask |= 1 << k;
        }
    }
    (near, mask)
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
        let inv = Vec3::ONE / ray.dir;
        let finite = inv.is_finite();
        if !finite || self.root_link & LEAF != 0 {
            // (Otherwise the root node's lanes are the first test.)
            let root = self.root.ray_entry(ray, 0.0)?;
            if root > ray.max_t {
                return None;
            }
        }
        if finite {
            let o = ray.origin;
            let s = Slabs {
                o: [Vec4::splat(o.x), Vec4::splat(o.y), Vec4::splat(o.z)],
                inv: [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)],
                neg: [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0],
            };
            self.traverse(ray, any, |n, limit| entry4(n, &s, limit))
        } else {
            self.traverse(ray, any, |n, limit| entry4_general(n, ray, limit))
        }
    }

    /// Front-to-back descent: at each node the four lanes are tested at once, the
    /// nearest entered child is visited next and the others are stacked, farthest
    /// first, with their entry `t`; a node entered beyond the best hit so far is
    /// skipped.
    #[inline(always)]
    fn traverse(
        &self,
        ray: &Ray,
        any: bool,
        entry: impl Fn(&RayNode, f32) -> (Vec4, u32),
    ) -> Option<RayHit> {
        let filter = RayFilter::new(ray);
        // The exact test's per-ray setup, on the first triangle that needs it.
        let mut woop: Option<WoopRay> = None;
        let mut best: Option<RayHit> = None;
        let mut limit = ray.max_t;
        let mut stack = Stack::new();
        let mut cur = self.root_link;
        loop {
            if cur & LEAF == 0 {
                let n = &self.nodes[cur as usize];
                let (near, mut mask) = entry(n, limit);
                if mask != 0 {
                    let first = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if mask == 0 {
                        // One lane entered (the common case): no sorting.
                        cur = n.child[first];
                        continue;
                    }
                    // Entered lanes sorted by entry t (at most four: insertion).
                    let mut hits = [(n.child[first], near[first]); 4];
                    let mut k = 1;
                    while mask != 0 {
                        let lane = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        let item = (n.child[lane], near[lane]);
                        let mut j = k;
                        while j > 0 && hits[j - 1].1 > item.1 {
                            hits[j] = hits[j - 1];
                            j -= 1;
                        }
                        hits[j] = item;
                        k += 1;
                    }
                    for h in hits[1..k].iter().rev() {
                        stack.push(*h);
                    }
                    cur = hits[0].0;
                    continue;
                }
            } else {
                let [s, count] = self.leaves[(cur & !LEAF) as usize];
                for k in s as usize..(s + count) as usize {
                    let t = &self.tris[k];
                    let e1 = t.v[0] - t.v[1];
                    let e2 = t.v[2] - t.v[0];
                    if !filter.may_hit(t.v[0], e1, e2, Vec3A::from_vec4(t.ng), t.ng.w, limit) {
                        continue;
                    }
                    let w = woop.get_or_insert_with(|| WoopRay::new(ray));
                    let Some(h) = w.hit(&[t.v[0].into(), t.v[1].into(), t.v[2].into()]) else {
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
