//! Range, frustum and ray queries: visit a set of cells that must hold the centre
//! of every selected gridded object, each cell once (so each object once).

use super::cells::Geometry;
use super::UniformGrid3d;
use crate::broad::walk::{Cast, Contact};
use crate::broad::{Filter, RayHit, Selection};
use crate::geom::exact::round_down_f32;
use crate::geom::overlap::RayClip;
use crate::geom::{Aabb, Frustum, Relation, Sphere};
use crate::Handle;
use std::ops::ControlFlow;

/// Ranges of at most this many cells are visited row by row without the block
/// descent (a small sphere or box query: classifying blocks would cost more
/// than it saves).
const FLAT_CELLS: u64 = 64;

/// Blocks of at most this many cells are not split further: their rows are
/// visited cell by cell.
const LEAF_CELLS: u64 = 8;

/// Number of cells in the block `[lo, hi]`.
#[inline]
fn block_cells(lo: [u32; 3], hi: [u32; 3]) -> u64 {
    (0..3).map(|a| (hi[a] - lo[a]) as u64 + 1).product()
}

impl<T> UniformGrid3d<T> {
    /// Reports the gridded objects selected by `q` in the cells `[lo, hi]`
    /// (inclusive). Small ranges are scanned row by row; larger ones (frusta,
    /// which give no bounding box, and large spheres or boxes) are descended as
    /// an implicit octree of cell blocks (see [`Self::visit_block`]).
    pub(super) fn visit_range<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        lo: [u32; 3],
        hi: [u32; 3],
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if block_cells(lo, hi) > FLAT_CELLS {
            return self.visit_block(q, lo, hi, Frustum::ALL_PLANES, f);
        }
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                self.visit_row::<Q, true>(q, [lo[0], y, z], hi[0], Frustum::ALL_PLANES, f)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// The cells `[lo, hi]` as one block: its box of centres and its loose box
    /// (every gridded sphere whose centre is in the block lies inside it) are
    /// classified with [`Selection::classify_centres`] over the planes in
    /// `mask`; `Outside` skips the block, `Inside` reports all of its objects
    /// without exact tests (valid by that method's contract), and
    /// `Intersecting` splits the block in two along its longest axis, passing
    /// down the planes that still cut it (plane masking, as in a BVH), until
    /// blocks of [`LEAF_CELLS`] are scanned cell by cell. This is the frustum
    /// culling of a hierarchy [sources: w4] over the dense grid, with no
    /// stored tree: cost O(blocks near the query's boundary + cells inside it).
    fn visit_block<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        lo: [u32; 3],
        hi: [u32; 3],
        mask: u8,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let single = block_cells(lo, hi) == 1;
        if single && self.store.count(self.geom.index(lo)) == 0 {
            return ControlFlow::Continue(());
        }
        let g = &self.geom;
        let (rel, mask) = q.classify_centres(&g.centre_block(lo, hi), &g.loose_block(lo, hi), mask);
        match rel {
            Relation::Outside => ControlFlow::Continue(()),
            Relation::Inside => self.report_block(lo, hi, f),
            Relation::Intersecting if single => {
                self.test_cell(q, self.geom.index(lo), Relation::Intersecting, mask, f)
            }
            Relation::Intersecting if block_cells(lo, hi) <= LEAF_CELLS => {
                for z in lo[2]..=hi[2] {
                    for y in lo[1]..=hi[1] {
                        self.visit_row::<Q, true>(q, [lo[0], y, z], hi[0], mask, f)?;
                    }
                }
                ControlFlow::Continue(())
            }
            Relation::Intersecting => {
                let a = (0..3).max_by_key(|&a| hi[a] - lo[a]).unwrap_or(0);
                let mid = lo[a] + (hi[a] - lo[a]) / 2;
                let (mut h1, mut l2) = (hi, lo);
                h1[a] = mid;
                l2[a] = mid + 1;
                self.visit_block(q, lo, h1, mask, f)?;
                self.visit_block(q, l2, hi, mask, f)
            }
        }
    }

    /// Reports every gridded object in the cells `[lo, hi]`, without tests.
    fn report_block(
        &self,
        lo: [u32; 3],
        hi: [u32; 3],
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                let first = self.geom.index([lo[0], y, z]);
                for c in first..=first + (hi[0] - lo[0]) {
                    for part in self.store.parts(c) {
                        for &slot in part {
                            let (h, v) = self.resolve(slot);
                            f(h, &self.spheres[slot as usize], v)?;
                        }
                    }
                }
            }
        }
        ControlFlow::Continue(())
    }

    /// The cells `start.x ..= x1` of one row. With `CLASSIFY`, cells holding
    /// several objects are first classified by their centres and loose box
    /// over the planes in `mask` (those that may still cut them): `Outside`
    /// skips them, `Inside` reports without exact tests. Without it (the cast
    /// walks, whose rows are already clipped to the path) every object is
    /// tested exactly.
    // Always inlined: the loop of the cast walk and of the small-range scan.
    #[inline(always)]
    fn visit_row<Q: Selection + ?Sized, const CLASSIFY: bool>(
        &self,
        q: &Q,
        start: [u32; 3],
        x1: u32,
        mask: u8,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let first = self.geom.index(start);
        for (x, c) in (start[0]..=x1).zip(first..) {
            let n = self.store.count(c);
            if n == 0 {
                continue;
            }
            let mut rel = Relation::Intersecting;
            if CLASSIFY && n > 2 {
                let c = [x, start[1], start[2]];
                let g = &self.geom;
                rel = q
                    .classify_centres(&g.centre_block(c, c), &g.loose(c), mask)
                    .0;
                if rel == Relation::Outside {
                    continue;
                }
            }
            self.test_cell(q, c, rel, mask, f)?;
        }
        ControlFlow::Continue(())
    }

    /// Reports the objects of cell `c` selected by `q`: all of them if `rel`
    /// is `Inside`, else those passing the exact test over the planes in
    /// `mask` (the others keep every sphere of the cell).
    // Always inlined: the loop body of the small-range row scan.
    #[inline(always)]
    fn test_cell<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        c: u32,
        rel: Relation,
        mask: u8,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for part in self.store.parts(c) {
            for &slot in part {
                let s = &self.spheres[slot as usize];
                if rel == Relation::Inside || q.selects_masked(s, mask) {
                    let (h, v) = self.resolve(slot);
                    f(h, s, v)?;
                }
            }
        }
        ControlFlow::Continue(())
    }

    /// The path of a ray or sweep over the gridded spheres ([`Cast::path`]),
    /// and the union box of the gridded spheres grown by its reach (every
    /// point of the path within reach of a gridded centre is inside it);
    /// `None` when nothing is gridded.
    fn path_of<C: Cast>(&self, cast: &C) -> Option<(Path<'_>, Aabb)> {
        let m = self.extent_magnitude()?;
        let (ray, r) = cast.path();
        let path = Path {
            g: &self.geom,
            clip: RayClip::new(&ray),
            r,
        };
        Some((path, self.extent.grown(path.reach(m) - self.geom.limit)))
    }

    /// The largest coordinate magnitude of the gridded spheres' bounds, or
    /// `None` when nothing is gridded.
    fn extent_magnitude(&self) -> Option<f32> {
        let e = &self.extent;
        (!e.min.cmpgt(e.max).any()).then(|| e.min.abs().max(e.max.abs()).max_element())
    }

    /// Whether [`UniformGrid3d::visit_cast`] can walk `cast`
    /// ([`Cast::walk_fits`] over the gridded spheres' bounds, padded by a
    /// cell: the walk clips to them grown by the reach). Other casts take the
    /// exact cell-range visit.
    pub(super) fn walkable<C: Cast>(&self, cast: &C) -> bool {
        // Nothing gridded: the walk returns at once.
        self.extent_magnitude()
            .is_none_or(|m| cast.walk_fits(m + self.geom.cell))
    }

    /// Reports the gridded objects a ray or a sphere sweep touches.
    ///
    /// The cast's path (a sweep's segment, [`Cast::path`]) is clipped to the
    /// bounds of every gridded sphere grown by its reach; then, slab by slab
    /// along z and row by row along y, the part of the path within reach
    /// (largest gridded radius plus a margin, plus a sweep's radius) of that
    /// slab and row gives the range of x cells to visit. Every cell whose
    /// centre slab the path passes within reach of is visited once; cost
    /// O(z slabs + rows + cells near the path). A sweep touches an object iff
    /// its centre is within both radii of the segment, so it is one of them
    /// [sources: index-queries].
    pub(super) fn visit_cast<C: Cast>(
        &self,
        cast: &C,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let Some((path, ext)) = self.path_of(cast) else {
            return ControlFlow::Continue(());
        };
        let g = &self.geom;
        let Some((z0, z1, _)) = path.span(&ext, 2) else {
            return ControlFlow::Continue(());
        };
        for k in g.coord(z0, 2)..=g.coord(z1, 2) {
            let bk = path.restrict(&ext, 2, k);
            let Some((y0, y1, _)) = path.span(&bk, 1) else {
                continue;
            };
            for j in g.coord(y0, 1)..=g.coord(y1, 1) {
                let Some((x0, x1, _)) = path.span(&path.restrict(&bk, 1, j), 0) else {
                    continue;
                };
                // No cell classification (`CLASSIFY = false`): the path
                // meets every cell's centres widened by the reach by
                // construction, and a cast never classifies a box `Inside`,
                // so it could only skip a cell the exact tests reject anyway.
                let (x0, x1) = (g.coord(x0, 0), g.coord(x1, 0));
                self.visit_row::<C, false>(cast, [x0, j, k], x1, Frustum::ALL_PLANES, f)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// The first contact of a ray or sweep (smallest `t`, ties by handle)
    /// among the objects `filter` admits: the large list, then the cells
    /// near the path (as [`Self::visit_cast`]) slab by slab along the path's
    /// dominant axis in its direction of travel, stopping before a slab whose
    /// reach the path enters after the best contact so far. Every object of
    /// that slab and those beyond has its centre there, so the path comes
    /// within both radii of it only after that entry (bounded below by
    /// [`Path::span`], at most the entry bound of each such sphere's box):
    /// the answer is the scan's.
    pub(super) fn first_cast<C: Cast>(&self, cast: &C, filter: Option<Filter>) -> Option<RayHit> {
        let mut best: Option<RayHit> = None;
        let test = cast.test();
        let offer = |best: &mut Option<RayHit>, slot: u32| {
            let s = &self.spheres[slot as usize];
            if let Some(t) = test.contact(s) {
                if filter.is_none_or(|f| f.interacts(self.filters[slot as usize])) {
                    RayHit::offer(best, t, self.resolve(slot).0);
                }
            }
        };
        for &slot in &self.large {
            offer(&mut best, slot);
        }
        if let Some((path, ext)) = self.path_of(cast) {
            let g = &self.geom;
            let ad = path.clip.d.map(f64::abs);
            let (a, b, c) = if ad[0] >= ad[1] && ad[0] >= ad[2] {
                (0, 1, 2)
            } else if ad[1] >= ad[2] {
                (1, 2, 0)
            } else {
                (2, 0, 1)
            };
            if let Some((a0, a1, _)) = path.span(&ext, a) {
                let (k0, k1) = (g.coord(a0, a), g.coord(a1, a));
                let back = path.clip.d[a] < 0.0;
                for i in 0..=k1 - k0 {
                    let k = if back { k1 - i } else { k0 + i };
                    let bk = path.restrict(&ext, a, k);
                    let Some((b0, b1, t0)) = path.span(&bk, b) else {
                        continue;
                    };
                    if best.is_some_and(|h| h.t < t0) {
                        break;
                    }
                    for j in g.coord(b0, b)..=g.coord(b1, b) {
                        let Some((c0, c1, _)) = path.span(&path.restrict(&bk, b, j), c) else {
                            continue;
                        };
                        for l in g.coord(c0, c)..=g.coord(c1, c) {
                            let mut key = [0; 3];
                            (key[a], key[b], key[c]) = (k, j, l);
                            for part in self.store.parts(g.index(key)) {
                                for &slot in part {
                                    offer(&mut best, slot);
                                }
                            }
                        }
                    }
                }
            }
        }
        best
    }
}

/// A ray's or sweep's path over a dense grid ([`Cast::path`]): the ray its
/// centre follows and how far from it the cast reaches.
#[derive(Clone, Copy)]
struct Path<'a> {
    g: &'a Geometry,
    /// The centre's ray, prepared for the many clips of one walk.
    clip: RayClip,
    r: f32,
}

impl Path<'_> {
    /// How far from the path, near coordinate `v`, the centre of a gridded
    /// sphere the cast touches may lie: the grid's reach plus the cast's.
    #[inline]
    fn reach(&self, v: f32) -> f32 {
        self.g.reach(v) + self.r
    }

    /// The range of the path's coordinate on axis `a` inside `b`, widened by
    /// the reach, and a lower bound on the parameter at which the path enters
    /// `b` (an `f32`, rounded down); `None` if it misses `b`. The clip is
    /// conservative ([`RayClip::clip`]: it contains the exact parameter
    /// interval, and the coordinate range the exact one), so every cell the
    /// exact clip would visit is visited; the entry bound is at most the
    /// `f32` floor of the exact entry, which is at most the entry bound of
    /// every sphere's box inside `b` ([`ray_aabb`](crate::geom::overlap::ray_aabb) is that floor and
    /// monotone), so the front-to-back stop of [`UniformGrid3d::first_cast`]
    /// stays exact. Cost: no division (the inverse direction is computed once
    /// per walk, in [`UniformGrid3d::path_of`]).
    #[inline]
    fn span(&self, b: &Aabb, a: usize) -> Option<(f32, f32, f32)> {
        let (t0, t1) = self.clip.clip(b)?;
        let (lo, hi) = self.clip.coord_range(a, t0, t1);
        let (lo, hi) = (round_down_f32(lo), -round_down_f32(-hi));
        Some((lo - self.reach(lo), hi + self.reach(hi), round_down_f32(t0)))
    }

    /// `b` restricted on axis `a` to the reach of slab `k`.
    #[inline]
    fn restrict(&self, b: &Aabb, a: usize, k: u32) -> Aabb {
        let (lo, hi) = self.g.slab(k, a);
        let (mut mn, mut mx) = (b.min.to_array(), b.max.to_array());
        mn[a] = mn[a].max(lo - self.reach(lo));
        mx[a] = mx[a].min(hi + self.reach(hi));
        Aabb::new(mn.into(), mx.into())
    }
}

