//! Distances in the world [sources: world]: between two objects
//! ([`World::distance`]), from one object to its nearest obstacle
//! ([`World::nearest_obstacle`]), and contacts with a margin
//! ([`World::contacts_within`]). The per-pair work is the narrow phase's
//! [`Proximity`] in the frame of one of the two meshes, the one `contacts`
//! uses (`pair.rs`), so that a distance of `0` is exactly a contact there.

use super::contacts::{ContactReport, ObjectContact, WorldCounters};
use super::pair::{a_moves, add, centre_in};
use super::{grown_radius, Object, Shape, World};
use crate::broad::Query;
use crate::geom::{overlap, Sphere};
use crate::narrow::{rotation_deviation, BoundingVolume, CostCounters, Mesh, Proximity};
use crate::{Error, Handle, Result};
use glam::{Affine3A, DVec3};

/// The distance between two objects of a [`World`], with a nearest pair of
/// points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectDistance {
    /// The first object (the one asked about).
    pub a: Handle,
    /// The second object (for [`World::nearest_obstacle`], the obstacle).
    pub b: Handle,
    /// The distance between the posed shapes: exactly `0` when they touch as
    /// [`World::contacts`] decides it (a mesh is its surface, a ball is
    /// solid), else positive. No penetration depth.
    pub distance: f64,
    /// A nearest point of `a`, then one of `b`, in the world frame (`f64`);
    /// for touching shapes, a point in common (within rounding).
    pub points: [DVec3; 2],
    /// The primitives the points lie on: `(of a, of b)`, a triangle index for a
    /// mesh, `0` for a ball.
    pub primitives: (u32, u32),
    /// Cost counters of the narrow-phase work.
    pub counters: CostCounters,
}

impl<T, BV: BoundingVolume> World<T, BV> {
    /// The distance between objects `a` and `b` and a nearest pair of points
    /// (whatever their filters and ignored pairs: the pair is named).
    ///
    /// Mesh–mesh: [`Proximity::distance`] in the frame of the mesh that
    /// `contacts` keeps fixed (the value is that of the triangles as
    /// `contacts` poses them: `0` exactly when it reports the pair). Ball–mesh:
    /// the mesh's nearest point to the centre ([`Proximity::closest_point`])
    /// minus the radius, `0` exactly when `contacts` reports the pair
    /// ([`Mesh::intersects_sphere`]). Ball–ball: the centres' distance minus
    /// the radii. Cost: one narrow-phase query (a new [`Proximity`]: keep the
    /// world's queries for loops).
    ///
    /// Fails with [`Error::StaleHandle`], [`Error::InvalidParameter`] for
    /// `a == b`, or [`Error::InvalidPose`] if the relative pose of the two
    /// objects leaves `f32` range.
    pub fn distance(&self, a: Handle, b: Handle) -> Result<ObjectDistance> {
        let oa = self.objects.get(a)?;
        let ob = self.objects.get(b)?;
        if a == b {
            return Err(Error::InvalidParameter(
                "a distance needs two different objects".into(),
            ));
        }
        let mut q = Proximity::new(self.config.rotation);
        pair_distance(&mut q, (a, oa), (b, ob))
    }

    /// The object nearest to `a` among those it may collide with: whose filter
    /// interacts with `a`'s ([`Filter::interacts`](crate::broad::Filter::interacts))
    /// and whose pair with `a` is not ignored. `None` if there is none. Ties go
    /// to the smaller handle.
    ///
    /// Cost: O(n log n) for the candidates ordered by the gap between broad-phase
    /// spheres (a lower bound on their distance), then [`World::distance`] to
    /// each in that order until the gap exceeds the nearest distance found:
    /// usually a few.
    ///
    /// Fails with [`Error::StaleHandle`], or as [`World::distance`].
    pub fn nearest_obstacle(&self, a: Handle) -> Result<Option<ObjectDistance>> {
        let oa = self.objects.get(a)?;
        let sa = a.index();
        let mut candidates: Vec<(f64, Handle)> = self
            .objects
            .iter()
            .filter(|(h, o)| {
                *h != a && oa.filter.interacts(o.filter) && !self.ignored.contains(sa, h.index())
            })
            .map(|(h, o)| (sphere_gap(&oa.sphere, &o.sphere), h))
            .collect();
        candidates.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let mut q = Proximity::new(self.config.rotation);
        let mut best: Option<ObjectDistance> = None;
        for (gap, h) in candidates {
            if let Some(b) = &best {
                // The narrow phase measures in one object's frame, whose pose
                // may scale distances by its deviation from a rotation; the
                // broad spheres are grown for it (`RADIUS_GROWTH`), the gap
                // is discounted as much again.
                if gap * (1.0 - 4e-3) > b.distance {
                    break;
                }
            }
            let ob = self.objects.get(h)?;
            let d = pair_distance(&mut q, (a, oa), (h, ob))?;
            let better = match &best {
                None => true,
                Some(b) => d.distance < b.distance || (d.distance == b.distance && h < b.b),
            };
            if better {
                best = Some(d);
            }
        }
        Ok(best)
    }

