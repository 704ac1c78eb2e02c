//! Simplification through the C ABI: parameters with defaults, LBO-ABGS into a
//! new grid with a progress callback that can cancel, the per-iteration
//! records, and every edge's score (the learned simplifier's labels).

use super::boundary::*;
use super::grid::{abgs_grid, checked_out};
use super::versioned::{check_out, own_size, read_in, versioned, write_out};
use crate::simplify::{self, IterationRecord, SimplifyParams, StopReason};
use std::ffi::c_void;

/// Method (`abgs_simplify_params.method`): LBO-ABGS, the procedural
/// simplifier (accurate estimation of every candidate).
pub const ABGS_METHOD_LBO: u32 = 0;
/// Method: GCN-ABGS, the learned simplifier (the embedded graph network
/// predicts every edge's errors in one pass; `t_score` and `verify` apply).
/// A library built without its `gcn` feature (on by default) answers
/// ABGS_ERR_INVALID_ARGUMENT with a message saying so.
pub const ABGS_METHOD_GCN: u32 = 1;

/// Selection (`abgs_simplify_params.selection`): every candidate of the pool
/// estimated, then the lowest scores with disjoint closed 1-rings taken (the
/// paper's selection; the only one before this field existed, hence 0).
pub const ABGS_SELECTION_GLOBAL: u32 = 0;
/// Selection (the default): the pool in LBO order in batches of 512 edges,
/// estimating only edges whose closed 1-rings are still free and taking
/// each batch's lowest scores; about 3x fewer estimates for a grid as good.
pub const ABGS_SELECTION_BATCHED: u32 = 1;

/// Why a simplification stopped (`abgs_simplify_report.stop`): nothing could
/// be selected any more.
pub const ABGS_STOP_CONVERGED: u32 = 0;
/// Stop: `max_iterations` reached.
pub const ABGS_STOP_MAX_ITERATIONS: u32 = 1;
/// Stop: the progress callback asked to stop; the grid is valid.
pub const ABGS_STOP_CANCELLED: u32 = 2;

/// What one iteration did (given to the progress callback, and readable
/// afterwards with `abgs_grid_simplify_iteration`). In the callback,
/// `struct_size` is the library's size: read a field only if it lies below it.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct abgs_iteration_record {
    /// `sizeof(abgs_iteration_record)` (the header's growth rule).
    pub struct_size: u32,
    /// Iteration number, from 1.
    pub iteration: u64,
    /// Faces after the iteration.
    pub faces: u64,
    /// Vertices after the iteration.
    pub vertices: u64,
    /// Candidates in the pool.
    pub candidates: u64,
    /// Candidates estimated afresh (the rest were known and unchanged).
    pub estimated: u64,
    /// Candidates found collapsible (y < 0.5).
    pub collapsible: u64,
    /// Collapses done.
    pub accepted: u64,
    /// Vertices moved by the local repair.
    pub moved: u64,
    /// Edges flipped by the local repair.
    pub flips: u64,
    /// (4/√3)∫h⁻²dA of the grid's own field over its own surface.
    pub element_count: f64,
    /// Seconds.
    pub seconds: f64,
}

versioned!(abgs_iteration_record, 96);

/// Called after every iteration that collapsed something, with its record and `user_data`; return 0 to
/// go on, anything else to stop (the grid made so far is returned, valid).
pub type abgs_progress_fn = Option<
    unsafe extern "C" fn(record: *const abgs_iteration_record, user_data: *mut c_void) -> i32,
>;

