//! # abgs — adaptive background grids for mesh sizing
//!
//! abgs turns a CAD surface (STL, OBJ, OFF, PLY, MSH, VTK or raw arrays) into a
//! triangular *background grid* carrying one element size per vertex, and answers
//! `size(x, y, z)` queries on it quickly and from any number of threads.
//!
//! The crate is the core library; it is also built as a C shared/static library
//! (see [`ffi`] and `include/abgs.h`).
//!
//! Module map (one concept per module):
//! - [`geometry`]: f64 vector helpers, exact point–triangle closest point, triangle quality.
//! - [`mesh`]: the [`Grid`] type, adjacency, bodies, welding, validation.
//! - [`io`]: readers and writers for the supported file formats.
//! - [`spatial`]: the bounding-volume hierarchy over triangles.
//! - [`query`]: surface, hinted, batch and volume size queries.
//! - [`sampling`]: deterministic point sets on and around a grid.
//! - [`ffi`]: the C ABI.
#![deny(missing_docs)]
// Index loops over x, y, z read better than zipped iterators in geometry code.
#![allow(clippy::needless_range_loop)]

pub mod error;
pub mod ffi;
pub mod geometry;
pub mod io;
pub mod mesh;
pub mod query;
pub mod sampling;
pub mod spatial;

pub use error::{Error, Result};
pub use mesh::{BuildOptions, Grid, ValidationReport};
pub use query::{QueryHit, VolumeHit};

/// Library version as `"MAJOR.MINOR.PATCH"`.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
