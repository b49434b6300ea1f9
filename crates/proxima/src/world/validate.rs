//! [`World::validate`]: the world's invariants, checked by the tests after every
//! operation.

use super::ignore::key_slots;
use super::{broad_sphere, World};
use crate::broad::SpatialIndex;
use crate::narrow::BoundingVolume;
use crate::{Error, Result};
use rustc_hash::FxHashSet;

fn fail<T>(msg: String) -> Result<T> {
    Err(Error::Invalid(msg))
}

impl<T, BV: BoundingVolume> World<T, BV> {
    /// Checks the world's invariants: the arena; each object's inverse pose and
    /// broad sphere recomputed from its pose and shape; the index (once built)
    /// holding exactly the live objects with those spheres and filters, and its own
    /// invariants; the drift count; the ignored pairs naming live objects, each
    /// once, with consistent partner lists; stamps and insertion numbers; the
    /// coherence cache's ranges. O(n + index + cache). Returns
    /// [`Error::Invalid`] naming the first broken invariant.
    pub fn validate(&self) -> Result<()> {
        self.objects.validate()?;
        let bounded = self.config.bounds.is_some();
        let mut seqs = FxHashSet::default();
        let mut drifted = 0;
        for (h, o) in self.objects.iter() {
            o.shape.validate()?;
            crate::narrow::check_pose(&o.pose)?;
            if o.inverse != o.pose.inverse() {
                return fail(format!("object {h:?}: stale inverse pose"));
            }
            if o.sphere != broad_sphere(&o.shape.local_bounding_sphere(), &o.pose) {
                return fail(format!("object {h:?}: stale bounding sphere"));
            }
            if o.stamp > self.epoch || o.seq >= self.next_seq || !seqs.insert(o.seq) {
                return fail(format!("object {h:?}: bad stamp or insertion number"));
            }
            if o.drift != self.broad.is_drifted(&o.sphere, bounded) {
                return fail(format!("object {h:?}: stale drift flag"));
            }
            drifted += o.drift as usize;
            match (&self.broad.index, o.broad) {
                (None, None) => {}
                (Some(index), Some(b)) => {
                    let (s, &slot) = index.get(b)?;
                    if s != o.sphere || slot != h.index() {
                        return fail(format!(
                            "object {h:?}: the index holds {s:?} for slot {slot}"
                        ));
                    }
                    if index.filter(b)? != o.filter {
                        return fail(format!("object {h:?}: the index holds another filter"));
                    }
                }
                _ => return fail(format!("object {h:?}: index handle out of step")),
            }
        }
        if drifted != self.broad.drifted {
            return fail(format!("drift count {} != {drifted}", self.broad.drifted));
        }
        if let Some(index) = &self.broad.index {
            if index.len() != self.objects.len() {
                return fail(format!(
                    "index holds {} objects, the world {}",
                    index.len(),
                    self.objects.len()
                ));
            }
            index.validate()?;
        }
        let live = |slot: u32| self.objects.get_by_index(slot).is_some();
        let mut links = 0;
        for key in self.ignored.keys() {
            let (a, b) = key_slots(key);
            if a >= b || !live(a) || !live(b) {
                return fail(format!("ignored pair ({a}, {b}) is not two live objects"));
            }
        }
        for (a, list) in self.ignored.partners() {
            for &b in list {
                links += 1;
                if !self.ignored.contains(a, b) || list.iter().filter(|&&x| x == b).count() != 1 {
                    return fail(format!("ignored partner list of {a} is out of step at {b}"));
                }
            }
        }
        if links != 2 * self.ignored.len() {
            return fail(format!(
                "{links} partner links for {} ignored pairs",
                self.ignored.len()
            ));
        }
        let cache = &self.coherence.cache;
        for (key, e) in &cache.entries {
            let (a, b) = key_slots(*key);
            if a >= b
                || e.tris.end > cache.tris.len()
                || e.cut.end > cache.cuts.len()
                || e.contact == e.tris.is_empty()
            {
                return fail(format!("coherence entry ({a}, {b}) is malformed"));
            }
        }
        if !self.config.coherence && (self.coherence.last.is_some() || !cache.entries.is_empty()) {
            return fail("coherence is off but a cache is kept".into());
        }
        Ok(())
    }
}
