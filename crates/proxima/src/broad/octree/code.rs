//! Location codes: the names of octree cells [sources: octree-code].
//!
//! A code is a `u64` holding a leading sentinel 1 bit followed by 3 bits per level,
//! from the root down: bit 0 of each triple is the x half (0 = low, 1 = high), bit 1
//! the y half, bit 2 the z half. It is a Morton (Z-order) code that also encodes its
//! depth: the sentinel sits at bit `3 * depth`. The root is `1`; depth 21 uses all
//! 64 bits. The source writes the same thing as octal digits `q1 q2 … qn`.
//!
//! Because the x bits of all levels sit at positions `0, 3, 6, …` ("dilated"
//! integers), adding or subtracting one cell along an axis is one integer addition
//! with masks: fill the other axes' bits with ones so the carry jumps over them
//! (`+1`), or let the borrow run through them and mask it away (`-1`). That is the
//! source's octal rule ("add 4 to the trailing digits of the upper set, subtract 4
//! from the first one that is not") done for all levels at once, in O(1), with no
//! loop over the levels [sources: octree-neighbour].

use crate::geom::Aabb;
use glam::Vec3;

/// Deepest level a `u64` code can name: 1 sentinel bit + 3 × 21 = 64 bits.
pub const MAX_DEPTH: u32 = 21;

/// The x bits of every level (positions 0, 3, …, 60); y and z are this shifted by 1
/// and 2.
const X_BITS: u64 = 0x1249_2492_4924_9249;

/// One of the six faces of a cell, naming the direction of a face neighbour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Face {
    /// Towards −x.
    NegX,
    /// Towards +x.
    PosX,
    /// Towards −y.
    NegY,
    /// Towards +y.
    PosY,
    /// Towards −z.
    NegZ,
    /// Towards +z.
    PosZ,
}

impl Face {
    /// All six faces, in the order −x, +x, −y, +y, −z, +z.
    pub const ALL: [Face; 6] = [
        Face::NegX,
        Face::PosX,
        Face::NegY,
        Face::PosY,
        Face::NegZ,
        Face::PosZ,
    ];

    /// The face along `axis` (0 = x, 1 = y, 2 = z) on the positive or negative side.
    /// `axis` is taken modulo 3.
    #[inline]
    pub fn new(axis: usize, positive: bool) -> Face {
        Face::ALL[(axis % 3) * 2 + positive as usize]
    }

    /// The axis the face is normal to (0 = x, 1 = y, 2 = z).
    #[inline]
    pub fn axis(self) -> usize {
        self as usize / 2
    }

    /// True for +x, +y, +z.
    #[inline]
    pub fn is_positive(self) -> bool {
        self as usize % 2 == 1
    }

    /// The face on the other side of the cell.
    #[inline]
    pub fn opposite(self) -> Face {
        Face::new(self.axis(), !self.is_positive())
    }
}

/// The name of an octree cell: sentinel bit + 3 bits (x, y, z) per level (see the
/// module docs). All operations are O(1) bit arithmetic.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct LocationCode(u64);

/// Spreads the low 21 bits of `v` to every third bit (Morton encoding of one axis).
#[inline]
pub(crate) fn dilate(v: u32) -> u64 {
    let mut x = (v as u64) & 0x1f_ffff;
    x = (x | (x << 32)) & 0x001f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x001f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & X_BITS;
    x
}

/// The depth of the cells [`morton_order`] sorts `m` points by, and the bits
/// of an index below `m`: as many levels of the placement key as fit one
/// `u64` beside the index (15 levels for 100k points, 14 for 1M, 19 for 17
/// to 128), so that a plain integer sort orders by cell, then index. A far
/// outlier widens the box, and the cells with it: at 100k points one 1000
/// times farther than the rest still leaves them in cells of 1/32 of their
/// extent, where a fixed 10 levels put them all in one (the order then the
/// input's). O(1).
fn order_depth(m: usize) -> (u32, u32) {
    let index_bits = usize::BITS - m.saturating_sub(1).leading_zeros();
    (((64 - index_bits) / 3).min(MAX_DEPTH), index_bits)
}

