//! The C ABI (DESIGN §4), declared in the generated header `include/abgs.h`.
//!
//! Conventions, as in meshoptimizer and rustls-ffi:
//! - every call returns an [`abgs_status`] (0 = [`abgs_status::ABGS_OK`]) and
//!   writes results through out-parameters into caller-owned memory;
//! - on failure, [`abgs_last_error_message`] gives a thread-local description;
//! - no panic crosses the boundary (each export runs inside `catch_unwind`), a
//!   NULL pointer is an error, never a crash;
//! - a grid is an opaque [`abgs_grid`]; const calls (queries, accessors) are
//!   thread-safe; a mutating call on a grid in use by another thread returns
//!   [`abgs_status::ABGS_ERR_BUSY`] instead of racing.
//!
//! This is the only module with `unsafe` code.
#![allow(non_camel_case_types)]

mod boundary;
mod grid;
mod metrics;
mod query;
mod remesh;
mod simplify;
mod sizing;

pub use boundary::*;
pub use grid::*;
pub use metrics::*;
pub use query::*;
pub use remesh::*;
pub use simplify::*;
pub use sizing::*;
