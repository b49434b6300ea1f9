//! The narrow-phase test of one object pair: mesh–mesh through a [`Collider`]
//! in the frame of one of the two meshes, ball–mesh in the mesh's frame,
//! ball–ball in the world frame. Shared by the sequential and the parallel
//! `contacts`.

use super::{Object, Shape};
use crate::geom::{overlap, Sphere};
use crate::narrow::{
    rotation_deviation, BoundingVolume, Collider, CostCounters, CutRecorder, RotationUpdate,
};
use crate::{Error, Result};
use std::ops::Range;

/// Scratch space of pair tests: one per thread.
#[derive(Clone, Debug)]
pub(crate) struct PairScratch<BV> {
    collider: Collider<BV>,
    stack: Vec<u32>,
    hits: Vec<u32>,
}

impl<BV: BoundingVolume> PairScratch<BV> {
    pub(crate) fn new(rotation: RotationUpdate) -> Self {
        PairScratch {
            collider: Collider::new(rotation),
            stack: Vec::new(),
            hits: Vec::new(),
        }
    }
}

/// What one pair test found.
#[derive(Clone, Debug, Default)]
pub(crate) struct PairOutcome {
    /// Whether the shapes share a point.
    pub(crate) contact: bool,
    /// The traversal cut recorded for the next test of this pair (a range of
    /// the `cuts` buffer), or `None`.
    pub(crate) cut: Option<Range<usize>>,
    /// Whether the test started from a cut (coherence).
    pub(crate) from_cut: bool,
    pub(crate) counters: CostCounters,
}

/// Whether object `a` is the one moved into the other's frame in a mesh–mesh
/// test: the mesh with more triangles moves (on a tie, the object inserted
/// later). Measured with callgrind (`run_from`, k-DOP18 with the conservative
/// rotation update; OBB is indifferent): moving the larger mesh costs 18 % fewer
/// instructions on 120 bunnies, teapots and robs at random poses (Nv 3.05 M
/// instead of 5.07 M, Np 0.58 M instead of 1.43 M, Nu 0.39 M instead of
/// 0.22 M) and 12 % fewer on SKINbody turned through BONERibcage: the
/// conservatively moved volumes are loose, and they hurt less on the many small
/// nodes of the larger tree than on the few large nodes of the smaller one,
/// which keeps its exact volumes when it stays fixed.
#[inline]
pub(crate) fn a_moves(tri_a: usize, seq_a: u64, tri_b: usize, seq_b: u64) -> bool {
    (tri_a, seq_a) > (tri_b, seq_b)
}

