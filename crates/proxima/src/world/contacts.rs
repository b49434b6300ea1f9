//! [`World::contacts`]: every pair of objects whose posed shapes share a point,
//! with their intersecting primitive pairs [sources: world, bvh-traverse].

use super::coherence::{Cache, Entry, Plan};
use super::ignore::key_slots;
use super::pair::{add, test_pair, PairOutcome, PairScratch};
use super::{Object, World};
use crate::arena::Arena;
use crate::narrow::{BoundingVolume, CostCounters};
use crate::{Handle, Result};
use std::ops::Range;

/// What `contacts` reports per object pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ContactMode {
    /// Every intersecting primitive pair ([`World::contacts`]).
    All,
    /// One witness primitive pair per object pair; each mesh traversal stops at
    /// its first contact ([`World::contacts_first`]).
    First,
}

/// The counters of one `contacts` query: how much work each stage did
/// [sources: bvh-cost].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WorldCounters {
    /// Pairs of objects whose broad-phase spheres overlap, as the broad phase
    /// reported them to this query (with coherence, only pairs involving a
    /// changed object may be enumerated; see `coherent_pairs`).
    pub broad_pairs: u64,
    /// Candidate pairs dropped before the narrow phase: the pair is ignored, or
    /// its filters do not interact (every index prunes such pairs inside its
    /// pair search, so they rarely reach the world and are not counted in
    /// `broad_pairs` either).
    pub filtered: u64,
    /// Pairs the narrow phase tested.
    pub narrow_pairs: u64,
    /// Pairs skipped by coherence: neither object changed since the last
    /// `contacts` of the same mode, so the last answer was reused.
    pub coherent_pairs: u64,
    /// Narrow tests that started from the traversal cut their pair's last test
    /// recorded instead of the roots (coherence for small motions).
    pub cut_starts: u64,
    /// Bounding-volume tests (`nv`), primitive tests (`np`) and node updates
    /// (`nu`) over all narrow tests.
    pub cost: CostCounters,
}

/// One pair of objects in contact: handles `a < b`, and its primitive pairs
/// `(primitive of a, primitive of b)` as a range of
/// [`ContactReport::triangles`] (a triangle index for a mesh, `0` for a ball).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ObjectContact {
    /// The object with the smaller handle.
    pub a: Handle,
    /// The object with the larger handle.
    pub b: Handle,
    /// Its primitive pairs in [`ContactReport::triangles`].
    pub triangles: Range<usize>,
}

/// The answer of a `contacts` query, deterministic: pairs sorted by handles,
/// each pair's primitive pairs ascending (in [`ContactMode::All`]; one witness
/// in [`ContactMode::First`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactReport {
    /// Object pairs in contact, sorted by `(a, b)`.
    pub pairs: Vec<ObjectContact>,
    /// Every pair's primitive pairs, one after the other.
    pub triangles: Vec<(u32, u32)>,
    /// What the query did.
    pub counters: WorldCounters,
}

impl ContactReport {
    /// The primitive pairs of one contact. O(1).
    pub fn triangles_of(&self, contact: &ObjectContact) -> &[(u32, u32)] {
        &self.triangles[contact.triangles.clone()]
    }

    /// Empties the report, keeping its memory.
    pub fn clear(&mut self) {
        self.pairs.clear();
        self.triangles.clear();
        self.counters = WorldCounters::default();
    }
}

/// Results of narrow tests: one buffer per thread.
#[derive(Debug, Default)]
pub(crate) struct Batch {
    /// `(pair key, outcome, its primitive pairs in tris)`.
    pub(crate) tested: Vec<(u64, PairOutcome, Range<usize>)>,
    pub(crate) tris: Vec<(u32, u32)>,
    pub(crate) cuts: Vec<(u32, u32)>,
}

impl<T, BV: BoundingVolume> World<T, BV> {
    /// Every pair of objects whose posed shapes share a point (closed: touching
    /// counts), each once, with all its intersecting primitive pairs; pairs
    /// whose filters do not interact or that are ignored are left out before
    /// the narrow phase. See [`World::contacts_into`].
    pub fn contacts(&mut self) -> Result<ContactReport> {
        let mut report = ContactReport::default();
        self.contacts_into(ContactMode::All, &mut report)?;
        Ok(report)
    }

    /// [`World::contacts`] with one witness primitive pair per object pair
    /// (the mesh traversals stop at their first contact).
    pub fn contacts_first(&mut self) -> Result<ContactReport> {
        let mut report = ContactReport::default();
        self.contacts_into(ContactMode::First, &mut report)?;
        Ok(report)
    }

