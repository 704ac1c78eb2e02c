//! Acceptance measures of a remeshed grid against its input: angle
//! percentiles, symmetric Hausdorff distance of the surfaces and of their
//! feature lines (by dense sampling and exact closest points), bodies, and
//! boundary / non-manifold edges that are not on the input's.

use crate::error::Result;
use crate::geometry::{dist2, lerp};
use crate::mesh::features::{BOUNDARY, NON_MANIFOLD};
use crate::mesh::{Features, Grid};
use crate::spatial::Bvh;
use rayon::prelude::*;

/// The acceptance table row of one remeshing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Acceptance {
    /// Faces of the input.
    pub faces_in: usize,
    /// Faces of the output.
    pub faces_out: usize,
    /// 1st percentile of the smallest angle per face of the output, degrees.
    pub min_angle_p1: f64,
    /// 99th percentile of the largest angle per face of the output, degrees.
    pub max_angle_p99: f64,
    /// Symmetric Hausdorff distance of the surfaces / input diagonal.
    pub hausdorff: f64,
    /// Symmetric Hausdorff distance of the feature lines / input diagonal:
    /// input feature edges against the output's kept feature edges (or, when
    /// none are given, the output's own detected feature edges).
    pub feature_hausdorff: f64,
    /// Output edges sharper than the feature angle farther than 0.1 % of the
    /// diagonal from every input edge sharper than half of it: creases the
    /// input does not have (e.g. a rounded rim thinner than the smallest
    /// target length folds into one edge). Informational.
    pub new_creases: usize,
    /// Bodies of the input.
    pub bodies_in: usize,
    /// Bodies of the output.
    pub bodies_out: usize,
    /// Output boundary edges not on an input boundary.
    pub new_boundary_edges: usize,
    /// Output non-manifold edges not on an input non-manifold edge.
    pub new_non_manifold_edges: usize,
}

/// Segments as degenerate triangles in a BVH.
struct Segments {
    bvh: Bvh,
    segs: Vec<[[f64; 3]; 2]>,
}

impl Segments {
    fn new(segs: Vec<[[f64; 3]; 2]>) -> Segments {
        let pts: Vec<[f64; 3]> = segs.iter().flat_map(|s| [s[0], s[1]]).collect();
        let tris: Vec<[u32; 3]> = (0..segs.len() as u32)
            .map(|i| [2 * i, 2 * i + 1, 2 * i + 1])
            .collect();
        Segments {
            bvh: Bvh::build(&pts, &tris),
            segs,
        }
    }
    fn distance(&self, p: [f64; 3]) -> f64 {
        self.bvh
            .closest(p, None)
            .map_or(f64::INFINITY, |h| h.closest.dist2.sqrt())
    }
    /// About `n` points spread evenly by length, ends included.
    fn samples(&self, n: usize) -> Vec<[f64; 3]> {
        let total: f64 = self.segs.iter().map(|s| dist2(s[0], s[1]).sqrt()).sum();
        let step = if total > 0.0 {
            total / n.max(1) as f64
        } else {
            1.0
        };
        let mut out = Vec::new();
        for s in &self.segs {
            let k = (dist2(s[0], s[1]).sqrt() / step).ceil().max(1.0) as usize;
            for i in 0..=k {
                out.push(lerp(s[0], s[1], i as f64 / k as f64));
            }
        }
        out
    }
}

/// Edges of `grid` whose feature flags intersect `mask`, as segments.
fn flagged(grid: &Grid, features: &Features, mask: u8) -> Vec<[[f64; 3]; 2]> {
    let v = grid.vertices();
    let topo = grid.topology();
    (0..topo.edges.len())
        .filter(|&e| features.edge_flags[e] & mask != 0)
        .map(|e| topo.edges[e].map(|i| v[i as usize]))
        .collect()
}

/// Largest distance from `a`'s samples to `b`, both ways (∞ if one side is
/// empty and the other not, 0 if both are).
fn two_way(a: &Segments, b: &Segments, n: usize) -> f64 {
    match (a.segs.is_empty(), b.segs.is_empty()) {
        (true, true) => return 0.0,
        (true, false) | (false, true) => return f64::INFINITY,
        _ => {}
    }
    let d1 = a
        .samples(n)
        .par_iter()
        .map(|&p| b.distance(p))
        .reduce(|| 0.0, f64::max);
    let d2 = b
        .samples(n)
        .par_iter()
        .map(|&p| a.distance(p))
        .reduce(|| 0.0, f64::max);
    d1.max(d2)
}

/// Symmetric sampled Hausdorff distance (moved to [`crate::metrics`]).
pub use crate::metrics::hausdorff;