/// Tests objects `a` and `b` (`a` the one with the smaller handle) and appends
/// their intersecting primitive pairs `(primitive of a, primitive of b)` to
/// `out`: every pair, ascending, or with `first` one witness. `start` is a cut
/// recorded by an earlier test of the same two objects, used for a mesh pair
/// (with `first` only if that test found no contact); a new cut of at most
/// `cut_limit` node pairs is appended to `cuts` when the traversal was complete.
///
/// Fails with [`Error::InvalidPose`] if the relative pose of two meshes (or a
/// ball's centre in a mesh's frame) leaves `f32` range.
#[allow(clippy::too_many_arguments)]
pub(crate) fn test_pair<T, BV: BoundingVolume>(
    scratch: &mut PairScratch<BV>,
    a: &Object<T, BV>,
    b: &Object<T, BV>,
    first: bool,
    start: Option<&[(u32, u32)]>,
    cut_limit: usize,
    out: &mut Vec<(u32, u32)>,
    cuts: &mut Vec<(u32, u32)>,
) -> Result<PairOutcome> {
    let base = out.len();
    let mut outcome = PairOutcome::default();
    match (&a.shape, &b.shape) {
        (Shape::Mesh(ma), Shape::Mesh(mb)) => {
            let (ta, tb) = (
                ma.trimesh().triangles().len(),
                mb.trimesh().triangles().len(),
            );
            let swapped = !a_moves(ta, a.seq, tb, b.seq);
            let (mv, fx, mesh_mv, mesh_fx) = if swapped {
                (b, a, mb, ma)
            } else {
                (a, b, ma, mb)
            };
            let rel = fx.inverse * mv.pose;
            let dev = rotation_deviation(&rel)?;
            let roots = [(0u32, 0u32)];
            let cut_base = cuts.len();
            let mut rec = CutRecorder {
                out: cuts,
                base: cut_base,
                cap: cut_limit,
                full: cut_limit == 0,
            };
            let from = start.filter(|s| !s.is_empty()).unwrap_or(&roots);
            outcome.from_cut = start.is_some_and(|s| !s.is_empty());
            let (c, stopped) = scratch.collider.run_from(
                mesh_mv, &rel, dev, mesh_fx, first, out, None, from, &mut rec,
            );
            let full = rec.full;
            add(&mut outcome.counters, c);
            if stopped || full {
                cuts.truncate(cut_base);
            } else {
                outcome.cut = Some(cut_base..cuts.len());
            }
            if stopped && outcome.from_cut {
                // The witness of a first-contact query is the first pair met from
                // the roots; a traversal from a cut may meet another one first.
                out.truncate(base);
                let (c, _) = scratch.collider.run_from(
                    mesh_mv,
                    &rel,
                    dev,
                    mesh_fx,
                    true,
                    out,
                    None,
                    &roots,
                    &mut (),
                );
                add(&mut outcome.counters, c);
            }
            if swapped {
                for p in &mut out[base..] {
                    *p = (p.1, p.0);
                }
            }
        }
        (Shape::Sphere(r), Shape::Mesh(m)) => {
            ball_mesh(scratch, a, *r, b, m, first, out, false, &mut outcome)?
        }
        (Shape::Mesh(m), Shape::Sphere(r)) => {
            ball_mesh(scratch, b, *r, a, m, first, out, true, &mut outcome)?
        }
        (Shape::Sphere(ra), Shape::Sphere(rb)) => {
            outcome.counters.np = 1;
            let sa = Sphere::new(a.pose.translation.into(), *ra);
            let sb = Sphere::new(b.pose.translation.into(), *rb);
            if overlap::sphere_sphere(&sa, &sb) {
                out.push((0, 0));
            }
        }
    }
    if !first {
        out[base..].sort_unstable();
    }
    outcome.contact = out.len() > base;
    Ok(outcome)
}

/// A ball (object `ball`, radius `r`) against a mesh: the ball's centre moved into
/// the mesh's frame, then [`Mesh::visit_sphere`](crate::narrow::Mesh). Appends
/// `(0, triangle)`, or `(triangle, 0)` when `mesh_first`.
#[allow(clippy::too_many_arguments)]
fn ball_mesh<T, BV: BoundingVolume>(
    scratch: &mut PairScratch<BV>,
    ball: &Object<T, BV>,
    r: f32,
    mesh_obj: &Object<T, BV>,
    mesh: &crate::narrow::Mesh<BV>,
    first: bool,
    out: &mut Vec<(u32, u32)>,
    mesh_first: bool,
    outcome: &mut PairOutcome,
) -> Result<()> {
    let c = mesh_obj
        .inverse
        .transform_point3(ball.pose.translation.into());
    if !c.is_finite() {
        return Err(Error::InvalidPose(
            "a ball's centre in a mesh's frame is beyond f32 range".into(),
        ));
    }
    scratch.hits.clear();
    let counters = mesh.visit_sphere(
        &Sphere::new(c, r),
        first,
        &mut scratch.stack,
        &mut scratch.hits,
    );
    add(&mut outcome.counters, counters);
    out.extend(
        scratch
            .hits
            .iter()
            .map(|&t| if mesh_first { (t, 0) } else { (0, t) }),
    );
    Ok(())
}

#[inline]
pub(crate) fn add(total: &mut CostCounters, c: CostCounters) {
    total.nv += c.nv;
    total.np += c.np;
    total.nu += c.nu;
}
