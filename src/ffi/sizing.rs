//! Sizing through the C ABI: parameters with defaults, size computation,
//! gradation, the Laplace–Beltrami operator and the edge list it is indexed by.

use super::boundary::*;
use super::grid::{abgs_grid, checked_out};
use super::versioned::{check_out, own_size, read_array, read_required, versioned, write_out};
use crate::sizing::{Gradation, SizeParams, SizeSource, SourceShape};

/// Source kind: a point (`points[0..3]`).
pub const ABGS_SOURCE_POINT: u32 = 0;
/// Source kind: a segment (`points[0..6]`).
pub const ABGS_SOURCE_SEGMENT: u32 = 1;
/// Source kind: a triangle (`points[0..9]`).
pub const ABGS_SOURCE_TRIANGLE: u32 = 2;

/// A user size source: every vertex within `radius` of the shape gets at most
/// `size`. In an array, every element states the same `struct_size`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct abgs_size_source {
    /// `sizeof(abgs_size_source)`, set by the caller (the header's growth rule).
    pub struct_size: u32,
    /// `ABGS_SOURCE_POINT`, `ABGS_SOURCE_SEGMENT` or `ABGS_SOURCE_TRIANGLE`.
    pub kind: u32,
    /// Up to three points, x y z each (unused entries ignored).
    pub points: [f64; 9],
    /// Size imposed (finite, > 0).
    pub size: f64,
    /// Radius of influence (finite, >= 0).
    pub radius: f64,
}

/// Parameters of `abgs_compute_size`; get the defaults from `abgs_size_params_default`.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct abgs_size_params {
    /// `sizeof(abgs_size_params)`, set by the caller (the header's growth rule).
    pub struct_size: u32,
    /// Elements per full circle for curvature sizes (default 24).
    pub n_circle: f64,
    /// Elements across a gap or wall (default 3).
    pub n_gap: f64,
    /// Smallest size; 0 = diagonal / 2000 (default 0).
    pub hmin: f64,
    /// Largest size; 0 = diagonal / 10 (default 0).
    pub hmax: f64,
    /// Dihedral angle above which an edge is a feature, degrees (default 30).
    pub feature_angle_deg: f64,
    /// Size on feature-edge vertices; 0 = off (default 0).
    pub feature_size: f64,
    /// Gradation ratio β > 1 (default 1.2), used when `slope` is 0.
    pub beta: f64,
    /// Gradation slope |∇h| bound; > 0 overrides `beta` (default 0).
    pub slope: f64,
    /// 1 = use curvature sizes (default 1).
    pub curvature: i32,
    /// 1 = use proximity sizes (default 1).
    pub proximity: i32,
    /// 1 = grade the result (default 1).
    pub gradation: i32,
    /// Bodies nearer than this touch (one size there, no gap size between
    /// them); 0 = the default: n_gap·hmin between bodies, hmin for the walls
    /// of one body (default 0).
    pub contact_gap: f64,
    /// `n_sources` user sources, or NULL.
    pub sources: *const abgs_size_source,
    /// Number of entries in `sources`.
    pub n_sources: usize,
}

/// What `abgs_compute_size` did.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct abgs_size_report {
    /// `sizeof(abgs_size_report)`, set by the caller (the header's growth rule).
    pub struct_size: u32,
    /// Smallest size used.
    pub hmin: f64,
    /// Largest size used.
    pub hmax: f64,
    /// Gradation slope used (0 when gradation was off).
    pub slope: f64,
    /// Feature edges found.
    pub feature_edges: u64,
    /// Smooth patches found.
    pub patches: u64,
    /// Vertices whose H0 came from curvature.
    pub limited_by_curvature: u64,
    /// Vertices whose H0 came from proximity.
    pub limited_by_proximity: u64,
    /// Vertices whose H0 came from feature refinement.
    pub limited_by_feature: u64,
    /// Vertices whose H0 came from a user source.
    pub limited_by_source: u64,
    /// Vertices clamped up to hmin.
    pub clamped_to_hmin: u64,
    /// Vertices at hmax.
    pub at_hmax: u64,
    /// Faces the gradation's verify pass had to fix.
    pub faces_fixed: u64,
    /// Largest face slope / slope after gradation (<= 1 + 1e-9).
    pub max_slope_ratio: f64,
    /// Seconds for features and normals.
    pub seconds_features: f64,
    /// Seconds for curvature.
    pub seconds_curvature: f64,
    /// Seconds for proximity.
    pub seconds_proximity: f64,
    /// Seconds for gradation (with the contact rounds).
    pub seconds_gradation: f64,
    /// Vertices lying on another body, whose size is shared with it.
    pub contact_vertices: u64,
    /// Seconds for finding where bodies touch.
    pub seconds_contacts: f64,
}

