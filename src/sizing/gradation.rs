//! Gradation (DESIGN §3.3): a size field `h ≤ H0` whose gradient is bounded by
//! `s = ln β` on every triangle, as large (close to `H0`) as we can make it.
//!
//! The target is `h(x) = min_y H0(y) + s·d_Γ(y, x)`, but the piecewise-linear
//! interpolant of that field is steeper than `s` on many faces: around every
//! local minimum of `H0` (a cone tip cannot be represented; a right angle at the
//! tip gives 41 % too much) and, by a little, wherever the fast marching's
//! discretisation error varies. Lowering the offending vertices one face at a
//! time is not stable: the deficit it leaves differs between neighbouring
//! characteristics, that difference is itself a slope, and along a ray the
//! deficit grows without bound (measured: 11 % too low 50 cells away from a
//! point source on a plate of right triangles). [`grade`] therefore works in
//! five O(n log n) steps:
//! 1. **Fast marching** (Dijkstra order, edge and triangle updates) with the
//!    slope `(1 − SLACK)·s`. The small slack absorbs the marching's own noise.
//! 2. **Slow down where too steep.** Every face steeper than `s·(1 + 1e-3)` asks
//!    for a local speed factor `1/ratio`; the request is spread to the
//!    neighbourhood (minus `SPREAD` per edge hop) so that neighbouring
//!    characteristics are slowed alike.
//! 3. **Fast marching again** with those speed factors (per face for triangle
//!    updates, the smaller of its faces' for an edge). The deficits this leaves
//!    are smooth across characteristics, so they stay bounded.
//! 4. **Verify and fix**: the faces still above `s·(1 + 1e-9)` are projected,
//!    steepest first and lowering only, onto their constraint (in the L2 sense:
//!    the smallest corner stays, the other two move down as little as possible);
//!    the faces around a lowered vertex are checked again, until none is steeper.
//! 5. **Raise**: two sweeps in increasing order of value lift every vertex to the
//!    largest value (≤ `H0`) its faces allow, which gives back what steps 1–2
//!    took where it was not needed.
//!
//! Values are only ever taken as a minimum with `H0`, so `h ≤ H0` holds exactly.
//!
//! [`reference_solution`] computes the exact L2 projection (the authors' IPOPT
//! problem) on small meshes, for the tests.

use crate::geometry::{cross, dist2, dot, lerp, norm, norm2, sub};
use crate::mesh::Topology;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

pub mod parts;
mod reference;
#[cfg(test)]
mod tests;

pub use reference::reference_solution;

/// Relative tolerance of the slope check: a face is accepted when its slope is at
/// most `s·(1 + SLOPE_TOLERANCE)`.
pub const SLOPE_TOLERANCE: f64 = 1e-9;

/// Fixes and raises aim at `s·(1 − FIX_MARGIN)` so that rounding cannot leave a
/// face outside the tolerance.
const FIX_MARGIN: f64 = 1e-11;

/// A triangle is degenerate (no slope constraint) when `(2·area)² ≤ DEGENERATE · L⁴`,
/// L its longest edge, i.e. when its height is below `1e-7·L`.
const DEGENERATE: f64 = 1e-14;

/// Relative slope given up by the fast marchings (step 1).
const SLACK: f64 = 0.02;

/// Faces steeper than `s·(1 + SPEED_TOLERANCE)` after step 1 are slowed down.
const SPEED_TOLERANCE: f64 = 1e-3;

/// Decrease of a speed reduction per edge hop when it is spread (step 2).
const SPREAD: f64 = 0.35;

/// Raising sweeps (step 5).
const RAISE_SWEEPS: usize = 2;

/// What [`grade`] did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GradationReport {
    /// Faces steeper than `s·(1 + 1e-9)` after the first fast marching (all
    /// fixed in the result).
    pub faces_fixed: usize,
    /// Vertices that end below the value of the first fast marching.
    pub vertices_lowered: usize,
    /// Largest `slope / s` over the faces after the first fast marching.
    pub max_slope_ratio_before_fix: f64,
    /// Largest `slope / s` over the faces of the result (≤ 1 + 1e-9); faces with a
    /// non-finite value are left out.
    pub max_slope_ratio: f64,
}

