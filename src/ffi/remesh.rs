//! Remeshing through the C ABI: parameters with defaults, uniform and
//! size-driven isotropic remeshing into a new grid, and what the remesher kept
//! (feature edges) and could not do (issues), held in the new grid's handle.

use super::boundary::*;
use super::grid::{abgs_grid, checked_out};
use super::handle::Held;
use super::versioned::{check_out, own_size, read_in, versioned, write_out};
use crate::remesh::{self, RemeshParams, TargetLength};
use std::ffi::c_char;

/// Parameters of `abgs_grid_remesh`; get the defaults from `abgs_remesh_params_default`.
/// Every field is checked in both modes: a NaN or infinite value gives
/// ABGS_ERR_NON_FINITE, a finite value out of range ABGS_ERR_INVALID_ARGUMENT.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct abgs_remesh_params {
    /// `sizeof(abgs_remesh_params)`, set by the caller (the header's growth rule).
    pub struct_size: u32,
    /// Uniform target edge length L0 in model units, >= 0; 0 = use
    /// `relative_length` (default 0). Ignored in size-driven mode.
    pub edge_length: f64,
    /// Uniform target edge length as a fraction of the bounding-box diagonal,
    /// used when `edge_length` is 0; must then be > 0 (default 0.01: diagonal / 100).
    /// Ignored in size-driven mode.
    pub relative_length: f64,
    /// Dihedral angle above which an edge is a feature kept as a line, degrees
    /// in [0, 180] (default 30).
    pub feature_angle_deg: f64,
    /// Split / collapse / flip / relax iterations, >= 1 (default 10).
    pub iterations: u32,
    /// 1 = cap the target length at half the curvature size
    /// `π / (κ · n_circle)`, so small fillets are resolved; 0 = off (default 1).
    pub curvature_limit: i32,
    /// Elements per full circle in that curvature size, in (0, 1e9] (default 24).
    pub n_circle: f64,
    /// A body expected to make more than twice this many triangles is cut
    /// along its creases into pieces of about this many, remeshed side by
    /// side (README "Large bodies in pieces"); the pieces do not depend on
    /// the thread count. 0 = never cut, else >= 1 (default 50000). Added
    /// after the first release: a caller whose `struct_size` ends before it
    /// gets the default, so grids of bodies that large differ from those of
    /// earlier versions.
    pub piece_faces: f64,
}

/// What `abgs_grid_remesh` did.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct abgs_remesh_report {
    /// `sizeof(abgs_remesh_report)`, set by the caller (the header's growth rule).
    pub struct_size: u32,
    /// Vertices of the input.
    pub vertices_in: u64,
    /// Triangles of the input.
    pub faces_in: u64,
    /// Vertices of the output.
    pub vertices_out: u64,
    /// Triangles of the output.
    pub faces_out: u64,
    /// Uniform target length L0 used (NaN in size-driven mode).
    pub target_length: f64,
    /// Smallest target length over the output vertices (after the curvature cap).
    pub target_min: f64,
    /// Largest target length over the output vertices.
    pub target_max: f64,
    /// Feature edges of the input (dihedral angle, boundary, non-manifold).
    pub feature_edges_in: u64,
    /// Feature edges kept in the output (see `abgs_grid_remesh_copy_feature_edges`).
    pub feature_edges_out: u64,
    /// Feature lines: chains of feature edges between corners, or loops.
    pub feature_lines: u64,
    /// Corners (fixed vertices), counting copies at non-manifold vertices.
    pub corners: u64,
    /// Iterations done.
    pub iterations: u64,
    /// Total seconds.
    pub seconds: f64,
    /// Number of things that could not be remeshed (0 when everything was);
    /// their texts come from `abgs_grid_remesh_issue`.
    pub n_issues: u64,
    /// Pieces the large bodies were cut into (0 when none was cut; see
    /// `piece_faces`). A cut whose seams would leave zero-area triangles is
    /// undone (remeshed whole): then 0, and `n_issues` counts the undoing.
    /// Added after the first release.
    pub pieces: u64,
}

versioned!(abgs_remesh_params, 48, default_params());
versioned!(abgs_remesh_report, 120);

