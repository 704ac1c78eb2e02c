//! First-hit ray casting through the BVH (Möller–Trumbore in f64).

use super::bvh::{Bvh, MAX_DEPTH};
use crate::geometry::{cross, dot, sub, Aabb};
use arrayvec::ArrayVec;

/// Entry parameter of the ray into `b` within `[t0, t1]`, or `None` if it misses.
#[inline(always)]
fn slab(b: &Aabb, o: [f64; 3], inv: [f64; 3], t0: f64, t1: f64) -> Option<f64> {
    let (mut lo, mut hi) = (t0, t1);
    for k in 0..3 {
        if inv[k].is_infinite() {
            // Ray parallel to this slab: inside it or never.
            if o[k] < b.min[k] || o[k] > b.max[k] {
                return None;
            }
            continue;
        }
        let a = (b.min[k] - o[k]) * inv[k];
        let c = (b.max[k] - o[k]) * inv[k];
        let (near, far) = if a <= c { (a, c) } else { (c, a) };
        if near > lo {
            lo = near;
        }
        if far < hi {
            hi = far;
        }
    }
    (lo <= hi).then_some(lo)
}

/// Ray parameter `t` where `o + t·d` crosses triangle (a, b, c), if it does
/// (edges included, with a relative tolerance of 1e-12 so that rays through an
/// edge or a vertex are not lost between two triangles).
#[inline]
pub fn ray_triangle(
    o: [f64; 3],
    d: [f64; 3],
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
) -> Option<f64> {
    let e1 = sub(b, a);
    let e2 = sub(c, a);
    let p = cross(d, e2);
    let det = dot(e1, p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = sub(o, a);
    let u = dot(s, p) * inv;
    const EPS: f64 = 1e-12;
    if !(-EPS..=1.0 + EPS).contains(&u) {
        return None;
    }
    let q = cross(s, e1);
    let v = dot(d, q) * inv;
    if v < -EPS || u + v > 1.0 + EPS {
        return None;
    }
    Some(dot(e2, q) * inv)
}

impl Bvh {
    /// The nearest triangle crossed by the ray `o + t·d` with `tmin < t ≤ tmax`
    /// for which `accept(triangle, t)` is true; returns (triangle, t). Rejected
    /// hits are skipped and the search goes on behind them. Expected O(log F).
    pub fn first_hit(
        &self,
        o: [f64; 3],
        d: [f64; 3],
        tmin: f64,
        tmax: f64,
        mut accept: impl FnMut(u32, f64) -> bool,
    ) -> Option<(u32, f64)> {
        if self.nodes.is_empty() {
            return None;
        }
        let inv = [1.0 / d[0], 1.0 / d[1], 1.0 / d[2]];
        let mut best: Option<(u32, f64)> = None;
        let mut best_t = tmax;
        // Uninitialised storage; one net entry per level, so within capacity.
        let mut stack: ArrayVec<(u32, f64), { MAX_DEPTH + 1 }> = ArrayVec::new();
        let t_root = slab(&self.nodes[0].bbox, o, inv, tmin, best_t)?;
        stack.push((0, t_root));
        while let Some((ni, t_enter)) = stack.pop() {
            if t_enter > best_t {
                continue;
            }
            let n = &self.nodes[ni as usize];
            if n.is_leaf() {
                let s = n.start as usize;
                for slot in s..s + n.count as usize {
                    let c = &self.prim_corners[slot];
                    if let Some(t) = ray_triangle(o, d, c[0], c[1], c[2]) {
                        let tri = self.prim_triangle[slot];
                        let closer = t < best_t || (t == best_t && best.is_some_and(|b| tri < b.0));
                        if t > tmin && closer && accept(tri, t) {
                            best_t = t;
                            best = Some((tri, t));
                        }
                    }
                }
            } else {
                let (l, r) = (ni as usize + 1, n.start as usize);
                let tl = slab(&self.nodes[l].bbox, o, inv, tmin, best_t);
                let tr = slab(&self.nodes[r].bbox, o, inv, tmin, best_t);
                // Push the farther child first so the nearer one is popped next.
                match (tl, tr) {
                    (Some(a), Some(b)) => {
                        let ((f, tf), (nn, tn)) = if a <= b {
                            ((r, b), (l, a))
                        } else {
                            ((l, a), (r, b))
                        };
                        stack.push((f as u32, tf));
                        stack.push((nn as u32, tn));
                    }
                    (Some(a), None) => stack.push((l as u32, a)),
                    (None, Some(b)) => stack.push((r as u32, b)),
                    (None, None) => {}
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_nearest_accepted_triangle() {
        // Three parallel unit squares (two triangles each) at z = 0, 1, 2.
        let mut v = Vec::new();
        let mut t = Vec::new();
        for k in 0..3 {
            let z = k as f64;
            let o = v.len() as u32;
            v.extend([[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]]);
            t.extend([[o, o + 1, o + 2], [o, o + 2, o + 3]]);
        }
        let bvh = Bvh::build(&v, &t);
        let o = [0.3, 0.6, -1.0];
        let d = [0.0, 0.0, 1.0];
        let (tri, tt) = bvh.first_hit(o, d, 0.0, 10.0, |_, _| true).unwrap();
        assert_eq!(tt, 1.0);
        assert!(tri < 2);
        let (tri, tt) = bvh.first_hit(o, d, 0.0, 10.0, |tri, _| tri >= 2).unwrap();
        assert_eq!((tri / 2, tt), (1, 2.0));
        assert!(bvh.first_hit(o, d, 0.0, 1.5, |tri, _| tri >= 2).is_none());
        // Through the shared diagonal: still a hit.
        assert!(bvh
            .first_hit([0.5, 0.5, -1.0], d, 0.0, 10.0, |_, _| true)
            .is_some());
        // Axis-parallel ray starting on a box face plane still hits.
        assert!(bvh
            .first_hit([0.0, 0.0, -1.0], d, 0.0, 10.0, |_, _| true)
            .is_some());
        // Parallel ray misses.
        assert!(bvh
            .first_hit([0.5, 0.5, 0.5], [1.0, 0.0, 0.0], 0.0, 10.0, |_, _| true)
            .is_none());
    }
}
