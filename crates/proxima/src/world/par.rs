//! Parallel `contacts` (feature `parallel`, [sources: parallel]): the plan is
//! made on the calling thread, the narrow tests run on rayon's pool with one
//! scratch space per worker, and the report is assembled in the same sorted
//! order, so it equals the sequential one.

use super::contacts::{test_task, Batch, ContactMode, ContactReport};
use super::pair::PairScratch;
use super::World;
use crate::narrow::BoundingVolume;
use crate::Result;
use rayon::prelude::*;

/// Tasks per parallel chunk: pair tests vary a lot in cost (a deep
/// interpenetration costs thousands of near misses), so chunks are small
/// enough to balance, large enough to amortize the per-chunk buffers.
const CHUNK: usize = 8;

impl<T: Sync, BV: BoundingVolume> World<T, BV> {
    /// [`World::contacts`] with the narrow tests spread over rayon's pool (the
    /// current one, or the global one). Same answer, same counters.
    pub fn par_contacts(&mut self) -> Result<ContactReport> {
        let mut report = ContactReport::default();
        self.par_contacts_into(ContactMode::All, &mut report)?;
        Ok(report)
    }

    /// [`World::contacts_into`] with the narrow tests spread over rayon's pool.
    /// Cost: as the sequential query, divided among the workers, plus one
    /// buffer set per chunk of pairs. Fails as the sequential query does,
    /// leaving the world unchanged.
    pub fn par_contacts_into(
        &mut self,
        mode: ContactMode,
        report: &mut ContactReport,
    ) -> Result<()> {
        report.clear();
        self.update_broad_phase()?;
        let plan = self.plan(mode)?;
        let (objects, cache, config) = (&self.objects, &self.coherence.cache, &self.config);
        let batches = plan
            .tasks
            .par_chunks(CHUNK)
            .map_init(
                || PairScratch::new(config.rotation),
                |scratch, tasks| {
                    let mut batch = Batch::default();
                    for task in tasks {
                        let start = task.start.clone().map(|r| &cache.cuts[r]);
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
                },
            )
            .collect::<Result<Vec<Batch>>>()?;
        self.commit(mode, plan, batches, report);
        Ok(())
    }
}
