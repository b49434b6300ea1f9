//! The W6 agreement check: Proxima's structures must give exactly the same closest
//! hit (triangle and `t`) as each other and as brute force; peers must agree on
//! hit/miss and `t` within a small relative tolerance, and every ray they disagree
//! on is re-cast by brute force to confirm our answer and classified.

use super::caster::{Answer, RayCaster};
use super::structures::Brute;
use proxima::geom::Ray;
use proxima::glam::DVec3;
use proxima::narrow::TriMesh;

/// Relative tolerance on `t` between a peer and us (of `t + mesh radius`).
const T_TOL: f32 = 1e-4;
/// A hit whose smallest barycentric is below this is "on an edge".
const EDGE: f64 = 1e-4;
/// A peer disagreeing on more than this fraction of the rays fails the run.
const MAX_PEER_DISAGREEMENT: f64 = 0.01;

/// How close a peer's `t` must be to ours (the triangle may differ: a tie).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tol {
    /// Within `T_TOL` of `t` plus the mesh's size: the Rust peers.
    Scene,
    /// Within this fraction of `t`, or (for `t` near 0, where `f32` rounding of
    /// the coordinates dominates) within 64 ε of the mesh's size: Embree.
    Relative(f32),
}

/// How one structure's answers compare with the reference.
#[derive(Clone, Debug, Default)]
pub struct Verdict {
    /// Rays with a different answer.
    pub disagree: usize,
    /// ...of which the hit (ours or the peer's) is within `EDGE` of a triangle edge.
    pub edge: usize,
    /// ...of which the hit is within the tolerance of the ray's `max_t`.
    pub max_t: usize,
    /// ...the rest.
    pub other: usize,
    /// The first of the rest: ray, peer's answer, ours.
    pub example: Option<String>,
}

impl Verdict {
    /// One line for the report.
    pub fn explain(&self) -> String {
        format!(
            "{} rays differ: {} hit within {EDGE:e} (barycentric) of an edge or corner (f32 Möller vs our watertight test), {} at max_t, {} other; on every one our answer equals brute force",
            self.disagree, self.edge, self.max_t, self.other
        ) + &self.example.as_ref().map_or(String::new(), |e| format!(" (e.g. {e})"))
    }
}

/// The reference answers and the oracle for one mesh and ray set.
pub struct Verifier<'a> {
    mesh: &'a TriMesh,
    rays: &'a [Ray],
    scale: f32,
    reference: Option<(&'static str, Vec<Answer>)>,
    brute: Brute,
}

/// Smallest barycentric of the point where `ray`'s line meets the plane of
/// triangle `i` (f64; infinite for a parallel ray).
fn min_barycentric(mesh: &TriMesh, i: u32, ray: &Ray) -> f64 {
    let [a, b, c] = mesh.triangle(i as usize).map(|p| p.as_dvec3());
    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
    let n = (b - a).cross(c - a);
    let den = n.dot(d);
    if den == 0.0 {
        return f64::INFINITY;
    }
    let p = o + d * (n.dot(a - o) / den);
    let area = |x: DVec3, y: DVec3, z: DVec3| (y - x).cross(z - x).dot(n);
    let nn = n.dot(n);
    [area(p, b, c), area(a, p, c), area(a, b, p)]
        .iter()
        .map(|w| w / nn)
        .fold(f64::INFINITY, f64::min)
}

impl<'a> Verifier<'a> {
    /// A verifier with no reference yet (the first structure checked becomes it).
    pub fn new(mesh: &'a TriMesh, rays: &'a [Ray]) -> Self {
        let b = super::rays::bounds(mesh);
        Verifier {
            mesh,
            rays,
            scale: (b.max - b.min).length().max(1e-6),
            reference: None,
            brute: Brute(mesh.clone()),
        }
    }

    fn agree(&self, a: Option<(u32, f32)>, b: Option<(u32, f32)>, tol: Tol) -> bool {
        match (a, b) {
            (None, None) => true,
            (Some((_, s)), Some((_, t))) => match tol {
                Tol::Scene => (s - t).abs() <= T_TOL * (s.abs() + self.scale),
                Tol::Relative(r) => {
                    (s - t).abs() <= r * s.abs().max(t.abs()) + 64.0 * f32::EPSILON * self.scale
                }
            },
            _ => false,
        }
    }

    /// Checks the answers `res` of structure `name` (for the first `res.len()` rays),
    /// a peer's within [`Tol::Scene`].
    pub fn check(
        &mut self,
        name: &'static str,
        peer: bool,
        res: &[Option<(u32, f32)>],
    ) -> Result<Verdict, String> {
        self.check_within(name, peer, res, Tol::Scene)
    }

    /// [`Verifier::check`] with the peer tolerance `tol`.
    pub fn check_within(
        &mut self,
        name: &'static str,
        peer: bool,
        res: &[Option<(u32, f32)>],
        tol: Tol,
    ) -> Result<Verdict, String> {
        let Some((ref_name, reference)) = &self.reference else {
            if peer {
                return Err("the first structure (the reference) must be Proxima's".into());
            }
            self.reference = Some((name, res.to_vec()));
            return Ok(Verdict::default());
        };
        let mut v = Verdict::default();
        for (i, (&got, &want)) in res.iter().zip(reference).enumerate() {
            if !peer {
                if got != want {
                    return Err(format!(
                        "ray {i} {:?}: {name} gives {got:?}, {ref_name} gives {want:?}",
                        self.rays[i]
                    ));
                }
                continue;
            }
            if self.agree(got, want, tol) {
                continue;
            }
            v.disagree += 1;
            let ray = &self.rays[i];
            let truth = self.brute.cast(ray);
            if truth != want {
                return Err(format!(
                    "ray {i} {ray:?}: {ref_name} gives {want:?}, brute force {truth:?}"
                ));
            }
            let near_max = |t: f32| (ray.max_t - t).abs() <= T_TOL * (t.abs() + self.scale);
            let on_edge = [got, want]
                .iter()
                .flatten()
                .any(|&(tri, _)| min_barycentric(self.mesh, tri, ray).abs() < EDGE);
            if on_edge {
                v.edge += 1;
            } else if [got, want].iter().flatten().any(|&(_, t)| near_max(t)) {
                v.max_t += 1;
            } else {
                v.other += 1;
                if v.example.is_none() {
                    v.example = Some(format!("{ray:?}: {name} {got:?}, ours {want:?}"));
                }
            }
        }
        if v.disagree as f64 > MAX_PEER_DISAGREEMENT * res.len() as f64 {
            return Err(format!(
                "{name} disagrees on {} of {} rays ({})",
                v.disagree,
                res.len(),
                v.explain()
            ));
        }
        Ok(v)
    }
}
