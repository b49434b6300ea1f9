//! Ray and segment casts against a [`RayBvh`].

use super::ray_tree::{RayBvh, RayNode, LEAF};
use super::stack::Stack;
use crate::geom::{Ray, Segment};
use crate::narrow::bv::BoundingVolume;
use crate::narrow::ray_triangle::{RayFilter, TriangleHit, WoopRay};
use crate::Result;
use glam::{Vec3, Vec3A, Vec4};

/// Relative widening of the box entry and exit parameters, folded into the
/// inverse direction: the subtraction, the rounded reciprocal, the widening
/// product and the final product each round by at most ε/2, so a factor of
/// `1 ∓ 4ε` keeps the computed entry at or below, and the exit at or above, the
/// exact ones (`(1 − 4ε)(1 + ε/2)⁴ < 1 < (1 + 4ε)(1 − ε/2)⁴`).
const WIDEN: f32 = 4.0 * f32::EPSILON;

/// The ray in the form the 4-wide slab test wants, per axis: the origin splatted
/// and the inverse direction widened down for the entry side and up for the
/// exit side ([`WIDEN`]).
struct Slabs {
    o: [Vec4; 3],
    inv_near: [Vec4; 3],
    inv_far: [Vec4; 3],
}

impl Slabs {
    /// The slabs of a ray from `origin` with finite inverse direction `inv`.
    #[inline(always)]
    fn new(origin: Vec3, inv: Vec3) -> Slabs {
        let lo = inv * (1.0 - WIDEN);
        let hi = inv * (1.0 + WIDEN);
        Slabs {
            o: [0, 1, 2].map(|a| Vec4::splat(origin[a])),
            inv_near: [0, 1, 2].map(|a| Vec4::splat(lo[a])),
            inv_far: [0, 1, 2].map(|a| Vec4::splat(hi[a])),
        }
    }
}

