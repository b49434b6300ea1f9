//! Temporal coherence of `contacts` [sources: bvh-next, world]: what the last
//! query learned, and the plan of which pairs the next one must test.
//!
//! Two reuses, both exact (answers are the same with coherence off, which the
//! tests check):
//!
//! 1. **Unchanged pairs are not tested.** Every object carries the epoch of its
//!    last change (pose, filter, insertion, an ignore or unignore of one of its
//!    pairs; a pose set to the identical pose is no change). A candidate pair
//!    neither of whose objects changed since the last `contacts` of the same
//!    mode had the same spheres, filters and shapes then, so its answer is
//!    copied from the last query. When few objects changed (at most a quarter),
//!    the broad phase is not even walked over all pairs: only the changed
//!    objects' spheres are queried, and the unchanged pairs come from the cache.
//! 2. **Small motions start where the last traversal ended.** A mesh–mesh test
//!    records the cut of node pairs where its BVH traversal stopped (disjoint
//!    volume pairs and overlapping leaf pairs), if it has at most
//!    [`WorldConfig::cut_limit`](super::WorldConfig::cut_limit) pairs. Those
//!    pairs' leaf products partition all triangle pairs, so the next test of the
//!    same two objects may start from the cut instead of the roots and find the
//!    same triangle pairs, skipping the volume tests (and the lazy node updates)
//!    above the cut. Small cuts are those of near misses and light touches, the
//!    pairs a slowly moving scene tests again and again. In first-contact mode a
//!    cut is used only for a pair that had no contact (a traversal from a cut
//!    could meet a different witness first; if it finds a contact, the pair is
//!    run again from the roots so that the witness is the one from the roots).
//!
//! Measured with callgrind on the bench's world scenes (`proxima-bench world
//! --cut-limit C`, instructions per frame; `BENCHMARKS.md`, "World"): reuse 1
//! pays on every scene, reuse 2 on none of them, so it is off by default
//! (`cut_limit` 0). A cut of a pair whose objects moved as the scenes move them
//! (a few hundredths of their size and of a radian per frame) lies deep in the
//! trees: testing its pairs, with exact moved volumes near the leaves, costs
//! more than the descent from the roots that it skips, which decides the
//! disjoint parts high up. With cuts of up to 1024 pairs a frame took 1–24%
//! more instructions (tumble 6%, a tenth of the tumble moving 12%, arms 2%, a
//! tenth of the arms 24%, churn 5%, deep 1%), with up to 16,384 pairs 30% more
//! on the tumble. Cuts pay for motions far smaller than that: a near miss
//! nudged by 0.2% of its size per frame (the coherence tests).

use super::contacts::{ContactMode, WorldCounters};
use super::ignore::{key_slots, pair_key};
use super::{Object, World};
use crate::arena::Arena;
use crate::broad::Query;
use crate::narrow::BoundingVolume;
use crate::Result;
use rustc_hash::FxHashMap;
use std::ops::Range;

/// Default [`WorldConfig::cut_limit`](super::WorldConfig::cut_limit): no cuts
/// (they cost instructions on every bench scene, see above).
pub(crate) const DEFAULT_CUT_LIMIT: usize = 0;

/// Largest accepted cut limit.
pub(crate) const MAX_CUT_LIMIT: usize = 1 << 20;

/// What the last query found for one candidate pair.
#[derive(Clone, Debug)]
pub(crate) struct Entry {
    /// The two objects' insertion numbers (slots are reused, these are not).
    pub(crate) seqs: (u64, u64),
    /// Its primitive pairs (in `Cache::tris`).
    pub(crate) tris: Range<usize>,
    /// Its traversal cut (in `Cache::cuts`); empty if none was kept.
    pub(crate) cut: Range<usize>,
    pub(crate) contact: bool,
}

/// The answers of one query for every candidate pair that passed the filters.
#[derive(Clone, Debug, Default)]
pub(crate) struct Cache {
    pub(crate) entries: FxHashMap<u64, Entry>,
    pub(crate) tris: Vec<(u32, u32)>,
    pub(crate) cuts: Vec<(u32, u32)>,
}

impl Cache {
    pub(crate) fn clear(&mut self) {
        self.entries.clear();
        self.tris.clear();
        self.cuts.clear();
    }

    fn memory_bytes(&self) -> usize {
        self.entries.capacity() * (8 + std::mem::size_of::<Entry>() + 1)
            + (self.tris.capacity() + self.cuts.capacity()) * 8
    }
}

/// The coherence state of a world.
#[derive(Clone, Debug, Default)]
pub(crate) struct Coherence {
    /// The epoch and mode of the last `contacts`.
    pub(crate) last: Option<(u64, ContactMode)>,
    pub(crate) cache: Cache,
}

impl Coherence {
    pub(crate) fn memory_bytes(&self) -> usize {
        self.cache.memory_bytes()
    }
}

