//! Metrics of a simplified background grid (the *candidate*) against the dense
//! grid it came from (the *reference*), one definition for every report
//! (DESIGN §3.9):
//!
//! - **reduction** `1 − F_c / F_r`;
//! - **size deviation**: the ratio `max(h_c/h_r, h_r/h_c)` at points sampled
//!   uniformly on the reference (mean, 95th and 99th percentile, max), `h_r`
//!   interpolated on the sample's own reference triangle, `h_c` a surface query
//!   on the candidate;
//! - **wrong-sheet share**: the share of those samples whose query lands on
//!   another body or on a face turned away (see `sheets`);
//! - **elements per background cell**: the estimated element count with the
//!   candidate's sizes over the candidate's face count, the number a mesher's
//!   user reads (how many mesh triangles one grid cell sizes);
//! - **geometric fidelity**: the symmetric sampled Hausdorff distance, absolute and
//!   relative to the reference's bounding-box diagonal;
//! - **estimated element count** `(4/√3) ∫ h⁻² dA` over the reference surface by
//!   the 7-point degree-5 triangle rule, with `h` from the reference itself and
//!   from the candidate;
//! - **contact agreement** of both grids: where bodies touch, how far their
//!   sizes differ (see [`contact`]);
//! - **angle statistics** of both grids.
//!
//! Every result is deterministic: the same bits whatever the rayon thread count
//! (per-item values are computed in parallel in fixed chunks, then reduced in a
//! fixed order; maxima are order-independent).

use crate::error::{Error, Result};
use crate::geometry::{closest_point_triangle, triangle_area, Aabb};
use crate::mesh::stats::percentile;
use crate::mesh::Grid;
use crate::sampling::surface_points;
pub use contact::ContactAgreement;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

pub mod contact;
mod sheets;
#[cfg(test)]
mod tests;

/// Samples per rayon task; consecutive samples share a query hint.
const SAMPLE_CHUNK: usize = 512;
/// Triangles per rayon task in the quadrature (7 queries each).
const TRIANGLE_CHUNK: usize = 128;

/// Parameters of [`evaluate`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EvalParams {
    /// Points sampled on the reference for the size deviation (default 100 000).
    pub samples: usize,
    /// Points sampled on each surface for the Hausdorff distance (default 100 000).
    pub hausdorff_samples: usize,
    /// Seed of every sampling (default 1).
    pub seed: u64,
}

impl Default for EvalParams {
    fn default() -> Self {
        EvalParams {
            samples: 100_000,
            hausdorff_samples: 100_000,
            seed: 1,
        }
    }
}

/// Distribution of the size ratio `max(h_c/h_r, h_r/h_c)` (≥ 1; 1 = equal sizes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SizeDeviation {
    /// Mean ratio.
    pub mean: f64,
    /// 95th percentile of the ratio (nearest rank).
    pub p95: f64,
    /// 99th percentile of the ratio (nearest rank).
    pub p99: f64,
    /// Largest ratio.
    pub max: f64,
    /// Number of samples.
    pub samples: usize,
    /// Share of the samples whose query landed on the wrong sheet (another
    /// body, or a face turned away; contacts left out).
    pub wrong_sheet: f64,
}

/// Distribution of the smallest and largest angle per face, in degrees
/// (percentiles by nearest rank; NaN for a grid without faces).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleStats {
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