#[cfg(test)]
mod tests {
    use crate::broad::test_util::check_ray;
    use crate::broad::walk::Walk;
    use crate::broad::Grid3dConfig;
    use crate::broad::SpatialIndexExt;
    use crate::broad::{BruteForce, SpatialIndex, UniformGrid3d};
    use crate::geom::{Aabb, Frustum, Plane, Ray, Sphere};
    use glam::{vec3, Mat4, Vec3};
    use rand::{Rng, SeedableRng};
    use std::ops::ControlFlow;

    /// Payload ids of `hits`, sorted.
    fn ids<I: SpatialIndex<u32>>(index: &I, hits: Vec<crate::Handle>) -> Vec<u32> {
        let mut v: Vec<u32> = hits.iter().map(|h| *index.get(*h).unwrap().1).collect();
        v.sort_unstable();
        v
    }

    fn rand_vec(rng: &mut impl Rng, lo: f32, hi: f32) -> Vec3 {
        vec3(
            rng.gen_range(lo..hi),
            rng.gen_range(lo..hi),
            rng.gen_range(lo..hi),
        )
    }

    /// A frustum of a random kind: a perspective or orthographic camera at any
    /// position and orientation, random inward planes (often empty or
    /// unbounded), or a degenerate matrix (zero rows: planes with zero normals).
    fn rand_frustum(rng: &mut impl Rng) -> Frustum {
        let eye = rand_vec(rng, -20.0, 50.0);
        let mut at = rand_vec(rng, -20.0, 50.0);
        if at == eye {
            at.x += 1.0;
        }
        let up = if rng.gen_bool(0.5) { Vec3::Y } else { Vec3::Z };
        let up = if (at - eye).normalize().cross(up).length() < 1e-3 {
            Vec3::X
        } else {
            up
        };
        let view = Mat4::look_at_rh(eye, at, up);
        match rng.gen_range(0..5) {
            0 | 1 => {
                let fov = rng.gen_range(0.01..3.0);
                let near = rng.gen_range(0.01..5.0);
                let far = near + rng.gen_range(0.01..80.0);
                let p = Mat4::perspective_rh(fov, rng.gen_range(0.2..4.0), near, far);
                Frustum::from_view_projection(p * view).unwrap()
            }
            2 => {
                let (w, h) = (rng.gen_range(0.01..40.0), rng.gen_range(0.01..40.0));
                let p = Mat4::orthographic_rh(-w, w, -h, h, rng.gen_range(-10.0..1.0), 40.0);
                Frustum::from_view_projection(p * view).unwrap()
            }
            3 => Frustum::from_planes([0; 6].map(|_| {
                let n = rand_vec(rng, -1.0, 1.0).normalize_or(Vec3::X);
                Plane::new(n, -n.dot(rand_vec(rng, -10.0, 40.0)))
            })),
            _ => {
                let mut m = Mat4::perspective_rh(1.0, 1.5, 0.5, 30.0) * view;
                // Zero some rows: planes with zero normals (everywhere in or out).
                let mut rows = [m.row(0), m.row(1), m.row(2), m.row(3)];
                for r in rows.iter_mut() {
                    if rng.gen_bool(0.4) {
                        *r = glam::Vec4::ZERO;
                    }
                }
                m = Mat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose();
                Frustum::from_view_projection(m).unwrap()
            }
        }
    }

