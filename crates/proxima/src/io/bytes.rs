//! A bounds-checked little/big-endian reader over a byte slice that reports the
//! offset of every failure.

/// Reads fixed-size values, advancing `pos`; never reads past the end.
pub(crate) struct Bytes<'a> {
    data: &'a [u8],
    /// Offset of the next unread byte.
    pub pos: usize,
    big_endian: bool,
}

impl<'a> Bytes<'a> {
    /// A reader at `pos` of `data`.
    pub fn new(data: &'a [u8], pos: usize, big_endian: bool) -> Bytes<'a> {
        Bytes {
            data,
            pos,
            big_endian,
        }
    }

    /// The next `N` bytes in little-endian order, or `None` (nothing consumed)
    /// if fewer remain.
    pub fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let end = self.pos.checked_add(N)?;
        let mut out: [u8; N] = self.data.get(self.pos..end)?.try_into().ok()?;
        if self.big_endian {
            out.reverse();
        }
        self.pos = end;
        Some(out)
    }

    /// A little-endian (or big-endian) `f32`.
    pub fn f32(&mut self) -> Option<f32> {
        self.take::<4>().map(f32::from_le_bytes)
    }

    /// The unread bytes.
    pub fn rest(&self) -> &'a [u8] {
        self.data.get(self.pos..).unwrap_or(&[])
    }
}
