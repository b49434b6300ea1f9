//! Distance and proximity queries (issue #15) against brute force over all
//! triangle pairs and independent `f64` references: triangle–triangle distance,
//! the volumes' lower bounds, mesh–mesh distance / within / pairs within on the
//! shared meshes and constructed ones, point and ball queries, the inside test,
//! and typed errors on bad input.

mod bounds;
mod common;
mod errors;
mod mesh_methods;
mod meshes;
mod points;
mod reference;
mod shapes;
mod triangles;