    /// Every pair of objects whose posed shapes are within `margin` of each
    /// other (closed), each once, with every primitive pair within `margin`:
    /// [`World::contacts`] with a contact margin (with `margin = 0` exactly its
    /// answer). Filters and ignored pairs are honoured as there; the report has
    /// the same form (pairs sorted by handles, primitive pairs ascending).
    ///
    /// Cost: the broad phase (built first if due) queried with each object's
    /// sphere grown by the margin, then per candidate pair that passes the
    /// filters: mesh–mesh [`Proximity::pairs_within`] in the frame `contacts`
    /// uses, ball–mesh the mesh's triangles within the grown ball
    /// ([`Mesh::triangles_in_sphere`]), ball–ball the centres' distance. No
    /// coherence: every candidate is tested.
    ///
    /// Fails on a negative or non-finite margin, or as [`World::contacts`].
    pub fn contacts_within(&mut self, margin: f64) -> Result<ContactReport> {
        if !margin.is_finite() {
            return Err(Error::NonFinite {
                what: "contact margin",
            });
        }
        if margin < 0.0 {
            return Err(Error::InvalidParameter(format!(
                "contact margin must not be negative, got {margin}"
            )));
        }
        self.update_broad_phase()?;
        // The margin as an `f32` no smaller than it, at most 1e31: posed
        // shapes stay within ±1e30 (`COORDINATE_LIMIT`), so every pair is within
        // that of each other.
        let m32 = {
            let m = margin.min(1e31) as f32;
            if (m as f64) < margin.min(1e31) {
                f32::from_bits(m.to_bits() + 1)
            } else {
                m
            }
        };
        let mut counters = WorldCounters::default();
        let mut candidates = Vec::new();
        for (h, o) in self.objects.iter() {
            let s = h.index();
            let c = o.sphere.center;
            let reach = Sphere::new(
                c,
                grown_radius(
                    o.sphere.radius + m32,
                    c.abs().max_element() + o.sphere.radius + m32,
                ),
            );
            self.broad
                .visit(&self.objects, &Query::Sphere(reach), |other| {
                    // Each pair once, from its smaller slot.
                    if other > s {
                        candidates.push((s, other));
                    }
                })?;
        }
        candidates.sort_unstable();
        candidates.dedup();
        let mut report = ContactReport::default();
        let mut q = Proximity::new(self.config.rotation);
        let mut tris = Vec::new();
        for (sa, sb) in candidates {
            counters.broad_pairs += 1;
            let (ha, a) = self.objects.get_by_index(sa).expect("a live slot");
            let (hb, b) = self.objects.get_by_index(sb).expect("a live slot");
            if !a.filter.interacts(b.filter) || self.ignored.contains(sa, sb) {
                counters.filtered += 1;
                continue;
            }
            counters.narrow_pairs += 1;
            tris.clear();
            let c = pair_within(&mut q, a, b, margin, m32, &mut tris)?;
            add(&mut counters.cost, c);
            if !tris.is_empty() {
                tris.sort_unstable();
                let start = report.triangles.len();
                report.triangles.extend_from_slice(&tris);
                report.pairs.push(ObjectContact {
                    a: ha,
                    b: hb,
                    triangles: start..report.triangles.len(),
                });
            }
        }
        report.counters = counters;
        Ok(report)
    }
}