versioned!(abgs_size_source, 96);
versioned!(abgs_size_params, 112, default_params());
versioned!(abgs_size_report, 160);

/// The library's defaults as a C struct.
fn default_params() -> abgs_size_params {
    let d = SizeParams::default();
    abgs_size_params {
        struct_size: own_size::<abgs_size_params>(),
        n_circle: d.n_circle,
        n_gap: d.n_gap,
        hmin: 0.0,
        hmax: 0.0,
        feature_angle_deg: d.feature_angle_deg,
        feature_size: 0.0,
        beta: 1.2,
        slope: 0.0,
        curvature: 1,
        proximity: 1,
        gradation: 1,
        contact_gap: 0.0,
        sources: std::ptr::null(),
        n_sources: 0,
    }
}

/// Writes the default parameters into `*out_params`, whose `struct_size` the
/// caller has set (`abgs_size_params p = {.struct_size = sizeof p};`).
///
/// # Safety
/// `out_params` is NULL (reported) or holds `struct_size` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn abgs_size_params_default(
    out_params: *mut abgs_size_params,
) -> abgs_status {
    guard("abgs_size_params_default", || {
        // SAFETY: NULL (reported) or `struct_size` writable bytes.
        unsafe { check_out(out_params, "out_params", false)? };
        // SAFETY: as above.
        unsafe { write_out(out_params, &default_params(), "out_params") }
    })
}

/// Converts C parameters to Rust ones.
///
/// # Safety
/// `p.sources` is NULL or holds `p.n_sources` entries.
unsafe fn to_params(p: &abgs_size_params) -> FfiResult<SizeParams> {
    let opt = |x: f64, what: &str| -> FfiResult<Option<f64>> {
        if x == 0.0 {
            Ok(None)
        } else if x.is_nan() {
            err(abgs_status::ABGS_ERR_NON_FINITE, format!("{what} is NaN"))
        } else {
            Ok(Some(x))
        }
    };
    // SAFETY: forwarded contract on sources.
    let src = unsafe { read_array(p.sources, p.n_sources, "sources")? };
    let mut sources = Vec::with_capacity(src.len());
    for (i, s) in src.iter().enumerate() {
        let q = |k: usize| [s.points[3 * k], s.points[3 * k + 1], s.points[3 * k + 2]];
        let shape = match s.kind {
            ABGS_SOURCE_POINT => SourceShape::Point(q(0)),
            ABGS_SOURCE_SEGMENT => SourceShape::Segment(q(0), q(1)),
            ABGS_SOURCE_TRIANGLE => SourceShape::Triangle(q(0), q(1), q(2)),
            k => {
                return err(
                    abgs_status::ABGS_ERR_INVALID_ARGUMENT,
                    format!("source {i}: unknown kind {k}"),
                )
            }
        };
        sources.push(SizeSource {
            shape,
            size: s.size,
            radius: s.radius,
        });
    }
    if p.beta.is_nan() || p.slope.is_nan() {
        return err(abgs_status::ABGS_ERR_NON_FINITE, "beta or slope is NaN");
    }
    let gradation = if p.gradation == 0 {
        None
    } else if p.slope != 0.0 {
        Some(Gradation::Slope(p.slope))
    } else {
        Some(Gradation::Beta(p.beta))
    };
    Ok(SizeParams {
        n_circle: p.n_circle,
        n_gap: p.n_gap,
        hmin: opt(p.hmin, "hmin")?,
        hmax: opt(p.hmax, "hmax")?,
        feature_angle_deg: p.feature_angle_deg,
        feature_size: opt(p.feature_size, "feature_size")?,
        curvature: p.curvature != 0,
        proximity: p.proximity != 0,
        gradation,
        sources,
        contact_gap: opt(p.contact_gap, "contact_gap")?,
    })
}