/// Every metric of a candidate grid against its reference (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Evaluation {
    /// Faces of the reference.
    pub faces_reference: usize,
    /// Faces of the candidate.
    pub faces_candidate: usize,
    /// Vertices of the reference.
    pub vertices_reference: usize,
    /// Vertices of the candidate.
    pub vertices_candidate: usize,
    /// `1 − F_c / F_r`.
    pub reduction: f64,
    /// Size ratio at points sampled uniformly on the reference.
    pub size_deviation: SizeDeviation,
    /// Symmetric sampled Hausdorff distance between the surfaces.
    pub hausdorff: f64,
    /// [`Evaluation::hausdorff`] / [`Evaluation::diagonal`].
    pub hausdorff_relative: f64,
    /// Bounding-box diagonal of the reference.
    pub diagonal: f64,
    /// `(4/√3) ∫ h⁻² dA` over the reference with the reference's sizes.
    pub element_count_reference: f64,
    /// `(4/√3) ∫ h⁻² dA` over the reference with the candidate's sizes.
    pub element_count_candidate: f64,
    /// `element_count_candidate / element_count_reference − 1`.
    pub element_count_change: f64,
    /// `element_count_candidate / faces_candidate`: mesh elements per
    /// background cell.
    pub elements_per_cell: f64,
    /// `element_count_reference / faces_reference`: the same for the reference.
    pub elements_per_cell_reference: f64,
    /// Where bodies touch: the reference's bodies' agreement.
    pub contact_reference: ContactAgreement,
    /// Where bodies touch: the candidate's bodies' agreement (at the same
    /// contact samples of the reference).
    pub contact_candidate: ContactAgreement,
    /// Angles of the reference.
    pub angles_reference: AngleStats,
    /// Angles of the candidate.
    pub angles_candidate: AngleStats,
    /// Wall time of [`evaluate`], seconds.
    pub seconds: f64,
}