/// The gap between two spheres (`0` if they overlap), in `f64`.
fn sphere_gap(a: &Sphere, b: &Sphere) -> f64 {
    let d = a.center.as_dvec3().distance(b.center.as_dvec3());
    (d - a.radius as f64 - b.radius as f64).max(0.0)
}

/// `p` (in the frame of `pose`) in the world frame, in `f64`.
fn to_world(pose: &Affine3A, p: DVec3) -> DVec3 {
    let m = pose.matrix3;
    m.x_axis.as_dvec3() * p.x
        + m.y_axis.as_dvec3() * p.y
        + m.z_axis.as_dvec3() * p.z
        + pose.translation.as_dvec3()
}

/// Two meshes as `contacts` tests them: `(moving object, fixed object, moving
/// mesh, fixed mesh, swapped)` with `swapped` when `b` moves, and the pose of
/// the moving mesh in the fixed one's frame with its deviation from a rotation.
#[allow(clippy::type_complexity)]
fn mesh_frames<'o, T, BV: BoundingVolume>(
    a: &'o Object<T, BV>,
    ma: &'o Mesh<BV>,
    b: &'o Object<T, BV>,
    mb: &'o Mesh<BV>,
) -> Result<(
    &'o Object<T, BV>,
    &'o Mesh<BV>,
    &'o Mesh<BV>,
    bool,
    Affine3A,
    f32,
)> {
    let (ta, tb) = (ma.trimesh().len(), mb.trimesh().len());
    let swapped = !a_moves(ta, a.seq, tb, b.seq);
    let (mv, fx, mesh_mv, mesh_fx) = if swapped {
        (b, a, mb, ma)
    } else {
        (a, b, ma, mb)
    };
    let rel = fx.inverse * mv.pose;
    let dev = rotation_deviation(&rel)?;
    Ok((fx, mesh_mv, mesh_fx, swapped, rel, dev))
}

/// The distance between two objects (see [`World::distance`]).
fn pair_distance<T, BV: BoundingVolume>(
    q: &mut Proximity<BV>,
    (ha, a): (Handle, &Object<T, BV>),
    (hb, b): (Handle, &Object<T, BV>),
) -> Result<ObjectDistance> {
    let mut out = ObjectDistance {
        a: ha,
        b: hb,
        distance: 0.0,
        points: [DVec3::ZERO; 2],
        primitives: (0, 0),
        counters: CostCounters::default(),
    };
    match (&a.shape, &b.shape) {
        (Shape::Mesh(ma), Shape::Mesh(mb)) => {
            let (fx, mesh_mv, mesh_fx, swapped, rel, dev) = mesh_frames(a, ma, b, mb)?;
            let d = q.distance_checked(mesh_mv, &rel, dev, mesh_fx)?;
            let p = d.points.map(|p| to_world(&fx.pose, p));
            out.distance = d.distance;
            out.counters = d.counters;
            (out.points, out.primitives) = if swapped {
                ([p[1], p[0]], (d.triangles.1, d.triangles.0))
            } else {
                (p, d.triangles)
            };
        }
        (Shape::Sphere(r), Shape::Mesh(m)) => {
            let (d, [pb, pm], t, c) = ball_mesh_distance(q, a, *r, b, m)?;
            (out.distance, out.points, out.primitives, out.counters) = (d, [pb, pm], (0, t), c);
        }
        (Shape::Mesh(m), Shape::Sphere(r)) => {
            let (d, [pb, pm], t, c) = ball_mesh_distance(q, b, *r, a, m)?;
            (out.distance, out.points, out.primitives, out.counters) = (d, [pm, pb], (t, 0), c);
        }
        (Shape::Sphere(ra), Shape::Sphere(rb)) => {
            out.counters.np = 1;
            let (ca, cb) = (a.pose.translation, b.pose.translation);
            let touching =
                overlap::sphere_sphere(&Sphere::new(ca.into(), *ra), &Sphere::new(cb.into(), *rb));
            let (ca, cb) = (ca.as_dvec3(), cb.as_dvec3());
            let (ra, rb) = (*ra as f64, *rb as f64);
            let v = cb - ca;
            let len = v.length();
            let u = if len > 0.0 { v / len } else { DVec3::X };
            out.distance = if touching {
                0.0
            } else {
                // Apart by the exact test: positive even if rounding says 0.
                (len - ra - rb).max(f64::MIN_POSITIVE)
            };
            out.points = if !touching {
                [ca + u * ra, cb - u * rb]
            } else if len <= ra {
                [cb, cb] // b's centre is in a
            } else if len <= rb {
                [ca, ca]
            } else {
                let p = ca + u * ra;
                [p, p]
            };
        }
    }
    Ok(out)
}