/// Gram data of triangle (a, b, c) seen from corner a, with `e1 = b − a`,
/// `e2 = c − a`: `[e1·e1, e1·e2, e2·e2, |e1 × e2|²]`; `None` when degenerate.
#[inline]
fn gram(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Option<[f64; 4]> {
    let (e1, e2) = (sub(b, a), sub(c, a));
    let (g11, g12, g22) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
    let det = norm2(cross(e1, e2));
    let l2 = g11.max(g22).max(dist2(b, c));
    (det > DEGENERATE * l2 * l2 && det.is_finite()).then_some([g11, g12, g22, det])
}

/// `|∇h|` of the linear interpolant of (ha, hb, hc) on triangle (a, b, c), the
/// gradient taken within the triangle's plane; 0 for a degenerate triangle (height
/// below 1e-7 of the longest edge), NaN when a value is NaN. O(1).
pub fn face_slope(a: [f64; 3], b: [f64; 3], c: [f64; 3], ha: f64, hb: f64, hc: f64) -> f64 {
    let Some(g) = gram(a, b, c) else {
        return 0.0;
    };
    // |∇h|² = rᵀ G⁻¹ r with r = (hb − ha, hc − ha).
    let (r1, r2) = (hb - ha, hc - ha);
    let q = (g[2] * r1 * r1 - 2.0 * g[1] * r1 * r2 + g[0] * r2 * r2) / g[3];
    if q < 0.0 {
        0.0
    } else {
        q.sqrt()
    }
}

/// Largest face slope of field `h` and the number of faces with slope above
/// `s·(1 + 1e-9)`. Faces with a NaN value are ignored. O(F).
pub fn max_face_slope(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    h: &[f64],
    s: f64,
) -> (f64, usize) {
    let bound = s * (1.0 + SLOPE_TOLERANCE);
    let mut max = 0.0f64;
    let mut count = 0;
    for t in triangles {
        let [a, b, c] = t.map(|v| v as usize);
        let sl = face_slope(vertices[a], vertices[b], vertices[c], h[a], h[b], h[c]);
        max = max.max(sl);
        count += usize::from(sl > bound);
    }
    (max, count)
}

/// Graded field: `h ≤ h0` with `|∇h| ≤ s` on every triangle, as close to `h0` as
/// the steps in the module documentation make it; returns it and a
/// [`GradationReport`].
///
/// `s = ln β` is the slope. `h0` holds the initial sizes (finite and > 0 is the
/// caller's job to check; non-finite values are kept as they are and neither
/// propagate nor constrain). Vertices on no triangle keep `h0`; an `h0` that
/// already satisfies the bound is returned unchanged. Degenerate triangles carry
/// no constraint. Bit-identical run to run.
///
/// O(n log n) (two fast marchings with a binary heap, then local work).
///
/// # Panics
/// When `h0` or `topo` does not match the grid, or `s` is not finite and > 0.
pub fn grade(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    topo: &Topology,
    h0: &[f64],
    s: f64,
) -> (Vec<f64>, GradationReport) {
    grade_with(vertices, triangles, topo, h0, s, true)
}

/// [`grade`], returning `h0` unchanged when no face is too steep only if
/// `early_exit` (a part of a larger mesh runs every step, as it would in the
/// whole mesh when another part has a steep face; see [`parts`]).
fn grade_with(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    topo: &Topology,
    h0: &[f64],
    s: f64,
    early_exit: bool,
) -> (Vec<f64>, GradationReport) {
    assert_eq!(h0.len(), vertices.len(), "one initial size per vertex");
    let grid_ok = topo.face_edges.len() == triangles.len()
        && topo.vertex_face_offsets.len() == vertices.len() + 1;
    assert!(grid_ok, "topology of another grid");
    assert!(s.is_finite() && s > 0.0, "slope {s} must be finite and > 0");
    let m = Surface {
        v: vertices,
        t: triangles,
        topo,
    };
    let (max0, bad0) = max_face_slope(vertices, triangles, h0, s);
    if bad0 == 0 && early_exit {
        return graded_already(h0, max0 / s);
    }
    let mut h = h0.to_vec();
    m.march(&mut h, s * (1.0 - SLACK), Update::Eikonal, None);
    let marched = h.clone();
    let (before, violating) = max_face_slope(vertices, triangles, &marched, s);
    let (face_speed, edge_speed) = m.speed_factors(&marched, s);
    if face_speed.iter().any(|&x| x < 1.0) {
        h.copy_from_slice(h0);
        let speed = Some((&face_speed[..], &edge_speed[..]));
        m.march(&mut h, s * (1.0 - SLACK), Update::Eikonal, speed);
    }
    m.fix_faces(&mut h, s);
    m.raise(&mut h, h0, s);
    let after = (0..triangles.len())
        .map(|f| m.slope(&h, f))
        .fold(0.0, f64::max);
    let report = GradationReport {
        faces_fixed: violating,
        vertices_lowered: h.iter().zip(&marched).filter(|(a, b)| a < b).count(),
        max_slope_ratio_before_fix: before / s,
        max_slope_ratio: after / s,
    };
    (h, report)
}

/// The result of [`grade`] when no face is too steep: `h0` itself, with
/// `ratio` its largest slope over `s`.
fn graded_already(h0: &[f64], ratio: f64) -> (Vec<f64>, GradationReport) {
    let report = GradationReport {
        max_slope_ratio_before_fix: ratio,
        max_slope_ratio: ratio,
        ..Default::default()
    };
    (h0.to_vec(), report)
}

/// Heap entry: largest key first, then lowest index (a min-heap on values pushes
/// their negation, which is exact).
#[derive(Clone, Copy, PartialEq)]
struct Entry {
    key: f64,
    i: u32,
}

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        self.key
            .total_cmp(&other.key)
            .then_with(|| other.i.cmp(&self.i))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Interior minimum over `t ∈ (0, 1)` of `hp + t(hq − hp) + s·|x − (p + t(q − p))|`
/// (a convex 1-D problem: stationary point of `k·τ + s·sqrt((τ − τ0)² + e²)` in arc
/// length τ), or +∞ when the minimum is at an end (those are the edge updates).
#[inline]
fn segment_min(x: [f64; 3], p: [f64; 3], q: [f64; 3], hp: f64, hq: f64, s: f64) -> f64 {
    let d = sub(q, p);
    let l2 = norm2(d);
    if !(l2.is_finite() && l2 > 0.0) {
        return f64::INFINITY;
    }
    let l = l2.sqrt();
    let k = (hq - hp) / l;
    if k.is_nan() || k.abs() >= s {
        return f64::INFINITY;
    }
    let xp = sub(x, p);
    let tau0 = dot(xp, d) / l;
    let e2 = (norm2(xp) - tau0 * tau0).max(0.0);
    let tau = tau0 - k * e2.sqrt() / (s * s - k * k).sqrt();
    if tau > 0.0 && tau < l {
        let t = tau / l;
        hp + t * (hq - hp) + s * norm(sub(x, lerp(p, q, t)))
    } else {
        f64::INFINITY
    }
}

/// The local update of [`Surface::march`].
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Update {
    /// Along edges only (kept to show, in the tests, why it is not enough).
    #[cfg_attr(not(test), allow(dead_code))]
    Edge,
    /// Edges, and the eikonal update from the segment between two finalised corners.
    Eikonal,
}

/// A triangle surface and its adjacency, borrowed.
#[derive(Clone, Copy)]
struct Surface<'a> {
    v: &'a [[f64; 3]],
    t: &'a [[u32; 3]],
    topo: &'a Topology,
}

