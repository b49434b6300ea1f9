//! Query shapes as selection functions (the `rstar` idea): an index traverses its
//! nodes with [`Selection::classify_box`] and tests stored spheres with
//! [`Selection::selects`], so one traversal serves every query shape. Internal:
//! users query with [`Query`](super::Query); the trait is sealed and hidden.

use super::walk::{Cast, Contact};
use crate::geom::overlap::{self, EntryBound};
use crate::geom::{Aabb, Frustum, Ray, Relation, Sphere, SphereSweep};
use crate::Result;

pub(crate) mod sealed {
    /// Only the crate implements [`Selection`](super::Selection): its box
    /// tests and plane masks are the indices' internals, free to change.
    pub trait Sealed {}
    impl Sealed for crate::geom::Sphere {}
    impl Sealed for crate::geom::Aabb {}
    impl Sealed for crate::geom::Ray {}
    impl Sealed for crate::geom::Frustum {}
    impl Sealed for crate::geom::SphereSweep {}
    impl<C: super::Cast> Sealed for super::Prepared<'_, C> {}
}

/// A query over stored spheres, as the index walks see it.
///
/// Implementations must be consistent: `classify_box(b)` may say `Outside` only if
/// no sphere lying inside `b` is selected, and `Inside` only if every sphere lying
/// inside `b` is selected. Index nodes bound whole spheres (loose bounds), which is
/// what makes these box answers valid for the spheres below a node.
pub trait Selection: sealed::Sealed {
    /// Checks the query's own numbers (finite, non-negative radius, …).
    fn validate(&self) -> Result<()>;

    /// Exact, closed test: is the stored sphere `s` selected?
    fn selects(&self, s: &Sphere) -> bool;

    /// [`Selection::selects`] for a sphere known to be kept by every plane
    /// outside `mask` (a mask returned by [`Selection::classify_box`] or
    /// [`Selection::classify_centres`] for a box holding it): only frustums use
    /// the mask, to test fewer planes. The default ignores it. Same answer as
    /// `selects` under that precondition.
    #[inline]
    fn selects_masked(&self, s: &Sphere, mask: u8) -> bool {
        let _ = mask;
        self.selects(s)
    }

    /// Whether [`Selection::rejects4`] is a real pre-test (else leaf scans
    /// take the spheres one at a time).
    const HAS_REJECTS4: bool = false;

    /// A mask of four stored spheres (bit `j` for `s[j]`) that
    /// [`Selection::selects`] certainly rejects, by a SIMD pre-test; 0 where
    /// the query has none (the default). The octree's leaf scans call it
    /// first where [`Selection::HAS_REJECTS4`] says it is real (sweeps).
    #[inline(always)]
    fn rejects4(&self, s: [&Sphere; 4]) -> u32 {
        let _ = s;
        0
    }

    /// [`Selection::selects`] of a sphere that [`Selection::rejects4`] left
    /// in: a query whose exact test starts with the same pre-test skips it.
    /// Same answer as `selects`.
    #[inline(always)]
    fn selects_after_rejects4(&self, s: &Sphere) -> bool {
        self.selects(s)
    }

    /// Conservative box test over the planes in `mask` (only frustums use the mask:
    /// others pass it through). Returns the relation and the mask for the children.
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8);

    /// Conservative test of a block of stored spheres known by two boxes: every
    /// sphere of the block has its centre in `centres` and lies inside `loose`
    /// (a grid's cells: the cells' extent and that extent widened by the largest
    /// radius). `Outside` only if no such sphere is selected, `Inside` only if
    /// every such sphere is selected; the returned mask, as for
    /// [`Selection::classify_box`], names the planes still to test for any
    /// sub-block (boxes inside both). Knowing the centres lets a query say
    /// `Inside` far more often than from the loose box alone: a sphere whose
    /// centre is inside a query sphere, box or frustum is selected.
    ///
    /// The default is `classify_box(loose, mask)`, always valid. Cost O(1).
    fn classify_centres(&self, centres: &Aabb, loose: &Aabb, mask: u8) -> (Relation, u8) {
        let _ = centres;
        self.classify_box(loose, mask)
    }

    /// A box that every selected sphere intersects, if the query has one; indices
    /// use it for one-comparison pruning and for cell ranges. May be infinite.
    fn bounds(&self) -> Option<Aabb>;

    /// The query as a [`Ray`], if it is one. Grids use it to walk the cells along
    /// the ray instead of the ray's (possibly unbounded) bounding box; every other
    /// index may ignore it.
    fn as_ray(&self) -> Option<&Ray> {
        None
    }

    /// The query as a [`SphereSweep`], if it is one: grids walk the cells
    /// along its segment, widened by its radius, instead of its bounding box.
    fn as_sweep(&self) -> Option<&SphereSweep> {
        None
    }
}

