//! The distance envelope: how far the simplified grid may lie from the target
//! (dense) grid, and why (DESIGN §3.5, the distance test).
//!
//! # What the distance test guards against
//!
//! A mesher asks `size(x)` at points `x` of its own surface, which is the CAD
//! surface the dense grid follows. The query finds the closest point `x'` of
//! the simplified grid and interpolates there. If the simplified grid lies a
//! distance `Δd` from the dense one, three things can go wrong:
//!
//! 1. **Misprojection**: `x'` is `Δd` away from where the dense grid would
//!    have answered, so the size is read at the wrong place. On a field whose
//!    gradient is `|∇h|`, the relative error is at most about `|∇h|·Δd / h`.
//!    Gradation bounds `|∇h| ≤ s = ln β` (and a volume query's slope is `s`
//!    too), so it is at most `s·Δd / h`.
//! 2. **Wrong sheet**: across a thin wall, a slot or a gap between bodies of
//!    width (*clearance*) `c`, the query lands on the other side when the two
//!    sides together moved by more than `c`: `Δd_A + Δd_B ≥ c`. The two sides
//!    may carry very different sizes (an outer skin and the inside of a
//!    cavity), and no size test at the samples sees it, because the samples
//!    are projected onto their own patch.
//! 3. **A lost feature**: a feature the mesher needs is either a sharp feature
//!    line (kept exactly: feature vertices only slide along their line, corners
//!    never move), a curved region, a wall or a gap that set the sizes (so the
//!    size test at the samples sees it when it is flattened), or smaller than
//!    the local size, which a mesh of that size cannot resolve anyway.
//!
//! So the distance test has two jobs left, and the envelope is their minimum.
//! At a sample landing on target triangle `t` (size `h_t` there, field
//! gradient `g_t` on `t`, clearance `c_t`):
//!
//! ```text
//! Δd ≤ min( ½·ln(T_size) · h_t / max(s, g_t),   κ · c_t )
//! ```
//!
//! - **Misprojection term.** The size test allows a ratio of `T_size` in all;
//!   half of that budget in log terms (`½·ln T_size`) goes to misprojection,
//!   the other half stays for interpolation. With the defaults (`T_size` = 1.2,
//!   β = 1.2) this is `Δd ≤ h/2`: a grid may flatten a bump by half the local
//!   size, which no mesh of that size resolves (point 3). `g_t` replaces `s`
//!   where a field that was not graded (sizes set by the user) is steeper.
//! - **Clearance term.** With both sides within `κ·c` and `κ = ¼`, the two
//!   sides together move at most `c/2`: a query point may still lie `c/4` off
//!   its sheet (the mesher's own chord error) and land on the right one. The
//!   clearance is measured on the target as the proximity sizes measure gaps
//!   ([`crate::sizing::proximity::clearances`]): rays along ±n to the nearest
//!   face that faces back or belongs to another body (a body nested inside
//!   another has a parallel sheet facing the same way), contacts (closer than
//!   the contact gap) excluded, since there the two bodies' sizes agree by
//!   construction.
//!
//! Where proximity sizing is on, `h ≤ c / n_gap`, so with `n_gap` = 3 the
//! clearance term is at least `0.75·h` and the misprojection term (`h/2`)
//! binds; the clearance term binds where the field is coarser than the gap
//! (proximity off, user sizes, gaps wider than `hmax·n_gap`).
//!
//! The old fixed rule `Δd ≤ τ_d·h_loc` (the paper's, with τ_d = 0.05) stays
//! available as an explicit `tau_d`; it replaces the misprojection term, and
//! the clearance term still applies. On curved parts the fixed 0.05 binds
//! first and makes the grid as fine as the mesh it sizes: a chord of length
//! `L` on a radius `R` deviates by `L²/8R`, and with `h = 2πR/24` the edge
//! cannot be longer than about `1.2·h`.
//!
//! # Cost
//!
//! Per target triangle: the gradient (O(F)) and the clearance (one ray pair
//! per patch normal per vertex, O(V log F), parallel, rays no longer than the
//! distance at which the clearance could bind). Each allowance is then O(1).