/// The indices of `points` sorted along the Morton (Z-order) curve over the
/// cube spanned by the points' bounding box (ties by index): a batch of
/// queries run in this order visits the same nodes and objects one query
/// after another, so they stay in cache [sources: octree-code]. The curve
/// is followed down to cells of the octree's own placement key as deep as
/// fit one `u64` beside the index (a `2^15` grid per axis for 100k points,
/// `2^14` for 1M). Non-finite coordinates are
/// allowed (the batch checks them itself): they get some key, never a
/// panic. Indices are `u32`: for at most `2^32` points (beyond, indices
/// wrap and the answer is no permutation). Cost: O(m log m)
/// for `m` points, one allocation besides the answer.
pub fn morton_order(points: &[Vec3]) -> Vec<u32> {
    let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
    for p in points.iter().filter(|p| p.is_finite()) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    // One scale for all axes, so cells stay cubes in a flat or long set; the
    // width in f64, so that a box as wide as the f32 range keeps a finite
    // scale.
    let w = (0..3)
        .map(|a| hi[a] as f64 - lo[a] as f64)
        .fold(0.0, f64::max);
    let top = ((1u32 << MAX_DEPTH) - 1) as f64;
    let scale = Vec3::splat(if w > 0.0 { (top / w) as f32 } else { 0.0 });
    let max = lo + Vec3::splat(w as f32);
    // Each cell's code with the index below it, one `u64`: a plain integer
    // sort orders by cell, then index. 100k random points: 3.1 ms a call
    // with the full 63-bit key in a `u128` beside the index, 2.2 ms in one
    // `u64` (measured with 10 levels; the depth changes only the shifts),
    // 4.2-4.4 ms as `(u64, u32)` tuples with `floorf` in the key.
    let (depth, index_bits) = order_depth(points.len());
    let cut = 3 * (MAX_DEPTH - depth);
    let cells = (1u64 << (3 * depth)) - 1;
    let mut keyed: Vec<u64> = (points.iter().enumerate())
        .map(|(i, &p)| {
            let cell = (point_key(lo, max, scale, p) >> cut) & cells;
            cell << index_bits | i as u64
        })
        .collect();
    keyed.sort_unstable();
    let index = (1u64 << index_bits) - 1;
    keyed.into_iter().map(|k| (k & index) as u32).collect()
}

/// Inverse of [`dilate`]: gathers every third bit (from bit 0) into the low 21 bits.
#[inline]
pub(crate) fn undilate(v: u64) -> u32 {
    let mut x = v & X_BITS;
    x = (x ^ (x >> 2)) & 0x10c3_0c30_c30c_30c3;
    x = (x ^ (x >> 4)) & 0x100f_00f0_0f00_f00f;
    x = (x ^ (x >> 8)) & 0x001f_0000_ff00_00ff;
    x = (x ^ (x >> 16)) & 0x001f_0000_0000_ffff;
    x = (x ^ (x >> 32)) & 0x1f_ffff;
    x as u32
}

impl LocationCode {
    /// The root cell (the whole world box): the bare sentinel.
    pub const ROOT: LocationCode = LocationCode(1);

    /// Deepest level a code can name: 21 (three bits per level and the
    /// sentinel bit fill a `u64`).
    pub const MAX_DEPTH: u32 = MAX_DEPTH;

    /// The root cell.
    #[inline]
    pub fn root() -> LocationCode {
        Self::ROOT
    }

    /// A code from its raw bits, if they are well formed (a sentinel at bit `3d`).
    pub fn from_raw(raw: u64) -> Option<LocationCode> {
        if raw == 0 || !(63 - raw.leading_zeros()).is_multiple_of(3) {
            None
        } else {
            Some(LocationCode(raw))
        }
    }

    /// Raw bits without checking (crate-internal: callers built them by shifting a
    /// well-formed code).
    #[inline]
    pub(crate) fn from_raw_unchecked(raw: u64) -> LocationCode {
        debug_assert!(Self::from_raw(raw).is_some(), "malformed code {raw:#x}");
        LocationCode(raw)
    }

    /// The raw `u64` (the key of the octree's hash map).
    #[inline]
    pub fn raw(self) -> u64 {
        self.0
    }