impl Selection for Sphere {
    fn validate(&self) -> Result<()> {
        Sphere::validate(self)
    }
    #[inline]
    fn selects(&self, s: &Sphere) -> bool {
        overlap::sphere_sphere(self, s)
    }
    #[inline]
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8) {
        if overlap::sphere_aabb(self, b) {
            (Relation::Intersecting, mask)
        } else {
            (Relation::Outside, mask)
        }
    }
    /// `Inside` when the query sphere contains the whole box of centres (a
    /// sphere centred inside it overlaps it).
    #[inline]
    fn classify_centres(&self, centres: &Aabb, loose: &Aabb, mask: u8) -> (Relation, u8) {
        if !overlap::sphere_aabb(self, loose) {
            (Relation::Outside, mask)
        } else if overlap::sphere_contains_aabb(self, centres) {
            (Relation::Inside, mask)
        } else {
            (Relation::Intersecting, mask)
        }
    }
    fn bounds(&self) -> Option<Aabb> {
        Some(self.aabb())
    }
}

impl Selection for Aabb {
    fn validate(&self) -> Result<()> {
        Aabb::validate(self)
    }
    #[inline]
    fn selects(&self, s: &Sphere) -> bool {
        overlap::sphere_aabb(s, self)
    }
    #[inline]
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8) {
        if !overlap::aabb_aabb(self, b) {
            (Relation::Outside, mask)
        } else if self.contains_aabb(b) {
            // Every sphere inside `b` is inside `self`, so it overlaps it.
            (Relation::Inside, mask)
        } else {
            (Relation::Intersecting, mask)
        }
    }
    /// `Inside` when the query box contains the whole box of centres (a sphere
    /// centred inside it overlaps it).
    #[inline]
    fn classify_centres(&self, centres: &Aabb, loose: &Aabb, mask: u8) -> (Relation, u8) {
        if !overlap::aabb_aabb(self, loose) {
            (Relation::Outside, mask)
        } else if self.contains_aabb(centres) {
            (Relation::Inside, mask)
        } else {
            (Relation::Intersecting, mask)
        }
    }
    fn bounds(&self) -> Option<Aabb> {
        Some(*self)
    }
}

impl Selection for Frustum {
    fn validate(&self) -> Result<()> {
        Frustum::validate(self)
    }
    #[inline]
    fn selects(&self, s: &Sphere) -> bool {
        overlap::frustum_sphere(self, s) != Relation::Outside
    }
    /// Conservative for spheres inside `b`: if `b` is wholly outside a plane, so is
    /// every sphere in it (culled); if `b` is inside every plane, so is every sphere.
    #[inline]
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8) {
        overlap::frustum_aabb(self, b, mask)
    }
    #[inline]
    fn selects_masked(&self, s: &Sphere, mask: u8) -> bool {
        overlap::frustum_sphere_masked(self, s, mask) != Relation::Outside
    }
    /// Per plane: the loose box outside it culls the block; the box of centres
    /// inside it drops the plane (a sphere whose centre is inside a plane is not
    /// culled by it). `Inside` when every plane is dropped. Exact: see
    /// [`overlap::frustum_aabb_centres`].
    #[inline]
    fn classify_centres(&self, centres: &Aabb, loose: &Aabb, mask: u8) -> (Relation, u8) {
        overlap::frustum_aabb_centres(self, centres, loose, mask)
    }
    /// None: a selected sphere may lie outside the frustum near a corner, by up to
    /// its radius, so no radius-independent box bounds it.
    fn bounds(&self) -> Option<Aabb> {
        None
    }
}