/// Computes sizes on the grid's vertices from its geometry (curvature,
/// proximity, features, sources, clamped to [hmin, hmax], then graded) and
/// installs them; `out_report` (may be NULL) receives what was done.
/// Errors: NULL, INVALID_ARGUMENT / NON_FINITE / INVALID_SIZE (parameters), BUSY.
///
/// # Safety
/// Pointers are NULL (reported) or valid; `params->sources` holds `n_sources` entries.
#[no_mangle]
pub unsafe extern "C" fn abgs_compute_size(
    grid: *mut abgs_grid,
    params: *const abgs_size_params,
    out_report: *mut abgs_size_report,
) -> abgs_status {
    guard("abgs_compute_size", || {
        // SAFETY: a grid from this library or NULL (checked).
        let h = unsafe { req(grid as *const abgs_grid, "grid")? };
        // SAFETY: NULL (reported) or `struct_size` readable bytes.
        let p = unsafe { read_required(params, "params")? };
        // SAFETY: sources contract forwarded.
        let params = unsafe { to_params(&p)? };
        // SAFETY: NULL (skipped) or `struct_size` writable bytes.
        unsafe { check_out(out_report, "out_report", true)? };
        let mut g = h.write()?;
        let r = g.compute_sizes(&params)?;
        let l = r.limited_by;
        let report = abgs_size_report {
            struct_size: 0,
            hmin: r.hmin,
            hmax: r.hmax,
            slope: r.slope.unwrap_or(0.0),
            feature_edges: r.feature_edges as u64,
            patches: r.patches as u64,
            limited_by_curvature: l.curvature as u64,
            limited_by_proximity: l.proximity as u64,
            limited_by_feature: l.feature as u64,
            limited_by_source: l.source as u64,
            clamped_to_hmin: l.hmin as u64,
            at_hmax: l.hmax as u64,
            faces_fixed: r.gradation.faces_fixed as u64,
            max_slope_ratio: r.gradation.max_slope_ratio,
            seconds_features: r.seconds_features,
            seconds_curvature: r.seconds_curvature,
            seconds_proximity: r.seconds_proximity,
            seconds_gradation: r.seconds_gradation,
            contact_vertices: r.contact_vertices as u64,
            seconds_contacts: r.seconds_contacts,
        };
        // SAFETY: checked above.
        unsafe { write_out(out_report, &report, "out_report") }
    })
}

/// Grades the grid's current sizes in place: the largest field below them with
/// |∇h| <= slope on every triangle, slope = `slope` if > 0 else ln(`beta`).
/// `out_faces_fixed` (may be NULL) receives the number of faces the verify pass
/// fixed. Errors: NULL, NO_SIZES, INVALID_ARGUMENT, BUSY. O(V log V).
///
/// # Safety
/// Pointers are NULL (reported / ignored for the out-parameter) or valid.
#[no_mangle]
pub unsafe extern "C" fn abgs_apply_gradation(
    grid: *mut abgs_grid,
    beta: f64,
    slope: f64,
    out_faces_fixed: *mut u64,
) -> abgs_status {
    guard("abgs_apply_gradation", || {
        // SAFETY: a grid from this library or NULL (checked).
        let h = unsafe { req(grid as *const abgs_grid, "grid")? };
        if beta.is_nan() || slope.is_nan() {
            return err(abgs_status::ABGS_ERR_NON_FINITE, "beta or slope is NaN");
        }
        let g = if slope != 0.0 {
            Gradation::Slope(slope)
        } else {
            Gradation::Beta(beta)
        };
        let r = h.write()?.apply_gradation(g)?;
        // SAFETY: NULL or writable.
        if let Some(o) = unsafe { out_faces_fixed.as_mut() } {
            *o = r.faces_fixed as u64;
        }
        Ok(())
    })
}

