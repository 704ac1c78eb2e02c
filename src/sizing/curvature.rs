//! Principal curvatures and directions per vertex, estimated per smooth patch.
//!
//! For each (vertex, patch) pair, every neighbour `q` of vertex `p` in that patch
//! gives a normal curvature along its tangent direction,
//! `κ = −2 n·(q − p) / |q − p|²` (exact for points on a sphere through p with
//! normal n); a least-squares fit of the second fundamental form
//! `κ(θ) = a cos²θ + 2b cosθ sinθ + c sin²θ` to these gives the shape operator,
//! whose eigen-pairs are the principal curvatures and directions (nalgebra:
//! Cholesky on the 3×3 normal equations, `SymmetricEigen` on the 2×2
//! operator; the same values as the closed forms to 1e-12 relative where the
//! fit is well conditioned, and steadier where it is not). Neighbours are
//! the 1-ring in the patch, widened to the 2-ring when fewer than four. Nothing
//! is taken across a feature edge or from another body. Sign: positive where the
//! surface bends away from its normal (convex for outward normals).

use super::normals::PatchNormals;
use crate::geometry::*;
use crate::mesh::{Features, Grid};
use nalgebra::{Matrix2, Matrix3, SymmetricEigen, Vector3};
use rayon::prelude::*;

/// Principal curvatures at a vertex (from the patch where they are largest).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Curvature {
    /// Curvature of largest magnitude.
    pub k1: f64,
    /// The other principal curvature (|k2| ≤ |k1|).
    pub k2: f64,
    /// Unit direction of `k1` (tangent).
    pub d1: [f64; 3],
    /// Unit direction of `k2` (tangent).
    pub d2: [f64; 3],
}

impl Curvature {
    /// `max(|k1|, |k2|)`.
    pub fn max_abs(&self) -> f64 {
        self.k1.abs().max(self.k2.abs())
    }
}