/// Parameters of `abgs_simplify`; get the defaults from
/// `abgs_simplify_params_default`. A NaN or infinite value gives
/// ABGS_ERR_NON_FINITE, a finite value out of range ABGS_ERR_INVALID_ARGUMENT.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct abgs_simplify_params {
    /// `sizeof(abgs_simplify_params)`, set by the caller (the header's growth rule).
    pub struct_size: u32,
    /// ABGS_METHOD_LBO (default) or ABGS_METHOD_GCN; other values are
    /// ABGS_ERR_INVALID_ARGUMENT.
    pub method: u32,
    /// Largest share of the edges collapsed per iteration, in (0, 1] (default 0.10).
    pub fraction: f64,
    /// Candidate pool as a multiple of `fraction`·|E|, >= 1 (default 2).
    pub pool_factor: f64,
    /// Largest size ratio a collapse may cause, > 1 (default 1.2).
    pub t_size: f64,
    /// 0 (default): the distance envelope is derived, Δd <= ½·ln(t_size)·h / ln(beta)
    /// (and the clearance term); > 0: the fixed rule Δd <= tau_d·h_loc in its
    /// place (the paper's is 0.05).
    pub tau_d: f64,
    /// Largest distance to the dense grid in model units; 0 = no limit (default 0).
    pub max_distance: f64,
    /// Most iterations, >= 1 (default 1000; a cap, not the stop rule).
    pub max_iterations: u32,
    /// Dihedral angle (degrees) above which an edge is a kept feature (default 30).
    pub feature_angle_deg: f64,
    /// A feature line turning more than this (degrees) has a fixed corner (default 30).
    pub corner_angle_deg: f64,
    /// Largest turn of a face normal, degrees (default 60).
    pub max_normal_turn_deg: f64,
    /// Largest angle of a new triangle, degrees in [60, 180] (default 170).
    pub max_angle_deg: f64,
    /// 1 = local repair (relaxation, flips) after each batch (default 1).
    pub repair: i32,
    /// Progress callback (NULL = none).
    pub progress: abgs_progress_fn,
    /// Passed to `progress` unchanged.
    pub user_data: *mut c_void,
    /// Gradation ratio the sizes were graded with, > 1 (default 1.2).
    pub beta: f64,
    /// Each side of a thin wall or gap may move at most this fraction of its
    /// width, > 0 (default 0.25); 0 turns the clearance term off.
    pub clearance_fraction: f64,
    /// ABGS_METHOD_GCN: edges whose predicted score is at or above this, in
    /// [0, 1], are not tried (default 0.5, "predicted not collapsible").
    pub t_score: f64,
    /// ABGS_METHOD_GCN: 1 = run the accurate estimate on the edges the model
    /// proposes and drop those that fail it (default 0).
    pub verify: u32,
    /// Largest size ratio a collapse may cause where bodies touch, > 1
    /// (default 1.2, the default t_size: no extra cost): each body follows
    /// the agreed (smaller) size there within it, so touching bodies agree
    /// within about its square. Queries read the smallest size at a contact
    /// whatever this is; 1.05 makes the bodies' own fields agree to about
    /// 5 % (p95) at 2-3x the faces on an assembly with much contact.
    pub t_contact: f64,
    /// ABGS_METHOD_LBO: how each iteration picks its collapses,
    /// ABGS_SELECTION_BATCHED (the default) or ABGS_SELECTION_GLOBAL; other
    /// values are ABGS_ERR_INVALID_ARGUMENT.
    pub selection: u32,
    /// 1 (the default): after the last iteration the vertex sizes are fitted
    /// to the dense field (least squares, weighted by element density, each
    /// within t_size of its value before), so the simplified field errs
    /// both ways instead of lying above the dense one where elements are
    /// small; 0: each vertex keeps the dense field's size at its position
    /// (the paper's rule; the only one before this field existed, hence 0).
    /// Other values are ABGS_ERR_INVALID_ARGUMENT.
    pub fit_sizes: u32,
}

