//! Exactness tests of `proxima::narrow::triangles_intersect` against two
//! references: `reference` (exact predicates, a different decomposition) and
//! `carath` (integer arithmetic, Carathéodory; grid inputs only).

mod carath;
mod cases;
mod prop;
mod random;
mod reference;
mod sym;