/// What the remesher kept and reported, held in the new grid's handle (its
/// provenance).
#[derive(Debug, Clone, Default)]
struct RemeshInfo {
    /// Kept feature edges, vertex pairs of the grid.
    pub feature_edges: Vec<[u32; 2]>,
    /// Texts of what could not be remeshed.
    pub issues: Vec<String>,
}

/// The library's defaults as a C struct.
fn default_params() -> abgs_remesh_params {
    let d = RemeshParams::default();
    abgs_remesh_params {
        struct_size: own_size::<abgs_remesh_params>(),
        edge_length: 0.0,
        relative_length: match d.target {
            TargetLength::Relative(r) => r,
            TargetLength::Absolute(_) => 0.01,
        },
        feature_angle_deg: d.feature_angle_deg,
        iterations: d.iterations as u32,
        curvature_limit: d.curvature_limit as i32,
        n_circle: d.n_circle,
        piece_faces: d.piece_faces,
    }
}

/// Writes the default parameters into `*out_params`, whose `struct_size` the
/// caller has set (`abgs_remesh_params p = {.struct_size = sizeof p};`).
///
/// # Safety
/// `out_params` is NULL (reported) or holds `struct_size` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn abgs_remesh_params_default(
    out_params: *mut abgs_remesh_params,
) -> abgs_status {
    guard("abgs_remesh_params_default", || {
        // SAFETY: NULL (reported) or `struct_size` writable bytes.
        unsafe { check_out(out_params, "out_params", false)? };
        // SAFETY: as above.
        unsafe { write_out(out_params, &default_params(), "out_params") }
    })
}

/// Converts C parameters to Rust ones (other fields keep their defaults).
fn to_params(p: &abgs_remesh_params) -> FfiResult<RemeshParams> {
    for (x, what) in [
        (p.edge_length, "edge_length"),
        (p.relative_length, "relative_length"),
        (p.feature_angle_deg, "feature_angle_deg"),
        (p.n_circle, "n_circle"),
        (p.piece_faces, "piece_faces"),
    ] {
        if !x.is_finite() {
            return err(
                abgs_status::ABGS_ERR_NON_FINITE,
                format!("{what} = {x} must be finite"),
            );
        }
    }
    let invalid = |msg: String| err(abgs_status::ABGS_ERR_INVALID_ARGUMENT, msg);
    if p.edge_length < 0.0 {
        return invalid(format!(
            "edge_length = {} must be > 0, or 0 to use relative_length",
            p.edge_length
        ));
    }
    if p.edge_length == 0.0 && p.relative_length <= 0.0 {
        return invalid(format!(
            "relative_length = {} must be > 0 when edge_length is 0",
            p.relative_length
        ));
    }
    if !(0.0..=180.0).contains(&p.feature_angle_deg) {
        return invalid(format!(
            "feature_angle_deg = {} must be in [0, 180]",
            p.feature_angle_deg
        ));
    }
    if p.iterations == 0 {
        return invalid("iterations = 0 must be >= 1".into());
    }
    if !(p.n_circle > 0.0 && p.n_circle <= 1e9) {
        return invalid(format!("n_circle = {} must be in (0, 1e9]", p.n_circle));
    }
    if p.piece_faces != 0.0 && p.piece_faces < 1.0 {
        return invalid(format!(
            "piece_faces = {} must be >= 1, or 0 to never cut",
            p.piece_faces
        ));
    }
    Ok(RemeshParams {
        target: if p.edge_length > 0.0 {
            TargetLength::Absolute(p.edge_length)
        } else {
            TargetLength::Relative(p.relative_length)
        },
        feature_angle_deg: p.feature_angle_deg,
        iterations: p.iterations as usize,
        curvature_limit: p.curvature_limit != 0,
        n_circle: p.n_circle,
        piece_faces: if p.piece_faces == 0.0 {
            f64::INFINITY
        } else {
            p.piece_faces
        },
        ..Default::default()
    })
}