/// What `abgs_simplify` did.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct abgs_simplify_report {
    /// `sizeof(abgs_simplify_report)`, set by the caller (the header's growth rule).
    pub struct_size: u32,
    /// Faces of the dense grid.
    pub faces_in: u64,
    /// Vertices of the dense grid.
    pub vertices_in: u64,
    /// Faces of the result.
    pub faces_out: u64,
    /// Vertices of the result.
    pub vertices_out: u64,
    /// Iterations run (records: `abgs_grid_simplify_iteration`).
    pub iterations: u64,
    /// Why it stopped: ABGS_STOP_CONVERGED, ABGS_STOP_MAX_ITERATIONS or
    /// ABGS_STOP_CANCELLED.
    pub stop: u32,
    /// Feature lines of the dense grid.
    pub feature_lines: u64,
    /// Corners (never moved).
    pub corners: u64,
    /// (4/√3)∫h⁻²dA of the dense grid's field.
    pub element_count_in: f64,
    /// The same for the result (its own field over its own surface).
    pub element_count_out: f64,
    /// Seconds in all.
    pub seconds: f64,
}

versioned!(abgs_simplify_params, 112, default_params());
versioned!(abgs_simplify_report, 96);

/// The library's defaults as a C struct.
fn default_params() -> abgs_simplify_params {
    let d = SimplifyParams::default();
    abgs_simplify_params {
        struct_size: own_size::<abgs_simplify_params>(),
        method: ABGS_METHOD_LBO,
        fraction: d.fraction,
        pool_factor: d.pool_factor,
        t_size: d.t_size,
        tau_d: d.tau_d.unwrap_or(0.0),
        max_distance: 0.0,
        max_iterations: d.max_iterations as u32,
        feature_angle_deg: d.feature_angle_deg,
        corner_angle_deg: d.corner_angle_deg,
        max_normal_turn_deg: d.max_normal_turn_deg,
        max_angle_deg: d.max_angle_deg,
        repair: 1,
        progress: None,
        user_data: std::ptr::null_mut(),
        beta: d.beta,
        clearance_fraction: d.clearance_fraction,
        t_score: d.t_score,
        verify: d.verify as u32,
        t_contact: d.t_contact,
        selection: ABGS_SELECTION_BATCHED,
        fit_sizes: d.fit_sizes as u32,
    }
}

/// The per-iteration records a simplified grid's handle keeps (its provenance).
struct SimplifyRecords(Vec<abgs_iteration_record>);

/// Writes the default parameters into `*out_params`, whose `struct_size` the
/// caller has set (`abgs_simplify_params p = {.struct_size = sizeof p};`).
///
/// # Safety
/// `out_params` is NULL (reported) or holds `struct_size` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn abgs_simplify_params_default(
    out_params: *mut abgs_simplify_params,
) -> abgs_status {
    guard("abgs_simplify_params_default", || {
        // SAFETY: NULL (reported) or `struct_size` writable bytes.
        unsafe { check_out(out_params, "out_params", false)? };
        // SAFETY: as above.
        unsafe { write_out(out_params, &default_params(), "out_params") }
    })
}