    /// The cell at `depth` with integer coordinates `c` (each in `0..2^depth`), or
    /// `None` if out of range.
    pub fn from_coords(depth: u32, c: [u32; 3]) -> Option<LocationCode> {
        if depth > MAX_DEPTH || c.iter().any(|&v| (v as u64) >> depth != 0) {
            return None;
        }
        let bits = dilate(c[0]) | (dilate(c[1]) << 1) | (dilate(c[2]) << 2);
        Some(LocationCode((1u64 << (3 * depth)) | bits))
    }

    /// The depth-`depth` cell containing point `p`, cells dividing `world` (the
    /// point is clamped into `world` first; `depth` is capped at [`LocationCode::MAX_DEPTH`]).
    /// Cells are half-open except on the world's upper faces.
    pub fn of_point(world: &Aabb, p: Vec3, depth: u32) -> LocationCode {
        let depth = depth.min(MAX_DEPTH);
        let ext = world.extent();
        let scale = Vec3::select(
            ext.cmpgt(Vec3::ZERO),
            Vec3::splat((1u32 << MAX_DEPTH) as f32) / ext,
            Vec3::ZERO,
        );
        LocationCode(point_key(world.min, world.max, scale, p)).ancestor(depth)
    }

    /// Depth of the cell (root = 0).
    #[inline]
    pub fn depth(self) -> u32 {
        (63 - self.0.leading_zeros()) / 3
    }

    /// The enclosing cell one level up, or `None` for the root.
    #[inline]
    pub fn parent(self) -> Option<LocationCode> {
        (self.0 > 1).then_some(LocationCode(self.0 >> 3))
    }

    /// The ancestor at `depth` (itself if `depth >= self.depth()`).
    #[inline]
    pub fn ancestor(self, depth: u32) -> LocationCode {
        let d = self.depth();
        if depth >= d {
            self
        } else {
            LocationCode(self.0 >> (3 * (d - depth)))
        }
    }

    /// Child `k` (bit 0 = high x half, bit 1 = high y, bit 2 = high z), or `None`
    /// at [`LocationCode::MAX_DEPTH`] or for `k > 7`.
    #[inline]
    pub fn child(self, k: u8) -> Option<LocationCode> {
        (k < 8 && self.depth() < MAX_DEPTH).then_some(LocationCode((self.0 << 3) | k as u64))
    }

    /// Which child of its parent this cell is (its last 3 bits; 0 for the root).
    #[inline]
    pub fn child_index(self) -> u8 {
        if self.0 == 1 {
            0
        } else {
            (self.0 & 7) as u8
        }
    }

    /// True if `other` is this cell or lies inside it.
    #[inline]
    pub fn contains(self, other: LocationCode) -> bool {
        let (a, b) = (self.depth(), other.depth());
        b >= a && other.0 >> (3 * (b - a)) == self.0
    }

    /// The smallest cell containing both (their common prefix).
    #[inline]
    pub fn common_ancestor(self, other: LocationCode) -> LocationCode {
        let d = self.depth().min(other.depth());
        let a = self.ancestor(d).0;
        let b = other.ancestor(d).0;
        let x = a ^ b;
        let levels = (64 - x.leading_zeros()).div_ceil(3);
        LocationCode(a >> (3 * levels))
    }

    /// Integer coordinates of the cell at its depth (each in `0..2^depth`).
    #[inline]
    pub fn coords(self) -> [u32; 3] {
        let m = self.0 ^ (1u64 << (3 * self.depth()));
        [undilate(m), undilate(m >> 1), undilate(m >> 2)]
    }

    /// The cell's box when the root cell is `world`: `world` split in halves
    /// `depth` times along every axis. O(1).
    pub fn cell_box(self, world: &Aabb) -> Aabb {
        let d = self.depth();
        let size = world.extent() * (1.0 / (1u32 << d) as f32);
        cell_box_of(world.min, size, self.coords())
    }

