//! Oracle tests, written once and instantiated for every index: each index runs
//! long random operation sequences against `BruteForce` in every scene.

use proxima::broad::{AnyIndex, IndexKind, LinearOctree, OctreeConfig, SpatialIndex};
use proxima_harness::oracle::{make_index, run, SceneParams, ALL_SCENES};

/// Number of random operations per scene and seed.
const OPS: usize = 6000;

/// The index of `kind` the suite runs: the harness's [`make_index`] (each
/// config's `for_scene`, a denser loose k-d tree), except a small-leaf octree
/// (more splits and merges per operation).
fn make(kind: IndexKind, p: &SceneParams) -> AnyIndex<u64> {
    let hint = p.hint();
    match kind {
        IndexKind::Octree => LinearOctree::with_config(OctreeConfig {
            max_per_leaf: 4,
            merge_below: 2,
            max_depth: 12,
            ..OctreeConfig::for_scene(&hint)
        })
        .unwrap()
        .into(),
        _ => make_index(kind, &hint),
    }
}

/// One `#[test]` per index kind: every scene, two seeds each. `COVERED` lists
/// the kinds, so that a kind without a suite fails `every_kind_has_a_suite`.
macro_rules! oracle_suite {
    ($($name:ident: $kind:ident),+ $(,)?) => {
        const COVERED: &[IndexKind] = &[$(IndexKind::$kind),+];
        $(
            #[test]
            fn $name() {
                for scene in ALL_SCENES {
                    for seed in [1u64, 2] {
                        run(scene, seed, OPS, |p| make(IndexKind::$kind, p));
                    }
                }
            }
        )+
    };
}

// The oracle against itself still exercises validate(), handles and bad input.
oracle_suite!(
    brute_force: Brute,
    octree: Octree,
    loose_kd: LooseKd,
    grid2d: Grid2d,
    hash_grid: HashGrid,
    grid3d: Grid3d,
);

#[test]
fn every_kind_has_a_suite() {
    let mut covered = COVERED.to_vec();
    covered.sort();
    assert_eq!(covered, IndexKind::ALL);
}

/// The index inside `any`, boxed as a trait object of its own type.
fn boxed(any: AnyIndex<u64>) -> Box<dyn SpatialIndex<u64>> {
    match any {
        AnyIndex::Brute(i) => Box::new(i),
        AnyIndex::LooseKd(i) => Box::new(i),
        AnyIndex::Octree(i) => Box::new(i),
        AnyIndex::Grid2d(i) => Box::new(i),
        AnyIndex::HashGrid(i) => Box::new(i),
        AnyIndex::Grid3d(i) => Box::new(i),
        other => panic!("a new kind to box here: {:?}", other.kind()),
    }
}

/// Every index behind `Box<dyn SpatialIndex>` (one vtable call per operation,
/// per reported object and per pair), through the same harness: the trait is
/// object-safe and the box forwards everything.
#[test]
fn every_kind_through_a_box_dyn() {
    for kind in IndexKind::ALL {
        for scene in ALL_SCENES {
            run(scene, 3, OPS / 4, |p| {
                let index = boxed(make(kind, p));
                assert_eq!(index.kind(), kind);
                index
            });
        }
    }
}
