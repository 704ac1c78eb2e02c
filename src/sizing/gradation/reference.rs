//! The reference solver of the tests: the exact L2 projection of the initial
//! sizes onto the gradation constraints, by an interior-point method.

use super::gram;
use crate::geometry::{add, dot, scale, sub};

/// Gradients of the three barycentric basis functions of triangle (a, b, c)
/// (in its plane): `∇h = Σ h_i g_i`. `None` for a degenerate triangle.
fn basis_gradients(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Option<[[f64; 3]; 3]> {
    let g = gram(a, b, c)?;
    let (e1, e2) = (sub(b, a), sub(c, a));
    let gb = scale(sub(scale(e1, g[2]), scale(e2, g[1])), 1.0 / g[3]);
    let gc = scale(sub(scale(e2, g[0]), scale(e1, g[1])), 1.0 / g[3]);
    Some([scale(add(gb, gc), -1.0), gb, gc])
}

/// Slow, obviously-correct reference: the L2 projection of `h0` onto
/// `{h ≤ h0, |∇h_f| ≤ s ∀f}`, i.e. `argmin ½‖h − h0‖²` under those constraints (the
/// authors' IPOPT problem), by a primal log-barrier interior-point method: Newton
/// steps (dense Cholesky) on
/// `½‖h − h0‖² − μ·[Σ_f log(s² − |∇h_f|²) + Σ_i log(h0_i − h_i)]`,
/// μ divided by 8 after each centring, from the constant `min h0 − 1`. The
/// iterates stay strictly feasible, so the result is below `h0` and within the
/// slope bound exactly; it stops once the duality-gap bound `μ·(F + n)` is below
/// `gap` (absolute, on `½‖h − h0‖²`), or after `max_newton` Newton steps.
/// Degenerate faces carry no constraint; `h0` must be finite.
/// O(n³) per step: small meshes (tests).
///
/// Dykstra's alternating projections, the obvious alternative, converge far too
/// slowly for this: on 288 faces, 10⁵ sweeps still leave slopes 4·10⁻⁴ above the
/// bound.
pub fn reference_solution(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    h0: &[f64],
    s: f64,
    gap: f64,
    max_newton: usize,
) -> Vec<f64> {
    let n = h0.len();
    // Per face: corners and Q = [g_i · g_j] (|∇h|² = hᵀ Q h on the corners).
    let faces: Vec<([usize; 3], [[f64; 3]; 3])> = triangles
        .iter()
        .filter_map(|t| {
            let t = t.map(|v| v as usize);
            let g = basis_gradients(vertices[t[0]], vertices[t[1]], vertices[t[2]])?;
            Some((
                t,
                std::array::from_fn(|i| std::array::from_fn(|j| dot(g[i], g[j]))),
            ))
        })
        .collect();
    let s2 = s * s;
    let qh = |q: &[[f64; 3]; 3], v: [f64; 3]| -> [f64; 3] { std::array::from_fn(|i| dot(q[i], v)) };
    // Barrier objective; None when not strictly feasible.
    let value = |h: &[f64], mu: f64| -> Option<f64> {
        let mut f = 0.0;
        for i in 0..n {
            let d = h0[i] - h[i];
            if d.is_nan() || d <= 0.0 {
                return None;
            }
            f += 0.5 * d * d - mu * d.ln();
        }
        for (t, q) in &faces {
            let v = t.map(|i| h[i]);
            let slack = s2 - dot(v, qh(q, v));
            if slack.is_nan() || slack <= 0.0 {
                return None;
            }
            f -= mu * slack.ln();
        }
        Some(f)
    };
    let m = (faces.len() + n) as f64;
    let mut h = vec![h0.iter().copied().fold(f64::INFINITY, f64::min) - 1.0; n];
    let mut mu = 1.0;
    let (mut hess, mut grad, mut step, mut trial) =
        (vec![0.0; n * n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for _ in 0..max_newton {
        hess.iter_mut().for_each(|x| *x = 0.0);
        for i in 0..n {
            let d = h0[i] - h[i];
            grad[i] = -d + mu / d;
            hess[i * n + i] = 1.0 + mu / (d * d);
        }
        for (t, q) in &faces {
            let v = t.map(|i| h[i]);
            let w = qh(q, v);
            let slack = s2 - dot(v, w);
            for a in 0..3 {
                grad[t[a]] += 2.0 * mu * w[a] / slack;
                for b in 0..3 {
                    hess[t[a] * n + t[b]] +=
                        mu * (2.0 * q[a][b] / slack + 4.0 * w[a] * w[b] / (slack * slack));
                }
            }
        }
        step.iter_mut().zip(&grad).for_each(|(d, g)| *d = -g);
        if !cholesky_solve(&mut hess, n, &mut step) {
            break;
        }
        let decrement: f64 = -grad.iter().zip(&step).map(|(g, d)| g * d).sum::<f64>();
        // Backtracking: strictly feasible and sufficient decrease.
        let f0 = value(&h, mu).unwrap_or(f64::INFINITY);
        let mut alpha = 1.0;
        while alpha >= 1e-20 {
            trial
                .iter_mut()
                .zip(h.iter().zip(&step))
                .for_each(|(x, (a, d))| *x = a + alpha * d);
            if value(&trial, mu).is_some_and(|f| f <= f0 - 0.25 * alpha * decrement) {
                h.copy_from_slice(&trial);
                break;
            }
            alpha *= 0.5;
        }
        if decrement <= 1e-14 * (1.0 + f0.abs()) || alpha < 1e-20 {
            if mu * m <= gap {
                break;
            }
            mu /= 8.0;
        }
    }
    h
}

/// Solves `A x = b` in place (`b` becomes x) for a symmetric positive definite
/// dense `n × n` matrix (overwritten by its Cholesky factor). False if not
/// positive definite. O(n³).
fn cholesky_solve(a: &mut [f64], n: usize, b: &mut [f64]) -> bool {
    for j in 0..n {
        let d = a[j * n + j] - (0..j).map(|k| a[j * n + k] * a[j * n + k]).sum::<f64>();
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let x = a[i * n + j] - (0..j).map(|k| a[i * n + k] * a[j * n + k]).sum::<f64>();
            a[i * n + j] = x / d;
        }
    }
    for i in 0..n {
        b[i] = (b[i] - (0..i).map(|k| a[i * n + k] * b[k]).sum::<f64>()) / a[i * n + i];
    }
    for i in (0..n).rev() {
        b[i] = (b[i] - (i + 1..n).map(|k| a[k * n + i] * b[k]).sum::<f64>()) / a[i * n + i];
    }
    true
}
