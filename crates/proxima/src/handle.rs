//! [`Handle`]: the stable, generational name of a stored object, shared by every
//! index (and by whatever stores objects the same way).

/// A reference to an object stored in an index.
///
/// Handles are generational: after `remove` (or `clear`) the same slot may be reused,
/// but the old handle then fails with [`Error::StaleHandle`](crate::Error::StaleHandle) instead of naming a
/// different object. Each arena also carries a tag drawn when it is created or
/// cleared, so a handle from another index is rejected too (up to 2^32 arenas).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Handle {
    // Crate-visible so that the arena, which issues handles, can build and read
    // them; users only compare them and read the slot and generation.
    pub(crate) tag: u32,
    pub(crate) index: u32,
    pub(crate) generation: u32,
}

impl Handle {
    /// The slot number: dense, small, stable while the object lives. Useful as an
    /// index into side tables.
    pub fn index(self) -> u32 {
        self.index
    }
    /// The slot's generation when this handle was issued.
    pub fn generation(self) -> u32 {
        self.generation
    }
}
