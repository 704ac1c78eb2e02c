//! Contact agreement: where two bodies of an assembly touch, a point lies on
//! both at once, and a mesher that asks for the size there must not get an
//! answer that depends on which body the search meets first (DESIGN §3.9).
//!
//! A sample `p` of the reference surface (on reference body `A`) is a
//! **contact sample** when a face of another reference body lies within the
//! contact distance `c` of it (`c` = [`Grid::contact_gap`], diagonal / 2000:
//! the gap of the queries' tie rule and of the simplifier's agreed sizes). Its **partners** are every
//! body with a face within `c` of `p` (found one at a time, closest first,
//! each excluding the bodies found before: at most [`MAX_BODIES`]).
//!
//! On a grid under test `G` (the reference itself, or a candidate whose bodies
//! are matched to the reference's by `super::sheets::body_map`), each body's
//! size at `p` is its own interpolated size at its own closest point to `p`
//! (the candidate body matched to that reference body; a body the candidate
//! lost is left out), and the **disagreement** at `p` is `max h / min h − 1`
//! over those bodies (0 when fewer than two remain). Reported: the share of
//! the samples that are contact samples (the contact share of the surface, by
//! area), and the distribution of the disagreement over the contact samples
//! (median, 95th percentile, max, share over 10 %).
//!
//! Cost: O(n log F_r) to find the contact samples, O(k · b log F) for the k
//! contact samples with b bodies each on the grid under test; parallel and
//! deterministic (fixed chunks, results in sample order).

use super::sheets::body_map;
use crate::error::{Error, Result};
use crate::mesh::stats::percentile;
use crate::mesh::Grid;
use crate::sampling::surface_points;
use rayon::prelude::*;

/// Most bodies considered at one contact sample.
pub const MAX_BODIES: usize = 4;

/// Samples per rayon task.
const CHUNK: usize = 512;

/// How the bodies of a grid agree on their sizes where they touch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactAgreement {
    /// Share of the samples lying on two bodies at once (the contact share of
    /// the reference surface, by area).
    pub share: f64,
    /// Number of contact samples.
    pub samples: usize,
    /// Median disagreement `max h / min h − 1` over the contact samples (0 when
    /// there is none).
    pub p50: f64,
    /// 95th percentile of the disagreement (nearest rank).
    pub p95: f64,
    /// Largest disagreement.
    pub max: f64,
    /// Share of the contact samples whose disagreement exceeds 10 %.
    pub over_10: f64,
}

impl ContactAgreement {
    /// No contact at all (a single body, or bodies that are apart).
    pub const NONE: ContactAgreement = ContactAgreement {
        share: 0.0,
        samples: 0,
        p50: 0.0,
        p95: 0.0,
        max: 0.0,
        over_10: 0.0,
    };
}

/// One contact sample: the point and the reference bodies it lies on (the
/// sample's own body first).
#[derive(Debug, Clone)]
pub(crate) struct ContactSample {
    point: [f64; 3],
    bodies: Vec<u32>,
}

/// The contact samples among `samples` area-uniform points of `reference`
/// (seed `seed`), and the number of points drawn. O(n log F), parallel.
pub(crate) fn contact_samples(
    reference: &Grid,
    samples: usize,
    seed: u64,
) -> (Vec<ContactSample>, usize) {
    let topo = reference.topology();
    if topo.body_count < 2 || samples == 0 {
        return (Vec::new(), samples);
    }
    let gap = reference.contact_gap();
    let body = &topo.face_body;
    let pts = surface_points(reference, samples, seed);
    let found: Vec<ContactSample> = pts
        .par_chunks(CHUNK)
        .map(|chunk| {
            chunk
                .iter()
                .filter_map(|&(f, p)| {
                    let mut bodies = vec![body[f as usize]];
                    while bodies.len() < MAX_BODIES {
                        let Some(hit) = reference.bvh().closest_filtered_within(p, gap, |t| {
                            !bodies.contains(&body[t as usize])
                        }) else {
                            break;
                        };
                        bodies.push(body[hit.triangle as usize]);
                    }
                    (bodies.len() > 1).then_some(ContactSample { point: p, bodies })
                })
                .collect::<Vec<_>>()
        })
        .collect::<Vec<_>>()
        .concat();
    (found, samples)
}

/// Contact agreement of `grid` (the reference itself when `grid` is
/// `reference`, else a candidate made from it) at `samples` area-uniform
/// points of `reference` drawn with `seed`. Errors when either grid has no
/// sizes. See the module doc for the definitions and the cost.
pub fn contact_agreement(
    reference: &Grid,
    grid: &Grid,
    samples: usize,
    seed: u64,
) -> Result<ContactAgreement> {
    if reference.sizes().is_none() || grid.sizes().is_none() {
        return Err(Error::NoSizes);
    }
    if samples == 0 {
        return Err(Error::InvalidArgument("samples must be > 0".into()));
    }
    let (contact, drawn) = contact_samples(reference, samples, seed);
    Ok(agreement_at(reference, grid, &contact, drawn))
}

/// [`contact_agreement`] at given contact samples (`drawn` points in all).
pub(crate) fn agreement_at(
    reference: &Grid,
    grid: &Grid,
    contact: &[ContactSample],
    drawn: usize,
) -> ContactAgreement {
    if contact.is_empty() {
        return ContactAgreement::NONE;
    }
    let same = std::ptr::eq(reference, grid);
    // Reference body of each body of `grid`.
    let map: Vec<u32> = if same {
        (0..grid.topology().body_count).collect()
    } else {
        body_map(reference, grid)
    };
    let gbody = &grid.topology().face_body;
    let sizes = grid.sizes().unwrap_or(&[]);
    let t = grid.triangles();
    let mut values: Vec<f64> = contact
        .par_chunks(CHUNK)
        .map(|chunk| {
            chunk
                .iter()
                .map(|s| {
                    let mut lo = f64::INFINITY;
                    let mut hi = 0.0f64;
                    let mut n = 0;
                    for &b in &s.bodies {
                        let hit = grid.bvh().closest_filtered(s.point, None, |f| {
                            map[gbody[f as usize] as usize] == b
                        });
                        let Some(hit) = hit else { continue };
                        let tri = t[hit.triangle as usize];
                        let h = crate::query::interpolate(
                            tri.map(|k| sizes[k as usize]),
                            hit.closest.bary,
                        );
                        lo = lo.min(h);
                        hi = hi.max(h);
                        n += 1;
                    }
                    if n < 2 {
                        0.0
                    } else {
                        hi / lo - 1.0
                    }
                })
                .collect::<Vec<f64>>()
        })
        .collect::<Vec<_>>()
        .concat();
    let over = values.iter().filter(|&&d| d > 0.1).count();
    values.par_sort_unstable_by(f64::total_cmp);
    ContactAgreement {
        share: contact.len() as f64 / drawn as f64,
        samples: contact.len(),
        p50: percentile(&values, 0.5),
        p95: percentile(&values, 0.95),
        max: values[values.len() - 1],
        over_10: over as f64 / values.len() as f64,
    }
}
