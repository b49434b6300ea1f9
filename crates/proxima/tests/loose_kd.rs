//! The generic oracle run on `LooseKdTree` variants that the one-line entry in
//! `tests/oracle/main.rs` (density 0.5, default depth cap) does not cover: other
//! densities, a depth cap low enough that capped nodes hold many spheres, and an
//! `R_max` far below the scenes' radii (nearly everything attached at the root).

use proxima::broad::{LooseKdConfig, LooseKdTree};
use proxima_harness::oracle::{run, SceneParams, ALL_SCENES};

const OPS: usize = 3000;

fn suite(make: impl Fn(&SceneParams) -> LooseKdTree<u64> + Copy) {
    for scene in ALL_SCENES {
        run(scene, 11, OPS, make);
    }
}

#[test]
fn density_0_1() {
    suite(|p| {
        LooseKdTree::with_config(LooseKdConfig {
            density: 0.1,
            ..LooseKdConfig::new(p.world, p.r_max)
        })
        .unwrap()
    });
}

#[test]
fn density_default() {
    suite(|p| LooseKdTree::new(p.world, p.r_max).unwrap());
}

#[test]
fn density_1_0() {
    suite(|p| {
        LooseKdTree::with_config(LooseKdConfig {
            density: 1.0,
            ..LooseKdConfig::new(p.world, p.r_max)
        })
        .unwrap()
    });
}

#[test]
fn depth_cap_3() {
    suite(|p| {
        LooseKdTree::with_config(LooseKdConfig {
            density: 0.5,
            max_depth: 3,
            ..LooseKdConfig::new(p.world, p.r_max)
        })
        .unwrap()
    });
}

#[test]
fn r_max_tiny() {
    suite(|p| {
        LooseKdTree::with_config(LooseKdConfig {
            density: 0.7,
            ..LooseKdConfig::new(p.world, p.r_max * 0.01)
        })
        .unwrap()
    });
}