use crate::geometry::{cross, lerp, norm, norm2, sub};
use crate::mesh::{Features, Grid};
use crate::sizing::normals::PatchNormals;
use crate::sizing::proximity;
use rayon::prelude::*;

/// Default clearance fraction `κ`: each side of a gap may move a quarter of
/// its width (see the module doc).
pub const DEFAULT_CLEARANCE_FRACTION: f64 = 0.25;

/// Gaps narrower than `diagonal · CONTACT_FRACTION` are contacts, not gaps:
/// the sizing's default contact gap (its default `hmin`, diagonal / 2000).
pub const CONTACT_FRACTION: f64 = crate::mesh::CONTACT_FRACTION;

/// How the size-related term of the envelope is set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SizeTerm {
    /// Derived: `½·ln(T_size)·h / max(s, g)` with slope `s`.
    Derived {
        /// `½·ln T_size`: the relative size error misprojection may cause.
        budget: f64,
        /// The gradation slope `s = ln β`.
        slope: f64,
    },
    /// Fixed: `τ_d · h_loc`.
    Fixed(f64),
}

impl SizeTerm {
    /// The size term for sizes `h` at the sample and `h_loc` of the edge, on
    /// a triangle with field gradient `g`.
    #[inline]
    pub fn allowance(&self, h: f64, h_loc: f64, g: f64) -> f64 {
        match *self {
            SizeTerm::Derived { budget, slope } => budget * h / slope.max(g),
            SizeTerm::Fixed(tau) => tau * h_loc,
        }
    }

    /// The largest allowance relative to the size (for ray limits).
    fn factor(&self) -> f64 {
        match *self {
            SizeTerm::Derived { budget, slope } => budget / slope,
            SizeTerm::Fixed(tau) => tau,
        }
    }
}

/// Per target triangle: the field's gradient and the clearance.
#[derive(Debug, Clone, Default)]
pub struct Envelope {
    /// `|∇h|` on each target triangle (0 on degenerate ones).
    pub gradient: Vec<f64>,
    /// Clearance of each target triangle: the smallest of its corners'
    /// (`+inf` where no other sheet lies within the binding distance).
    pub clearance: Vec<f64>,
}

impl Envelope {
    /// The envelope of `grid` (with `sizes`): gradients, and clearances for
    /// fraction `kappa` (none measured when `kappa` is infinite). Parallel.
    /// O(F + V log F).
    pub fn compute(
        grid: &Grid,
        sizes: &[f64],
        features: &Features,
        term: SizeTerm,
        kappa: f64,
    ) -> Envelope {
        let v = grid.vertices();
        let t = grid.triangles();
        let gradient: Vec<f64> = t
            .par_iter()
            .map(|tri| {
                let p = tri.map(|i| v[i as usize]);
                let h = tri.map(|i| sizes[i as usize]);
                triangle_gradient(p, h)
            })
            .collect();
        let clearance = if kappa.is_finite() {
            let normals = PatchNormals::compute(grid, features);
            let topo = grid.topology();
            // Beyond `factor·h_ring/κ` the clearance cannot bind (the size term
            // is smaller there), so rays stop at that distance.
            let limit: Vec<f64> = (0..v.len())
                .into_par_iter()
                .map(|i| {
                    let h = topo
                        .faces_of_vertex(i)
                        .iter()
                        .flat_map(|&f| t[f as usize])
                        .map(|j| sizes[j as usize])
                        .fold(sizes[i], f64::max);
                    term.factor() * h / kappa
                })
                .collect();
            let contact = grid.contact_gap();
            let c = proximity::clearances(grid, &normals, contact, &limit);
            t.par_iter()
                .enumerate()
                .map(|(f, tri)| {
                    let corners = tri
                        .iter()
                        .map(|&i| c[i as usize])
                        .fold(f64::INFINITY, f64::min);
                    if topo.body_count < 2 {
                        return corners;
                    }
                    // Another body can come closer inside the triangle than
                    // at its corners (its edge beside a large face): its
                    // distance at the centroid and the edge midpoints too.
                    let body = topo.face_body[f];
                    let p = tri.map(|i| v[i as usize]);
                    let at = [
                        lerp(lerp(p[0], p[1], 0.5), p[2], 1.0 / 3.0),
                        lerp(p[0], p[1], 0.5),
                        lerp(p[1], p[2], 0.5),
                        lerp(p[2], p[0], 0.5),
                    ];
                    let limit = tri.iter().map(|&i| limit[i as usize]).fold(0.0, f64::max);
                    at.iter().fold(corners, |m, &q| {
                        grid.bvh()
                            .closest_filtered_within(q, m.min(limit), |o| {
                                topo.face_body[o as usize] != body
                            })
                            .map(|h| h.closest.dist2.sqrt())
                            .filter(|&d| d >= contact)
                            .map_or(m, |d| m.min(d))
                    })
                })
                .collect()
        } else {
            vec![f64::INFINITY; t.len()]
        };
        Envelope {
            gradient,
            clearance,
        }
    }
}

