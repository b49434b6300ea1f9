//! The traversal stack of the ray casts ([`Stack`]), on the machine stack.

/// Slots of the traversal stack kept on the machine stack (deeper trees spill).
const STACK: usize = 16;

/// A LIFO of `(node, entry t)` on the machine stack, spilling to the heap only for
/// trees deeper than [`STACK`]. Items are packed in a `u64` (node in the low half,
/// the bits of `t` in the high half) so that creating the stack, once per ray,
/// is a few vector stores rather than one store per field.
pub(crate) struct Stack {
    items: [u64; STACK],
    len: usize,
    spill: Vec<u64>,
}

impl Stack {
    #[inline(always)]
    pub(crate) fn new() -> Stack {
        Stack {
            items: [0; STACK],
            len: 0,
            spill: Vec::new(),
        }
    }

    #[inline(always)]
    pub(crate) fn push(&mut self, (i, t): (u32, f32)) {
        let x = i as u64 | (t.to_bits() as u64) << 32;
        if self.len < STACK {
            self.items[self.len] = x;
            self.len += 1;
        } else {
            self.spill.push(x);
        }
    }

    #[inline(always)]
    pub(crate) fn pop(&mut self) -> Option<(u32, f32)> {
        let x = match self.spill.pop() {
            Some(x) => x,
            None if self.len == 0 => return None,
            None => {
                self.len -= 1;
                self.items[self.len]
            }
        };
        Some((x as u32, f32::from_bits((x >> 32) as u32)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stack is a LIFO across spills and refills: random pushes and pops
    /// against a `Vec`, deep enough to spill several times.
    #[test]
    fn lifo_across_spills() {
        let mut s = Stack::new();
        let mut v: Vec<(u32, f32)> = Vec::new();
        let mut x = 12345u32;
        for step in 0..20_000u32 {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12_345);
            // Phases that grow (up to ~100 deep) and shrink.
            let grow = (step / 500) % 2 == 0;
            if !(x >> 16).is_multiple_of(4) && grow || (x >> 16).is_multiple_of(4) && !grow {
                let item = (step, step as f32 * 0.5);
                s.push(item);
                v.push(item);
            } else {
                assert_eq!(s.pop(), v.pop());
            }
        }
        while let Some(item) = v.pop() {
            assert_eq!(s.pop(), Some(item));
        }
        assert_eq!(s.pop(), None);
    }
}