/// Number of unique edges into `*out_count`.
///
/// # Safety
/// Pointers are NULL (reported) or valid.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_edge_count(
    grid: *const abgs_grid,
    out_count: *mut usize,
) -> abgs_status {
    guard("abgs_grid_edge_count", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: writable or NULL (checked).
        *unsafe { out(out_count, "out_count")? } = g.topology().edges.len();
        Ok(())
    })
}

/// Copies the unique edges, two vertex indices each (smaller first), sorted
/// lexicographically, into `out_edges` (`capacity` >= 2 × edge count). This is
/// the order of the per-edge values of `abgs_lbo`.
///
/// # Safety
/// Pointers are NULL (reported) or valid for `capacity` indices.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_copy_edges(
    grid: *const abgs_grid,
    out_edges: *mut u32,
    capacity: usize,
) -> abgs_status {
    guard("abgs_grid_copy_edges", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        let flat = g.topology().edges.as_flattened();
        // SAFETY: the caller guarantees `capacity` writable indices (or NULL, reported).
        unsafe { checked_out(out_edges, capacity, flat.len(), "out_edges")? }.copy_from_slice(flat);
        Ok(())
    })
}

/// Laplace–Beltrami operator of the sizes: per vertex into `out_vertex`
/// (`vertex_capacity` >= vertex count) and per edge into `out_edge`
/// (`edge_capacity` >= edge count, in `abgs_grid_copy_edges` order). Either
/// output may be NULL (with capacity 0) to skip it. Errors: NULL (grid, or both
/// outputs), NO_SIZES, BUFFER_TOO_SMALL. O(F).
///
/// # Safety
/// Non-NULL outputs are writable for their capacity.
#[no_mangle]
pub unsafe extern "C" fn abgs_lbo(
    grid: *const abgs_grid,
    out_vertex: *mut f64,
    vertex_capacity: usize,
    out_edge: *mut f64,
    edge_capacity: usize,
) -> abgs_status {
    guard("abgs_lbo", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        if out_vertex.is_null() && out_edge.is_null() {
            return err(
                abgs_status::ABGS_ERR_NULL,
                "out_vertex and out_edge are both NULL",
            );
        }
        let (nv, ne) = (g.vertices().len(), g.topology().edges.len());
        if !out_vertex.is_null() && vertex_capacity < nv {
            return err(
                abgs_status::ABGS_ERR_BUFFER_TOO_SMALL,
                format!("out_vertex holds {vertex_capacity}, {nv} needed"),
            );
        }
        if !out_edge.is_null() && edge_capacity < ne {
            return err(
                abgs_status::ABGS_ERR_BUFFER_TOO_SMALL,
                format!("out_edge holds {edge_capacity}, {ne} needed"),
            );
        }
        disjoint(&[
            (out_vertex as *const u8, nv.saturating_mul(8), "out_vertex"),
            (out_edge as *const u8, ne.saturating_mul(8), "out_edge"),
        ])?;
        let l = g.lbo()?;
        if !out_vertex.is_null() {
            // SAFETY: non-NULL with capacity >= nv (checked).
            unsafe { slice_mut(out_vertex, nv, "out_vertex")? }.copy_from_slice(&l.vertex);
        }
        if !out_edge.is_null() {
            // SAFETY: non-NULL with capacity >= ne (checked).
            unsafe { slice_mut(out_edge, ne, "out_edge")? }.copy_from_slice(&l.edge);
        }
        Ok(())
    })
}
