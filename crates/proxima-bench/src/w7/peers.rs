//! W7's peers, each in its fastest documented k-nearest mode:
//! - kiddo 6's [`ImmutableKdTree`] over the points (its recommended tree for a
//!   static set), `nearest_one` for `k = 1` and `nearest_n` otherwise, with
//!   `SquaredEuclidean` (points only: kiddo stores no radii);
//! - rstar 0.13's bulk-loaded R*-tree and its best-first
//!   `nearest_neighbor` (`k = 1`) / `nearest_neighbor_iter_with_distance_2`:
//!   points as `GeomWithData<[f32; 3], u32>`; spheres as [`RBall`], whose
//!   envelope is the sphere's box and whose `distance_2` is the squared surface
//!   distance, so its search is exact (the box is never farther than the
//!   sphere);
//! - parry3d 0.31's `Bvh` (binned or PLOC build) through `Bvh::project_point`
//!   with a `Ball` point projection per leaf: its best-first closest-point
//!   search has no `k`, so parry answers `k = 1` only.

use super::Knn;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use parry3d::bounding_volume::Aabb as PAabb;
use parry3d::math::{Pose, Vector};
use parry3d::partitioning::{Bvh, BvhBuildStrategy};
use parry3d::query::PointQuery;
use parry3d::shape::Ball;
use proxima::geom::Sphere;
use proxima::glam::Vec3;
use rstar::primitives::GeomWithData;
use rstar::{PointDistance, RTree, RTreeObject, AABB};
use std::num::NonZeroUsize;

/// kiddo's immutable k-d tree over the centres (item `i` = point `i`).
pub struct KiddoKnn(ImmutableKdTree<f32, 3>);

impl KiddoKnn {
    /// Builds the tree from the centres.
    pub fn build(set: &[Sphere]) -> Self {
        let points: Vec<[f32; 3]> = set.iter().map(|s| s.center.to_array()).collect();
        KiddoKnn(ImmutableKdTree::new_from_slice(&points).expect("kiddo build"))
    }
}

fn nonzero(k: usize) -> NonZeroUsize {
    NonZeroUsize::new(k).expect("k >= 1")
}

impl Knn for KiddoKnn {
    fn run(&mut self, q: Vec3, k: usize) -> usize {
        let q = q.to_array();
        if k == 1 {
            let hit = self
                .0
                .query(&q)
                .nearest_one::<SquaredEuclidean<f32>>()
                .execute();
            usize::from(hit.distance.is_finite())
        } else {
            self.0
                .query(&q)
                .nearest_n::<SquaredEuclidean<f32>>(nonzero(k))
                .execute()
                .len()
        }
    }

    fn answer(&mut self, q: Vec3, k: usize) -> Vec<(u32, f32)> {
        self.0
            .query(&q.to_array())
            .nearest_n::<SquaredEuclidean<f32>>(nonzero(k))
            .execute()
            .into_iter()
            .map(|h| (h.item, h.distance.sqrt()))
            .collect()
    }
}

/// A sphere in rstar: its box as the envelope, the squared distance to its
/// surface as `distance_2`.
#[derive(Clone, Copy, Debug)]
pub struct RBall {
    center: Vec3,
    radius: f32,
    id: u32,
}

impl RTreeObject for RBall {
    type Envelope = AABB<[f32; 3]>;
    fn envelope(&self) -> Self::Envelope {
        let r = Vec3::splat(self.radius);
        AABB::from_corners((self.center - r).to_array(), (self.center + r).to_array())
    }
}

impl PointDistance for RBall {
    fn distance_2(&self, p: &[f32; 3]) -> f32 {
        let d = (self.center.distance(Vec3::from(*p)) - self.radius).max(0.0);
        d * d
    }
}

/// What W7 stores in rstar: its id and squared distance.
pub trait RItem: RTreeObject<Envelope = AABB<[f32; 3]>> + PointDistance {
    /// The object's id.
    fn id(&self) -> u32;
}

impl RItem for RBall {
    fn id(&self) -> u32 {
        self.id
    }
}

impl RItem for GeomWithData<[f32; 3], u32> {
    fn id(&self) -> u32 {
        self.data
    }
}

/// rstar's bulk-loaded tree over points or spheres.
pub struct RstarKnn<T: RItem>(RTree<T>);

impl RstarKnn<GeomWithData<[f32; 3], u32>> {
    /// Bulk load of the centres as points.
    pub fn points(set: &[Sphere]) -> Self {
        RstarKnn(RTree::bulk_load(
            (0..set.len())
                .map(|i| GeomWithData::new(set[i].center.to_array(), i as u32))
                .collect(),
        ))
    }
}

impl RstarKnn<RBall> {
    /// Bulk load of the spheres.
    pub fn spheres(set: &[Sphere]) -> Self {
        RstarKnn(RTree::bulk_load(
            (0..set.len())
                .map(|i| RBall {
                    center: set[i].center,
                    radius: set[i].radius,
                    id: i as u32,
                })
                .collect(),
        ))
    }
}

impl<T: RItem> Knn for RstarKnn<T> {
    fn run(&mut self, q: Vec3, k: usize) -> usize {
        if k == 1 {
            usize::from(self.0.nearest_neighbor(q.to_array()).is_some())
        } else {
            self.0
                .nearest_neighbor_iter_with_distance_2(q.to_array())
                .take(k)
                .count()
        }
    }

    fn answer(&mut self, q: Vec3, k: usize) -> Vec<(u32, f32)> {
        self.0
            .nearest_neighbor_iter_with_distance_2(q.to_array())
            .take(k)
            .map(|(t, d2)| (t.id(), d2.sqrt()))
            .collect()
    }
}

/// parry's BVH over the spheres' boxes, plus the balls for the leaf projection.
pub struct ParryKnn {
    bvh: Bvh,
    balls: Vec<(Pose, Ball)>,
}

fn vector(v: Vec3) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

impl ParryKnn {
    /// Bulk build with one of parry's strategies; leaf `i` = sphere `i`.
    pub fn build(set: &[Sphere], strategy: BvhBuildStrategy) -> Self {
        let aabbs: Vec<PAabb> = set
            .iter()
            .map(|s| {
                let r = Vec3::splat(s.radius);
                PAabb::new(vector(s.center - r), vector(s.center + r))
            })
            .collect();
        ParryKnn {
            bvh: Bvh::from_leaves(strategy, &aabbs),
            balls: set
                .iter()
                .map(|s| {
                    (
                        Pose::from_translation(vector(s.center)),
                        Ball::new(s.radius),
                    )
                })
                .collect(),
        }
    }

    /// The nearest ball and its distance (`Bvh::project_point`, solid balls).
    fn nearest(&self, q: Vec3) -> Option<(u32, f32)> {
        let p = vector(q);
        self.bvh
            .project_point(p, f32::MAX, |i, _| {
                let (pose, ball) = &self.balls[i as usize];
                Some(ball.project_point(pose, p, true))
            })
            .map(|(i, (d, _))| (i, d))
    }
}

impl Knn for ParryKnn {
    fn run(&mut self, q: Vec3, _k: usize) -> usize {
        usize::from(self.nearest(q).is_some())
    }

    fn answer(&mut self, q: Vec3, _k: usize) -> Vec<(u32, f32)> {
        self.nearest(q).into_iter().collect()
    }

    fn supports(&self, k: usize) -> bool {
        k == 1
    }
}