impl Surface<'_> {
    /// Slope of face `f` under `h`; 0 when one of its values is not finite
    /// (such faces are left as they are).
    #[inline]
    fn slope(&self, h: &[f64], f: usize) -> f64 {
        let [a, b, c] = self.t[f].map(|x| x as usize);
        if h[a].is_finite() && h[b].is_finite() && h[c].is_finite() {
            face_slope(self.v[a], self.v[b], self.v[c], h[a], h[b], h[c])
        } else {
            0.0
        }
    }

    /// Corner index of `v` in face `f` and the two other corners, in order.
    #[inline]
    fn others(&self, f: u32, v: usize) -> (usize, usize, usize) {
        let t = self.t[f as usize];
        let k = t.iter().position(|&c| c as usize == v).unwrap_or(0);
        (k, t[(k + 1) % 3] as usize, t[(k + 2) % 3] as usize)
    }

    /// Dijkstra-ordered fast marching of `min_y h(y) + s·d(y, x)`, lowering `h` in
    /// place: when a vertex is finalised, the other corners of its faces are
    /// updated. `speed` optionally scales the slope per face (triangle updates)
    /// and per edge (edge updates). Vertices on no triangle and non-finite values
    /// are left alone. O(n log n).
    fn march(&self, h: &mut [f64], s: f64, update: Update, speed: Option<(&[f64], &[f64])>) {
        let mut done = vec![false; self.v.len()];
        let mut heap: BinaryHeap<Entry> = (0..self.v.len())
            .filter(|&v| !self.topo.faces_of_vertex(v).is_empty())
            .map(|v| Entry {
                key: -h[v],
                i: v as u32,
            })
            .collect::<Vec<_>>()
            .into();
        while let Some(Entry { key, i }) = heap.pop() {
            let (v, hv) = (i as usize, -key);
            if done[v] || hv.to_bits() != h[v].to_bits() {
                continue; // finalised already, or a stale entry
            }
            done[v] = true;
            if !hv.is_finite() {
                continue;
            }
            for &f in self.topo.faces_of_vertex(v) {
                let (k, u, w) = self.others(f, v);
                // Edge k joins corners k and k + 1, edge k + 2 corners k + 2 and k.
                let (sf, su, sw) = match speed {
                    Some((fs, es)) => {
                        let fe = self.topo.face_edges[f as usize];
                        let e = |j: usize| s * es[fe[j] as usize];
                        (s * fs[f as usize], e(k), e((k + 2) % 3))
                    }
                    None => (s, s, s),
                };
                for (x, y, se) in [(u, w, su), (w, u, sw)] {
                    if done[x] {
                        continue;
                    }
                    let (px, pv) = (self.v[x], self.v[v]);
                    let mut cand = hv + se * norm(sub(px, pv));
                    if update == Update::Eikonal && done[y] && h[y].is_finite() {
                        cand = cand.min(segment_min(px, pv, self.v[y], hv, h[y], sf));
                    }
                    if cand < h[x] {
                        h[x] = cand;
                        heap.push(Entry {
                            key: -cand,
                            i: x as u32,
                        });
                    }
                }
            }
        }
    }

    /// Speed factors of step 2 from the marched field `h`: per face, 1 minus the
    /// largest spread reduction at its corners; per edge, the smaller of its
    /// faces'. O(n log n).
    fn speed_factors(&self, h: &[f64], s: f64) -> (Vec<f64>, Vec<f64>) {
        let mut need = vec![0.0f64; self.v.len()];
        for (f, t) in self.t.iter().enumerate() {
            let ratio = self.slope(h, f) / s;
            if ratio > 1.0 + SPEED_TOLERANCE {
                let r = 1.0 - (1.0 - SPEED_TOLERANCE) / ratio;
                for &v in t {
                    need[v as usize] = need[v as usize].max(r);
                }
            }
        }
        // Spread: need_x = max_y need_y − SPREAD·hops(y, x), largest first.
        let mut heap: BinaryHeap<Entry> = (0..need.len())
            .filter(|&v| need[v] > 0.0)
            .map(|v| Entry {
                key: need[v],
                i: v as u32,
            })
            .collect();
        while let Some(Entry { key, i }) = heap.pop() {
            let next = key - SPREAD;
            if key.to_bits() != need[i as usize].to_bits() || next <= 0.0 {
                continue;
            }
            for &f in self.topo.faces_of_vertex(i as usize) {
                for &w in &self.t[f as usize] {
                    if need[w as usize] < next {
                        need[w as usize] = next;
                        heap.push(Entry { key: next, i: w });
                    }
                }
            }
        }
        let face: Vec<f64> = (self.t.iter())
            .map(|t| 1.0 - t.iter().map(|&v| need[v as usize]).fold(0.0, f64::max))
            .collect();
        let edge = (0..self.topo.edges.len())
            .map(|e| (self.topo.faces_of_edge(e).iter()).fold(1.0, |a, &f| face[f as usize].min(a)))
            .collect();
        (face, edge)
    }

    /// Step 4: work queue of [`lower_face`] projections, steepest face first; the
    /// faces around a lowered vertex are checked again, until no face is steeper
    /// than `s·(1 + 1e-9)`. A face the projection cannot bring within the bound
    /// (or, past 16 fixes per face on average, any face) is flattened to its
    /// smallest value, so the loop ends. Returns the number of fixes.
    fn fix_faces(&self, h: &mut [f64], s: f64) -> usize {
        let bound = s * (1.0 + SLOPE_TOLERANCE);
        let target = s * (1.0 - FIX_MARGIN);
        let mut heap: BinaryHeap<Entry> = (0..self.t.len())
            .map(|f| Entry {
                key: self.slope(h, f),
                i: f as u32,
            })
            .filter(|e| e.key > bound)
            .collect();
        let cap = 16 * self.t.len() + 1024;
        let mut fixes = 0usize;
        while let Some(Entry { key, i: f }) = heap.pop() {
            let sl = self.slope(h, f as usize);
            if sl.to_bits() != key.to_bits() || sl.is_nan() || sl <= bound {
                continue; // stale entry, or fixed meanwhile
            }
            fixes += 1;
            let t = self.t[f as usize].map(|v| v as usize);
            let (p, old) = (t.map(|v| self.v[v]), t.map(|v| h[v]));
            let flat = [old[0].min(old[1]).min(old[2]); 3];
            let mut new = if fixes <= cap {
                lower_face(p, old, target)
            } else {
                flat
            };
            let sl_new = face_slope(p[0], p[1], p[2], new[0], new[1], new[2]);
            if sl_new.is_nan() || sl_new > bound {
                new = flat;
            }
            for k in 0..3 {
                h[t[k]] = new[k];
            }
            for k in (0..3).filter(|&k| new[k] < old[k]) {
                for &g in self.topo.faces_of_vertex(t[k]) {
                    let sg = self.slope(h, g as usize);
                    if sg > bound {
                        heap.push(Entry { key: sg, i: g });
                    }
                }
            }
        }
        fixes
    }

    /// Step 5: sweeps in increasing order of value; each vertex is raised to the
    /// largest value, at most `cap`, that keeps every face around it within the
    /// bound given its neighbours (checked, so feasible faces stay feasible).
    /// O(n log n + F) per sweep.
    fn raise(&self, h: &mut [f64], cap: &[f64], s: f64) {
        let bound = s * (1.0 + SLOPE_TOLERANCE);
        let target = s * (1.0 - FIX_MARGIN);
        let mut order: Vec<u32> = (0..self.v.len() as u32)
            .filter(|&v| {
                h[v as usize].is_finite() && !self.topo.faces_of_vertex(v as usize).is_empty()
            })
            .collect();
        for _ in 0..RAISE_SWEEPS {
            order
                .sort_unstable_by(|&a, &b| h[a as usize].total_cmp(&h[b as usize]).then(a.cmp(&b)));
            for &x in &order {
                let (x, mut hi) = (x as usize, cap[x as usize]);
                for &f in self.topo.faces_of_vertex(x) {
                    if hi.is_nan() || hi <= h[x] {
                        break;
                    }
                    let (_, a, b) = self.others(f, x);
                    let (pa, pb) = (self.v[a], self.v[b]);
                    if !(h[a].is_finite() && h[b].is_finite()) || gram(self.v[x], pa, pb).is_none()
                    {
                        continue;
                    }
                    hi = largest_admissible(self.v[x], pa, pb, h[a], h[b], target)
                        .map_or(f64::NEG_INFINITY, |c| hi.min(c));
                }
                if hi > h[x] {
                    let old = std::mem::replace(&mut h[x], hi);
                    let faces = self.topo.faces_of_vertex(x);
                    if !faces.iter().all(|&f| self.slope(h, f as usize) <= bound) {
                        h[x] = old;
                    }
                }
            }
        }
    }
}

