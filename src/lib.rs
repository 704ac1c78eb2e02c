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
//! - [`metrics`]: a simplified grid against its dense reference (reduction, size
//!   deviation, Hausdorff, estimated element count, angles).
//! - [`sizing`]: curvature, proximity, sources, gradation and LBO of the size field.
//! - [`simplify`]: LBO-ABGS, the sizing-aware simplifier (edge collapses).
//! - [`qem`]: plain quadric-error decimation (the baseline simplifier).
//! - [`gcn`]: GCN-ABGS, the learned edge scorer (an ONNX model run through `ort`).
//! - [`ffi`]: the C ABI.
//!
//! ```
//! use abgs::{BuildOptions, Grid};
//! // A unit square in z = 0 with sizes growing along x.
//! let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
//! let t = vec![[0, 1, 2], [0, 2, 3]];
//! let h = vec![0.1, 0.2, 0.2, 0.1];
//! let grid = Grid::from_arrays(v, t, Some(h), &BuildOptions::default())?;
//! // Surface mode: the closest point of (0.5, 0.5, 3) is (0.5, 0.5, 0).
//! assert!((grid.query_size([0.5, 0.5, 3.0])? - 0.15).abs() < 1e-15);
//! // Hinted: same answer, the hint now names the triangle used.
//! let mut hint = u32::MAX;
//! assert_eq!(grid.query_size_hinted([0.5, 0.5, 3.0], &mut hint)?, grid.query_size([0.5, 0.5, 3.0])?);
//! // Volume mode with gradation 1.2: never above the surface size + ln(1.2)·distance.
//! let vol = grid.query_volume([0.5, 0.5, 3.0], 1.2)?.size;
//! assert!(vol <= 0.15 + 1.2f64.ln() * 3.0);
//! # Ok::<(), abgs::Error>(())
//! ```
#![deny(missing_docs)]
// Index loops over x, y, z read better than zipped iterators in geometry code.
#![allow(clippy::needless_range_loop)]

pub mod error;
pub mod ffi;
#[cfg(feature = "gcn")]
pub mod gcn;
pub mod geometry;
pub mod io;
pub mod mesh;
pub mod metrics;
pub mod qem;
pub mod query;
pub mod remesh;
pub mod sampling;
pub mod simplify;
pub mod sizing;
pub mod spatial;
#[cfg(test)]
mod test_shapes;

pub use error::{Error, Result};
pub use mesh::{BuildOptions, Grid, ValidationReport};
pub use query::{QueryHit, VolumeHit};

/// Library version as `"MAJOR.MINOR.PATCH"`.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
