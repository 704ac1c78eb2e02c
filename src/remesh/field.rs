//! The cap on the target edge length: per input vertex, half the curvature
//! size `h = 2π / (κ · n_circle)` where the surface or a feature line bends,
//! and a crease size where two input facets meet at an angle below the
//! feature angle; then spread as a graded field of point sources, so it grows
//! by at most `slope` per unit distance (abrupt jumps make bad triangles).

use crate::geometry::{dot, norm, sub};
use crate::mesh::{Features, Grid};
use crate::sizing::curvature::principal_curvatures;
use crate::sizing::normals::PatchNormals;
use crate::spatial::{Bvh, MAX_DEPTH};
use std::f64::consts::PI;

/// Settings of [`length_cap`].
#[derive(Debug, Clone)]
pub struct CapSettings {
    /// Base target length at each input vertex (uniform length, or the sizing
    /// field there).
    pub base: Vec<f64>,
    /// Lower the cap by curvature.
    pub curvature: bool,
    /// Elements per full circle.
    pub n_circle: f64,
    /// Smallest curvature cap as a fraction of the base.
    pub min_ratio: f64,
    /// Smallest cap from the curvature of a feature line, as a fraction of the base.
    pub line_min_ratio: f64,
    /// Largest distance (fraction of the base) a chord may cut off a crease
    /// (an edge sharper than nothing but below the feature angle).
    pub crease_tolerance: f64,
    /// Feature lines turning by more than this (degrees) at a vertex have a
    /// corner there, not a curvature.
    pub corner_deg: f64,
}

/// The cap per input vertex (∞ where nothing limits it). O(V).
pub fn length_cap(grid: &Grid, features: &Features, s: &CapSettings) -> Vec<f64> {
    let nv = grid.vertices().len();
    let mut cap = vec![f64::INFINITY; nv];
    if !s.curvature {
        return cap;
    }
    let floor = |v: usize| s.min_ratio * s.base[v];
    let from_kappa = |k: f64, floor: f64| -> f64 {
        if k > 0.0 && k.is_finite() {
            (0.5 * 2.0 * PI / (k * s.n_circle)).max(floor)
        } else {
            f64::INFINITY
        }
    };
    let normals = PatchNormals::compute(grid, features);
    let curv = principal_curvatures(grid, features, &normals);
    for v in 0..nv {
        cap[v] = cap[v].min(from_kappa(curv[v].max_abs(), floor(v)));
    }
    // Creases below the feature angle: a chord of length L across a crease of
    // angle φ cuts off about L·φ/4, so L ≤ 4·tolerance·base/φ keeps the cut
    // within tolerance. (Curvature fits see a crease between large facets as
    // a gentle bend.)
    let fnormal = &normals.face_normal;
    let topo = grid.topology();
    for e in 0..topo.edges.len() {
        let fs = topo.faces_of_edge(e);
        if fs.len() != 2 || features.is_feature(e) {
            continue;
        }
        let phi = dot(fnormal[fs[0] as usize], fnormal[fs[1] as usize])
            .clamp(-1.0, 1.0)
            .acos();
        if phi > 1e-3 {
            for &v in &topo.edges[e] {
                let v = v as usize;
                let l = (4.0 * s.crease_tolerance * s.base[v] / phi).max(floor(v));
                cap[v] = cap[v].min(l);
            }
        }
    }
    // Curvature of feature lines: turning angle over the mean segment length.
    let v = grid.vertices();
    let cos_c = s.corner_deg.to_radians().cos();
    let mut ends: Vec<u32> = Vec::new();
    for (vi, c) in cap.iter_mut().enumerate() {
        if features.vertex_feature_valence[vi] != 2 {
            continue;
        }
        ends.clear();
        for &f in topo.faces_of_vertex(vi) {
            for &e in &topo.face_edges[f as usize] {
                let [a, b] = topo.edges[e as usize];
                if features.is_feature(e as usize) && (a as usize == vi || b as usize == vi) {
                    let o = if a as usize == vi { b } else { a };
                    if !ends.contains(&o) {
                        ends.push(o);
                    }
                }
            }
        }
        if ends.len() != 2 {
            continue;
        }
        let p = v[vi];
        let d1 = sub(p, v[ends[0] as usize]);
        let d2 = sub(v[ends[1] as usize], p);
        let (l1, l2) = (norm(d1), norm(d2));
        if !(l1 > 0.0 && l2 > 0.0) {
            continue;
        }
        let cos = (dot(d1, d2) / (l1 * l2)).clamp(-1.0, 1.0);
        if cos < cos_c {
            continue;
        }
        let k = cos.acos() / (0.5 * (l1 + l2));
        *c = c.min(from_kappa(k, s.line_min_ratio * s.base[vi]));
    }
    cap
}

/// A graded size field from point sources: `f(x) = min_i (h_i + slope·|x − p_i|)`
/// (∞ without sources), evaluated exactly by branch and bound over a BVH of
/// the points with the smallest value per node. Unlike values interpolated on
/// the input triangles, it grows away from a small source whatever the input
/// tessellation (a planar face tessellated only at its rim still gets large
/// elements inside).
#[derive(Debug, Clone, Default)]
pub struct PointField {
    bvh: Bvh,
    value: Vec<f64>,
    node_min: Vec<f64>,
    slope: f64,
}

impl PointField {
    /// The field of `points` with `values` (non-finite values are ignored) and
    /// growth `slope` (> 0). O(n log n).
    pub fn new(points: &[[f64; 3]], values: &[f64], slope: f64) -> PointField {
        let keep: Vec<usize> = (0..points.len())
            .filter(|&i| values[i].is_finite())
            .collect();
        let pts: Vec<[f64; 3]> = keep.iter().map(|&i| points[i]).collect();
        let value: Vec<f64> = keep.iter().map(|&i| values[i]).collect();
        let tris: Vec<[u32; 3]> = (0..pts.len() as u32).map(|i| [i, i, i]).collect();
        let bvh = Bvh::build(&pts, &tris);
        let node_min = bvh.node_minima(&value);
        PointField {
            bvh,
            value,
            node_min,
            slope: if slope.is_finite() && slope > 0.0 {
                slope
            } else {
                1e-12
            },
        }
    }

    /// `f(p)`. Expected O(log n).
    pub fn eval(&self, p: [f64; 3]) -> f64 {
        if self.bvh.nodes.is_empty() {
            return f64::INFINITY;
        }
        let mut best = f64::INFINITY;
        let mut stack = [0u32; MAX_DEPTH];
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let ni = stack[sp] as usize;
            let n = &self.bvh.nodes[ni];
            if self.node_min[ni] + self.slope * n.bbox.distance2(&p).sqrt() >= best {
                continue;
            }
            if n.is_leaf() {
                let s = n.start as usize;
                for slot in s..s + n.count as usize {
                    let q = self.bvh.prim_corners[slot][0];
                    let i = self.bvh.prim_triangle[slot] as usize;
                    best = best.min(self.value[i] + self.slope * norm(sub(p, q)));
                }
            } else if sp + 2 <= MAX_DEPTH {
                let (l, r) = (ni + 1, n.start as usize);
                let dl = self.node_min[l] + self.slope * self.bvh.nodes[l].bbox.distance2(&p).sqrt();
                let dr = self.node_min[r] + self.slope * self.bvh.nodes[r].bbox.distance2(&p).sqrt();
                // Visit the more promising child first.
                let (first, second) = if dl <= dr { (l, r) } else { (r, l) };
                stack[sp] = second as u32;
                stack[sp + 1] = first as u32;
                sp += 2;
            }
        }
        best
    }
}