/// Converts C parameters to Rust ones.
fn to_params(p: &abgs_simplify_params) -> FfiResult<SimplifyParams> {
    if p.method != ABGS_METHOD_LBO && p.method != ABGS_METHOD_GCN {
        return err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            format!(
                "method = {} is none of ABGS_METHOD_LBO (0), ABGS_METHOD_GCN (1)",
                p.method
            ),
        );
    }
    if p.selection != ABGS_SELECTION_GLOBAL && p.selection != ABGS_SELECTION_BATCHED {
        return err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            format!(
                "selection = {} is none of ABGS_SELECTION_GLOBAL (0), ABGS_SELECTION_BATCHED (1)",
                p.selection
            ),
        );
    }
    for (x, what) in [
        (p.fraction, "fraction"),
        (p.pool_factor, "pool_factor"),
        (p.t_size, "t_size"),
        (p.tau_d, "tau_d"),
        (p.max_distance, "max_distance"),
        (p.feature_angle_deg, "feature_angle_deg"),
        (p.corner_angle_deg, "corner_angle_deg"),
        (p.max_normal_turn_deg, "max_normal_turn_deg"),
        (p.max_angle_deg, "max_angle_deg"),
        (p.beta, "beta"),
        (p.clearance_fraction, "clearance_fraction"),
        (p.t_score, "t_score"),
        (p.t_contact, "t_contact"),
    ] {
        if !x.is_finite() {
            return err(
                abgs_status::ABGS_ERR_NON_FINITE,
                format!("{what} = {x} must be finite"),
            );
        }
    }
    for (x, what) in [
        (p.max_distance, "max_distance"),
        (p.tau_d, "tau_d"),
        (p.clearance_fraction, "clearance_fraction"),
    ] {
        if x < 0.0 {
            return err(
                abgs_status::ABGS_ERR_INVALID_ARGUMENT,
                format!("{what} = {x} must be >= 0 (0 = off)"),
            );
        }
    }
    if p.verify > 1 {
        return err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            format!("verify = {} must be 0 or 1", p.verify),
        );
    }
    if p.fit_sizes > 1 {
        return err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            format!("fit_sizes = {} must be 0 or 1", p.fit_sizes),
        );
    }
    if p.max_iterations == 0 {
        return err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            "max_iterations = 0 must be >= 1",
        );
    }
    let params = SimplifyParams {
        method: if p.method == ABGS_METHOD_GCN {
            simplify::Method::Gcn
        } else {
            simplify::Method::Lbo
        },
        t_score: p.t_score,
        verify: p.verify == 1,
        fraction: p.fraction,
        pool_factor: p.pool_factor,
        selection: if p.selection == ABGS_SELECTION_GLOBAL {
            simplify::Selection::Global
        } else {
            simplify::Selection::Batched
        },
        t_size: p.t_size,
        t_contact: p.t_contact,
        tau_d: (p.tau_d > 0.0).then_some(p.tau_d),
        beta: p.beta,
        clearance_fraction: if p.clearance_fraction > 0.0 {
            p.clearance_fraction
        } else {
            f64::INFINITY
        },
        max_distance: (p.max_distance > 0.0).then_some(p.max_distance),
        max_iterations: p.max_iterations as usize,
        feature_angle_deg: p.feature_angle_deg,
        corner_angle_deg: p.corner_angle_deg,
        max_normal_turn_deg: p.max_normal_turn_deg,
        max_angle_deg: p.max_angle_deg,
        repair: p.repair != 0,
        fit_sizes: p.fit_sizes == 1,
    };
    params.check()?;
    Ok(params)
}

fn record(r: &IterationRecord) -> abgs_iteration_record {
    abgs_iteration_record {
        struct_size: own_size::<abgs_iteration_record>(),
        iteration: r.iteration as u64,
        faces: r.faces as u64,
        vertices: r.vertices as u64,
        candidates: r.candidates as u64,
        estimated: r.estimated as u64,
        collapsible: r.collapsible as u64,
        accepted: r.accepted as u64,
        moved: r.moved as u64,
        flips: r.flips as u64,
        element_count: r.element_count,
        seconds: r.seconds,
    }
}