    /// The same-depth cell across `face`, or `None` when this cell lies on that face
    /// of the world box.
    ///
    /// O(1), no loop over levels: the axis' dilated coordinate is incremented by
    /// `(a | !mask) + 1` (ones in the other axes' bits carry the increment across
    /// them) or decremented by `a - 1` (the borrow through the other axes' bits is
    /// masked off). The world border is where the coordinate is all ones (+) or all
    /// zeros (−) — the source's "every digit in the E/W/… set" test [sources: octree-neighbour].
    #[inline]
    pub fn face_neighbor(self, face: Face) -> Option<LocationCode> {
        let d = self.depth();
        let sentinel = 1u64 << (3 * d);
        let low = sentinel - 1;
        let mask = (X_BITS << face.axis()) & low;
        let a = self.0 & mask;
        let rest = self.0 & !mask;
        let moved = if face.is_positive() {
            if a == mask {
                return None;
            }
            ((a | !mask).wrapping_add(1)) & mask
        } else {
            if a == 0 {
                return None;
            }
            (a - 1) & mask
        };
        Some(LocationCode(rest | moved))
    }

    /// Offset of the same-depth cell `other` from this one, per axis in `-1..=1`, or
    /// `None` if it is farther than one cell on some axis or at another depth.
    /// O(1): compares dilated coordinates directly (no decoding).
    #[inline]
    pub fn offset_to(self, other: LocationCode) -> Option<[i8; 3]> {
        let d = self.depth();
        if other.depth() != d {
            return None;
        }
        let mut off = [0i8; 3];
        for (axis, o) in off.iter_mut().enumerate() {
            let mask = (X_BITS << axis) & ((1u64 << (3 * d)) - 1);
            let a = self.0 & mask;
            let b = other.0 & mask;
            if a == b {
                continue;
            }
            *o = if a != mask && b == ((a | !mask).wrapping_add(1)) & mask {
                1
            } else if a != 0 && b == (a - 1) & mask {
                -1
            } else {
                return None;
            };
        }
        Some(off)
    }
}

/// The full-depth key (depth 21, sentinel at bit 63) of point `p`, clamped into
/// `[min, max]`; `scale` is `2^21 / extent` per axis. Shared by
/// [`LocationCode::of_point`] and the octree so both quantize identically.
#[inline]
pub(crate) fn point_key(min: Vec3, max: Vec3, scale: Vec3, p: Vec3) -> u64 {
    let top = ((1u32 << MAX_DEPTH) - 1) as f32;
    // Clamped to `[0, top]` before the casts, and `top` is a whole number:
    // on that range truncating is the floor, so the key is the one flooring
    // first gave, without a `floorf` call per axis (no SSE4.1 rounding in the
    // baseline x86-64 target). A NaN casts to 0 either way (`as u32`
    // saturates).
    let q = ((p.clamp(min, max) - min) * scale).clamp(Vec3::ZERO, Vec3::splat(top));
    (1u64 << 63) | dilate(q.x as u32) | (dilate(q.y as u32) << 1) | (dilate(q.z as u32) << 2)
}

