//! Discrete Laplace–Beltrami operator of the size field (DESIGN §3.4): cotangent
//! weights with mixed Voronoi areas (Meyer et al. 2003),
//! `LBO_v(i) = |Σ_j ½(cot α_ij + cot β_ij)(h_j − h_i)| / A_i`, and per edge
//! `LBO_e = ½(LBO_v(a) + LBO_v(b))`, in the order of `Topology::edges`.

use crate::geometry::*;
use crate::mesh::Grid;

/// Per-vertex and per-edge LBO values.
#[derive(Debug, Clone, PartialEq)]
pub struct Lbo {
    /// One value per vertex (0 for a vertex without faces).
    pub vertex: Vec<f64>,
    /// One value per edge, in `grid.topology().edges` order.
    pub edge: Vec<f64>,
}

/// Computes the LBO of `h` (one value per vertex) on `grid`. O(F).
pub fn lbo(grid: &Grid, h: &[f64]) -> Lbo {
    let vertex = vertex_lbo(grid.vertices(), grid.triangles().iter().copied(), h);
    let edge = grid
        .topology()
        .edges
        .iter()
        .map(|e| 0.5 * (vertex[e[0] as usize] + vertex[e[1] as usize]))
        .collect();
    Lbo { vertex, edge }
}

/// Per-vertex LBO of `h` over the given triangles of the vertices `v` (one
/// value per vertex slot; 0 for a vertex without faces). Sums in triangle
/// order, so the result is deterministic. O(F).
pub fn vertex_lbo(
    v: &[[f64; 3]],
    triangles: impl Iterator<Item = [u32; 3]>,
    h: &[f64],
) -> Vec<f64> {
    let nv = v.len();
    let mut sum = vec![0.0f64; nv];
    let mut area = vec![0.0f64; nv];
    for t in triangles {
        let t = &t;
        let p = t.map(|i| v[i as usize]);
        let a2 = norm(triangle_normal2(p[0], p[1], p[2]));
        if a2 <= 0.0 {
            continue;
        }
        let tri_area = 0.5 * a2;
        // cot of the angle at corner k, and the squared opposite side.
        let mut cot = [0.0; 3];
        let mut obtuse = None;
        for k in 0..3 {
            let u = sub(p[(k + 1) % 3], p[k]);
            let w = sub(p[(k + 2) % 3], p[k]);
            let d = dot(u, w);
            cot[k] = d / a2;
            if d < 0.0 {
                obtuse = Some(k);
            }
        }
        for k in 0..3 {
            // Edge (k+1, k+2) is opposite corner k.
            let (i, j) = (t[(k + 1) % 3] as usize, t[(k + 2) % 3] as usize);
            let w = 0.5 * cot[k];
            sum[i] += w * (h[j] - h[i]);
            sum[j] += w * (h[i] - h[j]);
        }
        match obtuse {
            None => {
                for k in 0..3 {
                    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                    let lij = dist2(p[k], p[i]);
                    let lik = dist2(p[k], p[j]);
                    // Voronoi area of corner k: (|k-i|² cot(j) + |k-j|² cot(i)) / 8.
                    area[t[k] as usize] += (lij * cot[j] + lik * cot[i]) / 8.0;
                }
            }
            Some(o) => {
                for k in 0..3 {
                    area[t[k] as usize] += if k == o {
                        tri_area / 2.0
                    } else {
                        tri_area / 4.0
                    };
                }
            }
        }
    }
    (0..nv)
        .map(|i| {
            if area[i] > 0.0 {
                sum[i].abs() / area[i]
            } else {
                0.0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::BuildOptions;

    fn plate(n: usize, f: impl Fn(f64, f64) -> f64) -> (Grid, Vec<f64>) {
        let (v, t) = crate::test_shapes::unit_square(n, |_, _| 0.0);
        let h = v.iter().map(|p| f(p[0], p[1])).collect();
        (
            Grid::from_arrays(v, t, None, &BuildOptions::default()).unwrap(),
            h,
        )
    }

    #[test]
    fn linear_field_has_zero_interior_lbo_and_quadratic_has_constant() {
        let n = 10;
        let (g, h) = plate(n, |x, y| 1.0 + 2.0 * x - y);
        let l = lbo(&g, &h);
        let interior = |i: usize| {
            let p = g.vertices()[i];
            p[0] > 0.0 && p[0] < 1.0 && p[1] > 0.0 && p[1] < 1.0
        };
        for i in 0..g.vertices().len() {
            if interior(i) {
                assert!(l.vertex[i] < 1e-9, "{}", l.vertex[i]);
            }
        }
        // Δ(x² + y²) = 4.
        let (g, h) = plate(n, |x, y| x * x + y * y);
        let l = lbo(&g, &h);
        for i in 0..g.vertices().len() {
            if interior(i) {
                assert!((l.vertex[i] - 4.0).abs() < 1e-9, "{}", l.vertex[i]);
            }
        }
        assert_eq!(l.edge.len(), g.topology().edges.len());
        let e = g.topology().edges[7];
        assert_eq!(
            l.edge[7],
            0.5 * (l.vertex[e[0] as usize] + l.vertex[e[1] as usize])
        );
    }
}