/// Simplifies the dense grid `grid` (which must carry sizes) into a new grid
/// with sizes: edge collapses chosen by accurate estimation (LBO-ABGS) or by
/// the embedded model's predictions (GCN-ABGS, `method`), each
/// keeping the interpolated size within `t_size` of the dense grid's and the
/// surface within `tau_d`·h (and `max_distance`) of it; feature lines,
/// corners, boundaries and bodies are kept. `params` NULL = the defaults.
///
/// `progress` (if set) is called after every iteration that collapsed
/// something (not after the last, empty one), on the calling thread; a non-zero return stops the loop and the grid made so far is
/// returned (status OK, `stop` = ABGS_STOP_CANCELLED). On success `*out_grid`
/// owns the new grid, whose handle also holds the per-iteration records
/// (`abgs_grid_simplify_iteration`); on failure it is NULL. `out_report` (may
/// be NULL) receives what was done. `grid` is only read. The result does not
/// depend on the thread count. Cost: about O(I·(E log E + C·S log F)) for I
/// iterations, C candidates estimated with S samples each (parallel).
///
/// Errors: NULL (grid, out_grid), NON_FINITE / INVALID_ARGUMENT (parameters),
/// NO_SIZES, BUSY (a mutation is running on `grid`), INVALID_ARGUMENT naming
/// the model when the embedded model cannot run.
///
/// # Safety
/// Pointers are NULL (reported / "absent" where documented) or valid; `grid`
/// comes from this library; `progress` is safe to call with `user_data`.
#[no_mangle]
pub unsafe extern "C" fn abgs_simplify(
    grid: *const abgs_grid,
    params: *const abgs_simplify_params,
    out_grid: *mut *mut abgs_grid,
    out_report: *mut abgs_simplify_report,
) -> abgs_status {
    guard("abgs_simplify", || {
        // SAFETY: writable or NULL (checked).
        let o = unsafe { out(out_grid, "out_grid")? };
        *o = std::ptr::null_mut();
        // SAFETY: a grid from this library or NULL (checked).
        let h = unsafe { req(grid, "grid")? };
        // SAFETY: NULL (defaults) or `struct_size` readable bytes.
        let p = unsafe { read_in(params, "params")? }.unwrap_or_else(default_params);
        // SAFETY: NULL (skipped) or `struct_size` writable bytes; checked
        // before the work so that a bad struct_size fails fast.
        unsafe { check_out(out_report, "out_report", true)? };
        let rp = to_params(&p)?;
        let g = h.read()?;
        if g.sizes().is_none() {
            return err(abgs_status::ABGS_ERR_NO_SIZES, "the grid has no sizes");
        }
        let (cb, user) = (p.progress, p.user_data);
        let mut call = |r: &IterationRecord| -> bool {
            let rec = record(r);
            match cb {
                // SAFETY: the caller guarantees the callback is safe to call
                // with its user data; the record outlives the call.
                Some(f) => unsafe { f(&rec, user) == 0 },
                None => true,
            }
        };
        let s = simplify::simplify(&g, &rp, Some(&mut call))?;
        let r = &s.report;
        let report = abgs_simplify_report {
            struct_size: 0,
            faces_in: r.faces_in as u64,
            vertices_in: r.vertices_in as u64,
            faces_out: r.faces_out as u64,
            vertices_out: r.vertices_out as u64,
            iterations: r.iterations.len() as u64,
            stop: match r.stop {
                StopReason::Converged => ABGS_STOP_CONVERGED,
                StopReason::MaxIterations => ABGS_STOP_MAX_ITERATIONS,
                StopReason::Cancelled => ABGS_STOP_CANCELLED,
            },
            feature_lines: r.feature_lines as u64,
            corners: r.corners as u64,
            element_count_in: r.element_count_in,
            element_count_out: r
                .iterations
                .last()
                .map_or(r.element_count_in, |i| i.element_count),
            seconds: r.seconds,
        };
        // SAFETY: checked above.
        unsafe { write_out(out_report, &report, "out_report")? };
        let records = SimplifyRecords(r.iterations.iter().map(record).collect());
        *o = abgs_grid::boxed_with(s.grid, records);
        Ok(())
    })
}