    /// The block descent (frusta; spheres and boxes spanning more than a few
    /// cells) and the cell-by-cell path against brute force, over grids of every
    /// shape, crowded and sparse cells (spills), centres outside the world,
    /// large objects, and queries tiny, huge, inside, outside and straddling.
    #[test]
    fn block_descent_matches_brute_force() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let shapes = [
            (vec3(30.0, 30.0, 30.0), 3.0),
            (vec3(30.0, 3.0, 30.0), 3.0),
            (vec3(60.0, 2.0, 2.0), 2.0),
            (vec3(5.0, 5.0, 5.0), 10.0),
            (vec3(30.0, 30.0, 30.0), 1.5),
        ];
        for (ext, cell) in shapes {
            let w = Aabb::new(Vec3::ZERO, ext);
            let mut g = UniformGrid3d::with_config(Grid3dConfig {
                world: w,
                cell_size: cell,
            })
            .unwrap();
            let mut b = BruteForce::new();
            let lim = 0.49 * g.cell_size();
            for i in 0..600u32 {
                // Crowded clusters (spills) and spread centres, some outside.
                let c = if i % 3 == 0 {
                    vec3(7.0, 1.0, 7.0) + rand_vec(&mut rng, -1.0, 1.0)
                } else {
                    rand_vec(&mut rng, -10.0, 40.0)
                };
                let r = match i % 50 {
                    0 => 6.0,
                    1 => 0.0,
                    2 => lim,
                    _ => rng.gen_range(0.0..lim),
                };
                g.insert(Sphere::new(c, r), i).unwrap();
                b.insert(Sphere::new(c, r), i).unwrap();
            }
            g.validate().unwrap();
            for k in 0..150 {
                let fr = rand_frustum(&mut rng);
                assert_eq!(
                    ids(&g, g.query(fr).unwrap()),
                    ids(&b, b.query(fr).unwrap()),
                    "{fr:?}"
                );
                let scale = [0.01, 1.0, 5.0, 20.0, 200.0][k % 5];
                let q = Sphere::new(rand_vec(&mut rng, -15.0, 45.0), rng.gen_range(0.0..scale));
                assert_eq!(
                    ids(&g, g.query(q).unwrap()),
                    ids(&b, b.query(q).unwrap()),
                    "{q:?}"
                );
                let c = rand_vec(&mut rng, -15.0, 45.0);
                let h = rand_vec(&mut rng, 0.0, scale);
                let q = Aabb::new(c - h, c + h);
                assert_eq!(
                    ids(&g, g.query(q).unwrap()),
                    ids(&b, b.query(q).unwrap()),
                    "{q:?}"
                );
            }
        }
    }

    /// A visit stopped by the callback reports nothing more, on the block path.
    #[test]
    fn block_descent_stops_early() {
        let w = Aabb::new(Vec3::ZERO, Vec3::splat(30.0));
        let mut g = UniformGrid3d::with_config(Grid3dConfig {
            world: w,
            cell_size: 3.0,
        })
        .unwrap();
        for i in 0..500u32 {
            let c = vec3(
                (i % 10) as f32 * 3.0,
                (i / 10 % 10) as f32 * 3.0,
                (i / 100) as f32,
            );
            g.insert(Sphere::new(c, 1.0), i).unwrap();
        }
        let big = Sphere::new(Vec3::splat(15.0), 100.0);
        for stop in [1, 7, 499] {
            let mut n = 0;
            let r = g.walk(&big, |_, _, _| {
                n += 1;
                if n == stop {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            });
            assert_eq!((r, n), (ControlFlow::Break(()), stop));
        }
    }

    #[test]
    fn rays_and_ranges_match_brute_force() {
        let w = Aabb::new(Vec3::ZERO, Vec3::splat(30.0));
        let mut g = UniformGrid3d::with_config(Grid3dConfig {
            world: w,
            cell_size: 3.0,
        })
        .unwrap();
        let mut b = BruteForce::new();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        for i in 0..400u32 {
            let c = vec3(
                rng.gen_range(-10.0..40.0),
                rng.gen_range(-10.0..40.0),
                rng.gen_range(-10.0..40.0),
            );
            let r = if i % 40 == 0 {
                5.0
            } else {
                rng.gen_range(0.0..1.47)
            };
            g.insert(Sphere::new(c, r), i).unwrap();
            b.insert(Sphere::new(c, r), i).unwrap();
        }
        for _ in 0..300 {
            let o = vec3(
                rng.gen_range(-20.0..50.0),
                rng.gen_range(-20.0..50.0),
                rng.gen_range(-20.0..50.0),
            );
            let mut d = vec3(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            );
            if rng.gen_bool(0.3) {
                d[rng.gen_range(0..3)] = 0.0;
            }
            if d == Vec3::ZERO {
                d = Vec3::X;
            }
            let t = if rng.gen_bool(0.5) {
                f32::INFINITY
            } else {
                rng.gen_range(0.0..60.0)
            };
            check_ray(&g, &b, &Ray::with_max_t(o, d, t));
            let q = Sphere::new(o, rng.gen_range(0.0..8.0));
            let mut hg = g.query(q).unwrap();
            let mut hb: Vec<u32> = b
                .query(q)
                .unwrap()
                .iter()
                .map(|h| *b.get(*h).unwrap().1)
                .collect();
            let mut ig: Vec<u32> = hg.drain(..).map(|h| *g.get(h).unwrap().1).collect();
            ig.sort_unstable();
            hb.sort_unstable();
            assert_eq!(ig, hb);
        }
    }

    /// The cast walks' fast clipping against brute force (bit-identical hits,
    /// times and first hits) on adversarial sweeps and rays: axis-parallel
    /// and with zero components, along cell lines, exactly tangent to stored
    /// spheres (grazes the exact test decides), tiny and zero radii, near and
    /// far from the origin (1e6, where the grid's rounding margin matters),
    /// and beyond the walk's guard (`Cast::walk_fits`).
    #[test]
    fn cast_walks_match_brute_force_on_adversarial_casts() {
        use crate::broad::test_util::check_knn_sweep;
        use crate::broad::walk::Cast;
        use crate::geom::SphereSweep;
        let mut rng = rand_pcg::Pcg64::seed_from_u64(17);
        for offset in [0.0f32, -16.0, 1e6] {
            let base = Vec3::splat(offset);
            let w = Aabb::new(base, base + Vec3::splat(24.0));
            let mut g = UniformGrid3d::with_config(Grid3dConfig {
                world: w,
                cell_size: 2.0,
            })
            .unwrap();
            let mut b = BruteForce::new();
            let mut spheres = Vec::new();
            for i in 0..500u32 {
                // Centres on a coarse lattice (cell lines, exact ties) or anywhere.
                let c = if i % 2 == 0 {
                    base + vec3(
                        rng.gen_range(-2..26) as f32,
                        rng.gen_range(-2..26) as f32,
                        rng.gen_range(-2..26) as f32,
                    )
                } else {
                    base + rand_vec(&mut rng, -2.0, 26.0)
                };
                let r = [0.0, 0.5, 0.98, 1e-6][i as usize % 4];
                let s = Sphere::new(c, r);
                g.insert(s, i).unwrap();
                b.insert(s, i).unwrap();
                spheres.push(s);
            }
            for k in 0..400 {
                let axis = k % 3;
                let mut dir = Vec3::ZERO;
                dir[axis] = if k % 2 == 0 { 1.0 } else { -1.0 };
                if k % 5 == 1 {
                    dir[(axis + 1) % 3] = rng.gen_range(-1.0..1.0);
                }
                let radius = [0.0, 1e-7, 0.25, 1.0, 3.0][k % 5];
                let len = [0.0, 0.5, 3.0, 30.0][k / 5 % 4];
                let from = match k % 4 {
                    // Tangent to a stored sphere: moving along `axis`, offset
                    // on the next axis by exactly both radii.
                    0 | 1 => {
                        let s = spheres[rng.gen_range(0..spheres.len())];
                        let mut p = s.center - dir * (len * 0.5);
                        p[(axis + 1) % 3] += s.radius + radius;
                        p
                    }
                    // On a cell line.
                    2 => base + (rand_vec(&mut rng, 0.0, 12.0) * 2.0).floor() * 2.0 / 2.0,
                    _ => base + rand_vec(&mut rng, -4.0, 28.0),
                };
                let sw = SphereSweep::new(from, from + dir * len, radius);
                assert!(g.walkable(&sw), "{sw:?}");
                check_knn_sweep(&g, &b, from, 3, &sw);
                if dir != Vec3::ZERO {
                    let t = if k % 2 == 0 { len } else { f32::INFINITY };
                    check_ray(&g, &b, &Ray::with_max_t(from, dir, t));
                }
            }
            // Beyond the guard: the exact cell-range visit answers.
            let far = SphereSweep::new(base, base + Vec3::X, f32::MAX / 8.0);
            assert!(!far.walk_fits(0.0) && !g.walkable(&far));
            check_knn_sweep(&g, &b, base, 3, &far);
        }
    }

    /// k nearest and sweeps against brute force (see
    /// [`knn_sweep_suite`](crate::broad::test_util::knn_sweep_suite)).
    #[test]
    fn nearest_and_sweeps_match_brute_force() {
        use crate::broad::test_util::knn_sweep_suite;
        use crate::broad::{Grid3dConfig, UniformGrid3d};
        use crate::geom::Aabb;
        use glam::{vec3, Vec3};
        for (ext, cell) in [(vec3(30.0, 30.0, 30.0), 3.0), (vec3(60.0, 5.0, 20.0), 1.5)] {
            let w = Aabb::new(Vec3::ZERO, ext);
            for seed in 1..3 {
                let g = UniformGrid3d::with_config(Grid3dConfig {
                    world: w,
                    cell_size: cell,
                });
                knn_sweep_suite(g.unwrap(), w, seed);
            }
        }
    }
}
