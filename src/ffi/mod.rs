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
//!   [`abgs_status::ABGS_ERR_BUSY`] instead of racing;
//! - nothing from C is trusted to be a valid Rust value: enumerations cross as
//!   `uint32_t` with constants and are checked; every struct begins with
//!   `struct_size` and grows by the one rule of `versioned`.
//!
//! This is the only module with `unsafe` code.
#![allow(non_camel_case_types)]

mod boundary;
mod grid;
mod handle;
mod metrics;
#[cfg(feature = "onnxruntime")]
pub(crate) mod onnxruntime;
mod query;
mod remesh;
mod serialize;
mod simplify;
mod sizing;
pub(crate) mod versioned;

pub use boundary::*;
pub use grid::*;
pub use metrics::*;
pub use query::*;
pub use remesh::*;
pub use serialize::*;
pub use simplify::*;
pub use sizing::*;
pub use versioned::ABGS_MAX_STRUCT_SIZE;

#[cfg(test)]
mod tests {
    use super::versioned::{own_size, Versioned};
    use super::*;

    /// `first`: the struct's size when it was first released, written here
    /// once and never changed (the struct only gets longer after it).
    fn check<T: Versioned>(first: usize) {
        let n = std::mem::size_of::<T>();
        assert!(n <= ABGS_MAX_STRUCT_SIZE as usize, "{}", T::NAME);
        assert_eq!(T::FIRST_SIZE, first, "{}: FIRST_SIZE", T::NAME);
        assert!(first <= n, "{}: shrank below its first size", T::NAME);
        let v = T::initial();
        // SAFETY: struct_size is the first field of every Versioned type.
        let s = unsafe { std::ptr::read(&v as *const T as *const u32) };
        assert_eq!(s, own_size::<T>(), "{}: initial struct_size", T::NAME);
    }

    /// Every struct that crosses the ABI follows the growth rule.
    #[test]
    fn every_struct_follows_the_rule() {
        check::<abgs_grid_stats>(184);
        check::<abgs_eval_params>(32);
        check::<abgs_evaluation>(232);
        check::<abgs_hit>(72);
        check::<abgs_remesh_params>(48);
        check::<abgs_remesh_report>(120);
        check::<abgs_iteration_record>(96);
        check::<abgs_simplify_params>(112);
        check::<abgs_simplify_report>(96);
        check::<abgs_size_source>(96);
        check::<abgs_size_params>(112);
        check::<abgs_size_report>(160);
    }
}
