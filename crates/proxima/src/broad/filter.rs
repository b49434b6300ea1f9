//! [`Filter`]: collision filter bits, the group/mask scheme of Box2D, Bullet and
//! Rapier [sources: index-queries].

/// Which objects may interact: an object belongs to the groups set in `group`
/// and interacts with the groups set in `mask`. Two filters interact iff each
/// one's group meets the other's mask:
/// `(a.group & b.mask) != 0 && (b.group & a.mask) != 0` ([`Filter::interacts`]).
///
/// [`Filter::ALL`] (every bit in both, the default) interacts with every filter
/// that has a bit in each field. A filter with `mask == 0` or `group == 0`
/// interacts with nothing.
///
/// Stored objects carry one (pair searches report only interacting pairs); a
/// query may carry one too, and then reports only the objects whose filter
/// interacts with it, exactly as if the query were one more object.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Filter {
    /// The groups the object belongs to.
    pub group: u32,
    /// The groups the object interacts with.
    pub mask: u32,
}

impl Filter {
    /// Every group, interacting with every group: the default.
    pub const ALL: Filter = Filter {
        group: u32::MAX,
        mask: u32::MAX,
    };

    /// A filter with these bits.
    pub const fn new(group: u32, mask: u32) -> Filter {
        Filter { group, mask }
    }

    /// Whether two filters interact: `(self.group & other.mask) != 0 &&
    /// (other.group & self.mask) != 0`. Symmetric. O(1).
    #[inline]
    pub const fn interacts(self, other: Filter) -> bool {
        (self.group & other.mask) != 0 && (other.group & self.mask) != 0
    }

    /// Whether this query filter may interact with some object of a set whose
    /// groups are all within `groups` and masks all within `masks` (the OR of
    /// the set's groups and masks, or any superset): `false` proves it
    /// interacts with none, so an index may skip the whole set (a subtree whose
    /// ORs it keeps). O(1).
    #[inline]
    pub const fn may_interact(self, groups: u32, masks: u32) -> bool {
        (self.mask & groups) != 0 && (self.group & masks) != 0
    }

    /// Whether this filter interacts with nothing (`group == 0 || mask == 0`):
    /// an index may leave such an object out of its pair search. O(1).
    #[inline]
    pub const fn is_inert(self) -> bool {
        self.group == 0 || self.mask == 0
    }
}

impl Default for Filter {
    /// [`Filter::ALL`].
    fn default() -> Self {
        Filter::ALL
    }
}

/// How many stored objects are inert ([`Filter::is_inert`]): an index keeps
/// one so that its pair search leaves inert objects out only when there are
/// some, and an index without any runs the unchanged loops (no filter read per
/// object). Updated on insert, remove and filter change, O(1) each.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct InertCount(usize);

impl InertCount {
    /// Counts an object stored with filter `f`.
    #[inline]
    pub(crate) fn add(&mut self, f: Filter) {
        self.0 += f.is_inert() as usize;
    }

    /// Uncounts an object removed with filter `f`.
    #[inline]
    pub(crate) fn sub(&mut self, f: Filter) {
        self.0 -= f.is_inert() as usize;
    }

    /// An object's filter changed from `old` to `new`.
    #[inline]
    pub(crate) fn change(&mut self, old: Filter, new: Filter) {
        self.sub(old);
        self.add(new);
    }

    /// Whether some stored object is inert.
    #[inline]
    pub(crate) fn any(self) -> bool {
        self.0 != 0
    }

    /// `validate`'s check: the count equals the number of inert filters
    /// among `stored` (every stored object's). O(n).
    pub(crate) fn check(self, stored: impl Iterator<Item = Filter>) -> crate::Result<()> {
        let inert = stored.filter(|f| f.is_inert()).count();
        if inert == self.0 {
            Ok(())
        } else {
            Err(crate::Error::Invalid(format!(
                "{inert} inert objects but {} counted",
                self.0
            )))
        }
    }
}

/// What an index walk reports besides the shape test: `()` everything (no
/// code at all), a [`Filter`] the objects whose filter interacts with it,
/// skipping the subtrees whose OR-ed filter bits cannot
/// ([`Filter::may_interact`]). Lets one traversal serve filtered and
/// unfiltered queries without a cost to the unfiltered one.
pub(crate) trait Admit: Copy {
    /// Whether a set of objects whose groups and masks are within `groups` and
    /// `masks` may hold an admitted one.
    fn node(&self, groups: u32, masks: u32) -> bool;
    /// Whether an object with filter `f` is admitted.
    fn object(&self, f: Filter) -> bool;
}

impl Admit for () {
    #[inline(always)]
    fn node(&self, _: u32, _: u32) -> bool {
        true
    }
    #[inline(always)]
    fn object(&self, _: Filter) -> bool {
        true
    }
}

impl Admit for Filter {
    #[inline(always)]
    fn node(&self, groups: u32, masks: u32) -> bool {
        self.may_interact(groups, masks)
    }
    #[inline(always)]
    fn object(&self, f: Filter) -> bool {
        self.interacts(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interacts_is_the_two_way_rule() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            // Few bits, so that both outcomes are common.
            (seed as u32) & 0x0f0f_0005
        };
        let mut seen = [0u32; 2];
        for _ in 0..10_000 {
            let a = Filter::new(next(), next());
            let b = Filter::new(next(), next());
            let want = (a.group & b.mask) != 0 && (b.group & a.mask) != 0;
            assert_eq!(a.interacts(b), want, "{a:?} {b:?}");
            assert_eq!(b.interacts(a), want, "{a:?} {b:?}");
            if a.is_inert() {
                assert!(!a.interacts(b));
            }
            seen[want as usize] += 1;
        }
        assert!(seen.iter().all(|&n| n > 1000), "{seen:?}");
        assert!(Filter::ALL.interacts(Filter::ALL));
        assert!(!Filter::new(1, 0).interacts(Filter::ALL));
        assert_eq!(Filter::default(), Filter::ALL);
    }
}