/// A ball (object `ball`, radius `r`) and a mesh: `(distance, [point of the
/// ball, point of the mesh] in the world frame, triangle, counters)`.
#[allow(clippy::type_complexity)]
fn ball_mesh_distance<T, BV: BoundingVolume>(
    q: &mut Proximity<BV>,
    ball: &Object<T, BV>,
    r: f32,
    mesh_obj: &Object<T, BV>,
    mesh: &Mesh<BV>,
) -> Result<(f64, [DVec3; 2], u32, CostCounters)> {
    let c = centre_in(ball, mesh_obj)?;
    let near = q.closest_point(mesh, c)?;
    // Touching as `contacts` decides it (the exact ball–triangle test).
    let touching = mesh.intersects_sphere(&Sphere::new(c, r))?;
    let pm = to_world(&mesh_obj.pose, near.point);
    let cw = ball.pose.translation.as_dvec3();
    let v = pm - cw;
    let len = v.length();
    let r64 = r as f64;
    let (d, pb) = if touching {
        (0.0, if len <= r64 { pm } else { cw + v * (r64 / len) })
    } else {
        let pb = if len > 0.0 { cw + v * (r64 / len) } else { cw };
        ((near.distance - r64).max(f64::MIN_POSITIVE), pb)
    };
    Ok((d, [pb, pm], near.triangle, near.counters))
}

/// Appends the primitive pairs of objects `a` and `b` (`a` in the smaller
/// slot) within `margin` (`m32`: the margin as an `f32` no smaller) to `out`
/// (unsorted); returns the cost counters.
fn pair_within<T, BV: BoundingVolume>(
    q: &mut Proximity<BV>,
    a: &Object<T, BV>,
    b: &Object<T, BV>,
    margin: f64,
    m32: f32,
    out: &mut Vec<(u32, u32)>,
) -> Result<CostCounters> {
    match (&a.shape, &b.shape) {
        (Shape::Mesh(ma), Shape::Mesh(mb)) => {
            let (_, mesh_mv, mesh_fx, swapped, rel, dev) = mesh_frames(a, ma, b, mb)?;
            let near = q.pairs_within_checked(mesh_mv, &rel, dev, mesh_fx, margin)?;
            out.extend(near.pairs.iter().map(|p| {
                let (i, j) = p.triangles;
                if swapped {
                    (j, i)
                } else {
                    (i, j)
                }
            }));
            Ok(near.counters)
        }
        (Shape::Sphere(r), Shape::Mesh(m)) => {
            let c = centre_in(a, b)?;
            let hits = m.triangles_in_sphere(&Sphere::new(c, grown_ball(*r, m32)))?;
            out.extend(hits.iter().map(|&t| (0, t)));
            Ok(CostCounters::default())
        }
        (Shape::Mesh(m), Shape::Sphere(r)) => {
            let c = centre_in(b, a)?;
            let hits = m.triangles_in_sphere(&Sphere::new(c, grown_ball(*r, m32)))?;
            out.extend(hits.iter().map(|&t| (t, 0)));
            Ok(CostCounters::default())
        }
        (Shape::Sphere(ra), Shape::Sphere(rb)) => {
            let sa = Sphere::new(a.pose.translation.into(), grown_ball(*ra, m32));
            let sb = Sphere::new(b.pose.translation.into(), *rb);
            if overlap::sphere_sphere(&sa, &sb) {
                out.push((0, 0));
            }
            Ok(CostCounters {
                np: 1,
                ..CostCounters::default()
            })
        }
    }
}

/// A ball's radius grown by the margin (exactly `r` for a zero margin).
fn grown_ball(r: f32, m32: f32) -> f32 {
    if m32 == 0.0 {
        r
    } else {
        r + m32
    }
}