/// Per unique edge of `grid`: its length over the target `h` at its midpoint
/// (`h(point, hint)`, hinted per chunk); returns the mean and the share in
/// [0.6, 1.5], the size-driven acceptance measures. O(E) queries, parallel;
/// the first error of `h` is returned.
pub fn length_ratios(
    grid: &Grid,
    h: impl Fn([f64; 3], &mut u32) -> Result<f64> + Sync,
) -> Result<(f64, f64)> {
    let v = grid.vertices();
    let edges = &grid.topology().edges;
    let r: Vec<f64> = edges
        .par_chunks(1024)
        .map(|chunk| {
            let mut hint = u32::MAX;
            chunk
                .iter()
                .map(|e| {
                    let (a, b) = (v[e[0] as usize], v[e[1] as usize]);
                    let m = [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]));
                    let l = [0, 1, 2]
                        .map(|k| (a[k] - b[k]).powi(2))
                        .iter()
                        .sum::<f64>()
                        .sqrt();
                    Ok(l / h(m, &mut hint)?)
                })
                .collect::<Result<Vec<f64>>>()
        })
        .collect::<Result<Vec<_>>>()?
        .concat();
    let n = r.len().max(1) as f64;
    let mean = r.iter().sum::<f64>() / n;
    let within = r.iter().filter(|&&x| (0.6..=1.5).contains(&x)).count() as f64 / n;
    Ok((mean, within))
}

/// Evaluates `output` against `input` with `n` samples per surface and per
/// feature set; input features are detected with `feature_angle_deg`, output
/// features are `output_features` (vertex pairs, e.g. [`super::Remeshed::feature_edges`])
/// or, when `None`, detected the same way.
pub fn evaluate(
    input: &Grid,
    output: &Grid,
    output_features: Option<&[[u32; 2]]>,
    feature_angle_deg: f64,
    n: usize,
) -> Acceptance {
    let diag = input.bbox().diagonal();
    let fi = Features::detect(input, feature_angle_deg);
    let fo = Features::detect(output, feature_angle_deg);
    let all = u8::MAX;
    let out_segs = match output_features {
        Some(edges) => {
            let v = output.vertices();
            edges
                .iter()
                .filter(|e| e.iter().all(|&i| (i as usize) < v.len()))
                .map(|e| e.map(|i| v[i as usize]))
                .collect()
        }
        None => flagged(output, &fo, all),
    };
    let feature_hausdorff = two_way(
        &Segments::new(flagged(input, &fi, all)),
        &Segments::new(out_segs),
        n,
    ) / diag;
    let tol = 1e-3 * diag;
    let soft = Segments::new(flagged(
        input,
        &Features::detect(input, 0.5 * feature_angle_deg),
        all,
    ));
    let new_creases = flagged(output, &fo, all)
        .par_iter()
        .filter(|s| soft.distance(lerp(s[0], s[1], 0.5)) > tol)
        .count();
    let new_edges = |mask: u8| {
        let reference = Segments::new(flagged(input, &fi, mask));
        flagged(output, &fo, mask)
            .par_iter()
            .filter(|s| reference.distance(lerp(s[0], s[1], 0.5)) > tol)
            .count()
    };
    let stats = output.angle_stats();
    Acceptance {
        faces_in: input.triangles().len(),
        faces_out: output.triangles().len(),
        min_angle_p1: stats.min_angle_p1,
        max_angle_p99: stats.max_angle_p99,
        hausdorff: hausdorff(input, output, n, 7) / diag,
        feature_hausdorff,
        new_creases,
        bodies_in: input.topology().body_count as usize,
        bodies_out: output.topology().body_count as usize,
        new_boundary_edges: new_edges(BOUNDARY),
        new_non_manifold_edges: new_edges(NON_MANIFOLD),
    }
}

impl Acceptance {
    /// The acceptance thresholds: min-angle p1 ≥ 25°, max-angle p99 ≤ 110°,
    /// both Hausdorff distances ≤ 0.1 % of the diagonal, same bodies, no new
    /// boundary or non-manifold edges. Returns the failures (empty = pass).
    /// A NaN measure fails.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn failures(&self) -> Vec<String> {
        let mut f = Vec::new();
        if !(self.min_angle_p1 >= 25.0) {
            f.push(format!("min-angle p1 {:.1}° < 25°", self.min_angle_p1));
        }
        if !(self.max_angle_p99 <= 110.0) {
            f.push(format!("max-angle p99 {:.1}° > 110°", self.max_angle_p99));
        }
        if !(self.hausdorff <= 1e-3) {
            f.push(format!(
                "Hausdorff {:.2e} > 1e-3 of the diagonal",
                self.hausdorff
            ));
        }
        if !(self.feature_hausdorff <= 1e-3) {
            f.push(format!(
                "feature Hausdorff {:.2e} > 1e-3 of the diagonal",
                self.feature_hausdorff
            ));
        }
        if self.bodies_in != self.bodies_out {
            f.push(format!("bodies {} -> {}", self.bodies_in, self.bodies_out));
        }
        if self.new_boundary_edges > 0 || self.new_non_manifold_edges > 0 {
            f.push(format!(
                "{} new boundary, {} new non-manifold edges",
                self.new_boundary_edges, self.new_non_manifold_edges
            ));
        }
        f
    }
}