/// Euclidean projection of `y` onto the ellipse `{z : zᵀ A z ≤ t²}`, `A = [a11, a12,
/// a22]` symmetric positive semi-definite: `z = (I + μA)⁻¹ y` with μ found by Newton
/// on `1/sqrt(zᵀAz) = 1/t` (concave in μ, so the iterates rise monotonically to the
/// root); a last scaling puts the result on or inside the ellipse. O(1).
fn project_ellipse(a: [f64; 3], y: [f64; 2], t: f64) -> [f64; 2] {
    let q = a[0] * y[0] * y[0] + 2.0 * a[1] * y[0] * y[1] + a[2] * y[1] * y[1];
    if q.is_nan() || q <= t * t {
        return y;
    }
    let (half, diff) = (0.5 * (a[0] + a[2]), 0.5 * (a[0] - a[2]));
    let rad = diff.hypot(a[1]);
    let (l1, l2) = (half + rad, (half - rad).max(0.0));
    let v1 = if rad == 0.0 {
        [1.0, 0.0]
    } else if diff >= 0.0 {
        [diff + rad, a[1]]
    } else {
        [a[1], rad - diff]
    };
    let nv = v1[0].hypot(v1[1]);
    let v1 = [v1[0] / nv, v1[1] / nv];
    let v2 = [-v1[1], v1[0]];
    let (c1, c2) = (v1[0] * y[0] + v1[1] * y[1], v2[0] * y[0] + v2[1] * y[1]);
    let (w1, w2) = (l1 * c1 * c1, l2 * c2 * c2);
    let mut mu = 0.0f64;
    for _ in 0..60 {
        let (d1, d2) = (1.0 + mu * l1, 1.0 + mu * l2);
        let f = w1 / (d1 * d1) + w2 / (d2 * d2);
        if f.is_nan() || f <= t * t {
            break;
        }
        let df = -2.0 * (w1 * l1 / (d1 * d1 * d1) + w2 * l2 / (d2 * d2 * d2));
        let step = (1.0 / t - 1.0 / f.sqrt()) / (-0.5 * df / (f * f.sqrt()));
        if !(step.is_finite() && step > 0.0) {
            break;
        }
        mu += step;
        if step <= 1e-15 * mu {
            break;
        }
    }
    let (mut z1, mut z2) = (c1 / (1.0 + mu * l1), c2 / (1.0 + mu * l2));
    let f = l1 * z1 * z1 + l2 * z2 * z2;
    if f > t * t {
        let k = t / f.sqrt();
        z1 *= k;
        z2 *= k;
    }
    [z1 * v1[0] + z2 * v2[0], z1 * v1[1] + z2 * v2[1]]
}