/// Copies the record of iteration `index` (0-based, below
/// `abgs_simplify_report.iterations`) of a grid made by `abgs_simplify` into
/// `*out_record`. Errors: NULL, OUT_OF_RANGE (index, or a grid not made by
/// `abgs_simplify`, which has no records).
///
/// # Safety
/// Pointers are NULL (reported) or valid.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_simplify_iteration(
    grid: *const abgs_grid,
    index: usize,
    out_record: *mut abgs_iteration_record,
) -> abgs_status {
    guard("abgs_grid_simplify_iteration", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: NULL (reported) or `struct_size` writable bytes.
        unsafe { check_out(out_record, "out_record", false)? };
        let recs = g.provenance::<SimplifyRecords>().map_or(&[][..], |r| &r.0);
        let rec = recs.get(index).ok_or_else(|| {
            FfiError(
                abgs_status::ABGS_ERR_OUT_OF_RANGE,
                format!("iteration {index} of {}", recs.len()),
            )
        })?;
        // SAFETY: checked above.
        unsafe { write_out(out_record, rec, "out_record") }
    })
}

/// Every edge's collapse estimate on `grid` as it is (the first iteration's
/// view, exact Δs and Δd), in the order of `abgs_grid_copy_edges`: `out_ds`
/// (Δs), `out_dd` (Δd / h_loc), `out_valid` (1 = the collapse passes the
/// topological and geometric checks) and `out_y` (the score in [0, 1];
/// < 0.5 = collapsible; 1 when invalid). Invalid edges get NaN in `out_ds` and
/// `out_dd`. Each buffer holds `capacity` >= the edge count
/// (`abgs_grid_stats.edges`) elements (`abgs_grid_edge_count`), else BUFFER_TOO_SMALL; any of the four
/// may be NULL to skip it. `params` NULL = defaults (only the thresholds and
/// angles are used). Parallel; the result does not depend on the thread count.
/// Errors: NULL (grid), NON_FINITE / INVALID_ARGUMENT, NO_SIZES, BUSY.
///
/// # Safety
/// Pointers are NULL or valid for `capacity` elements.
#[no_mangle]
pub unsafe extern "C" fn abgs_edge_scores(
    grid: *const abgs_grid,
    params: *const abgs_simplify_params,
    out_ds: *mut f64,
    out_dd: *mut f64,
    out_valid: *mut u8,
    out_y: *mut f64,
    capacity: usize,
) -> abgs_status {
    guard("abgs_edge_scores", || {
        // SAFETY: a grid from this library or NULL (checked).
        let h = unsafe { req(grid, "grid")? };
        // SAFETY: NULL (defaults) or `struct_size` readable bytes.
        let rp = match unsafe { read_in(params, "params")? } {
            Some(p) => to_params(&p)?,
            None => SimplifyParams::default(),
        };
        let g = h.read()?;
        if g.sizes().is_none() {
            return err(abgs_status::ABGS_ERR_NO_SIZES, "the grid has no sizes");
        }
        let n = g.topology().edges.len();
        if capacity < n {
            return err(
                abgs_status::ABGS_ERR_BUFFER_TOO_SMALL,
                format!("capacity {capacity} < {n} edges"),
            );
        }
        let b = n.saturating_mul(8);
        disjoint(&[
            (out_ds as *const u8, b, "out_ds"),
            (out_dd as *const u8, b, "out_dd"),
            (out_valid as *const u8, n, "out_valid"),
            (out_y as *const u8, b, "out_y"),
        ])?;
        let scores = simplify::edge_scores(&g, &rp)?;
        macro_rules! fill {
            ($ptr:expr, $name:expr, $f:expr) => {
                if !$ptr.is_null() {
                    // SAFETY: non-NULL with `capacity` >= n writable elements by contract.
                    let dst = unsafe { checked_out($ptr, capacity, n, $name)? };
                    for (d, s) in dst.iter_mut().zip(&scores) {
                        *d = $f(s);
                    }
                }
            };
        }
        fill!(out_ds, "out_ds", |s: &simplify::EdgeScore| s.ds);
        fill!(out_dd, "out_dd", |s: &simplify::EdgeScore| s.dd_rel);
        fill!(out_valid, "out_valid", |s: &simplify::EdgeScore| u8::from(
            s.valid
        ));
        fill!(out_y, "out_y", |s: &simplify::EdgeScore| s.y);
        Ok(())
    })
}
