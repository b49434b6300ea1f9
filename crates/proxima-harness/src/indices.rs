//! The broad-phase indices every command, fuzz target and test runs: the
//! library's [`IndexKind`]s, by the names the command line takes. A user parses a
//! name into an [`IndexKind`], builds the index with [`IndexKind::build`] and
//! drives the [`AnyIndex`](proxima::broad::AnyIndex) it gets (static dispatch
//! inside each call).

use proxima::broad::IndexKind;

/// Names of the indices, in [`IndexKind::ALL`] order (`brute` first).
pub const NAMES: [&str; IndexKind::ALL.len()] = {
    let mut names = [""; IndexKind::ALL.len()];
    let mut i = 0;
    while i < names.len() {
        names[i] = IndexKind::ALL[i].name();
        i += 1;
    }
    names
};

/// Name of the oracle; every other index is compared with it.
pub const BRUTE: &str = IndexKind::Brute.name();

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brute_is_registered_first() {
        assert_eq!(NAMES[0], BRUTE);
        assert_eq!(NAMES.len(), IndexKind::ALL.len());
    }
}
