//! A hint to the processor to start loading a cache line before it is read.

/// Asks the processor to bring the cache line holding `r` into every cache
/// level, without waiting for it: a later read of `r` then finds it there
/// instead of stalling on main memory. It neither reads nor writes `r` as far
/// as the program can tell, so it never changes a result; only timing. On
/// x86-64 it is one `prefetcht0` instruction (through `safe_arch`'s safe
/// wrapper, so this crate keeps `#![forbid(unsafe_code)]`); elsewhere it does
/// nothing. O(1).
///
/// Unlike touching the memory with a plain read, a prefetch does not hold up
/// the instructions behind it while the line is on its way.
#[inline(always)]
pub(crate) fn prefetch<T>(r: &T) {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse"))]
    safe_arch::prefetch_t0(r);
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse")))]
    let _ = r;
}