impl Selection for Ray {
    fn validate(&self) -> Result<()> {
        Ray::validate(self)
    }
    #[inline]
    fn selects(&self, s: &Sphere) -> bool {
        overlap::ray_touches_sphere(self, s)
    }
    #[inline]
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8) {
        if overlap::ray_aabb(self, b).is_some() {
            (Relation::Intersecting, mask)
        } else {
            (Relation::Outside, mask)
        }
    }
    fn bounds(&self) -> Option<Aabb> {
        let end = if self.max_t.is_finite() {
            self.at(self.max_t)
        } else {
            // Infinite ray: unbounded on the axes it moves along.
            let inf = glam::Vec3::splat(f32::INFINITY);
            glam::Vec3::select(
                self.dir.cmpgt(glam::Vec3::ZERO),
                inf,
                glam::Vec3::select(self.dir.cmplt(glam::Vec3::ZERO), -inf, self.origin),
            )
        };
        Some(Aabb::new(self.origin.min(end), self.origin.max(end)))
    }
    fn as_ray(&self) -> Option<&Ray> {
        Some(self)
    }
}

/// A sweep selects what it touches ([`overlap::sweep_sphere`], exact); boxes
/// are tested with [`overlap::sweep_aabb`], conservative and monotone, so a
/// box holding a touched sphere is never `Outside`. No `Inside` answers. The
/// grids walk the cells along its segment widened by its radius (`as_sweep`).
impl Selection for SphereSweep {
    fn validate(&self) -> Result<()> {
        SphereSweep::validate(self)
    }
    #[inline]
    fn selects(&self, s: &Sphere) -> bool {
        overlap::sweep_touches_sphere(self, s)
    }
    #[inline]
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8) {
        if overlap::sweep_aabb(self, b).is_some() {
            (Relation::Intersecting, mask)
        } else {
            (Relation::Outside, mask)
        }
    }
    /// The swept volume's box, rounded outward.
    fn bounds(&self) -> Option<Aabb> {
        Some(self.aabb())
    }
    fn as_sweep(&self) -> Option<&SphereSweep> {
        Some(self)
    }
}

/// A ray or a sphere sweep prepared for one walk: the same selection as the
/// cast itself, but its box tests use [`EntryBound::enter`] (the inverse
/// direction and the growth computed once per walk, no division per box)
/// instead of the exact [`overlap::ray_aabb`] / [`overlap::sweep_aabb`]:
/// `None` there only where the exact test says `None` or the exact interval
/// is empty, so a box holding a touched sphere is never `Outside`; its
/// sphere tests are the cast's prepared ones ([`Cast::test`]). What
/// [`super::walk::visit`] hands the indices for [`Query::Ray`](super::Query::Ray)
/// and [`Query::Sweep`](super::Query::Sweep).
pub(crate) struct Prepared<'a, C: Cast> {
    cast: &'a C,
    entry: EntryBound,
    test: C::Test,
}

impl<'a, C: Cast> Prepared<'a, C> {
    /// Prepares `cast` (validated). O(1).
    #[inline]
    pub(crate) fn new(cast: &'a C) -> Self {
        Prepared {
            cast,
            // Touch tests only (`Outside` = touches nothing): no magnitude.
            entry: cast.entry(0.0),
            test: cast.test(),
        }
    }
}

