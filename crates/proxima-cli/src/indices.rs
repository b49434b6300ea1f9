//! The registry of broad-phase indices every command runs: one line per index.
//!
//! `SpatialIndex` has generic methods, so it is not object-safe and an index cannot
//! be a `Box<dyn …>`. Instead a command implements [`IndexJob`] (a generic `run`)
//! and [`with_index`] instantiates it for the named index. Adding an index is one
//! entry in the `registry!` invocation at the bottom of this file.

use proxima::broad::{
    BruteForce, HashGrid, LinearOctree, LooseKdTree, OctreeConfig, SpatialIndex, UniformGrid2d,
    UniformGrid3d,
};
use proxima::geom::{Aabb, Sphere};
use proxima::glam::Vec3;

/// What an index constructor is told about a scene before it is built: computed by
/// a pre-pass over a trace (see [`SceneHint::from_spheres`]) or given by a
/// generated scene. Constructors read what they need (world box for trees and
/// grids, `r_max` for loose borders and cell sizes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneHint {
    /// A non-empty box holding every centre of the scene (the world box).
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

/// A command's work over one index, generic over the index type so that every
/// registered index gets its own monomorphized (static-dispatch) copy.
pub trait IndexJob {
    /// What the job returns for one index.
    type Output;
    /// Runs the job on a freshly built, empty index called `name`.
    fn run<I: SpatialIndex<u64>>(&mut self, name: &'static str, index: I) -> Self::Output;
}

/// Generates [`NAMES`] and [`with_index`] from `"name" => constructor` entries; a
/// constructor is a non-capturing closure `Fn(&SceneHint) -> proxima::Result<Index>`.
macro_rules! registry {
    ($($name:literal => $make:expr),+ $(,)?) => {
        /// Names of the registered indices, in registry order (`brute` first).
        pub const NAMES: &[&str] = &[$($name),+];

        /// Builds the index `name` for `hint` and runs `job` on it. `None` for an
        /// unknown name; `Some(Err)` when the constructor rejects the hint.
        pub fn with_index<J: IndexJob>(
            name: &str,
            hint: &SceneHint,
            job: &mut J,
        ) -> Option<proxima::Result<J::Output>> {
            match name {
                $($name => {
                    let make: fn(&SceneHint) -> proxima::Result<_> = $make;
                    Some(make(hint).map(|index| job.run($name, index)))
                })+
                _ => None,
            }
        }
    };
}

/// Name of the oracle; every other index is compared with it.
pub const BRUTE: &str = "brute";

/// The loose k-d tree as every command builds it (pictures draw this one too).
pub fn loose_kd(h: &SceneHint) -> proxima::Result<LooseKdTree<u64>> {
    LooseKdTree::new(h.world, h.r_max, KD_DENSITY)
}

/// Density `d` of the loose k-d tree [sources: kd-tree]: the library's measured default.
pub const KD_DENSITY: f32 = proxima::broad::loose_kd::DEFAULT_DENSITY;

/// The linear octree as every command builds it (pictures draw this one too).
pub fn octree(h: &SceneHint) -> proxima::Result<LinearOctree<u64>> {
    LinearOctree::new(h.world, OctreeConfig::default())
}

registry! {
    "brute" => |_| Ok(BruteForce::<u64>::new()),
    "loose-kd" => loose_kd,
    "octree" => octree,
    "grid2d" => |h| UniformGrid2d::<u64>::new(h.world, h.r_max),
    "hashgrid" => |h| HashGrid::<u64>::new(h.r_max),
    "grid3d" => |h| UniformGrid3d::<u64>::new(h.world, h.r_max),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brute_is_registered_first() {
        assert_eq!(NAMES[0], BRUTE);
    }

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
