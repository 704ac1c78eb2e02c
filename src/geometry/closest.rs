//! Exact closest point from a point to a triangle (Voronoi-region method of
//! Ericson, *Real-Time Collision Detection* §5.1.5), in f64, with barycentric
//! coordinates, robust to degenerate (needle or zero-area) triangles.

use super::vec3::*;

/// The point of a triangle closest to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoint {
    /// The closest point.
    pub point: [f64; 3],
    /// Its barycentric coordinates on (a, b, c): non-negative, summing to 1.
    pub bary: [f64; 3],
    /// Squared distance from the query point.
    pub dist2: f64,
}

/// Closest point to `p` on segment `[a, b]`, as the parameter `t ∈ [0, 1]`.
#[inline]
pub fn closest_point_on_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab = sub(b, a);
    let l2 = norm2(ab);
    if l2 <= 0.0 {
        return 0.0;
    }
    (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
}

/// Squared distance from `p` to the axis-aligned bounding box of triangle
/// `c`: a lower bound of the triangle's own distance, for skipping a
/// triangle before [`closest_point_triangle`] (callers pad the bound for
/// rounding). O(1).
#[inline(always)]
pub fn triangle_box_distance2(c: &[[f64; 3]; 3], p: &[f64; 3]) -> f64 {
    let mut d2 = 0.0;
    for k in 0..3 {
        let lo = c[0][k].min(c[1][k]).min(c[2][k]);
        let hi = c[0][k].max(c[1][k]).max(c[2][k]);
        let v = (lo - p[k]).max(0.0).max(p[k] - hi);
        d2 += v * v;
    }
    d2
}

/// Exact closest point to `p` on triangle (a, b, c). O(1).
///
/// Barycentric coordinates are clamped to the triangle; for a degenerate triangle
/// the answer is the closest point on its three edges.
#[inline]
pub fn closest_point_triangle(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> ClosestPoint {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return at(p, a, [1.0, 0.0, 0.0]);
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return at(p, b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let den = d1 - d3;
        if den > 0.0 {
            let v = d1 / den;
            return at(p, add(a, scale(ab, v)), [1.0 - v, v, 0.0]);
        }
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return at(p, c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let den = d2 - d6;
        if den > 0.0 {
            let w = d2 / den;
            return at(p, add(a, scale(ac, w)), [1.0 - w, 0.0, w]);
        }
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let den = (d4 - d3) + (d5 - d6);
        if den > 0.0 {
            let w = (d4 - d3) / den;
            return at(p, add(b, scale(sub(c, b), w)), [0.0, 1.0 - w, w]);
        }
    }
    let sum = va + vb + vc;
    if sum > 0.0 && sum.is_finite() {
        let v = (vb / sum).clamp(0.0, 1.0);
        let w = (vc / sum).clamp(0.0, 1.0 - v);
        let u = 1.0 - v - w;
        let q = add(a, add(scale(ab, v), scale(ac, w)));
        return at(p, q, [u, v, w]);
    }
    degenerate(p, a, b, c)
}

#[inline(always)]
fn at(p: [f64; 3], q: [f64; 3], bary: [f64; 3]) -> ClosestPoint {
    ClosestPoint {
        point: q,
        bary,
        dist2: dist2(p, q),
    }
}

/// Closest point on the three edges; used when the triangle has no interior.
#[cold]
fn degenerate(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> ClosestPoint {
    let mut best: Option<ClosestPoint> = None;
    for (i, j, u, v) in [(0usize, 1usize, a, b), (1, 2, b, c), (2, 0, c, a)] {
        let t = closest_point_on_segment(p, u, v);
        let q = lerp(u, v, t);
        let mut bary = [0.0; 3];
        bary[i] = 1.0 - t;
        bary[j] += t;
        let cand = at(p, q, bary);
        if best.is_none_or(|b| cand.dist2 < b.dist2) {
            best = Some(cand);
        }
    }
    best.expect("three edges were tried")
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Brute force: dense barycentric sampling plus the edges.
    fn brute(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
        let mut best = f64::INFINITY;
        let n = 200;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let u = i as f64 / n as f64;
                let v = j as f64 / n as f64;
                let q = add(a, add(scale(sub(b, a), u), scale(sub(c, a), v)));
                best = best.min(dist2(p, q));
            }
        }
        for (u, v) in [(a, b), (b, c), (c, a)] {
            let t = closest_point_on_segment(p, u, v);
            best = best.min(dist2(p, lerp(u, v, t)));
        }
        best
    }

    #[test]
    fn matches_brute_force_and_reconstructs_point() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..300 {
            let mut r = || {
                [
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                ]
            };
            let (a, b, c, p) = (r(), r(), r(), r());
            let cp = closest_point_triangle(p, a, b, c);
            let bf = brute(p, a, b, c);
            assert!(cp.dist2 <= bf + 1e-12, "{} > {}", cp.dist2, bf);
            assert!(cp.dist2 >= bf - 1e-3, "sampling bound");
            let q = add(
                add(scale(a, cp.bary[0]), scale(b, cp.bary[1])),
                scale(c, cp.bary[2]),
            );
            assert!(dist2(q, cp.point) < 1e-24);
            assert!(cp.bary.iter().all(|&x| (0.0..=1.0).contains(&x)));
            assert!((cp.bary.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn degenerate_triangles() {
        let a = [0.0, 0.0, 0.0];
        let b = [1.0, 0.0, 0.0];
        let c = [2.0, 0.0, 0.0];
        let cp = closest_point_triangle([1.5, 1.0, 0.0], a, b, c);
        assert!((cp.dist2 - 1.0).abs() < 1e-15);
        let cp = closest_point_triangle([3.0, 0.0, 0.0], a, a, a);
        assert_eq!(cp.dist2, 9.0);
        assert!((cp.bary.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn interior_projection() {
        let cp = closest_point_triangle(
            [0.25, 0.25, 2.0],
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
        );
        assert_eq!(cp.point, [0.25, 0.25, 0.0]);
        assert_eq!(cp.dist2, 4.0);
        assert!((cp.bary[1] - 0.25).abs() < 1e-15 && (cp.bary[2] - 0.25).abs() < 1e-15);
    }
}