/// A pair the narrow phase must test, with the cut to start from (a range of the
/// cache's cuts).
#[derive(Clone, Debug)]
pub(crate) struct Task {
    pub(crate) key: u64,
    pub(crate) start: Option<Range<usize>>,
}

/// Which pairs a `contacts` query tests and which it copies.
#[derive(Debug, Default)]
pub(crate) struct Plan {
    pub(crate) tasks: Vec<Task>,
    /// Keys of cache entries whose answer is reused.
    pub(crate) reused: Vec<u64>,
    pub(crate) counters: WorldCounters,
}

impl<T, BV: BoundingVolume> World<T, BV> {
    /// Whether the object changed since the query of epoch `last`.
    #[inline]
    fn changed(o: &Object<T, BV>, last: Option<u64>) -> bool {
        last.is_none_or(|e| o.stamp > e)
    }

    /// The plan of a `contacts` query in `mode` (the broad phase is built).
    pub(crate) fn plan(&self, mode: ContactMode) -> Result<Plan> {
        let coherent = self.config.coherence;
        // Answers are reused only from a query of the same mode; cuts from any.
        let last = match self.coherence.last {
            Some((e, m)) if coherent && m == mode => Some(e),
            _ => None,
        };
        let mut plan = Plan::default();
        let changed: Vec<u32> = match last {
            Some(_) => self
                .objects
                .iter()
                .filter(|(_, o)| Self::changed(o, last) && !o.filter.is_inert())
                .map(|(h, _)| h.index())
                .collect(),
            None => Vec::new(),
        };
        if last.is_some() && changed.len() * 4 <= self.objects.len() {
            self.plan_changed(&changed, last, mode, &mut plan)?;
        } else {
            self.plan_all(last, mode, &mut plan);
        }
        Ok(plan)
    }

    /// Every candidate pair from the broad phase's pair search.
    fn plan_all(&self, last: Option<u64>, mode: ContactMode, plan: &mut Plan) {
        self.broad
            .for_each_pair(&mut |sa, sb| self.consider(sa, sb, last, mode, plan));
    }

    /// The pairs of the changed objects from sphere queries; the others from
    /// the cache.
    fn plan_changed(
        &self,
        changed: &[u32],
        last: Option<u64>,
        mode: ContactMode,
        plan: &mut Plan,
    ) -> Result<()> {
        for &s in changed {
            let (_, o) = self.objects.get_by_index(s).expect("a live slot");
            self.broad
                .visit(&self.objects, &Query::Sphere(o.sphere), |other| {
                    if other == s {
                        return;
                    }
                    let (_, p) = self.objects.get_by_index(other).expect("a live slot");
                    // A pair of two changed objects is met from both: keep one.
                    if Self::changed(p, last) && !p.filter.is_inert() && other < s {
                        return;
                    }
                    self.consider(s, other, last, mode, plan);
                })?;
        }
        let objects = &self.objects;
        for (&key, e) in &self.coherence.cache.entries {
            let (a, b) = key_slots(key);
            let same = |slot: u32, seq: u64| {
                live(objects, slot).is_some_and(|o| o.seq == seq && !Self::changed(o, last))
            };
            if same(a, e.seqs.0) && same(b, e.seqs.1) {
                plan.reused.push(key);
                plan.counters.coherent_pairs += 1;
            }
        }
        Ok(())
    }

    /// A candidate pair of slots from the broad phase: filtered, reused or
    /// planned for a test.
    fn consider(&self, sa: u32, sb: u32, last: Option<u64>, mode: ContactMode, plan: &mut Plan) {
        plan.counters.broad_pairs += 1;
        let (_, a) = self.objects.get_by_index(sa).expect("a live slot");
        let (_, b) = self.objects.get_by_index(sb).expect("a live slot");
        if !a.filter.interacts(b.filter) || self.ignored.contains(sa, sb) {
            plan.counters.filtered += 1;
            return;
        }
        let key = pair_key(sa, sb);
        let (a, b) = if sa < sb { (a, b) } else { (b, a) };
        let entry = self
            .coherence
            .cache
            .entries
            .get(&key)
            .filter(|e| self.config.coherence && e.seqs == (a.seq, b.seq));
        if entry.is_some() && !Self::changed(a, last) && !Self::changed(b, last) {
            plan.reused.push(key);
            plan.counters.coherent_pairs += 1;
            return;
        }
        let start = entry
            .filter(|e| !e.cut.is_empty() && (mode == ContactMode::All || !e.contact))
            .map(|e| e.cut.clone());
        plan.tasks.push(Task { key, start });
    }
}

/// The live object in `slot`, if any.
#[inline]
pub(crate) fn live<T, BV>(objects: &Arena<Object<T, BV>>, slot: u32) -> Option<&Object<T, BV>> {
    objects.get_by_index(slot).map(|(_, o)| o)
}
