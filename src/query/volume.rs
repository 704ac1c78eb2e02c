//! Volume-mode queries: the paper's 3-D field
//! `H(x) = min_{y ∈ Γ} [h(y) + s·|x − y|]`, `s = ln β`, the size a volume mesher
//! should use at `x` so that sizes grow by at most β per element away from the
//! surface Γ.
//!
//! On one triangle, `h` is linear, so `h(y) + s|x − y|` is convex and its minimum
//! has a closed form (interior stationary point, else the best of the three edges,
//! each a 1-D convex problem with a closed form). Over the grid, branch and bound
//! on the BVH with the smallest size stored per node: a node whose
//! `min_size + s·dist(x, box)` is not below the best value cannot hold the
//! minimum. Exact; typically O(log F) for points near the surface, up to O(F) for
//! points far from a grid with strongly varying sizes.

use super::check_batch;
use crate::error::{Error, Result};
use crate::geometry::*;
use crate::mesh::Grid;
use crate::spatial::MAX_DEPTH;
use arrayvec::ArrayVec;
use rayon::prelude::*;

/// Answer of a volume query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeHit {
    /// The size `H(x)`.
    pub size: f64,
    /// Triangle where the minimum is reached.
    pub triangle: u32,
    /// The minimising surface point `y`.
    pub point: [f64; 3],
}

/// Converts a gradation ratio β (> 1) to the slope `ln β`.
pub fn slope_from_beta(beta: f64) -> Result<f64> {
    if !(beta.is_finite() && beta > 1.0) {
        return Err(Error::InvalidArgument(format!(
            "gradation ratio beta = {beta} must be finite and > 1"
        )));
    }
    Ok(beta.ln())
}

/// `min over t ∈ [0,1]` of `hp + t(hq − hp) + s·|x − (p + t(q − p))|`; returns (value, t).
#[inline]
fn edge_min(x: [f64; 3], p: [f64; 3], q: [f64; 3], hp: f64, hq: f64, s: f64) -> (f64, f64) {
    let d = sub(q, p);
    let l2 = norm2(d);
    // (1 − t)·hp + t·hq, not hp + t(hq − hp): exact at both ends, where the
    // latter gives 0 at t = 1 when hp dwarfs hq (hp = 1e197, hq = 0.45: found
    // by fuzzing), a value below every size of the edge.
    let f = |t: f64| (1.0 - t) * hp + t * hq + s * norm(sub(x, lerp(p, q, t)));
    let (f0, f1) = (f(0.0), f(1.0));
    let (mut best, mut bt) = if f1 < f0 { (f1, 1.0) } else { (f0, 0.0) };
    if l2 > 0.0 {
        let l = l2.sqrt();
        let k = (hq - hp) / l; // size slope along the edge
        if k.abs() < s {
            let tau0 = dot(sub(x, p), d) / l; // foot of x along the edge (arc length)
            let e2 = (norm2(sub(x, p)) - tau0 * tau0).max(0.0);
            let tau = tau0 - k * e2.sqrt() / (s * s - k * k).sqrt();
            let t = (tau / l).clamp(0.0, 1.0);
            let ft = f(t);
            if ft < best {
                best = ft;
                bt = t;
            }
        }
    }
    (best, bt)
}

/// Exact minimum of `h(y) + s·|x − y|` over triangle (a, b, c) with vertex sizes
/// `h`; returns (value, barycentric coordinates of the minimiser). O(1).
///
/// The value is kept at or above `min h`, its exact lower bound: rounding of
/// `h(y)` could otherwise give 0 (or less) for subnormal sizes (found by fuzzing).
pub fn triangle_min(x: [f64; 3], c: [[f64; 3]; 3], h: [f64; 3], s: f64) -> (f64, [f64; 3]) {
    let (val, b) = triangle_min_unclamped(x, c, h, s);
    (val.max(h[0].min(h[1]).min(h[2])), b)
}

