//! Geometric primitives and the closed overlap tests between them.
//!
//! Every test lives once, in [`overlap`], named by the shape pair; the indices call
//! these functions and never re-implement them. "Closed" means touching counts:
//! two spheres at distance exactly `r1 + r2` overlap.

mod aabb;
pub(crate) mod exact;
mod frustum;
pub mod overlap;
mod plane;
mod ray;
mod sphere;

pub use aabb::Aabb;
pub use frustum::{Frustum, Relation};
pub use plane::Plane;
pub use ray::{Ray, Segment};
pub use sphere::Sphere;
