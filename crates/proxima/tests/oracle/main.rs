//! Oracle tests, written once and instantiated for every index: each index runs
//! long random operation sequences against `BruteForce` in every scene.

mod harness;

use harness::{run, SceneParams, ALL_SCENES};
use proxima::broad::{BruteForce, HashGrid, LooseKdTree, UniformGrid2d, UniformGrid3d};

/// Number of random operations per scene and seed.
const OPS: usize = 6000;

/// One `#[test]` per index: every scene, two seeds each.
macro_rules! oracle_suite {
    ($name:ident, $make:expr) => {
        #[test]
        fn $name() {
            for scene in ALL_SCENES {
                for seed in [1u64, 2] {
                    run(scene, seed, OPS, $make);
                }
            }
        }
    };
}

// The oracle against itself still exercises validate(), handles and bad input.
oracle_suite!(brute_force, |_: &SceneParams| BruteForce::new());
oracle_suite!(octree, |p: &SceneParams| {
    let cfg = proxima::broad::OctreeConfig {
        max_per_leaf: 4,
        merge_below: 2,
        max_depth: 12,
    };
    proxima::broad::LinearOctree::new(p.world, cfg).unwrap()
});
oracle_suite!(loose_kd, |p: &SceneParams| LooseKdTree::new(
    p.world, p.r_max, 0.5
)
.unwrap());
oracle_suite!(grid2d, |p: &SceneParams| UniformGrid2d::new(
    p.world, p.r_max
)
.unwrap());
oracle_suite!(hash_grid, |p: &SceneParams| HashGrid::new(p.r_max).unwrap());
oracle_suite!(grid3d, |p: &SceneParams| UniformGrid3d::new(
    p.world, p.r_max
)
.unwrap());