fn triangle_min_unclamped(x: [f64; 3], c: [[f64; 3]; 3], h: [f64; 3], s: f64) -> (f64, [f64; 3]) {
    let e1 = sub(c[1], c[0]);
    let e2 = sub(c[2], c[0]);
    let (g11, g12, g22) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
    let det = g11 * g22 - g12 * g12;
    if det > 1e-14 * g11 * g22 && det.is_finite() {
        // In-plane size gradient g with g·e1 = hb − ha, g·e2 = hc − ha.
        let (r1, r2) = (h[1] - h[0], h[2] - h[0]);
        let al = (g22 * r1 - g12 * r2) / det;
        let be = (g11 * r2 - g12 * r1) / det;
        let g = add(scale(e1, al), scale(e2, be));
        let gn2 = norm2(g);
        if gn2 < s * s {
            let n = cross(e1, e2);
            let nn = norm(n);
            let w = sub(x, c[0]);
            let dist = dot(w, n) / nn;
            let xp = sub(x, scale(n, dist / nn)); // projection on the plane
            let y = sub(xp, scale(g, dist.abs() / (s * s - gn2).sqrt()));
            // Barycentric coordinates of y.
            let wy = sub(y, c[0]);
            let (d1, d2) = (dot(wy, e1), dot(wy, e2));
            let v = (g22 * d1 - g12 * d2) / det;
            let wv = (g11 * d2 - g12 * d1) / det;
            let u = 1.0 - v - wv;
            if u >= 0.0 && v >= 0.0 && wv >= 0.0 {
                let val = h[0] + dot(g, wy) + s * norm(sub(x, y));
                return (val, [u, v, wv]);
            }
        }
    }
    // Minimum on the boundary.
    let mut best = (f64::INFINITY, [1.0, 0.0, 0.0]);
    for (i, j) in [(0usize, 1usize), (1, 2), (2, 0)] {
        let (v, t) = edge_min(x, c[i], c[j], h[i], h[j], s);
        if v < best.0 {
            let mut b = [0.0; 3];
            b[i] = 1.0 - t;
            b[j] = t;
            best = (v, b);
        }
    }
    best
}

impl Grid {
    /// `H(x)` for gradation ratio `beta` (> 1): see the module documentation.
    pub fn query_volume(&self, x: [f64; 3], beta: f64) -> Result<VolumeHit> {
        let s = slope_from_beta(beta)?;
        if !crate::geometry::is_coordinate3(x) {
            return Err(super::non_finite_point(x));
        }
        self.require_sizes()?;
        Ok(self.volume_with_slope(x, s))
    }

    /// Batch of volume queries in parallel; `out[i]` answers `points[i]`,
    /// the same value as [`Grid::query_volume`]. A scattered batch is
    /// answered in Morton order (see [`Grid::query_sizes`]).
    pub fn query_sizes_volume(
        &self,
        points: &[[f64; 3]],
        beta: f64,
        out: &mut [f64],
    ) -> Result<()> {
        let s = slope_from_beta(beta)?;
        self.require_sizes()?;
        check_batch(points, out.len())?;
        let Some(order) = super::order::batch_order(points) else {
            out.par_iter_mut()
                .zip(points.par_iter())
                .with_min_len(64)
                .for_each(|(o, p)| *o = self.volume_with_slope(*p, s).size);
            return Ok(());
        };
        // In Morton order (see `query_sizes`): the same answers, warmer caches.
        let sorted: Vec<f64> = order
            .par_iter()
            .with_min_len(64)
            .map(|&i| self.volume_with_slope(points[i as usize], s).size)
            .collect();
        for (&i, v) in order.iter().zip(sorted) {
            out[i as usize] = v;
        }
        Ok(())
    }