/// `|∇h|` of the linear interpolant of sizes `h` on the triangle `p` (0 when
/// the triangle is degenerate). O(1).
pub fn triangle_gradient(p: [[f64; 3]; 3], h: [f64; 3]) -> f64 {
    let e1 = sub(p[1], p[0]);
    let e2 = sub(p[2], p[0]);
    let n = cross(e1, e2);
    let a2 = norm2(n);
    if !(a2 > 0.0 && a2.is_finite()) {
        return 0.0;
    }
    // The in-plane g with g·e1 = d1 and g·e2 = d2: (e2×n)·e1 = (n×e1)·e2 = |n|²
    // and (e2×n)·e2 = (n×e1)·e1 = 0.
    let (d1, d2) = (h[1] - h[0], h[2] - h[0]);
    let g1 = cross(e2, n);
    let g2 = cross(n, e1);
    let g = [0, 1, 2].map(|k| (d1 * g1[k] + d2 * g2[k]) / a2);
    let r = norm(g);
    if r.is_finite() {
        r
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradient_of_a_linear_field_is_its_slope() {
        let p = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0]];
        // h = 1 + 0.3·x + 0.4·y: |∇h| = 0.5.
        let h = p.map(|q| 1.0 + 0.3 * q[0] + 0.4 * q[1]);
        assert!((triangle_gradient(p, h) - 0.5).abs() < 1e-12);
        // Tilted out of the plane: the same field along the surface.
        let r = [[0.0, 0.0, 0.0], [2.0, 0.0, 2.0], [0.0, 3.0, 0.0]];
        let h = [1.0, 1.0 + 0.3 * 8f64.sqrt(), 1.0 + 1.2];
        assert!((triangle_gradient(r, h) - 0.5).abs() < 1e-12);
        assert_eq!(triangle_gradient([[0.0; 3]; 3], [1.0, 2.0, 3.0]), 0.0);
    }

    #[test]
    fn derived_term_is_half_the_size_at_the_defaults() {
        let term = SizeTerm::Derived {
            budget: 0.5 * 1.2f64.ln(),
            slope: 1.2f64.ln(),
        };
        assert!((term.allowance(2.0, 1.0, 0.0) - 1.0).abs() < 1e-15);
        // A steeper (ungraded) field tightens it.
        assert!((term.allowance(2.0, 1.0, 2.0 * 1.2f64.ln()) - 0.5).abs() < 1e-15);
        assert_eq!(SizeTerm::Fixed(0.05).allowance(2.0, 1.0, 9.0), 0.05);
    }
}