/// Entry parameters of the ray into the four lanes of `n` and the mask of lanes it
/// enters at or before `limit` (widened by [`WIDEN`], so a box entered exactly at
/// the best hit is kept: a tie may go to a smaller triangle index), for a ray of
/// octant `OCT` (bit `a` set when the direction is negative on axis `a`): slab
/// test with the precomputed inverse direction (all finite), the entry side of
/// each slab (the min corner for a positive direction, else the max) fixed at
/// compile time, so a node costs two subtractions, two products, a max and a min
/// per axis, vertical SIMD only (computing both sides and sorting them with a min
/// and a max costs a third more).
/// Unused lanes hold the empty box (`+∞` min, `−∞` max): entered at `+∞`, left
/// at `−∞`, never entered. Rounding never culls a box the ray touches
/// ([`WIDEN`]).
#[inline(always)]
fn entry4<const OCT: usize>(n: &RayNode, s: &Slabs, limit: f32) -> (Vec4, u32) {
    let mut near = Vec4::ZERO;
    let mut far = Vec4::splat(limit * (1.0 + WIDEN));
    for a in 0..3 {
        let k = (OCT >> a) & 1;
        near = near.max((n.b[k][a] - s.o[a]) * s.inv_near[a]);
        far = far.min((n.b[1 - k][a] - s.o[a]) * s.inv_far[a]);
    }
    (near, near.cmple(far).bitmask())
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
    /// O(log n) typical. Fails on an invalid ray (non-finite, zero direction,
    /// negative or NaN `max_t`).
    pub fn cast_ray(&self, ray: &Ray) -> Result<Option<TriangleHit>> {
        ray.validate()?;
        Ok(self.cast_valid(ray, false))
    }

    /// Whether `ray` hits the mesh at all: stops at the first hit found, which
    /// need not be the closest. O(log n) typical. Fails on an invalid ray.
    pub fn intersects_ray(&self, ray: &Ray) -> Result<bool> {
        ray.validate()?;
        Ok(self.cast_valid(ray, true).is_some())
    }

    /// [`RayBvh::cast_ray`] for the segment from `seg.a` (`t = 0`) to `seg.b` (`t = 1`).
    pub fn cast_segment(&self, seg: &Segment) -> Result<Option<TriangleHit>> {
        self.cast_ray(&seg.to_ray())
    }

    /// The cast of a validated ray (`any`: stop at the first hit found).
    pub(crate) fn cast_valid(&self, ray: &Ray, any: bool) -> Option<TriangleHit> {
        let inv = Vec3::ONE / ray.dir;
        if !inv.is_finite() || self.root_link & LEAF != 0 {
            return self.cast_other(ray, any, inv);
        }
        // (The root node's lanes are the first test.)
        self.cast_octant(ray, any, inv)
    }

    /// [`RayBvh::cast_valid`] of a ray with a zero or subnormal direction
    /// component, or on a one-leaf tree: clipped to the root box first. Out of
    /// line, so that the common case needs no stack frame of its own.
    #[inline(never)]
    fn cast_other(&self, ray: &Ray, any: bool, inv: Vec3) -> Option<TriangleHit> {
        let root = self.root.ray_entry(ray, 0.0)?;
        if root > ray.max_t {
            return None;
        }
        if inv.is_finite() {
            self.cast_octant(ray, any, inv)
        } else {
            self.traverse(ray, any, |n, limit| entry4_general(n, ray, limit))
        }
    }

    /// The descent of a ray with finite inverse direction `inv`, by its octant.
    #[inline(always)]
    fn cast_octant(&self, ray: &Ray, any: bool, inv: Vec3) -> Option<TriangleHit> {
        match inv.cmplt(Vec3::ZERO).bitmask() {
            0 => self.traverse_octant::<0>(ray, any, inv),
            1 => self.traverse_octant::<1>(ray, any, inv),
            2 => self.traverse_octant::<2>(ray, any, inv),
            3 => self.traverse_octant::<3>(ray, any, inv),
            4 => self.traverse_octant::<4>(ray, any, inv),
            5 => self.traverse_octant::<5>(ray, any, inv),
            6 => self.traverse_octant::<6>(ray, any, inv),
            _ => self.traverse_octant::<7>(ray, any, inv),
        }
    }

    /// [`RayBvh::traverse`] of a ray of octant `OCT` with finite inverse
    /// direction `inv`: one copy of the descent per octant, so each reads its
    /// slab sides at fixed offsets.
    #[inline(never)]
    fn traverse_octant<const OCT: usize>(
        &self,
        ray: &Ray,
        any: bool,
        inv: Vec3,
    ) -> Option<TriangleHit> {
        let s = Slabs::new(ray.origin, inv);
        self.traverse(ray, any, |n, limit| entry4::<OCT>(n, &s, limit))
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
    ) -> Option<TriangleHit> {
        let filter = RayFilter::new(ray);
        // The exact test's per-ray setup, on the first triangle that needs it.
        let mut woop: Option<WoopRay> = None;
        let mut best: Option<TriangleHit> = None;
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
                    // Lanes read from an array: indexing a Vec4 by a variable
                    // compiles to a jump table (an indirect branch per read).
                    let near = near.to_array();
                    let second = mask.trailing_zeros() as usize;
                    if mask & (mask - 1) == 0 {
                        // Two lanes (the common multi-lane case): the nearer
                        // next, the other stacked, chosen without a branch.
                        let (a, b) = (first, second);
                        let swap = near[b] < near[a];
                        let (a, b) = if swap { (b, a) } else { (a, b) };
                        stack.push((n.child[b], near[b]));
                        cur = n.child[a];
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
                let [s, count, first] = self.leaves[(cur & !LEAF) as usize];
                // Four triangles per pre-test, then the exact test on the
                // survivors nearest first: a leaf often holds several triangles
                // the ray crosses (both faces of a thin wall), and once the near
                // one is hit the far ones fail the pre-test against the new limit.
                for q in 0..count.div_ceil(4) {
                    let lanes = (count - 4 * q).min(4);
                    let (mask, est) = filter.may_hit4(&self.packets[(first + q) as usize], limit);
                    let mask = mask & ((1 << lanes) - 1);
                    if mask == 0 {
                        continue;
                    }
                    if self.exact_tests(
                        s + 4 * q,
                        mask,
                        est,
                        &filter,
                        ray,
                        &mut woop,
                        &mut best,
                        any,
                    ) {
                        return best;
                    }
                    limit = best.map_or(limit, |b| b.t);
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

    /// The exact tests of the pre-tested lanes `mask` of the packet of triangles
    /// from leaf-order index `base`, in order of the estimates `est`: the first
    /// runs at once, each later one only if it still passes the pre-test against
    /// the best hit so far. Updates `best` (smallest `t`, ties to the smaller
    /// triangle index, so the order of the tests never changes the answer); true
    /// when `any` and a hit was found (the caller returns it).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn exact_tests(
        &self,
        base: u32,
        mut mask: u32,
        est: Vec4,
        filter: &RayFilter,
        ray: &Ray,
        woop: &mut Option<WoopRay>,
        best: &mut Option<TriangleHit>,
        any: bool,
    ) -> bool {
        // Lanes by estimate (at most four: insertion; NaN estimates compare
        // false and stay where they are).
        let est = est.to_array();
        let mut cand = [(0u32, 0f32); 4];
        let mut nc = 0;
        while mask != 0 {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let item = (base + lane as u32, est[lane]);
            let mut j = nc;
            while j > 0 && cand[j - 1].1 > item.1 {
                cand[j] = cand[j - 1];
                j -= 1;
            }
            cand[j] = item;
            nc += 1;
        }
        let cand = &cand[..nc];
        for (n, &(k, _)) in cand.iter().enumerate() {
            let t = &self.tris[k as usize];
            if n > 0 {
                if let Some(b) = best {
                    let e1 = t.v[0] - t.v[1];
                    let e2 = t.v[2] - t.v[0];
                    let ng = Vec3A::from_vec4(t.ng);
                    if !filter.may_hit(t.v[0], e1, e2, ng, t.ng.w, b.t) {
                        continue;
                    }
                }
            }
            let w = woop.get_or_insert_with(|| WoopRay::new(ray));
            let Some(h) = w.hit(&[t.v[0].into(), t.v[1].into(), t.v[2].into()]) else {
                continue;
            };
            let id = self.ids[k as usize];
            if h.precedes(id, best) {
                *best = Some(h.on(id));
                if any {
                    return true;
                }
            }
        }
        false
    }
}
