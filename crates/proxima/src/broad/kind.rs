//! [`IndexKind`]: the built-in indices by name, for choosing one at run time
//! (command lines, config files, benchmarks).

use super::{AnyIndex, SceneHint};
use crate::{Error, Result};
use std::fmt;
use std::str::FromStr;

/// One of the six built-in indices. [`IndexKind::build`] makes an empty
/// [`AnyIndex`] of this kind; [`FromStr`] and [`IndexKind::name`] convert from
/// and to the short names the command-line tool uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[non_exhaustive]
pub enum IndexKind {
    /// [`BruteForce`](super::BruteForce): the oracle.
    Brute,
    /// [`LooseKdTree`](super::LooseKdTree).
    LooseKd,
    /// [`LinearOctree`](super::LinearOctree).
    Octree,
    /// [`UniformGrid2d`](super::UniformGrid2d).
    Grid2d,
    /// [`HashGrid`](super::HashGrid).
    HashGrid,
    /// [`UniformGrid3d`](super::UniformGrid3d).
    Grid3d,
}

impl IndexKind {
    /// Every kind, the oracle first.
    pub const ALL: [IndexKind; 6] = [
        IndexKind::Brute,
        IndexKind::LooseKd,
        IndexKind::Octree,
        IndexKind::Grid2d,
        IndexKind::HashGrid,
        IndexKind::Grid3d,
    ];

    /// The short name: `brute`, `loose-kd`, `octree`, `grid2d`, `hashgrid`,
    /// `grid3d`.
    pub const fn name(self) -> &'static str {
        match self {
            IndexKind::Brute => "brute",
            IndexKind::LooseKd => "loose-kd",
            IndexKind::Octree => "octree",
            IndexKind::Grid2d => "grid2d",
            IndexKind::HashGrid => "hashgrid",
            IndexKind::Grid3d => "grid3d",
        }
    }

    /// The name of the index's Rust type (`LooseKdTree`, ...), as benchmark
    /// tables show it.
    pub const fn type_name(self) -> &'static str {
        match self {
            IndexKind::Brute => "BruteForce",
            IndexKind::LooseKd => "LooseKdTree",
            IndexKind::Octree => "LinearOctree",
            IndexKind::Grid2d => "UniformGrid2d",
            IndexKind::HashGrid => "HashGrid",
            IndexKind::Grid3d => "UniformGrid3d",
        }
    }

    /// An empty index of this kind configured for `hint` (each config's
    /// `for_scene`). Errors with [`Error::InvalidParameter`] (or the box's own
    /// error) when the hint's numbers are unusable for this kind.
    pub fn build<T: Send + Sync>(self, hint: &SceneHint) -> Result<AnyIndex<T>> {
        AnyIndex::new(self, hint)
    }
}

impl fmt::Display for IndexKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for IndexKind {
    type Err = Error;

    /// Parses a short name ([`IndexKind::name`]); the error lists the known ones.
    fn from_str(s: &str) -> Result<Self> {
        IndexKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                let known: Vec<_> = IndexKind::ALL.iter().map(|k| k.name()).collect();
                Error::InvalidParameter(format!(
                    "unknown index {s:?} (known: {})",
                    known.join(", ")
                ))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_list_the_known_ones() {
        for k in IndexKind::ALL {
            assert_eq!(k.name().parse::<IndexKind>(), Ok(k));
            assert_eq!(k.to_string(), k.name());
        }
        assert_eq!(IndexKind::ALL[0], IndexKind::Brute);
        let e = "kd".parse::<IndexKind>().unwrap_err().to_string();
        for k in IndexKind::ALL {
            assert!(e.contains(k.name()), "{e}");
        }
    }
}
