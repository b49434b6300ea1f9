//! The list of structures every benchmark runs: Proxima's indices, one per
//! [`IndexKind`] (named by their type), then the peers.

use crate::parry::{ParryBvh, ParryMode};
use crate::structure::{Indexed, Structure};
use proxima::broad::IndexKind;
use proxima_harness::workloads::Scene;

/// One benchmarked structure: a name and how to make it empty for a scene.
pub struct Entry {
    /// Name shown in tables and criterion ids.
    pub name: &'static str,
    /// How a peer is driven (one entry per documented mode, e.g. parry3d's
    /// `refit`, `optimize+refit`, `rebuild`); `-` for Proxima's indices.
    pub mode: &'static str,
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

    /// `name` for a single-mode structure, `name:mode` for a peer's mode: the
    /// criterion id and what `--only` accepts besides the bare name.
    pub fn label(&self) -> String {
        if self.mode == NO_MODE {
            self.name.to_string()
        } else {
            format!("{}:{}", self.name, self.mode)
        }
    }

    /// Whether `--only` item `n` selects this entry: its name (every mode of a
    /// peer) or its [`Entry::label`] (one mode), ignoring case.
    pub fn matches(&self, n: &str) -> bool {
        self.name.eq_ignore_ascii_case(n) || self.label().eq_ignore_ascii_case(n)
    }

    /// Whether this structure is affordable on `n` objects.
    pub fn runs_on(&self, n: usize) -> bool {
        !self.quadratic || n <= QUADRATIC_LIMIT
    }
}

/// Largest object count an O(n²) structure is run on.
pub const QUADRATIC_LIMIT: usize = 20_000;

/// Name of parry3d's entries (one per [`ParryMode`]); the `vs parry` ratio is
/// taken against the fastest of them in the same run.
pub const PARRY: &str = "parry3d";

/// The mode of a structure that has only one (Proxima's indices).
pub const NO_MODE: &str = "-";

/// Every structure, Proxima's indices first (in [`IndexKind::ALL`] order, the
/// brute-force oracle being the one whose pair finding is O(n²)), then the peers,
/// one entry per mode.
pub fn entries() -> Vec<Entry> {
    let ours = IndexKind::ALL.into_iter().map(|kind| Entry {
        name: kind.type_name(),
        mode: NO_MODE,
        quadratic: kind == IndexKind::Brute,
        peer: false,
        maker: Maker::Index(kind),
    });
    // Each of parry's documented ways to maintain a moving tree is its own entry:
    // which is fastest depends on the scene and the run length.
    let peers = ParryMode::ALL.into_iter().map(|mode| Entry {
        name: PARRY,
        mode: mode.name(),
        quadratic: false,
        peer: true,
        maker: Maker::Peer(match mode {
            ParryMode::Refit => |_| Box::new(ParryBvh::new(ParryMode::Refit)),
            ParryMode::OptimizeRefit => |_| Box::new(ParryBvh::new(ParryMode::OptimizeRefit)),
            ParryMode::Rebuild => |_| Box::new(ParryBvh::new(ParryMode::Rebuild)),
        }),
    });
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
        if !all.iter().any(|e| e.matches(n)) {
            let known: Vec<_> = all.iter().map(Entry::label).collect();
            return Err(format!(
                "unknown structure {n:?} (known: {})",
                known.join(", ")
            ));
        }
    }
    Ok(all
        .into_iter()
        .filter(|e| names.iter().any(|n| e.matches(n)))
        .collect())
}