/// Remeshes `input` into a new grid of well-shaped triangles (isotropic
/// remeshing: split, collapse, flip, tangential relaxation with projection onto
/// the input). Feature lines (dihedral angle above `feature_angle_deg`,
/// boundaries, non-manifold edges) and their corners are kept, bodies stay apart,
/// and no boundary or non-manifold edge is added.
///
/// Uniform mode when `sizing` is NULL (target length from `edge_length` or
/// `relative_length`); size-driven mode otherwise: the target length at a point
/// is the size `sizing` gives there (`abgs_query_size`), so `sizing` must carry
/// sizes (it may be `input` itself). In both modes the target is capped by
/// curvature when `curvature_limit` is 1. `params` NULL = the defaults.
///
/// On success `*out_grid` owns a new grid without sizes (set them with
/// `abgs_grid_set_sizes` or `abgs_compute_size`), whose handle also holds the
/// kept feature edges and the texts of what could not be remeshed
/// (`abgs_grid_remesh_copy_feature_edges`, `abgs_grid_remesh_issue`); on
/// failure `*out_grid` is NULL. `out_report` (may be NULL) receives what was
/// done, on success only. Dirty input (slivers, open surfaces, touching bodies)
/// is not an error: what was left as it was is counted in `n_issues`.
/// `input` and `sizing` are only read (other const calls may run on them
/// meanwhile; a mutating call on them returns BUSY until this one returns).
/// Cost: O(F log F) per iteration, parallel on the rayon thread pool: bodies
/// side by side, and a body expected to make more than 2 × `piece_faces`
/// (default 50,000) triangles cut along its creases into pieces that run
/// side by side too (README "Large bodies in pieces"). The result does not
/// depend on the thread count.
///
/// Errors: NULL (input, out_grid), NON_FINITE / INVALID_ARGUMENT (parameters),
/// NO_SIZES (a sizing grid without sizes), BUSY (a mutation is running on
/// `input` or `sizing`), EMPTY (nothing left).
///
/// # Safety
/// Pointers are NULL (reported, or meaning "absent" where documented) or valid;
/// grid pointers come from this library and are not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_remesh(
    input: *const abgs_grid,
    sizing: *const abgs_grid,
    params: *const abgs_remesh_params,
    out_grid: *mut *mut abgs_grid,
    out_report: *mut abgs_remesh_report,
) -> abgs_status {
    guard("abgs_grid_remesh", || {
        // SAFETY: writable or NULL (checked).
        let o = unsafe { out(out_grid, "out_grid")? };
        *o = std::ptr::null_mut();
        // SAFETY: a grid from this library or NULL (checked).
        let h = unsafe { req(input, "input")? };
        // SAFETY: NULL (defaults) or `struct_size` readable bytes.
        let params = match unsafe { read_in(params, "params")? } {
            Some(p) => to_params(&p)?,
            None => RemeshParams::default(),
        };
        // SAFETY: NULL (skipped) or `struct_size` writable bytes.
        unsafe { check_out(out_report, "out_report", true)? };
        let g = h.read()?;
        let r = if sizing.is_null() {
            remesh::remesh(&g, &params)?
        } else if std::ptr::eq(sizing, input) {
            // One read guard is enough (and avoids taking the lock twice).
            if g.sizes().is_none() {
                return err(
                    abgs_status::ABGS_ERR_NO_SIZES,
                    "the sizing grid has no sizes",
                );
            }
            remesh::remesh_sized(&g, &g, &params)?
        } else {
            // SAFETY: a non-NULL sizing grid comes from this library and is live.
            let s = unsafe { req(sizing, "sizing")? }.read()?;
            if s.sizes().is_none() {
                return err(
                    abgs_status::ABGS_ERR_NO_SIZES,
                    "the sizing grid has no sizes",
                );
            }
            remesh::remesh_sized(&g, &s, &params)?
        };
        // SAFETY: checked above.
        unsafe { write_out(out_report, &report(&r), "out_report")? };
        let info = RemeshInfo {
            feature_edges: r.feature_edges,
            issues: r.report.issues,
        };
        *o = abgs_grid::boxed_with(r.grid, info);
        Ok(())
    })
}

/// The C report of a Rust remeshing.
fn report(r: &remesh::Remeshed) -> abgs_remesh_report {
    let p = &r.report;
    abgs_remesh_report {
        struct_size: 0,
        vertices_in: p.vertices_in as u64,
        faces_in: p.faces_in as u64,
        vertices_out: p.vertices_out as u64,
        faces_out: p.faces_out as u64,
        target_length: p.target_length,
        target_min: p.target_range[0],
        target_max: p.target_range[1],
        feature_edges_in: p.feature_edges_in as u64,
        feature_edges_out: r.feature_edges.len() as u64,
        feature_lines: p.feature_lines as u64,
        corners: p.corners as u64,
        iterations: p.iterations.len() as u64,
        seconds: p.seconds,
        n_issues: p.issues.len() as u64,
        pieces: p.pieces as u64,
    }
}