/// Box of the cell with integer coordinates `c` and edge lengths `size`, the root
/// cell starting at `origin`. The one formula used by codes, traversals and
/// validation, so they round identically.
#[inline]
pub(crate) fn cell_box_of(origin: Vec3, size: Vec3, c: [u32; 3]) -> Aabb {
    let min = origin + Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) * size;
    Aabb::new(min, min + size)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::vec3;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    fn world() -> Aabb {
        Aabb::new(vec3(-3.0, 1.0, 10.0), vec3(5.0, 9.0, 18.0))
    }

    /// The Z-order key of integer coordinates, one bit at a time.
    fn interleave(c: [u32; 3]) -> u64 {
        (0..21)
            .map(|b| {
                (0..3)
                    .map(|a| ((c[a] as u64 >> b) & 1) << (3 * b + a))
                    .sum::<u64>()
            })
            .sum()
    }

    #[test]
    fn morton_order_sorts_by_z_order_then_index() {
        let mut rng = Pcg64::seed_from_u64(3);
        // Points on an 8^3 lattice of a cube with side 7 (corners included),
        // many repeated: the cells are exact, so the keys are known.
        let pts: Vec<Vec3> = (0..2000)
            .map(|_| {
                let c = [0; 3].map(|_| rng.gen_range(0..8u32));
                vec3(c[0] as f32, c[1] as f32, c[2] as f32) - Vec3::splat(2.0)
            })
            .collect();
        let order = morton_order(&pts);
        let mut reference: Vec<u32> = (0..pts.len() as u32).collect();
        let key = |p: Vec3| {
            let c = (p + Vec3::splat(2.0)).to_array().map(|v| v as u32);
            // 7 * (2^21 - 1) / 7 per unit: exact on the lattice.
            interleave(c.map(|v| (v as u64 * ((1 << 21) - 1) / 7) as u32))
        };
        reference.sort_by_key(|&i| (key(pts[i as usize]), i));
        assert_eq!(order, reference);
        // Non-finite coordinates are placed, not lost; no points, no order.
        let odd = [
            vec3(f32::NAN, 0.0, 0.0),
            vec3(f32::INFINITY, -1.0, 2.0),
            Vec3::ZERO,
        ];
        let mut o = morton_order(&odd);
        o.sort_unstable();
        assert_eq!(o, vec![0, 1, 2]);
        assert!(morton_order(&[]).is_empty());
        assert_eq!(
            morton_order(&[vec3(f32::MAX, -f32::MAX, 0.0); 2]),
            vec![0, 1]
        );
    }

    /// On random points the order of the keys cut to `order_depth` levels,
    /// then the index, exactly: with duplicates, and with pairs of points in
    /// one cell whose full keys order them against their indices.
    #[test]
    fn morton_order_of_random_points_is_by_cell_then_index() {
        let mut rng = Pcg64::seed_from_u64(9);
        // Two corners fix the box morton_order spans: (0, 0, -1) and a
        // side of 3 (the widest axis).
        let mut pts = vec![vec3(0.0, 0.0, -1.0), vec3(1.0, 3.0, 0.0)];
        pts.extend((0..5000).map(|_| vec3(rng.gen(), rng.gen::<f32>() * 3.0, -rng.gen::<f32>())));
        for j in 2..202 {
            let p = pts[j] * 0.9;
            pts.push(p + Vec3::splat(1e-6));
            pts.push(p);
            pts.push(p + Vec3::splat(1e-6));
        }
        let (lo, hi) = (vec3(0.0, 0.0, -1.0), vec3(3.0, 3.0, 2.0));
        let scale = Vec3::splat((((1u32 << MAX_DEPTH) - 1) as f64 / 3.0) as f32);
        let mut expect: Vec<(u64, u32)> = (pts.iter().enumerate())
            .map(|(i, &p)| {
                let code = LocationCode(point_key(lo, hi, scale, p));
                (code.ancestor(order_depth(5602).0).0, i as u32)
            })
            .collect();
        expect.sort_unstable();
        let order = morton_order(&pts);
        assert_eq!(order, expect.iter().map(|e| e.1).collect::<Vec<_>>());
    }

    /// The depth and the index bits fit one `u64` for every batch size, the
    /// index bits hold every index below `m`, and the depth is the deepest
    /// that fits (at most 21).
    #[test]
    fn order_depth_fits_the_index_beside_the_cell() {
        for m in [
            0usize,
            1,
            2,
            3,
            16,
            17,
            128,
            129,
            100_000,
            1_000_000,
            1 << 32,
            (1 << 32) + 1,
        ] {
            let (d, b) = order_depth(m);
            assert!(3 * d + b <= 64, "{m}: {d} levels and {b} bits");
            assert!(m <= 1 || (m - 1) >> b == 0, "{m}: {b} bits");
            assert!(
                d == MAX_DEPTH || 3 * (d + 1) + b > 64,
                "{m}: {d} is not the deepest"
            );
        }
        assert_eq!(order_depth(100_000), (15, 17));
        assert_eq!(order_depth(1_000_000), (14, 20));
        assert_eq!(order_depth(128), (19, 7));
        assert_eq!(order_depth(2), (21, 1));
    }

    /// One point far from the rest widens the box; the others still follow
    /// the curve (in cells of `1e4 / 2^17` here), not the input order: a
    /// step from one to the next averages well below a random step (~0.66
    /// in the unit cube).
    #[test]
    fn morton_order_survives_a_far_outlier() {
        let mut rng = Pcg64::seed_from_u64(11);
        let mut pts: Vec<Vec3> = (0..4096)
            .map(|_| vec3(rng.gen(), rng.gen(), rng.gen()))
            .collect();
        pts.push(Vec3::splat(1e4));
        let order: Vec<Vec3> = (morton_order(&pts).into_iter())
            .map(|i| pts[i as usize])
            .filter(|p| p.x < 2.0)
            .collect();
        let step = order.windows(2).map(|w| w[0].distance(w[1])).sum::<f32>() / 4095.0;
        assert!(step < 0.15, "mean step {step}");
    }

    #[test]
    fn dilate_round_trips_and_matches_bit_loop() {
        let mut rng = Pcg64::seed_from_u64(7);
        for _ in 0..10_000 {
            let v: u32 = rng.gen_range(0..1 << 21);
            let mut slow = 0u64;
            for i in 0..21 {
                slow |= (((v >> i) & 1) as u64) << (3 * i);
            }
            assert_eq!(dilate(v), slow);
            assert_eq!(undilate(slow), v);
        }
    }

    #[test]
    fn parent_child_depth() {
        let r = LocationCode::root();
        assert_eq!(r.depth(), 0);
        assert_eq!(r.parent(), None);
        let mut c = r;
        for d in 1..=MAX_DEPTH {
            c = c.child((d % 8) as u8).unwrap();
            assert_eq!(c.depth(), d);
            assert_eq!(c.child_index(), (d % 8) as u8);
            assert_eq!(c.parent().unwrap().depth(), d - 1);
            assert!(r.contains(c));
            assert_eq!(c.ancestor(0), r);
        }
        assert_eq!(c.child(0), None, "no level 22 in a u64");
        assert_eq!(LocationCode::from_raw(c.raw()), Some(c));
        assert_eq!(LocationCode::from_raw(0b10), None);
        assert_eq!(LocationCode::from_raw(0), None);
    }

    #[test]
    fn common_ancestor_is_longest_prefix() {
        let mut rng = Pcg64::seed_from_u64(3);
        for _ in 0..5000 {
            let d1 = rng.gen_range(0..=MAX_DEPTH);
            let d2 = rng.gen_range(0..=MAX_DEPTH);
            let a = random_code(&mut rng, d1);
            let b = random_code(&mut rng, d2);
            let l = a.common_ancestor(b);
            assert!(l.contains(a) && l.contains(b));
            for k in 0..8 {
                if let Some(c) = l.child(k) {
                    assert!(!(c.contains(a) && c.contains(b)));
                }
            }
        }
    }

    fn random_code(rng: &mut Pcg64, d: u32) -> LocationCode {
        let n = 1u32 << d;
        LocationCode::from_coords(
            d,
            [
                rng.gen_range(0..n),
                rng.gen_range(0..n),
                rng.gen_range(0..n),
            ],
        )
        .unwrap()
    }

    /// Geometric definition: shift the cell's box by one cell size along the axis
    /// and take the code of the shifted box's centre (or nothing if it leaves the
    /// world).
    fn geometric_neighbor(c: LocationCode, f: Face, w: &Aabb) -> Option<LocationCode> {
        let b = c.cell_box(w);
        let mut shift = Vec3::ZERO;
        let size = b.extent();
        shift[f.axis()] = if f.is_positive() {
            size[f.axis()]
        } else {
            -size[f.axis()]
        };
        let centre = b.center() + shift;
        if !w.contains_point(centre) {
            return None;
        }
        Some(LocationCode::of_point(w, centre, c.depth()))
    }

    #[test]
    fn face_neighbor_matches_geometry_for_every_code_to_depth_4() {
        let w = world();
        let mut n = 0;
        for d in 0..=4u32 {
            let side = 1u32 << d;
            for x in 0..side {
                for y in 0..side {
                    for z in 0..side {
                        let c = LocationCode::from_coords(d, [x, y, z]).unwrap();
                        assert_eq!(c.coords(), [x, y, z]);
                        assert_eq!(LocationCode::of_point(&w, c.cell_box(&w).center(), d), c);
                        for f in Face::ALL {
                            let got = c.face_neighbor(f);
                            assert_eq!(got, geometric_neighbor(c, f, &w), "{c:?} {f:?}");
                            if let Some(nb) = got {
                                assert_eq!(nb.face_neighbor(f.opposite()), Some(c));
                                let mut off = [0i8; 3];
                                off[f.axis()] = if f.is_positive() { 1 } else { -1 };
                                assert_eq!(c.offset_to(nb), Some(off));
                            }
                            n += 1;
                        }
                    }
                }
            }
        }
        assert_eq!(n, 6 * (1 + 8 + 64 + 512 + 4096));
    }

    #[test]
    fn face_neighbor_matches_geometry_at_depth_21() {
        // A power-of-two world keeps depth-21 cell centres exact in f32.
        let w = Aabb::new(Vec3::splat(-1024.0), Vec3::splat(1024.0));
        let mut rng = Pcg64::seed_from_u64(21);
        let top = (1u32 << 21) - 1;
        for i in 0..20_000 {
            let mut c = random_code(&mut rng, 21);
            if i % 10 == 0 {
                // Force border cells.
                let mut xyz = c.coords();
                xyz[i % 3] = if i % 20 == 0 { 0 } else { top };
                c = LocationCode::from_coords(21, xyz).unwrap();
            }
            for f in Face::ALL {
                assert_eq!(
                    c.face_neighbor(f),
                    geometric_neighbor(c, f, &w),
                    "{c:?} {f:?}"
                );
                let mut xyz = c.coords();
                let a = f.axis();
                let expect = if f.is_positive() {
                    (xyz[a] < top).then(|| xyz[a] += 1)
                } else {
                    (xyz[a] > 0).then(|| xyz[a] -= 1)
                };
                assert_eq!(
                    c.face_neighbor(f),
                    expect.map(|_| LocationCode::from_coords(21, xyz).unwrap())
                );
            }
        }
    }

    #[test]
    fn offsets_reject_far_cells_and_other_depths() {
        let c = LocationCode::from_coords(3, [3, 3, 3]).unwrap();
        assert_eq!(
            c.offset_to(LocationCode::from_coords(3, [4, 2, 3]).unwrap()),
            Some([1, -1, 0])
        );
        assert_eq!(
            c.offset_to(LocationCode::from_coords(3, [5, 3, 3]).unwrap()),
            None
        );
        assert_eq!(c.offset_to(c.parent().unwrap()), None);
        assert_eq!(c.offset_to(c), Some([0, 0, 0]));
    }

    /// `point_key` truncates where it used to floor: the same key as the
    /// floor-first formula, bit for bit, on random points inside and outside
    /// the box, at every magnitude, on cell boundaries, and for NaN and
    /// infinite coordinates and scales.
    #[test]
    fn point_key_equals_flooring_first() {
        let floored = |min: Vec3, max: Vec3, scale: Vec3, p: Vec3| {
            let top = ((1u32 << MAX_DEPTH) - 1) as f32;
            let q = ((p.clamp(min, max) - min) * scale)
                .floor()
                .clamp(Vec3::ZERO, Vec3::splat(top));
            (1u64 << 63)
                | dilate(q.x as u32)
                | (dilate(q.y as u32) << 1)
                | (dilate(q.z as u32) << 2)
        };
        let mut rng = Pcg64::seed_from_u64(5);
        let specials = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -0.0];
        for round in 0..200_000 {
            let m = 10f32.powi(rng.gen_range(-40..38));
            let u = |rng: &mut Pcg64| match rng.gen_range(0..40) {
                0 => specials[rng.gen_range(0..specials.len())],
                // On a cell boundary of the unit box's grid.
                1..=9 => rng.gen_range(0..=1u32 << MAX_DEPTH) as f32 / (1u32 << MAX_DEPTH) as f32,
                _ => rng.gen_range(-1.5f32..1.5) * m,
            };
            let (a, b) = (u(&mut rng), u(&mut rng));
            let (lo, hi) = if round % 2 == 0 {
                (Vec3::ZERO, Vec3::ONE)
            } else {
                let (lo, hi) = (a.min(b), a.max(b));
                (Vec3::splat(lo), Vec3::splat(hi))
            };
            let w = hi.x as f64 - lo.x as f64;
            let s = if round % 7 == 0 {
                u(&mut rng).abs()
            } else {
                (((1u32 << MAX_DEPTH) - 1) as f64 / w) as f32
            };
            let scale = Vec3::splat(if s.is_nan() { 0.0 } else { s });
            let p = Vec3::new(u(&mut rng), u(&mut rng), u(&mut rng));
            assert_eq!(
                point_key(lo, hi, scale, p),
                floored(lo, hi, scale, p),
                "{lo} {hi} {scale} {p}"
            );
        }
    }
}
