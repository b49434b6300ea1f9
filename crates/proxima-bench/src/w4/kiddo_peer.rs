//! Peer: kiddo 6's immutable k-d tree over the sphere centres (points only).
//! A sphere query `(c, r)` asks for the centres within `r + r_max` of `c` (kiddo's
//! inclusive squared-Euclidean radius, widened by a few ulps so rounding never
//! loses a candidate) and filters them exactly. kiddo has no box, ray or frustum
//! query, so those kinds are skipped for it.

use super::engine::Engine;
use super::queries::{Batches, QueryKind};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use proxima::broad::Selection;
use proxima::geom::Sphere;

/// kiddo's tree over the centres, plus the spheres for the exact test.
pub struct KiddoQuery {
    tree: ImmutableKdTree<f32, 3>,
    spheres: Vec<Sphere>,
    r_max: f32,
}

impl KiddoQuery {
    /// Builds the immutable tree from the centres (item `i` = sphere `i`).
    pub fn build(spheres: &[Sphere]) -> Self {
        let points: Vec<[f32; 3]> = spheres.iter().map(|s| s.center.to_array()).collect();
        let r_max = spheres.iter().map(|s| s.radius).fold(0.0, f32::max);
        KiddoQuery {
            tree: ImmutableKdTree::new_from_slice(&points).expect("kiddo build"),
            spheres: spheres.to_vec(),
            r_max,
        }
    }

    fn sphere(&self, q: &Sphere) -> usize {
        let reach = q.radius + self.r_max;
        let r2 = reach * reach * (1.0 + 1e-5) + 1e-30;
        let mut n = 0;
        self.tree
            .query(&q.center.to_array())
            .within::<SquaredEuclidean<f32>>(r2)
            .unsorted()
            .visit(|hit| n += usize::from(q.selects(&self.spheres[hit.item as usize])));
        n
    }
}

impl Engine for KiddoQuery {
    fn count(&self, b: &Batches, kind: QueryKind, i: usize) -> Option<usize> {
        match kind {
            QueryKind::Sphere => Some(self.sphere(&b.spheres[i])),
            _ => None,
        }
    }

    fn supports(&self, kind: QueryKind) -> bool {
        kind == QueryKind::Sphere
    }

    /// Estimate (kiddo does not report its size): 12-byte point and 4-byte item
    /// per object in the leaves, the stems (about one `f32` split per 32-item
    /// leaf), plus the sphere copy.
    fn memory_bytes(&self) -> usize {
        let n = self.spheres.len();
        n * (12 + 4) + (n / 32 + 1) * 4 + n * std::mem::size_of::<Sphere>()
    }
}
