//! Geometric primitives ([`Sphere`], [`Aabb`], [`Ray`], [`Segment`],
//! [`SphereSweep`], [`Plane`], [`Frustum`]) and the closed overlap tests and
//! distances between them.
//!
//! Every test lives once, in [`overlap`], named by the shape pair; the indices call
//! these functions and never re-implement them. "Closed" means touching counts:
//! two spheres at distance exactly `r1 + r2` overlap.

mod aabb;
pub(crate) mod exact;
mod frustum;
mod line_ball;
pub mod overlap;
mod plane;
mod ray;
mod sphere;
mod sweep;

pub use aabb::Aabb;
pub use frustum::{Frustum, Relation};
pub use plane::Plane;
pub use ray::{Ray, Segment};
pub use sphere::Sphere;
pub use sweep::SphereSweep;
