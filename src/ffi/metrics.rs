//! Metrics through the C ABI (DESIGN §3.9): every metric of a candidate grid
//! against its dense reference in one call, and the sampled Hausdorff distance
//! (symmetric and one-sided) on its own. All are const and thread-safe.

use super::boundary::*;
use super::grid::abgs_grid;
use super::versioned::{check_out, own_size, read_required, versioned, write_out};
use crate::metrics::{self, AngleStats, EvalParams};

/// Parameters of `abgs_evaluate`; get the defaults from `abgs_eval_params_default`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct abgs_eval_params {
    /// `sizeof(abgs_eval_params)`, set by the caller (the header's growth rule).
    pub struct_size: u32,
    /// Points sampled uniformly on the reference for the size deviation, > 0
    /// (default 100 000).
    pub samples: u64,
    /// Points sampled on each surface for the Hausdorff distance (every vertex
    /// is added to them), > 0 (default 100 000).
    pub hausdorff_samples: u64,
    /// Seed of every sampling (default 1).
    pub seed: u64,
}

/// Smallest and largest angle per face of a grid, in degrees (percentiles by
/// nearest rank).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct abgs_angle_stats {
    /// Smallest angle of the grid.
    pub min: f64,
    /// 1st percentile of the per-face smallest angle.
    pub min_p1: f64,
    /// 5th percentile of the per-face smallest angle.
    pub min_p5: f64,
    /// 99th percentile of the per-face largest angle.
    pub max_p99: f64,
    /// Largest angle of the grid.
    pub max: f64,
    /// Mean of the per-face smallest angle.
    pub mean_min: f64,
}

/// Where bodies touch (an assembly's coincident faces, a shaft in a bore): how
/// far the touching bodies' interpolated sizes differ at points of the
/// reference surface lying on two bodies at once (within the contact distance
/// diagonal / 2000 of another body's face). The disagreement at such a point
/// is `max h / min h − 1` over the bodies there. All zero for a single body.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct abgs_contact_agreement {
    /// Share of the reference surface (by area) lying on two bodies.
    pub share: f64,
    /// Number of such sample points.
    pub samples: u64,
    /// Median disagreement.
    pub p50: f64,
    /// 95th percentile of the disagreement (nearest rank).
    pub p95: f64,
    /// Largest disagreement.
    pub max: f64,
    /// Share of the contact samples whose disagreement exceeds 0.1.
    pub over_10: f64,
}

impl From<metrics::ContactAgreement> for abgs_contact_agreement {
    fn from(c: metrics::ContactAgreement) -> Self {
        abgs_contact_agreement {
            share: c.share,
            samples: c.samples as u64,
            p50: c.p50,
            p95: c.p95,
            max: c.max,
            over_10: c.over_10,
        }
    }
}

/// What `abgs_evaluate` measured: a candidate grid against its reference.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct abgs_evaluation {
    /// `sizeof(abgs_evaluation)`, set by the caller (the header's growth rule).
    pub struct_size: u32,
    /// Faces of the reference.
    pub faces_reference: u64,
    /// Faces of the candidate.
    pub faces_candidate: u64,
    /// Vertices of the reference.
    pub vertices_reference: u64,
    /// Vertices of the candidate.
    pub vertices_candidate: u64,
    /// `1 − faces_candidate / faces_reference`.
    pub reduction: f64,
    /// Mean of the size ratio `max(h_c/h_r, h_r/h_c)` (>= 1; 1 = equal sizes)
    /// at points sampled uniformly on the reference.
    pub size_deviation_mean: f64,
    /// 95th percentile of that ratio (nearest rank).
    pub size_deviation_p95: f64,
    /// Largest ratio.
    pub size_deviation_max: f64,
    /// Number of points the ratio was measured at.
    pub size_deviation_samples: u64,
    /// Symmetric sampled Hausdorff distance between the surfaces (model units).
    pub hausdorff: f64,
    /// `hausdorff / diagonal`.
    pub hausdorff_relative: f64,
    /// Bounding-box diagonal of the reference.
    pub diagonal: f64,
    /// Estimated element count `(4/√3) ∫ h⁻² dA` over the reference with the
    /// reference's own sizes.
    pub element_count_reference: f64,
    /// The same integral over the reference with the candidate's sizes (surface queries).
    pub element_count_candidate: f64,
    /// `element_count_candidate / element_count_reference − 1`.
    pub element_count_change: f64,
    /// Angles of the reference.
    pub angles_reference: abgs_angle_stats,
    /// Angles of the candidate.
    pub angles_candidate: abgs_angle_stats,
    /// Wall time of the evaluation, seconds.
    pub seconds: f64,
    /// 99th percentile of the size ratio.
    pub size_deviation_p99: f64,
    /// Share of the size samples whose query landed on the wrong sheet
    /// (another body, or a face turned away; contacts left out).
    pub wrong_sheet: f64,
    /// element_count_candidate / faces_candidate: mesh elements per background cell.
    pub elements_per_cell: f64,
    /// element_count_reference / faces_reference.
    pub elements_per_cell_reference: f64,
    /// Where bodies touch: the reference's bodies' agreement.
    pub contact_reference: abgs_contact_agreement,
    /// Where bodies touch: the candidate's bodies' agreement at the same points.
    pub contact_candidate: abgs_contact_agreement,
}