/// Evaluates `candidate` against `reference`: every field of [`Evaluation`].
///
/// Errors when a grid has no sizes or no triangles, when a parameter is zero, or
/// when a non-positive or non-finite size is met. Parallel (rayon), deterministic.
/// O(F_r log F_c + (n + V_r) log F_c + (n + V_c) log F_r + F log F) for n samples,
/// with the 7 queries per reference face of the element count dominating on dense
/// references.
pub fn evaluate(reference: &Grid, candidate: &Grid, params: &EvalParams) -> Result<Evaluation> {
    let t0 = Instant::now();
    checked_sizes(reference, "reference")?;
    checked_sizes(candidate, "candidate")?;
    if params.hausdorff_samples == 0 {
        return Err(Error::InvalidArgument(
            "hausdorff_samples must be > 0".into(),
        ));
    }
    let size_deviation = size_deviation(reference, candidate, params.samples, params.seed)?;
    let element_count_reference = estimated_element_count(reference, None)?;
    let element_count_candidate = estimated_element_count(reference, Some(candidate))?;
    let hausdorff = hausdorff(reference, candidate, params.hausdorff_samples, params.seed);
    let (at, drawn) = contact::contact_samples(reference, params.samples, params.seed);
    let contact_reference = contact::agreement_at(reference, reference, &at, drawn);
    let contact_candidate = contact::agreement_at(reference, candidate, &at, drawn);
    let diagonal = reference.bbox().diagonal();
    let (fr, fc) = (reference.triangles().len(), candidate.triangles().len());
    Ok(Evaluation {
        faces_reference: fr,
        faces_candidate: fc,
        vertices_reference: reference.vertices().len(),
        vertices_candidate: candidate.vertices().len(),
        reduction: 1.0 - fc as f64 / fr as f64,
        size_deviation,
        hausdorff,
        hausdorff_relative: hausdorff / diagonal,
        diagonal,
        element_count_reference,
        element_count_candidate,
        element_count_change: element_count_candidate / element_count_reference - 1.0,
        elements_per_cell: element_count_candidate / fc as f64,
        elements_per_cell_reference: element_count_reference / fr as f64,
        contact_reference,
        contact_candidate,
        angles_reference: angle_stats(reference),
        angles_candidate: angle_stats(candidate),
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// Size ratio `max(h_c/h_r, h_r/h_c)` at `samples` points sampled uniformly (by
/// area) on `reference` with `seed`: `h_r` interpolated at the point's exact
/// barycentric coordinates on its own reference triangle, `h_c` the candidate's
/// surface query ([`Grid::closest`]). Equal sizes give exactly 1. Also the
/// share of those queries that land on the wrong sheet (see `sheets`; the
/// contact distance is [`Grid::contact_gap`] of the reference).
///
/// Errors when a grid has no sizes or triangles, when `samples` is 0, or when a
/// size that is not finite and > 0 is met. Parallel, deterministic.
/// O(F_r + F_c log F_r + n log F_r + n log F_c + n log n).
pub fn size_deviation(
    reference: &Grid,
    candidate: &Grid,
    samples: usize,
    seed: u64,
) -> Result<SizeDeviation> {
    let rs = checked_sizes(reference, "reference")?;
    checked_sizes(candidate, "candidate")?;
    if samples == 0 {
        return Err(Error::InvalidArgument("samples must be > 0".into()));
    }
    let v = reference.vertices();
    let t = reference.triangles();
    // In Z-order, so that consecutive candidate queries are close.
    let pts = surface_points(reference, samples, seed);
    let positions: Vec<[f64; 3]> = pts.iter().map(|s| s.1).collect();
    let pts: Vec<(u32, [f64; 3])> = morton_order(&positions)
        .into_iter()
        .map(|i| pts[i as usize])
        .collect();
    let sheets = sheets::Sheets::new(reference, candidate, reference.contact_gap());
    let wrong = std::sync::atomic::AtomicUsize::new(0);
    let mut ratios: Vec<f64> = pts
        .par_chunks(SAMPLE_CHUNK)
        .map(|chunk| {
            let mut hint = None;
            chunk
                .iter()
                .map(|&(f, p)| {
                    let tri = t[f as usize];
                    let cp = closest_point_triangle(
                        p,
                        v[tri[0] as usize],
                        v[tri[1] as usize],
                        v[tri[2] as usize],
                    );
                    let hr = positive(interpolate(rs, tri, cp.bary), "reference", p)?;
                    let hit = candidate.closest(p, hint)?;
                    hint = Some(hit.triangle);
                    if sheets.wrong(p, f, hit.triangle, hit.bary) {
                        wrong.fetch_add(1, Ordering::Relaxed);
                    }
                    let hc = positive(hit.size, "candidate", p)?;
                    Ok(if hc == hr {
                        1.0
                    } else {
                        (hc / hr).max(hr / hc)
                    })
                })
                .collect::<Result<Vec<f64>>>()
        })
        .collect::<Result<Vec<Vec<f64>>>>()?
        .concat();
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    ratios.par_sort_unstable_by(f64::total_cmp);
    Ok(SizeDeviation {
        mean,
        p95: percentile(&ratios, 0.95),
        p99: percentile(&ratios, 0.99),
        max: ratios[ratios.len() - 1],
        samples: ratios.len(),
        wrong_sheet: wrong.into_inner() as f64 / ratios.len() as f64,
    })
}

/// The 7-point degree-5 rule on a triangle (Radon; Dunavant's degree-5 rule):
/// barycentric coordinates and weights summing to 1.
pub(crate) fn quadrature() -> [([f64; 3], f64); 7] {
    let s = 15f64.sqrt();
    let (a1, b1, w1) = (
        (6.0 - s) / 21.0,
        (9.0 + 2.0 * s) / 21.0,
        (155.0 - s) / 1200.0,
    );
    let (a2, b2, w2) = (
        (6.0 + s) / 21.0,
        (9.0 - 2.0 * s) / 21.0,
        (155.0 + s) / 1200.0,
    );
    let c = 1.0 / 3.0;
    [
        ([c, c, c], 9.0 / 40.0),
        ([b1, a1, a1], w1),
        ([a1, b1, a1], w1),
        ([a1, a1, b1], w1),
        ([b2, a2, a2], w2),
        ([a2, b2, a2], w2),
        ([a2, a2, b2], w2),
    ]
}

/// Estimated number of elements `(4/√3) ∫ h⁻² dA` of an isotropic mesh of
/// `surface` with the size field `h` (equilateral triangles of side h have area
/// `(√3/4) h²`): the integral over `surface` by the 7-point degree-5 rule per
/// triangle, `h` being the surface's own sizes at the exact barycentric
/// coordinates of each quadrature point (`sizing = None`) or a surface query on
/// `sizing` there.
///
/// Errors when the grid that gives the sizes has none, when a grid has no
/// triangles, or when a size that is not finite and > 0 is met. Parallel,
/// deterministic (fixed chunks summed in order). O(F) with the surface's own
/// sizes, O(F log F_s) with a sizing grid of F_s faces.
pub fn estimated_element_count(surface: &Grid, sizing: Option<&Grid>) -> Result<f64> {
    let own = match sizing {
        None => Some(checked_sizes(surface, "surface")?),
        Some(g) => {
            checked_sizes(g, "sizing")?;
            if surface.triangles().is_empty() {
                return Err(Error::Empty("surface has no triangles".into()));
            }
            None
        }
    };
    let rule = quadrature();
    let v = surface.vertices();
    let t = surface.triangles();
    // Along a Z-order curve when querying, so that consecutive queries are close.
    let order: Vec<u32> = if own.is_some() {
        (0..t.len() as u32).collect()
    } else {
        let centroids: Vec<[f64; 3]> = t
            .iter()
            .map(|tri| {
                let [a, b, c] = tri.map(|i| v[i as usize]);
                [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0)
            })
            .collect();
        morton_order(&centroids)
    };
    let partial: Vec<f64> = order
        .par_chunks(TRIANGLE_CHUNK)
        .map(|chunk| {
            let mut hint = None;
            let mut sum = 0.0;
            for &f in chunk {
                let tri = t[f as usize];
                let [a, b, c] = tri.map(|i| v[i as usize]);
                let mut s = 0.0;
                for (l, w) in rule {
                    let p = [0, 1, 2].map(|k| l[0] * a[k] + l[1] * b[k] + l[2] * c[k]);
                    let h = match (own, sizing) {
                        (Some(sz), _) => interpolate(sz, tri, l),
                        (None, Some(g)) => {
                            let hit = g.closest(p, hint)?;
                            hint = Some(hit.triangle);
                            hit.size
                        }
                        (None, None) => unreachable!("own sizes or a sizing grid"),
                    };
                    let h = positive(h, if own.is_some() { "surface" } else { "sizing" }, p)?;
                    s += w / (h * h);
                }
                sum += triangle_area(a, b, c) * s;
            }
            Ok(sum)
        })
        .collect::<Result<Vec<f64>>>()?;
    Ok(4.0 / 3f64.sqrt() * partial.iter().sum::<f64>())
}

/// Smallest and largest angle per face of `grid`, summarised (see
/// [`AngleStats`]). Parallel, deterministic. O(F log F).
pub fn angle_stats(grid: &Grid) -> AngleStats {
    let (mins, maxs) = grid.sorted_angles();
    AngleStats {
        min: mins.first().copied().unwrap_or(f64::NAN),
        min_p1: percentile(&mins, 0.01),
        min_p5: percentile(&mins, 0.05),
        max_p99: percentile(&maxs, 0.99),
        max: maxs.last().copied().unwrap_or(f64::NAN),
        mean_min: mins.iter().sum::<f64>() / mins.len() as f64,
    }
}

/// Symmetric Hausdorff distance between two surfaces, from `n` area-uniform
/// samples on each (plus every vertex), measured exactly through each grid's
/// BVH: the larger of the two [`hausdorff_directed`] values. Deterministic (a
/// maximum). O((n + V) log F).
pub fn hausdorff(a: &Grid, b: &Grid, n: usize, seed: u64) -> f64 {
    hausdorff_directed(a, b, n, seed).max(hausdorff_directed(b, a, n, seed))
}

/// One-sided Hausdorff distance from `from` to `to`: the largest exact distance
/// to `to` (through its BVH) over `n` area-uniform samples of `from` (with
/// `seed`) and every vertex of `from`. 0 when `from` has no triangles.
/// Deterministic (the exact maximum, whatever the thread count). O((n + V_from) log F_to);
/// most points are settled by one triangle test near the previous one.
pub fn hausdorff_directed(from: &Grid, to: &Grid, n: usize, seed: u64) -> f64 {
    if from.triangles().is_empty() {
        return 0.0;
    }
    let mut pts: Vec<[f64; 3]> = surface_points(from, n, seed)
        .into_iter()
        .map(|s| s.1)
        .collect();
    pts.extend_from_slice(from.vertices());
    let pts: Vec<[f64; 3]> = morton_order(&pts)
        .into_iter()
        .map(|i| pts[i as usize])
        .collect();
    // The running maximum of the squared distance, shared by all threads (the
    // bits of a non-negative f64 order like the values). A point that has a
    // triangle within it cannot raise it, and `any_within` proves that at the
    // first such triangle; only the others pay for an exact closest point. The
    // result is the exact maximum whatever the order, so it is deterministic.
    let max2 = AtomicU64::new(0f64.to_bits());
    pts.par_chunks(SAMPLE_CHUNK).for_each(|c| {
        let mut hint = None;
        for &p in c {
            let m2 = f64::from_bits(max2.load(Ordering::Relaxed));
            if let Some(t) = to.bvh().any_within(p, m2, hint) {
                hint = Some(t);
            } else if let Some(h) = to.bvh().closest(p, hint) {
                max2.fetch_max(h.closest.dist2.to_bits(), Ordering::Relaxed);
                hint = Some(h.triangle);
            }
        }
    });
    f64::from_bits(max2.into_inner()).sqrt()
}

/// Indices of `points` in Z-order (Morton order on a 2²¹ lattice over their
/// bounding box; ties by index). O(n log n).
fn morton_order(points: &[[f64; 3]]) -> Vec<u32> {
    let b = Aabb::from_points(points);
    let spread = |mut x: u64| {
        x &= 0x1f_ffff;
        x = (x | x << 32) & 0x001f_0000_0000_ffff;
        x = (x | x << 16) & 0x001f_0000_ff00_00ff;
        x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
        x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
        (x | x << 2) & 0x1249_2492_4924_9249
    };
    let cell = |p: [f64; 3], k: usize| {
        let w = b.max[k] - b.min[k];
        if w > 0.0 {
            ((p[k] - b.min[k]) / w * 2_097_151.0) as u64
        } else {
            0
        }
    };
    let mut keyed: Vec<(u64, u32)> = points
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let key = spread(cell(p, 0)) | spread(cell(p, 1)) << 1 | spread(cell(p, 2)) << 2;
            (key, i as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|k| k.1).collect()
}

/// The sizes of `grid`, which must have triangles (`what` names it in errors).
fn checked_sizes<'a>(grid: &'a Grid, what: &str) -> Result<&'a [f64]> {
    if grid.triangles().is_empty() {
        return Err(Error::Empty(format!("the {what} grid has no triangles")));
    }
    grid.sizes().ok_or(Error::NoSizes)
}

/// Barycentric interpolation of per-vertex `sizes` on triangle `tri`: the
/// surface query's own function, so equal inputs give equal bits.
#[inline]
fn interpolate(sizes: &[f64], tri: [u32; 3], b: [f64; 3]) -> f64 {
    crate::query::interpolate(tri.map(|v| sizes[v as usize]), b)
}

/// `h` when it is finite and > 0, else [`Error::InvalidSize`].
#[inline]
fn positive(h: f64, what: &str, p: [f64; 3]) -> Result<f64> {
    if h.is_finite() && h > 0.0 {
        Ok(h)
    } else {
        Err(Error::InvalidSize(format!("{what} size {h} at {p:?}")))
    }
}