/// A unit vector orthogonal to unit `n`.
fn perpendicular(n: [f64; 3]) -> [f64; 3] {
    let a = if n[0].abs() < 0.6 {
        [1.0, 0.0, 0.0]
    } else if n[1].abs() < 0.6 {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let c = cross(n, a);
    scale(c, 1.0 / norm(c))
}

/// Fits the shape operator at `p` with normal `n` to the neighbours `qs`.
fn fit(p: [f64; 3], n: [f64; 3], qs: &[[f64; 3]]) -> Curvature {
    if qs.is_empty() || norm2(n) == 0.0 {
        return Curvature::default();
    }
    let e1 = perpendicular(n);
    let e2 = cross(n, e1);
    let mut ata = [[0.0f64; 3]; 3];
    let mut atb = [0.0f64; 3];
    let mut kmax: f64 = 0.0;
    let mut kmin: f64 = f64::INFINITY;
    let mut kmax_dir = e1;
    for &q in qs {
        let d = sub(q, p);
        let l2 = norm2(d);
        if l2 == 0.0 {
            continue;
        }
        let kappa = -2.0 * dot(n, d) / l2;
        let (x, y) = (dot(d, e1), dot(d, e2));
        let r = (x * x + y * y).sqrt();
        if r == 0.0 {
            continue;
        }
        let (c, s) = (x / r, y / r);
        let row = [c * c, 2.0 * c * s, s * s];
        for i in 0..3 {
            for j in 0..3 {
                ata[i][j] += row[i] * row[j];
            }
            atb[i] += row[i] * kappa;
        }
        if kappa.abs() > kmax.abs() {
            kmax = kappa;
            kmax_dir = add(scale(e1, c), scale(e2, s));
        }
        kmin = kmin.min(kappa.abs());
    }
    let ata = Matrix3::from_fn(|i, j| ata[i][j]);
    let tr = ata.trace();
    let well_posed = ata.determinant() > 1e-6 * tr * tr * tr;
    // The normal equations are symmetric positive definite when well posed.
    let solved = if well_posed {
        ata.cholesky().map(|ch| ch.solve(&Vector3::from(atb)))
    } else {
        None
    };
    let Some(x) = solved else {
        // Too few directions for a tensor: keep the largest normal curvature seen.
        let k2 = if kmin.is_finite() {
            kmin.copysign(kmax)
        } else {
            0.0
        };
        return Curvature {
            k1: kmax,
            k2,
            d1: kmax_dir,
            d2: cross(n, kmax_dir),
        };
    };
    // Eigen-pairs of the shape operator [[a, b], [b, c]] in the (e1, e2) frame.
    let eig = SymmetricEigen::new(Matrix2::new(x[0], x[1], x[1], x[2]));
    let (i1, i2) = if eig.eigenvalues[0].abs() >= eig.eigenvalues[1].abs() {
        (0, 1)
    } else {
        (1, 0)
    };
    let u = eig.eigenvectors.column(i1);
    let d1 = add(scale(e1, u[0]), scale(e2, u[1]));
    let l = norm(d1);
    let d1 = if l > 0.0 { scale(d1, 1.0 / l) } else { e1 };
    Curvature {
        k1: eig.eigenvalues[i1],
        k2: eig.eigenvalues[i2],
        d1,
        d2: cross(n, d1),
    }
}

/// Principal curvatures of every vertex: the largest (by `max_abs`) over its
/// patches. O(V · ring size), parallel.
pub fn principal_curvatures(
    grid: &Grid,
    features: &Features,
    normals: &PatchNormals,
) -> Vec<Curvature> {
    let per_patch = patch_curvatures(grid, features, normals);
    (0..grid.vertices().len())
        .into_par_iter()
        .map(|vi| {
            let mut best = Curvature::default();
            for e in normals.range(vi) {
                let c = per_patch[e];
                if c.max_abs() > best.max_abs() || best.d1 == [0.0; 3] {
                    best = c;
                }
            }
            best
        })
        .collect()
}

/// Principal curvatures of every (vertex, patch) entry of `normals`, fitted
/// to the vertex's neighbours within that patch (1-ring, 2-ring when the
/// 1-ring has fewer than 4). O(V · ring size), parallel.
pub fn patch_curvatures(
    grid: &Grid,
    features: &Features,
    normals: &PatchNormals,
) -> Vec<Curvature> {
    let v = grid.vertices();
    let tris = grid.triangles();
    let topo = grid.topology();
    (0..normals.patch.len())
        .into_par_iter()
        .map_init(
            || (Vec::<u32>::new(), Vec::<[f64; 3]>::new()),
            |(ring, pts), e| {
                // Vertex of entry e: the last offset not above e.
                let vi = normals.offsets.partition_point(|&o| o as usize <= e) - 1;
                let patch = normals.patch[e];
                ring.clear();
                let collect = |u: usize, ring: &mut Vec<u32>| {
                    for &f in topo.faces_of_vertex(u) {
                        if features.face_patch[f as usize] == patch {
                            for &w in &tris[f as usize] {
                                if w as usize != vi && !ring.contains(&w) {
                                    ring.push(w);
                                }
                            }
                        }
                    }
                };
                collect(vi, ring);
                if ring.len() < 4 {
                    let first: Vec<u32> = ring.clone();
                    for u in first {
                        collect(u as usize, ring);
                    }
                }
                pts.clear();
                pts.extend(ring.iter().map(|&w| v[w as usize]));
                fit(v[vi], normals.normal[e], pts)
            },
        )
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference_fit(p: [f64; 3], n: [f64; 3], qs: &[[f64; 3]]) -> Curvature {
        if qs.is_empty() || norm2(n) == 0.0 {
            return Curvature::default();
        }
        let e1 = perpendicular(n);
        let e2 = cross(n, e1);
        let mut ata = [[0.0f64; 3]; 3];
        let mut atb = [0.0f64; 3];
        let mut kmax: f64 = 0.0;
        let mut kmin: f64 = f64::INFINITY;
        let mut kmax_dir = e1;
        for &q in qs {
            let d = sub(q, p);
            let l2 = norm2(d);
            if l2 == 0.0 {
                continue;
            }
            let kappa = -2.0 * dot(n, d) / l2;
            let (x, y) = (dot(d, e1), dot(d, e2));
            let r = (x * x + y * y).sqrt();
            if r == 0.0 {
                continue;
            }
            let (c, s) = (x / r, y / r);
            let row = [c * c, 2.0 * c * s, s * s];
            for i in 0..3 {
                for j in 0..3 {
                    ata[i][j] += row[i] * row[j];
                }
                atb[i] += row[i] * kappa;
            }
            if kappa.abs() > kmax.abs() {
                kmax = kappa;
                kmax_dir = add(scale(e1, c), scale(e2, s));
            }
            kmin = kmin.min(kappa.abs());
        }
        let det = det3(&ata);
        let tr = ata[0][0] + ata[1][1] + ata[2][2];
        let well_posed = det > 1e-6 * tr * tr * tr;
        if !well_posed {
            // Too few directions for a tensor: keep the largest normal curvature seen.
            let k2 = if kmin.is_finite() {
                kmin.copysign(kmax)
            } else {
                0.0
            };
            return Curvature {
                k1: kmax,
                k2,
                d1: kmax_dir,
                d2: cross(n, kmax_dir),
            };
        }
        let [a, b, c] = solve3(&ata, &atb, det);
        // Eigen-decomposition of [[a, b], [b, c]].
        let m = 0.5 * (a + c);
        let r = (0.25 * (a - c) * (a - c) + b * b).sqrt();
        let (l1, l2) = (m + r, m - r);
        let (k1, k2) = if l1.abs() >= l2.abs() {
            (l1, l2)
        } else {
            (l2, l1)
        };
        let (ux, uy) = if (k1 - a).abs() + b.abs() > (k1 - c).abs() + b.abs() {
            (b, k1 - a)
        } else {
            (k1 - c, b)
        };
        let ul = (ux * ux + uy * uy).sqrt();
        let d1 = if ul > 0.0 {
            add(scale(e1, ux / ul), scale(e2, uy / ul))
        } else {
            e1
        };
        Curvature {
            k1,
            k2,
            d1,
            d2: cross(n, d1),
        }
    }

    fn det3(m: &[[f64; 3]; 3]) -> f64 {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    }

    /// Cramer's rule.
    fn solve3(m: &[[f64; 3]; 3], b: &[f64; 3], det: f64) -> [f64; 3] {
        let mut out = [0.0; 3];
        for k in 0..3 {
            let mut mk = *m;
            for i in 0..3 {
                mk[i][k] = b[i];
            }
            out[k] = det3(&mk) / det;
        }
        out
    }

    /// Principal curvatures of every vertex: the largest (by `max_abs`) over its
    /// patches. O(V · ring size), parallel.

    #[test]
    fn nalgebra_fit_equals_the_closed_form() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let (mut compared, mut well) = (0, 0);
        for _ in 0..2000 {
            let n = {
                let v = [0, 1, 2].map(|_| rng.gen_range(-1.0..1.0));
                scale(v, 1.0 / norm(v))
            };
            let p = [0, 1, 2].map(|_| rng.gen_range(-1.0..1.0));
            let k = rng.gen_range(3..9);
            let qs: Vec<[f64; 3]> = (0..k)
                .map(|_| add(p, [0, 1, 2].map(|_| rng.gen_range(-0.3..0.3))))
                .collect();
            let (a, b) = (fit(p, n, &qs), reference_fit(p, n, &qs));
            let m = a.max_abs().max(b.max_abs()).max(1e-300);
            // Within 1e-12 where the normal equations are well conditioned;
            // elsewhere Cramer's rule (the reference) loses digits in
            // proportion to the condition number, Cholesky does not.
            let cond = condition(p, n, &qs);
            let tol = 1e-12 * m * if cond < 1e3 { 1.0 } else { cond };
            assert!((a.k1 - b.k1).abs() <= tol, "{a:?} {b:?} cond {cond}");
            assert!((a.k2 - b.k2).abs() <= tol, "{a:?} {b:?} cond {cond}");
            well += usize::from(cond < 1e3);
            // Directions up to sign, where the two curvatures are distinct.
            if (a.k1 - a.k2).abs() > 1e-6 * m {
                assert!(dot(a.d1, b.d1).abs() >= 1.0 - 1e-9, "{a:?} {b:?}");
                compared += 1;
            }
        }
        assert!(compared > 1000 && well > 1000, "{compared} {well}");
    }

    /// `trace³ / |det|` of the fit's normal equations: 27 when perfectly
    /// conditioned, growing with the condition number, infinite when singular.
    fn condition(p: [f64; 3], n: [f64; 3], qs: &[[f64; 3]]) -> f64 {
        let e1 = perpendicular(n);
        let e2 = cross(n, e1);
        let mut ata = Matrix3::zeros();
        for &q in qs {
            let d = sub(q, p);
            let (x, y) = (dot(d, e1), dot(d, e2));
            let r = (x * x + y * y).sqrt();
            if r == 0.0 {
                continue;
            }
            let row = Vector3::new(x * x / (r * r), 2.0 * x * y / (r * r), y * y / (r * r));
            ata += row * row.transpose();
        }
        ata.trace().powi(3) / ata.determinant().abs()
    }

    #[test]
    fn fit_on_exact_sphere_and_cylinder_points() {
        // Sphere of radius 2 through p = (0,0,2), outward normal +z.
        let r: f64 = 2.0;
        let p = [0.0, 0.0, r];
        let qs: Vec<[f64; 3]> = (0..7)
            .map(|i| {
                let ph = i as f64 * 0.9;
                let th: f64 = 0.3 + 0.05 * i as f64;
                [
                    r * th.sin() * ph.cos(),
                    r * th.sin() * ph.sin(),
                    r * th.cos(),
                ]
            })
            .collect();
        let c = fit(p, [0.0, 0.0, 1.0], &qs);
        assert!(
            (c.k1 - 0.5).abs() < 1e-12 && (c.k2 - 0.5).abs() < 1e-12,
            "{c:?}"
        );
        // Cylinder of radius 1 along y through p = (0,0,1): k1 = 1 along x, k2 = 0 along y.
        let qs: Vec<[f64; 3]> = [
            (0.2, 0.0),
            (-0.2, 0.0),
            (0.0, 0.3),
            (0.0, -0.3),
            (0.15, 0.15),
            (-0.1, 0.2),
        ]
        .iter()
        .map(|&(a, y): &(f64, f64)| [a.sin(), y, a.cos()])
        .collect();
        let c = fit([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], &qs);
        assert!((c.k1 - 1.0).abs() < 0.02, "{c:?}");
        assert!(c.k2.abs() < 0.02);
        assert!(c.d1[0].abs() > 0.99);
    }
}