versioned!(abgs_eval_params, 32, default_params());
versioned!(abgs_evaluation, 232);

/// The library's defaults as a C struct.
fn default_params() -> abgs_eval_params {
    let d = EvalParams::default();
    abgs_eval_params {
        struct_size: own_size::<abgs_eval_params>(),
        samples: d.samples as u64,
        hausdorff_samples: d.hausdorff_samples as u64,
        seed: d.seed,
    }
}

impl From<AngleStats> for abgs_angle_stats {
    fn from(a: AngleStats) -> Self {
        abgs_angle_stats {
            min: a.min,
            min_p1: a.min_p1,
            min_p5: a.min_p5,
            max_p99: a.max_p99,
            max: a.max,
            mean_min: a.mean_min,
        }
    }
}

/// A sample count from C as a `usize`, which must be > 0.
fn count(n: u64, what: &str) -> FfiResult<usize> {
    match usize::try_from(n) {
        Ok(0) => err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            format!("{what} must be > 0"),
        ),
        Ok(v) => Ok(v),
        Err(_) => err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            format!("{what} = {n} is too large"),
        ),
    }
}

/// Writes the default parameters into `*out_params` (100 000 samples for the
/// size deviation and for each side of the Hausdorff distance, seed 1); the
/// caller has set its `struct_size` (`abgs_eval_params p = {.struct_size = sizeof p};`).
///
/// # Safety
/// `out_params` is NULL (reported) or holds `struct_size` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn abgs_eval_params_default(
    out_params: *mut abgs_eval_params,
) -> abgs_status {
    guard("abgs_eval_params_default", || {
        // SAFETY: NULL (reported) or `struct_size` writable bytes.
        unsafe { check_out(out_params, "out_params", false)? };
        // SAFETY: as above.
        unsafe { write_out(out_params, &default_params(), "out_params") }
    })
}

