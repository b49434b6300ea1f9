//! All overlapping pairs: within each occupied cell, then the oversized objects.

use super::keys::Key;
use super::list::Packed;
use super::store::{Entries, Store};
use super::CellGrid;
use crate::geom::{overlap, Sphere};
use crate::Handle;
use std::ops::ControlFlow;

/// `overlap::sphere_sphere_candidate` on two stored spheres.
#[inline(always)]
fn candidate(a: &Sphere, b: &Sphere) -> bool {
    let (p, q) = (a.center, b.center);
    overlap::sphere_sphere_candidate(p.x, p.y, p.z, a.radius, q.x, q.y, q.z, b.radius)
}

impl<T, S: Store> CellGrid<T, S> {
    /// Calls `f` once per overlapping pair whose filters interact (checked
    /// after the exact test: only overlapping pairs read the filters). Inert
    /// objects never enter it [sources: index-queries]: while some are stored,
    /// each cell's list is copied without them first (the copy is O(k), the
    /// tests it saves O(k²)), and inert oversized objects are skipped.
    ///
    /// Gridded pairs: two overlapping objects have overlapping footprints, so
    /// they share at least one cell. A pair found in cell `key` is reported only
    /// if that cell is the lowest one both cover (the `max` of their lowest
    /// cells per axis), read from the key boxes stored in the references. Order
    /// of the checks: the `f32` pre-filter first (it rejects almost every pair,
    /// a well-predicted branch), then the cell rule, then the exact test, so
    /// each pair gets the exact test once, in its lowest common cell, however
    /// many cells the two share (objects listed in thousands of cells, with ties
    /// that need the expansion arithmetic, took seconds when the exact test ran
    /// in every cell; the cell rule first doubled W1's pair time by mispredicted
    /// branches).
    ///
    /// Pairs with an oversized object: each oversized object against the others
    /// after it in the list, then a grid query with its sphere (each gridded
    /// object once, by the query's own rule). Cost O(Σ k² pre-filters over cells
    /// with `k` references + oversized² + oversized × query).
    pub fn pairs(
        &self,
        mut f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if self.inert.any() {
            // Inert objects leave each cell's list before its k² tests (one
            // filter read per reference).
            let mut live = Vec::new();
            self.store.cells(|key, es| {
                live.clear();
                live.extend((es.iter()).filter(|e| !self.filters[e.slot as usize].is_inert()));
                self.cell_pairs(key, &live, &mut f)
            })?;
        } else {
            self.store
                .cells(|key, es| self.cell_pairs(key, es, &mut f))?;
        }
        for (i, &a) in self.oversized.iter().enumerate() {
            let fa = self.filters[a as usize];
            if fa.is_inert() {
                continue;
            }
            let (ha, va) = self.resolve(a);
            let sa = &self.spheres[a as usize];
            for &b in &self.oversized[i + 1..] {
                if fa.interacts(self.filters[b as usize])
                    && overlap::sphere_sphere(sa, &self.spheres[b as usize])
                {
                    let (hb, vb) = self.resolve(b);
                    f(ha, va, hb, vb)?;
                }
            }
            let kb = self.store.lattice().sphere_box(sa, S::AXES);
            self.visit_cells(sa, kb, &mut |hb, _, vb| {
                if fa.interacts(self.filters[hb.index() as usize]) {
                    f(ha, va, hb, vb)
                } else {
                    ControlFlow::Continue(())
                }
            })?;
        }
        ControlFlow::Continue(())
    }

    /// The pairs first met in cell `key`, among its references `es`.
    #[inline]
    fn cell_pairs(
        &self,
        key: Key,
        es: Entries<'_, S::Packed>,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if es.len() < 2 {
            return ControlFlow::Continue(());
        }
        for (i, ea) in es.iter().enumerate() {
            let sa = &self.spheres[ea.slot as usize];
            let la = ea.keys.lo();
            for eb in &es[i + 1..] {
                let sb = &self.spheres[eb.slot as usize];
                if candidate(sa, sb)
                    && {
                        let lb = eb.keys.lo();
                        (0..S::AXES).all(|a| la[a].max(lb[a]) == key[a])
                    }
                    && overlap::sphere_sphere(sa, sb)
                    && self.filters[ea.slot as usize].interacts(self.filters[eb.slot as usize])
                {
                    let (ha, va) = self.resolve(ea.slot);
                    let (hb, vb) = self.resolve(eb.slot);
                    f(ha, va, hb, vb)?;
                }
            }
        }
        ControlFlow::Continue(())
    }
}