/// New values of a face steeper than `t`: its smallest corner stays, the other
/// two are lowered as little as possible (L2) to slope `t`, never raised and
/// never below the smallest corner. O(1).
fn lower_face(p: [[f64; 3]; 3], h: [f64; 3], t: f64) -> [f64; 3] {
    let m = (0..3).fold(0, |m, k| if h[k] < h[m] { k } else { m });
    let (b, c) = ((m + 1) % 3, (m + 2) % 3);
    let Some(g) = gram(p[m], p[b], p[c]) else {
        return [h[m]; 3];
    };
    // |∇h|² = rᵀ G⁻¹ r with r = (hb − hm, hc − hm).
    let minv = [g[2] / g[3], -g[1] / g[3], g[0] / g[3]];
    let r0 = [h[b] - h[m], h[c] - h[m]];
    let mut r = project_ellipse(minv, r0, t);
    // Lowering only: if the projection raises one corner, that corner stays and
    // the other takes the largest admissible value (the larger root).
    let other = |fixed: f64, a_ff: f64, a_oo: f64| -> Option<f64> {
        let disc = (minv[1] * fixed).powi(2) - a_oo * (a_ff * fixed * fixed - t * t);
        (disc >= 0.0).then(|| (-minv[1] * fixed + disc.sqrt()) / a_oo)
    };
    if r[0] > r0[0] {
        r = other(r0[0], minv[0], minv[2]).map_or([0.0; 2], |y| [r0[0], y]);
    } else if r[1] > r0[1] {
        r = other(r0[1], minv[2], minv[0]).map_or([0.0; 2], |x| [x, r0[1]]);
    }
    // Nothing below the smallest corner: on a sliver the projection can send a
    // corner far below it (below zero with large sizes). That corner then
    // takes the smallest value and the other the largest admissible one.
    if r[0] < 0.0 {
        r = [
            0.0,
            other(0.0, minv[0], minv[2]).map_or(0.0, |y| y.clamp(0.0, r0[1])),
        ];
    } else if r[1] < 0.0 {
        r = [
            other(0.0, minv[2], minv[0]).map_or(0.0, |x| x.clamp(0.0, r0[0])),
            0.0,
        ];
    }
    let mut out = h;
    out[b] = h[b].min(h[m] + r[0]);
    out[c] = h[c].min(h[m] + r[1]);
    out
}