impl<C: Cast> Selection for Prepared<'_, C> {
    fn validate(&self) -> Result<()> {
        self.cast.validate()
    }
    #[inline]
    fn selects(&self, s: &Sphere) -> bool {
        self.test.touches(s)
    }
    const HAS_REJECTS4: bool = <C::Test as Contact>::HAS_MISSES4;
    #[inline(always)]
    fn rejects4(&self, s: [&Sphere; 4]) -> u32 {
        self.test.misses4(s)
    }
    #[inline(always)]
    fn selects_after_rejects4(&self, s: &Sphere) -> bool {
        self.test.touches_after_misses4(s)
    }
    #[inline]
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8) {
        if self.entry.enter(b).is_some() {
            (Relation::Intersecting, mask)
        } else {
            (Relation::Outside, mask)
        }
    }
    fn bounds(&self) -> Option<Aabb> {
        self.cast.bounds()
    }
    fn as_ray(&self) -> Option<&Ray> {
        self.cast.as_ray()
    }
    fn as_sweep(&self) -> Option<&SphereSweep> {
        self.cast.as_sweep()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{vec3, Vec3};
    use rand::{Rng, SeedableRng};

    fn rand_vec(rng: &mut impl Rng, lo: f32, hi: f32) -> Vec3 {
        vec3(
            rng.gen_range(lo..hi),
            rng.gen_range(lo..hi),
            rng.gen_range(lo..hi),
        )
    }

    /// The `classify_centres` contract, sampled: for random blocks (a box of
    /// centres and a loose box widened by `rmax`) and spheres of the block
    /// (centre in the first, radius at most `rmax`, so inside the second),
    /// `Outside` means none is selected, `Inside` means all are, and otherwise
    /// `selects_masked` with the returned mask agrees with `selects`.
    fn check<Q: Selection>(q: &Q, rng: &mut impl Rng) -> [u32; 3] {
        let mut seen = [0; 3];
        for _ in 0..40 {
            let lo = rand_vec(rng, -20.0, 20.0);
            let centres = Aabb::new(lo, lo + rand_vec(rng, 0.0, 8.0));
            let rmax = rng.gen_range(0.0..3.0);
            let loose = centres.grown(rmax * 1.01 + 1e-3);
            let (rel, mask) = q.classify_centres(&centres, &loose, Frustum::ALL_PLANES);
            seen[rel as usize] += 1;
            for k in 0..30 {
                // Corners and faces too: the boundary is where it goes wrong.
                let t = rand_vec(rng, 0.0, 1.0).to_array().map(|v| match k % 3 {
                    0 => v,
                    1 => v.round(),
                    _ => (v * 2.0).floor().min(1.0),
                });
                let c = centres.min + (centres.max - centres.min) * Vec3::from(t);
                let c = c.clamp(centres.min, centres.max);
                let r = if k % 4 == 0 {
                    rmax
                } else {
                    rng.gen_range(0.0..=rmax)
                };
                let s = Sphere::new(c, r);
                let sel = q.selects(&s);
                match rel {
                    Relation::Outside => assert!(!sel, "{s:?} {centres:?}"),
                    Relation::Inside => assert!(sel, "{s:?} {centres:?}"),
                    Relation::Intersecting => {}
                }
                // The mask means nothing for a culled block.
                if rel != Relation::Outside {
                    assert_eq!(q.selects_masked(&s, mask), sel, "{s:?} {centres:?}");
                }
            }
        }
        seen
    }

    #[test]
    fn classify_centres_contract() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        let mut seen = [0; 3];
        let mut add = |s: [u32; 3]| (0..3).for_each(|i| seen[i] += s[i]);
        for _ in 0..200 {
            let q = Sphere::new(rand_vec(&mut rng, -20.0, 20.0), rng.gen_range(0.0..20.0));
            add(check(&q, &mut rng));
            let c = rand_vec(&mut rng, -20.0, 20.0);
            let q = Aabb::new(c, c + rand_vec(&mut rng, 0.0, 25.0));
            add(check(&q, &mut rng));
            let eye = rand_vec(&mut rng, -20.0, 20.0);
            let at = eye + rand_vec(&mut rng, -1.0, 1.0).normalize_or(Vec3::X);
            let up = if rng.gen_bool(0.5) { Vec3::Y } else { Vec3::Z };
            let m = glam::Mat4::perspective_rh(rng.gen_range(0.3..2.5), 1.5, 0.1, 40.0)
                * glam::Mat4::look_at_rh(eye, at, up);
            if let Ok(f) = Frustum::from_view_projection(m) {
                add(check(&f, &mut rng));
            }
        }
        // Every answer occurs, so the assertions above were exercised.
        assert!(seen.iter().all(|&n| n > 100), "{seen:?}");
    }

    #[test]
    fn sphere_contains_box() {
        let s = Sphere::new(Vec3::ZERO, 3.0f32.sqrt());
        // The unit cube's corners are exactly at distance √3 in the reals only
        // if √3 rounds up; the test is exact, so compare with the exact answer.
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::ONE);
        let r = s.radius as f64;
        assert_eq!(overlap::sphere_contains_aabb(&s, &b), r * r >= 3.0);
        assert!(overlap::sphere_contains_aabb(
            &Sphere::new(Vec3::ZERO, 2.0),
            &b
        ));
        assert!(!overlap::sphere_contains_aabb(
            &Sphere::new(Vec3::ZERO, 1.5),
            &b
        ));
        let inf = Aabb::new(Vec3::ZERO, Vec3::new(f32::INFINITY, 1.0, 1.0));
        assert!(!overlap::sphere_contains_aabb(
            &Sphere::new(Vec3::ZERO, f32::MAX),
            &inf
        ));
    }
}
