//! W8's peer: parry3d 0.31's shape cast of a `Ball` through its BVH, two ways:
//! - `compound`: the set as one `Compound` of balls and one
//!   `query::cast_shapes` call per sweep (its documented composite cast:
//!   best-first over the compound's `Bvh`, a ray against each node's box grown
//!   by the moving ball's box, `cast_shapes` through the default dispatcher on
//!   each candidate);
//! - `bvh`: the same traversal written over a bare `Bvh` (binned build) with
//!   `Bvh::find_best`, the Minkowski-box node cost copied from parry's
//!   composite cast, and `cast_shapes_ball_ball` on each leaf (no dispatch,
//!   no shape handles).
//!
//! Every hit of a sweep (the counted kind) walks the same tree with
//! `Bvh::leaves` under the node test "the ray enters the grown box by `t = 1`"
//! and casts each candidate.

use super::Sweeper;
use parry3d::bounding_volume::Aabb as PAabb;
use parry3d::math::{Pose, Real, Vector};
use parry3d::partitioning::{Bvh, BvhBuildStrategy, BvhNode};
use parry3d::query::details::cast_shapes_ball_ball;
use parry3d::query::{cast_shapes, Ray, RayCast, ShapeCastOptions};
use parry3d::shape::{Ball, Compound, SharedShape};
use proxima::geom::{Sphere, SphereSweep};
use proxima::glam::Vec3;

fn vector(v: Vec3) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

fn options() -> ShapeCastOptions {
    ShapeCastOptions::with_max_time_of_impact(1.0)
}

/// How a leaf is cast: its index, the moving ball's start pose, velocity and
/// ball; the time of impact.
type Cast<'a> = dyn Fn(u32, &Pose, Vector, &Ball) -> Option<Real> + 'a;

/// The parry structure: a compound (its own BVH) or a bare BVH and the balls.
pub enum ParryCast {
    /// One `Compound` of all the balls.
    Compound(Compound),
    /// A bare BVH over the balls' boxes and the balls (centre, radius).
    Bvh(Bvh, Vec<(Vector, Ball)>),
}

impl ParryCast {
    /// The compound of the set's balls (`Compound::new` builds its BVH).
    pub fn compound(set: &[Sphere]) -> Self {
        ParryCast::Compound(Compound::new(
            set.iter()
                .map(|s| {
                    (
                        Pose::from_translation(vector(s.center)),
                        SharedShape::ball(s.radius),
                    )
                })
                .collect(),
        ))
    }

    /// A binned BVH over the balls' boxes.
    pub fn bvh(set: &[Sphere]) -> Self {
        let aabbs: Vec<PAabb> = set
            .iter()
            .map(|s| {
                let r = Vec3::splat(s.radius);
                PAabb::new(vector(s.center - r), vector(s.center + r))
            })
            .collect();
        ParryCast::Bvh(
            Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs),
            set.iter()
                .map(|s| (vector(s.center), Ball::new(s.radius)))
                .collect(),
        )
    }

    fn tree(&self) -> &Bvh {
        match self {
            ParryCast::Compound(c) => c.bvh(),
            ParryCast::Bvh(b, _) => b,
        }
    }

    /// The cast of leaf `i` against the moving ball.
    fn with_leaf_cast<R>(&self, f: impl FnOnce(&Cast<'_>) -> R) -> R {
        match self {
            ParryCast::Compound(c) => f(&|i, pose, vel, ball| {
                let (p1, shape) = &c.shapes()[i as usize];
                cast_shapes(p1, Vector::ZERO, shape.as_ref(), pose, vel, ball, options())
                    .ok()
                    .flatten()
                    .map(|h| h.time_of_impact)
            }),
            ParryCast::Bvh(_, balls) => f(&|i, pose, vel, ball| {
                let (c, b1) = &balls[i as usize];
                let pos12 = Pose::from_translation(pose.translation - *c);
                cast_shapes_ball_ball(&pos12, vel, b1, ball, options()).map(|h| h.time_of_impact)
            }),
        }
    }
}

/// The moving ball: start pose, velocity over `t in [0, 1]`, shape, and the
/// ray and margin of the Minkowski-box node test.
struct Moving {
    pose: Pose,
    vel: Vector,
    ball: Ball,
    ray: Ray,
    margin: Vector,
}

impl Moving {
    fn new(s: &SphereSweep) -> Self {
        let vel = vector(s.to - s.from);
        Moving {
            pose: Pose::from_translation(vector(s.from)),
            vel,
            ball: Ball::new(s.radius),
            ray: Ray::new(vector(s.from), vel),
            margin: Vector::splat(s.radius),
        }
    }

    /// When the ray enters the node's box grown by the ball (parry's composite
    /// cast node cost), if by `max_t`.
    fn node_toi(&self, node: &BvhNode, max_t: Real) -> Option<Real> {
        let grown = PAabb::new(node.mins() - self.margin, node.maxs() + self.margin);
        grown.cast_local_ray(&self.ray, max_t, true)
    }
}

impl ParryCast {
    /// Calls `f` on every ball the sweep touches (`Bvh::leaves` pruned by the
    /// node test, then the leaf cast).
    fn each_hit(&self, s: &SphereSweep, mut f: impl FnMut(u32)) {
        let m = Moving::new(s);
        self.with_leaf_cast(|cast| {
            for i in self.tree().leaves(|node| m.node_toi(node, 1.0).is_some()) {
                if cast(i, &m.pose, m.vel, &m.ball).is_some() {
                    f(i);
                }
            }
        })
    }
}

impl Sweeper for ParryCast {
    fn first(&self, s: &SphereSweep) -> Option<(u32, f32)> {
        self.first_key(s).map(|(i, t)| (i as u32, t))
    }

    fn first_key(&self, s: &SphereSweep) -> Option<(u64, f32)> {
        let m = Moving::new(s);
        if let ParryCast::Compound(c) = self {
            // The documented one-call composite cast.
            let hit = cast_shapes(
                &Pose::IDENTITY,
                Vector::ZERO,
                c,
                &m.pose,
                m.vel,
                &m.ball,
                options(),
            )
            .ok()??;
            return Some((hit.subshape1 as u64, hit.time_of_impact));
        }
        self.with_leaf_cast(|cast| {
            self.tree().find_best(
                1.0,
                |node: &BvhNode, best| m.node_toi(node, best).unwrap_or(Real::MAX),
                |i, _| cast(i, &m.pose, m.vel, &m.ball),
            )
        })
        .map(|(i, t)| (i as u64, t))
    }

    fn count(&self, s: &SphereSweep) -> usize {
        let mut n = 0;
        self.each_hit(s, |_| n += 1);
        n
    }

    fn hits(&self, s: &SphereSweep) -> Vec<u32> {
        let mut out = Vec::new();
        self.each_hit(s, |i| out.push(i));
        out
    }
}
