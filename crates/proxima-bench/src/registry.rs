//! The list of structures every benchmark runs: Proxima's indices, one per
//! [`IndexKind`] (named by their type), then the peers.

use crate::parry::ParryBvh;
use crate::structure::{Indexed, Structure};
use proxima::broad::IndexKind;
use proxima_harness::workloads::Scene;

/// One benchmarked structure: a name and how to make it empty for a scene.
pub struct Entry {
    /// Name shown in tables and criterion ids.
    pub name: &'static str,
    /// Pair finding is O(n²): run only on small scenes (see [`QUADRATIC_LIMIT`]).
    pub quadratic: bool,
    /// True for the peers (not Proxima's own indices).
    pub peer: bool,
    maker: Maker,
}

/// How an entry makes its empty structure.
enum Maker {
    /// A Proxima index, built by the library for the scene's hint.
    Index(IndexKind),
    /// A peer's adapter.
    Peer(fn(&Scene) -> Box<dyn Structure>),
}

impl Entry {
    /// Makes the empty structure for a scene.
    pub fn make(&self, scene: &Scene) -> Box<dyn Structure> {
        match self.maker {
            Maker::Index(kind) => {
                let index = kind
                    .build(&scene.hint())
                    .unwrap_or_else(|e| panic!("{}: {e}", self.name));
                Box::new(Indexed::new(index))
            }
            Maker::Peer(make) => make(scene),
        }
    }

    /// Whether this structure is affordable on `n` objects.
    pub fn runs_on(&self, n: usize) -> bool {
        !self.quadratic || n <= QUADRATIC_LIMIT
    }
}

/// Largest object count an O(n²) structure is run on.
pub const QUADRATIC_LIMIT: usize = 20_000;

/// Name of the reference peer that frame-time ratios are taken against.
pub const PARRY: &str = "parry3d";

/// Every structure, Proxima's indices first (in [`IndexKind::ALL`] order, the
/// brute-force oracle being the one whose pair finding is O(n²)), then the peers.
pub fn entries() -> Vec<Entry> {
    let ours = IndexKind::ALL.into_iter().map(|kind| Entry {
        name: kind.type_name(),
        quadratic: kind == IndexKind::Brute,
        peer: false,
        maker: Maker::Index(kind),
    });
    let peers = [
        Entry {
            name: PARRY,
            quadratic: false,
            peer: true,
            maker: Maker::Peer(|_| Box::new(ParryBvh::new(true))),
        },
        Entry {
            name: "parry3d-noopt",
            quadratic: false,
            peer: true,
            maker: Maker::Peer(|_| Box::new(ParryBvh::new(false))),
        },
    ];
    ours.chain(peers).collect()
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