/// Largest `hx` such that face (x, v, y) has slope at most `t` given `hv`, `hy`
/// (the larger root of a quadratic); `None` when the face is degenerate or edge
/// (v, y) alone is steeper. O(1).
#[inline]
fn largest_admissible(
    px: [f64; 3],
    pv: [f64; 3],
    py: [f64; 3],
    hv: f64,
    hy: f64,
    t: f64,
) -> Option<f64> {
    let g = gram(px, pv, py)?;
    // Lengths and sizes are taken in units of u, a power of two near the
    // longest of e1, e2: the discriminant below is of degree six in lengths,
    // which would underflow (overflow) in model units for models near 1e-50
    // (1e50); a power of two rescales exactly, so the answer's bits scale
    // with the model's.
    let u = pow2_floor(g[0].max(g[2]).sqrt());
    let (u2, u4) = (u * u, u * u * u * u);
    let g = [g[0] / u2, g[1] / u2, g[2] / u2, g[3] / u4];
    // With z = hx − hv, δ = hy − hv: |pv − py|²·z² − 2δ(g11 − g12)·z + g11·δ² − t²·det = 0.
    let delta = (hy - hv) / u;
    let a = g[0] - 2.0 * g[1] + g[2];
    let b = delta * (g[0] - g[1]);
    let c = g[0] * delta * delta - t * t * g[3];
    let disc = b * b - a * c;
    (disc >= 0.0 && a > 0.0).then(|| hv + (b + disc.sqrt()) / a * u)
}

/// The largest power of two at most `x` (a positive normal number). O(1).
fn pow2_floor(x: f64) -> f64 {
    f64::from_bits(x.to_bits() & (0x7ff << 52))
}
