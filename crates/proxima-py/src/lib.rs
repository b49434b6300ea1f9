//! Proxima for Python: the extension module `proxima._native`, re-exported by
//! the `proxima` package (`python/proxima/__init__.py`) [sources: python].
//!
//! - [`index::Index`]: any of the six broad-phase indices by name, over spheres
//!   given as numpy arrays and named by integer ids; batch queries returning
//!   CSR `(ids, offsets)`; `pairs()` as an `(P, 2)` array; k nearest as
//!   `cKDTree.query` does; sphere sweeps; per-object collision filters.
//! - [`mesh::Mesh`]: a triangle mesh with its collision and ray BVHs, from
//!   arrays or a file; batch ray casts with Open3D's result names.
//! - [`collide::collide`]: mesh–mesh collision for one pose or a batch, with the
//!   cost counters ([`collide::Contacts`]).
//! - [`world::World`]: the collision world — shared meshes and balls at rigid
//!   poses, filters, ignored pairs, contacts ([`world::WorldContacts`]), ray
//!   casts, sphere queries, culling — with objects named by integer ids
//!   ([`ids`]).
//!
//! Every array argument is converted in [`arrays`] (any real dtype, lists,
//! non-contiguous views; wrong shapes and NaN raise `ValueError`); library
//! errors become Python exceptions in [`errors`]; long work runs with the
//! interpreter released, on the calling thread or on a rayon pool of
//! `workers` threads ([`workers`]).
//!
//! Still to come, with a marked place: mesh distance queries (issue #15, in
//! `collide.rs`).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod arrays;
pub mod collide;
pub mod errors;
pub mod ids;
pub mod index;
pub mod mesh;
pub mod queries;
pub mod workers;
pub mod world;

use pyo3::prelude::*;

/// The module `proxima._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<index::Index>()?;
    m.add_class::<mesh::Mesh>()?;
    m.add_class::<collide::Contacts>()?;
    m.add_function(wrap_pyfunction!(collide::collide, m)?)?;
    m.add(
        "INDEX_KINDS",
        proxima::broad::IndexKind::ALL.map(|k| k.name()).to_vec(),
    )?;
    m.add("BOUNDING_VOLUMES", mesh::BV_NAMES.to_vec())?;
    m.add_class::<world::World>()?;
    m.add_class::<world::WorldContacts>()?;
    Ok(())
}