    fn volume_with_slope(&self, x: [f64; 3], s: f64) -> VolumeHit {
        let bvh = self.bvh();
        let nmin = self.node_min_size();
        let sizes = self.sizes().expect("checked by caller");
        let tris = self.triangles();
        let bound = |i: usize| nmin[i] + s * bvh.nodes[i].bbox.distance2(&x).sqrt();
        // Seed the bound with the triangle of the closest point: for graded fields
        // the minimum is usually there or nearby.
        let mut best = VolumeHit {
            size: f64::INFINITY,
            triangle: u32::MAX,
            point: x,
        };
        if let Some(hit) = bvh.closest(x, None) {
            let slot = bvh.triangle_prim[hit.triangle as usize] as usize;
            let c = bvh.prim_corners[slot];
            let h = tris[hit.triangle as usize].map(|v| sizes[v as usize]);
            let (val, b) = triangle_min(x, c, h, s);
            best = VolumeHit {
                size: val,
                triangle: hit.triangle,
                point: add(add(scale(c[0], b[0]), scale(c[1], b[1])), scale(c[2], b[2])),
            };
        }
        // Uninitialised storage (zeroing a fixed array costs more than the walk);
        // at most one entry per level, so within capacity.
        let mut stack: ArrayVec<(u32, f64), MAX_DEPTH> = ArrayVec::new();
        let mut node = 0usize;
        loop {
            let n = &bvh.nodes[node];
            if n.is_leaf() {
                let st = n.start as usize;
                for slot in st..st + n.count as usize {
                    let tri = bvh.prim_triangle[slot];
                    let t = tris[tri as usize];
                    let h = t.map(|v| sizes[v as usize]);
                    let c = bvh.prim_corners[slot];
                    let (val, b) = triangle_min(x, c, h, s);
                    if val < best.size || (val == best.size && tri < best.triangle) {
                        let y = add(add(scale(c[0], b[0]), scale(c[1], b[1])), scale(c[2], b[2]));
                        best = VolumeHit {
                            size: val,
                            triangle: tri,
                            point: y,
                        };
                    }
                }
            } else {
                let (l, r) = (node + 1, n.start as usize);
                let (bl, br) = (bound(l), bound(r));
                let (near, bn, far, bf) = if bl <= br {
                    (l, bl, r, br)
                } else {
                    (r, br, l, bl)
                };
                if bn <= best.size {
                    if bf <= best.size {
                        stack.push((far as u32, bf));
                    }
                    node = near;
                    continue;
                }
            }
            let mut next = None;
            while let Some((nd, b)) = stack.pop() {
                if b <= best.size {
                    next = Some(nd as usize);
                    break;
                }
            }
            match next {
                Some(nd) => node = nd,
                None => break,
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Dense sampling of the objective over the triangle.
    fn sampled(x: [f64; 3], c: [[f64; 3]; 3], h: [f64; 3], s: f64, n: usize) -> f64 {
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let (v, w) = (i as f64 / n as f64, j as f64 / n as f64);
                let u = 1.0 - v - w;
                let y = add(add(scale(c[0], u), scale(c[1], v)), scale(c[2], w));
                best = best.min(u * h[0] + v * h[1] + w * h[2] + s * norm(sub(x, y)));
            }
        }
        best
    }

    /// Sizes of very different magnitude on one edge: the value at an end is
    /// that end's size, never lost to cancellation (the minimum here is at the
    /// vertex of size 0.45, at distance 1 from x).
    #[test]
    fn triangle_min_keeps_small_sizes_beside_huge_ones() {
        let c = [[2.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
        let x = [1.0, 0.0, 2.0];
        for big in [1e20, 1e197, 1e300] {
            let (v, b) = triangle_min(x, c, [big, 0.45, 0.5], 0.4);
            assert_eq!(v, 0.45 + 0.4, "{big}: {v} at {b:?}");
            let (v, _) = triangle_min(x, [c[1], c[0], c[2]], [0.45, big, 0.5], 0.4);
            assert_eq!(v, 0.45 + 0.4, "{big}: {v}");
        }
    }

    #[test]
    fn triangle_min_matches_sampling() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for _ in 0..400 {
            let mut r = || {
                [
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                ]
            };
            let c = [r(), r(), r()];
            let x = r();
            let h = [
                rng.gen_range(0.01..1.0),
                rng.gen_range(0.01..1.0),
                rng.gen_range(0.01..1.0),
            ];
            let s = rng.gen_range(0.05..2.0);
            let (v, b) = triangle_min(x, c, h, s);
            let sm = sampled(x, c, h, s, 300);
            assert!(v <= sm + 1e-12, "exact {v} above sampled {sm}");
            // Sampling spacing bounds the gap: |∇f| ≤ max|∇h| + s over the triangle.
            assert!(v >= sm - 0.05, "exact {v} far below sampled {sm}");
            let y = add(add(scale(c[0], b[0]), scale(c[1], b[1])), scale(c[2], b[2]));
            let fy = b[0] * h[0] + b[1] * h[1] + b[2] * h[2] + s * norm(sub(x, y));
            assert!((fy - v).abs() < 1e-12, "value matches its minimiser");
        }
    }
}