/// The remesher's record of a grid made by `abgs_grid_remesh`, read under
/// the grid's lock (so that a concurrent `abgs_grid_free` returns BUSY).
fn info(h: &Held) -> FfiResult<&RemeshInfo> {
    h.provenance::<RemeshInfo>().ok_or_else(|| {
        FfiError(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            "the grid was not made by abgs_grid_remesh".into(),
        )
    })
}

/// Number of feature edges the remesher kept into `*out_count` (the
/// constrained polylines along the input's feature lines, boundaries and
/// non-manifold edges). Errors: NULL, INVALID_ARGUMENT (the grid was not made
/// by `abgs_grid_remesh`).
///
/// # Safety
/// Pointers are NULL (reported) or valid.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_remesh_feature_edge_count(
    grid: *const abgs_grid,
    out_count: *mut usize,
) -> abgs_status {
    guard("abgs_grid_remesh_feature_edge_count", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: writable or NULL (checked).
        let o = unsafe { out(out_count, "out_count")? };
        *o = info(&g)?.feature_edges.len();
        Ok(())
    })
}

/// Copies the kept feature edges, two vertex indices of the grid each, into
/// `out_edges` (`capacity` >= 2 × `abgs_grid_remesh_feature_edge_count`, else
/// BUFFER_TOO_SMALL). Errors: NULL, INVALID_ARGUMENT (not a remeshed grid).
///
/// # Safety
/// Pointers are NULL (reported) or valid for `capacity` indices.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_remesh_copy_feature_edges(
    grid: *const abgs_grid,
    out_edges: *mut u32,
    capacity: usize,
) -> abgs_status {
    guard("abgs_grid_remesh_copy_feature_edges", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        let flat = info(&g)?.feature_edges.as_flattened();
        // SAFETY: the caller guarantees `capacity` writable indices (or NULL, reported).
        unsafe { checked_out(out_edges, capacity, flat.len(), "out_edges")? }.copy_from_slice(flat);
        Ok(())
    })
}

/// Copies the text of issue `index` (0-based, below `abgs_remesh_report.n_issues`)
/// of a remeshed grid, UTF-8 and NUL-terminated, into `out_text` (`capacity`
/// bytes). `*out_len` (may be NULL) receives the bytes needed, NUL included,
/// also when the buffer is too small; `out_text` may be NULL with `capacity` 0
/// to ask for that length only. Errors: NULL (grid), INVALID_ARGUMENT (not a
/// remeshed grid), OUT_OF_RANGE (index), BUFFER_TOO_SMALL.
///
/// # Safety
/// Pointers are NULL (reported / ignored where documented) or valid;
/// `out_text` holds `capacity` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_remesh_issue(
    grid: *const abgs_grid,
    index: usize,
    out_text: *mut c_char,
    capacity: usize,
    out_len: *mut usize,
) -> abgs_status {
    guard("abgs_grid_remesh_issue", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        let issues = &info(&g)?.issues;
        let text = issues.get(index).ok_or_else(|| {
            FfiError(
                abgs_status::ABGS_ERR_OUT_OF_RANGE,
                format!("issue {index} of {}", issues.len()),
            )
        })?;
        let bytes = text.as_bytes();
        let needed = bytes.len() + 1;
        // SAFETY: NULL or writable.
        if let Some(l) = unsafe { out_len.as_mut() } {
            *l = needed;
        }
        if out_text.is_null() {
            if capacity == 0 {
                return Ok(());
            }
            return err(abgs_status::ABGS_ERR_NULL, "out_text is NULL");
        }
        if capacity < needed {
            return err(
                abgs_status::ABGS_ERR_BUFFER_TOO_SMALL,
                format!("out_text holds {capacity} bytes, {needed} needed"),
            );
        }
        // SAFETY: non-NULL with `capacity` >= needed writable bytes by contract.
        let dst = unsafe { slice_mut(out_text as *mut u8, needed, "out_text")? };
        dst[..bytes.len()].copy_from_slice(bytes);
        dst[bytes.len()] = 0;
        Ok(())
    })
}
