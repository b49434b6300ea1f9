//! The interface every W6 structure implements ([`RayCaster`]), Proxima's and the
//! peers' alike.

use proxima::geom::Ray;
use rayon::prelude::*;

/// A closest hit: `(mesh triangle, t)`, or `None` for a miss.
pub type Answer = Option<(u32, f32)>;

/// A closest-hit ray caster over one mesh: `(mesh triangle, t)` or `None`.
pub trait RayCaster: Sync {
    /// The closest hit of a valid ray.
    fn cast(&self, ray: &Ray) -> Answer;

    /// Every ray of a batch on the current rayon pool (the generic `par_iter`; ours
    /// override it with the library's batch helper).
    fn cast_par(&self, rays: &[Ray]) -> Vec<Answer> {
        rays.par_iter()
            .with_min_len(256)
            .map(|r| self.cast(r))
            .collect()
    }
}