    /// The contacts query in `mode`, into `report` (cleared first; its memory
    /// is reused).
    ///
    /// Cost: the broad phase (built or rebuilt first if due, see
    /// [`World::update_broad_phase`]) finds the candidate pairs, then each
    /// candidate that passes the filters goes to the narrow phase (mesh–mesh:
    /// a simultaneous BVH traversal, cost `Nv·Cv + Np·Cp + Nu·Cu` in
    /// [`WorldCounters::cost`]). With coherence
    /// ([`WorldConfig::coherence`](super::WorldConfig::coherence)), pairs
    /// neither of whose objects changed since the last query of the same mode
    /// are not tested again, and when few objects changed only their
    /// neighbourhoods are searched; the answers are the same.
    ///
    /// Fails with [`Error::InvalidPose`](crate::Error::InvalidPose) if two
    /// objects are so far apart that their relative pose leaves `f32` range, or
    /// with the index's error if it cannot be built; the world is then
    /// unchanged (and `report` cleared).
    pub fn contacts_into(&mut self, mode: ContactMode, report: &mut ContactReport) -> Result<()> {
        report.clear();
        self.update_broad_phase()?;
        let plan = self.plan(mode)?;
        let batch = self.test_sequential(&plan, mode)?;
        self.commit(mode, plan, vec![batch], report);
        Ok(())
    }

    /// Runs the plan's narrow tests on this thread.
    fn test_sequential(&mut self, plan: &Plan, mode: ContactMode) -> Result<Batch> {
        let mut batch = Batch::default();
        let World {
            objects,
            coherence,
            scratch,
            config,
            ..
        } = self;
        for task in &plan.tasks {
            let start = task.start.clone().map(|r| &coherence.cache.cuts[r]);
            test_task(
                scratch,
                objects,
                task.key,
                start,
                mode,
                config.cut_limit,
                &mut batch,
            )?;
        }
        Ok(batch)
    }

    /// Assembles the report from the tests and the reused answers, sorted by
    /// pair, and keeps what coherence needs for the next query.
    pub(crate) fn commit(
        &mut self,
        mode: ContactMode,
        plan: Plan,
        batches: Vec<Batch>,
        report: &mut ContactReport,
    ) {
        enum Source {
            Tested(usize, usize),
            Reused,
        }
        let mut items: Vec<(u64, Source)> =
            plan.reused.iter().map(|&k| (k, Source::Reused)).collect();
        let mut counters = plan.counters;
        for (bi, b) in batches.iter().enumerate() {
            for (ti, (key, outcome, _)) in b.tested.iter().enumerate() {
                items.push((*key, Source::Tested(bi, ti)));
                counters.narrow_pairs += 1;
                counters.cut_starts += outcome.from_cut as u64;
                add(&mut counters.cost, outcome.counters);
            }
        }
        items.sort_unstable_by_key(|(k, _)| *k);
        let coherent = self.config.coherence;
        let old = &self.coherence.cache;
        let mut next = Cache::default();
        for (key, source) in &items {
            let (tris, cut, contact) = match *source {
                Source::Tested(bi, ti) => {
                    let (_, outcome, tris) = &batches[bi].tested[ti];
                    let cut = outcome.cut.clone().unwrap_or(0..0);
                    (
                        &batches[bi].tris[tris.clone()],
                        &batches[bi].cuts[cut],
                        outcome.contact,
                    )
                }
                Source::Reused => {
                    let e = &old.entries[key];
                    (
                        &old.tris[e.tris.clone()],
                        &old.cuts[e.cut.clone()],
                        e.contact,
                    )
                }
            };
            let (sa, sb) = key_slots(*key);
            let (ha, oa) = self.objects.get_by_index(sa).expect("a live slot");
            let (hb, ob) = self.objects.get_by_index(sb).expect("a live slot");
            let start = report.triangles.len();
            if contact {
                report.triangles.extend_from_slice(tris);
                report.pairs.push(ObjectContact {
                    a: ha,
                    b: hb,
                    triangles: start..report.triangles.len(),
                });
            }
            if coherent {
                let c0 = next.cuts.len();
                next.cuts.extend_from_slice(cut);
                next.entries.insert(
                    *key,
                    Entry {
                        seqs: (oa.seq, ob.seq),
                        tris: start..report.triangles.len(),
                        cut: c0..next.cuts.len(),
                        contact,
                    },
                );
            }
        }
        report.counters = counters;
        if coherent {
            next.tris.extend_from_slice(&report.triangles);
            self.coherence.cache = next;
            self.coherence.last = Some((self.epoch, mode));
        } else {
            self.coherence.cache.clear();
            self.coherence.last = None;
        }
        self.epoch += 1;
    }
}

/// Tests the pair `key` into `batch`.
pub(crate) fn test_task<T, BV: BoundingVolume>(
    scratch: &mut PairScratch<BV>,
    objects: &Arena<Object<T, BV>>,
    key: u64,
    start: Option<&[(u32, u32)]>,
    mode: ContactMode,
    cut_limit: usize,
    batch: &mut Batch,
) -> Result<()> {
    let (sa, sb) = key_slots(key);
    let (_, a) = objects.get_by_index(sa).expect("a live slot");
    let (_, b) = objects.get_by_index(sb).expect("a live slot");
    let t0 = batch.tris.len();
    let outcome = test_pair(
        scratch,
        a,
        b,
        mode == ContactMode::First,
        start,
        cut_limit,
        &mut batch.tris,
        &mut batch.cuts,
    )?;
    let t1 = batch.tris.len();
    batch.tested.push((key, outcome, t0..t1));
    Ok(())
}
