//! The list of structures every benchmark runs. Adding a Proxima index is one
//! `proxima!` line in [`entries`].

use crate::parry::ParryBvh;
use crate::structure::{Indexed, IndexedPar, Structure};
use crate::workloads::Scene;
use proxima::broad::{
    loose_kd, BruteForce, HashGrid, LinearOctree, LooseKdTree, OctreeConfig, UniformGrid2d,
    UniformGrid3d,
};

/// One benchmarked structure: a name and how to make it empty for a scene.
pub struct Entry {
    /// Name shown in tables and criterion ids.
    pub name: &'static str,
    /// Pair finding is O(n²): run only on small scenes (see [`QUADRATIC_LIMIT`]).
    pub quadratic: bool,
    /// True for the peers (not Proxima's own indices).
    pub peer: bool,
    /// Makes the empty structure for a scene.
    pub make: fn(&Scene) -> Box<dyn Structure>,
}

impl Entry {
    /// Whether this structure is affordable on `n` objects.
    pub fn runs_on(&self, n: usize) -> bool {
        !self.quadratic || n <= QUADRATIC_LIMIT
    }
}

/// Largest object count an O(n²) structure is run on.
pub const QUADRATIC_LIMIT: usize = 20_000;

/// Name of the reference peer that frame-time ratios are taken against.
pub const PARRY: &str = "parry3d";

/// A Proxima index: `proxima!(name, |scene| constructor)`, the constructor
/// returning `proxima::Result<Index>` for the empty index (it may read
/// `scene.world`, `scene.r_max`, ...). `proxima!(name, quadratic, ...)` marks an
/// index whose pair finding is O(n²).
macro_rules! proxima {
    ($name:expr, $make:expr) => {
        proxima!(@entry $name, false, $make)
    };
    ($name:expr, quadratic, $make:expr) => {
        proxima!(@entry $name, true, $make)
    };
    // An index implementing `ParallelPairs` (used by `--threads K`).
    ($name:expr, parallel, $make:expr) => {
        Entry {
            name: $name,
            quadratic: false,
            peer: false,
            make: |scene: &Scene| -> Box<dyn Structure> {
                let make: fn(&Scene) -> proxima::Result<_> = $make;
                let index = make(scene).unwrap_or_else(|e| panic!("{}: {e}", $name));
                Box::new(IndexedPar(Indexed::<_>::new(index)))
            },
        }
    };
    (@entry $name:expr, $quadratic:expr, $make:expr) => {
        Entry {
            name: $name,
            quadratic: $quadratic,
            peer: false,
            make: |scene: &Scene| -> Box<dyn Structure> {
                let make: fn(&Scene) -> proxima::Result<_> = $make;
                let index = make(scene).unwrap_or_else(|e| panic!("{}: {e}", $name));
                Box::new(Indexed::<_>::new(index))
            },
        }
    };
}

/// Every structure, Proxima's indices first, then the peers.
pub fn entries() -> Vec<Entry> {
    vec![
        proxima!("BruteForce", quadratic, |_| Ok(BruteForce::new())),
        proxima!("LooseKdTree", parallel, |s| LooseKdTree::new(
            s.world,
            s.r_max,
            loose_kd::DEFAULT_DENSITY
        )),
        proxima!("LinearOctree", |s| LinearOctree::new(
            s.world,
            OctreeConfig::default()
        )),
        proxima!("UniformGrid2d", |s| UniformGrid2d::new(s.world, s.r_max)),
        proxima!("HashGrid", |s| HashGrid::new(s.r_max)),
        proxima!("UniformGrid3d", parallel, |s| UniformGrid3d::new(
            s.world, s.r_max
        )),
        Entry {
            name: PARRY,
            quadratic: false,
            peer: true,
            make: |_| Box::new(ParryBvh::new(true)),
        },
        Entry {
            name: "parry3d-noopt",
            quadratic: false,
            peer: true,
            make: |_| Box::new(ParryBvh::new(false)),
        },
    ]
}

/// The entries whose name matches one of `names` (all of them when `names` is
/// empty); unknown names are returned as the error.
pub fn select(names: &[String]) -> Result<Vec<Entry>, String> {
    let all = entries();
    if names.is_empty() {
        return Ok(all);
    }
    for n in names {
        if !all.iter().any(|e| e.name.eq_ignore_ascii_case(n)) {
            let known: Vec<_> = all.iter().map(|e| e.name).collect();
            return Err(format!(
                "unknown structure {n:?} (known: {})",
                known.join(", ")
            ));
        }
    }
    Ok(all
        .into_iter()
        .filter(|e| names.iter().any(|n| e.name.eq_ignore_ascii_case(n)))
        .collect())
}
