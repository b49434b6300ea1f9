//! [`SceneHint`]: what an index constructor is told about a scene before any
//! object is inserted (world box, typical large radius), from which each
//! config's `for_scene` derives its parameters.

use crate::geom::{Aabb, Sphere};
use glam::Vec3;

/// What an index constructor is told about a scene before it is built: given by
/// the caller ([`SceneHint::new`]) or computed by a pre-pass over the positions
/// the objects will take ([`SceneHint::from_spheres`]). Each index's config
/// reads what it needs in its `for_scene` (the world box for trees and grids,
/// `r_max` for loose borders and cell sizes), and
/// [`IndexKind::build`](super::IndexKind::build) builds any index from it.
///
/// A hint only tunes: every index still accepts objects outside the world box
/// or larger than `r_max`, and answers them exactly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneHint {
    /// The world box: where the centres are (the box trees and dense grids
    /// subdivide). [`SceneHint::from_spheres`] makes it non-empty on every axis.
    pub world: Aabb,
    /// A typical large radius: a high quantile of the radii, `> 0`. Objects larger
    /// than this are rare (indices must still accept them).
    pub r_max: f32,
    /// The largest radius seen (`>= r_max`).
    pub r_largest: f32,
    /// The largest number of objects alive at once (a capacity hint).
    pub max_live: usize,
}

/// Largest coordinate of a hinted world box.
const WORLD_LIMIT: f32 = 1e30;

/// Quantile of the radii used for [`SceneHint::r_max`].
const R_QUANTILE: f64 = 0.99;

impl SceneHint {
    /// A hint of a world box and a typical large radius; `r_largest` is set to
    /// `r_max` and `max_live` to 0 (unknown). Checked only when an index is
    /// built from it.
    pub fn new(world: Aabb, r_max: f32) -> Self {
        SceneHint {
            world,
            r_max,
            r_largest: r_max,
            max_live: 0,
        }
    }

    /// The hint for a scene whose objects take the positions `spheres` (every
    /// insert and move of a trace, in any order) with at most `max_live` objects
    /// alive at once. O(n) time and one `Vec<f32>` of the radii.
    ///
    /// The world is the bounding box of the centres, grown to at least one unit
    /// per axis so that no axis is degenerate; `r_max` is the 99th percentile of
    /// the radii (at least a small positive value so cell sizes stay positive).
    pub fn from_spheres(spheres: impl IntoIterator<Item = Sphere>, max_live: usize) -> Self {
        let mut world = Aabb::EMPTY;
        let mut radii = Vec::new();
        for s in spheres {
            world = world.union(&Aabb::new(s.center, s.center));
            radii.push(s.radius);
        }
        if radii.is_empty() {
            world = Aabb::new(Vec3::ZERO, Vec3::ONE);
        }
        // Keep the world within ±WORLD_LIMIT (objects beyond it are still stored:
        // every index accepts centres outside its world), so that constructors
        // never meet a box whose extent overflows.
        let lim = Vec3::splat(WORLD_LIMIT);
        world = Aabb::new(world.min.clamp(-lim, lim), world.max.clamp(-lim, lim));
        // Pad thin axes symmetrically to a unit extent, or 1e-3 of the magnitude far
        // from the origin (where a unit would be lost to rounding).
        let magnitude = world.min.abs().max(world.max.abs());
        let want = Vec3::ONE.max(magnitude * 1e-3);
        let pad = ((want - world.extent()) * 0.5).max(Vec3::ZERO);
        world = Aabb::new(world.min - pad, world.max + pad);
        let (r_max, r_largest) = if radii.is_empty() {
            (1.0, 1.0)
        } else {
            let k = ((radii.len() - 1) as f64 * R_QUANTILE).round() as usize;
            let (_, q, _) = radii.select_nth_unstable_by(k, f32::total_cmp);
            let q = *q;
            let largest = radii.iter().copied().fold(q, f32::max);
            (q, largest)
        };
        const MIN_R: f32 = 1e-3;
        SceneHint {
            world,
            r_max: r_max.max(MIN_R),
            r_largest: r_largest.max(MIN_R),
            max_live,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hint_is_never_degenerate() {
        let h = SceneHint::from_spheres([], 0);
        assert!(h.world.extent().min_element() >= 1.0 && h.r_max > 0.0);
        let one = Sphere::new(Vec3::new(5.0, 5.0, 5.0), 0.0);
        let h = SceneHint::from_spheres([one], 1);
        assert!(h.world.contains_point(one.center));
        assert!(h.world.extent().min_element() >= 1.0 && h.r_max > 0.0);
    }

    #[test]
    fn hint_quantile_ignores_rare_giants() {
        let mut v: Vec<Sphere> = (0..1000)
            .map(|i| Sphere::new(Vec3::splat(i as f32), 1.0 + (i % 10) as f32 * 0.1))
            .collect();
        v.push(Sphere::new(Vec3::ZERO, 500.0));
        let h = SceneHint::from_spheres(v, 1001);
        assert!((1.8..=1.91).contains(&h.r_max), "{}", h.r_max);
        assert_eq!(h.r_largest, 500.0);
        assert_eq!(h.world.min, Vec3::ZERO);
        assert_eq!(h.world.max, Vec3::splat(999.0));
    }
}