/// Evaluates `candidate` (e.g. a simplified grid) against `reference` (the
/// dense grid it came from): reduction, size deviation, symmetric Hausdorff
/// distance, estimated element counts and angles (see `abgs_evaluation`), the
/// same numbers as `abgs eval`. Both grids need sizes. Parallel on the rayon
/// pool, deterministic (the same bits whatever the thread count).
/// O(F_r log F_c + (n + V_r) log F_c + (m + V_c) log F_r + F log F) for n size
/// samples and m Hausdorff samples; the 7 candidate queries per reference face
/// of the element count dominate on dense references.
///
/// Errors: NULL, INVALID_ARGUMENT (a sample count of 0), NO_SIZES, INVALID_SIZE
/// (a size met that is not finite and > 0), BUSY.
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid; grid pointers
/// come from this library and are not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_evaluate(
    reference: *const abgs_grid,
    candidate: *const abgs_grid,
    params: *const abgs_eval_params,
    out_evaluation: *mut abgs_evaluation,
) -> abgs_status {
    guard("abgs_evaluate", || {
        // SAFETY: grids from this library or NULL (checked).
        let r = unsafe { req(reference, "reference")? }.read()?;
        // SAFETY: as above.
        let c = unsafe { req(candidate, "candidate")? }.read()?;
        // SAFETY: NULL (reported) or `struct_size` readable bytes.
        let p = unsafe { read_required(params, "params")? };
        // SAFETY: NULL (reported) or `struct_size` writable bytes.
        unsafe { check_out(out_evaluation, "out_evaluation", false)? };
        let ep = EvalParams {
            samples: count(p.samples, "samples")?,
            hausdorff_samples: count(p.hausdorff_samples, "hausdorff_samples")?,
            seed: p.seed,
        };
        let e = metrics::evaluate(&r, &c, &ep)?;
        let ev = abgs_evaluation {
            struct_size: 0,
            faces_reference: e.faces_reference as u64,
            faces_candidate: e.faces_candidate as u64,
            vertices_reference: e.vertices_reference as u64,
            vertices_candidate: e.vertices_candidate as u64,
            reduction: e.reduction,
            size_deviation_mean: e.size_deviation.mean,
            size_deviation_p95: e.size_deviation.p95,
            size_deviation_max: e.size_deviation.max,
            size_deviation_samples: e.size_deviation.samples as u64,
            hausdorff: e.hausdorff,
            hausdorff_relative: e.hausdorff_relative,
            diagonal: e.diagonal,
            element_count_reference: e.element_count_reference,
            element_count_candidate: e.element_count_candidate,
            element_count_change: e.element_count_change,
            angles_reference: e.angles_reference.into(),
            angles_candidate: e.angles_candidate.into(),
            seconds: e.seconds,
            size_deviation_p99: e.size_deviation.p99,
            wrong_sheet: e.size_deviation.wrong_sheet,
            elements_per_cell: e.elements_per_cell,
            elements_per_cell_reference: e.elements_per_cell_reference,
            contact_reference: e.contact_reference.into(),
            contact_candidate: e.contact_candidate.into(),
        };
        // SAFETY: checked above.
        unsafe { write_out(out_evaluation, &ev, "out_evaluation") }
    })
}

/// Symmetric Hausdorff distance between the surfaces of `a` and `b` into
/// `*out_distance`: the larger of the two one-sided distances of
/// `abgs_hausdorff_directed` (each from `samples` area-uniform points with
/// `seed`, plus every vertex, measured exactly to the other surface). The value
/// `abgs_evaluate` reports as `hausdorff`. Sizes are not needed. Parallel,
/// deterministic. O((samples + V_a) log F_b + (samples + V_b) log F_a).
///
/// Errors: NULL, INVALID_ARGUMENT (`samples` is 0), BUSY.
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid; grid pointers
/// come from this library and are not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_hausdorff(
    a: *const abgs_grid,
    b: *const abgs_grid,
    samples: u64,
    seed: u64,
    out_distance: *mut f64,
) -> abgs_status {
    guard("abgs_hausdorff", || {
        // SAFETY: grids from this library or NULL (checked).
        let ga = unsafe { req(a, "a")? }.read()?;
        // SAFETY: as above.
        let gb = unsafe { req(b, "b")? }.read()?;
        // SAFETY: writable or NULL (checked).
        let o = unsafe { out(out_distance, "out_distance")? };
        *o = metrics::hausdorff(&ga, &gb, count(samples, "samples")?, seed);
        Ok(())
    })
}

/// One-sided Hausdorff distance from the surface of `from` to that of `to` into
/// `*out_distance`: the largest exact distance to `to` over `samples`
/// area-uniform points of `from` (with `seed`) and every vertex of `from`.
/// Sizes are not needed. Parallel, deterministic (the exact maximum whatever
/// the thread count). O((samples + V_from) log F_to) worst case; a point with a
/// triangle of `to` within the running maximum is settled by the first such
/// triangle found, so most points cost one triangle test.
///
/// Errors: NULL, INVALID_ARGUMENT (`samples` is 0), BUSY.
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid; grid pointers
/// come from this library and are not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_hausdorff_directed(
    from: *const abgs_grid,
    to: *const abgs_grid,
    samples: u64,
    seed: u64,
    out_distance: *mut f64,
) -> abgs_status {
    guard("abgs_hausdorff_directed", || {
        // SAFETY: grids from this library or NULL (checked).
        let gf = unsafe { req(from, "from")? }.read()?;
        // SAFETY: as above.
        let gt = unsafe { req(to, "to")? }.read()?;
        // SAFETY: writable or NULL (checked).
        let o = unsafe { out(out_distance, "out_distance")? };
        *o = metrics::hausdorff_directed(&gf, &gt, count(samples, "samples")?, seed);
        Ok(())
    })
}
