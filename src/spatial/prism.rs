//! Certified hinted search: the exact answer of [`Bvh::closest`] for a point
//! near a known triangle, found by a short walk across edges and one exact
//! point–triangle test instead of a descent from the root.
//!
//! # The certificate
//!
//! Let `P_t` be the infinite prism over triangle `t`: the points whose
//! projection onto `t`'s plane falls strictly inside `t`. Every point `x`
//! outside it lies beyond the line of some edge `e` of `t` (in the closed
//! half-space `(x − e₀)·m_e ≥ 0`, `m_e` the edge's outward normal within
//! `t`'s plane). For a query point `p = q + s·n` over `q` inside `t` (`n`
//! the unit normal, `|s| = d` its distance to `t`) and `δ` the distance
//! from `q` to `t`'s boundary:
//!
//! ```text
//! x ∉ P_t:  |p − x| ≥ (x − p)·m_e = (x − e₀)·m_e − (q − e₀)·m_e ≥ δ
//! x ∈ P_t:  |p − x| ≥ |h(x) − s| ≥ z_t − d
//! ```
//!
//! where `h(x)` is the height of `x` over `t`'s plane and the *prism
//! clearance* `z_t`, computed once per triangle, is a lower bound of `|h|`
//! over the parts of all other triangles inside `P_t`. So when `d < δ` and
//! `2d < z_t`, every other triangle is strictly farther from `p` than `t`,
//! and `t` is the answer, with the BVH's closest point and distance (the
//! same corners, the same function: the same bits). On a grid without
//! sharp concave folds no triangle enters another's prism near it (an edge
//! neighbour leaves it across the shared edge, a flat or convex fan stays
//! outside), so `z_t` is the distance to the far side of the part (a thin
//! wall's other side, capped at two longest edges of `t`), and the test
//! certifies every point deeper inside its triangle's prism than its own
//! height over it: one exact test where the descent makes about 5 and
//! visits about 8 wide nodes. It fails near `t`'s edges, at concave folds
//! sharper than a right angle, on points farther off the surface than
//! their depth inside the prism, and over thin gaps; then the BVH answers.
//!
//! Rounding: the prism is shrunk by `ε` (four times the BVH's rounding
//! allowance `1e-12 · max |coordinate|`) when `z_t` is computed, points in
//! that band are bounded by `δ − ε`, `z_t` is lowered by `ε`, and the test
//! at query time keeps another `8 · 1e-12 · max |coordinate|` of margin:
//! far above the rounding of f64 distances and barycentric coordinates, so
//! no tie can pass.
//!
//! # The walk
//!
//! From the hint, the search steps to the neighbour across the edge that
//! `p`'s projection lies farthest beyond (the plane's barycentric
//! coordinates), at most [`MAX_WALK`] steps, until it stands on the triangle
//! whose prism holds `p`; a non-manifold or boundary edge in the way ends
//! the walk. An advancing front queries a fraction of an element from its
//! last answer: one or two steps.
//!
//! # Cost and ties
//!
//! Building: one bounded BVH range search per triangle and a clip of each
//! triangle it finds against the prism (most are dismissed by one side
//! plane or by their height first), O(F log F), parallel (sequential when
//! first reached from a rayon worker, as the grid's other lazy tables):
//! 0.19 s for 76–89k triangles on 2 cores. 16 bytes per triangle
//! ([`PrismSlot`]: the faces across its edges and the clearance as f32),
//! stored in the BVH's slot order, so a walk reads the corners and the
//! table of neighbouring triangles from neighbouring memory. A query: a few
//! plane coordinates per step, one exact point–triangle test, the
//! certificate. Ties the search to the mesh's edge adjacency
//! ([`crate::mesh::Topology`]) and to the BVH (corners in leaf order, the
//! same corner order as the tree's search).

use super::bvh::{Bvh, ClosestHit};
use crate::geometry::{closest_point_triangle, cross, dist2, dot, norm, norm2, scale, sub};
use arrayvec::ArrayVec;
use rayon::prelude::*;

/// Most edges the walk crosses before it gives up.
pub const MAX_WALK: usize = 8;

/// A hint this many of its longest edges or more from the query point is
/// not walked from (see [`Prisms::closest_from`]).
pub const FAR_HINT: f64 = 4.0;

/// The prism clearance is capped at this many longest edges of the triangle.
const CLEARANCE_CAP: f64 = 2.0;

/// A grid with a triangle whose longest edge lies outside this range gets no
/// certificate (see [`PrismMesh::build`]).
pub const EDGE_RANGE: (f64, f64) = (1e-60, 1e60);

/// What the certified search reads: the edge adjacency of the triangles and
/// the BVH over them (for its corners and rounding scale).
#[derive(Clone, Copy)]
pub struct PrismMesh<'a> {
    /// The three edges of each face: edge `k` joins corners `k` and `k + 1`.
    pub face_edges: &'a [[u32; 3]],
    /// Start of each edge's faces in `edge_faces` (one more than edges).
    pub edge_face_offsets: &'a [u32],
    /// Faces of each edge.
    pub edge_faces: &'a [u32],
    /// The BVH over the triangles.
    pub bvh: &'a Bvh,
}

impl PrismMesh<'_> {
    /// The face across edge `k` of face `t`, if that edge has exactly two.
    #[inline(always)]
    fn across(&self, t: u32, k: usize) -> Option<u32> {
        let e = self.face_edges[t as usize][k] as usize;
        let (a, b) = (
            self.edge_face_offsets[e] as usize,
            self.edge_face_offsets[e + 1] as usize,
        );
        match self.edge_faces[a..b] {
            [f, g] => Some(if f == t { g } else { f }),
            _ => None,
        }
    }

    /// The prism table of every triangle (module doc), in the BVH's slot
    /// order. O(F log F), parallel unless `sequential`.
    pub fn build(&self, sequential: bool) -> Prisms {
        let n = self.bvh.prim_triangle.len();
        // The exact point–triangle distance squares a triangle's doubled
        // area; below about 1e-146 or above about 1e154 of it the square
        // under- or overflows and an interior projection is measured to the
        // edges instead, which breaks the bounds the certificate rests on.
        // A grid with a longest edge outside `EDGE_RANGE` gets no
        // certificate at all.
        let (lo, hi) = (EDGE_RANGE.0 * EDGE_RANGE.0, EDGE_RANGE.1 * EDGE_RANGE.1);
        let in_range = self
            .bvh
            .prim_corners
            .iter()
            .all(|&[a, b, c]| (lo..=hi).contains(&longest_edge2(&[a, b, c])));
        let one = |slot: usize| {
            let t = self.bvh.prim_triangle[slot];
            let across = [0, 1, 2].map(|k| {
                self.across(t, k)
                    .map_or(NO_SLOT, |u| self.bvh.triangle_prim[u as usize])
            });
            let z = if in_range {
                self.clearance(slot)
            } else {
                f64::NEG_INFINITY
            };
            // Rounded down to f32 (a lower bound stays one).
            let mut c = z as f32;
            if c as f64 > z {
                c = c.next_down();
            }
            PrismSlot { across, clear: c }
        };
        let slots = if sequential {
            (0..n).map(one).collect()
        } else {
            (0..n).into_par_iter().map(one).collect()
        };
        Prisms { slots }
    }

    /// The prism clearance of the triangle in BVH slot `slot`, less the
    /// rounding slack.
    fn clearance(&self, slot: usize) -> f64 {
        let c = self.bvh.prim_corners[slot];
        let n2 = cross(sub(c[1], c[0]), sub(c[2], c[0]));
        let area2 = norm(n2);
        if area2.is_nan() || area2 <= 0.0 || area2.is_infinite() {
            return f64::NEG_INFINITY;
        }
        let n = scale(n2, 1.0 / area2);
        let eps = 4.0 * self.bvh.rounding_scale(&c[0]);
        // Outward normals of the side planes: edge k joins corners k, k + 1.
        let sides: [([f64; 3], [f64; 3]); 3] = [0, 1, 2].map(|k| {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            let m = cross(sub(b, a), n);
            let m = scale(m, 1.0 / norm(m));
            let m = if dot(m, sub(c[(k + 2) % 3], a)) > 0.0 {
                scale(m, -1.0)
            } else {
                m
            };
            (a, m)
        });
        let cap = CLEARANCE_CAP * longest_edge2(&c).sqrt();
        let g = [0, 1, 2].map(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0);
        let r = c.iter().map(|&x| dist2(g, x)).fold(0.0, f64::max).sqrt();
        let reach = (r + cap) * (1.0 + 1e-9);
        let mut z = cap;
        self.bvh.visit_within(
            g,
            reach * reach,
            |_| true,
            |other| {
                if other != slot {
                    let u = &self.bvh.prim_corners[other];
                    if let Some(h) = height_inside(u, &sides, eps, c[0], n, z) {
                        z = z.min(h);
                    }
                }
                z <= 0.0
            },
        );
        z - eps
    }
}

/// Sentinel of [`PrismSlot::across`]: no single face across that edge.
const NO_SLOT: u32 = u32::MAX;

/// What the certified search keeps per BVH slot: 16 bytes, in the BVH's
/// leaf order (neighbours in space lie near in memory, so a walk reads few
/// cache lines).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrismSlot {
    /// The slot of the face across edge `k` (corners `k` and `k + 1`), or
    /// `u32::MAX` at a boundary or non-manifold edge.
    pub across: [u32; 3],
    /// The prism clearance (module doc), rounded down to f32; `-∞` where
    /// there is none.
    pub clear: f32,
}

/// The prism table of a grid ([`PrismMesh::build`]): the certified hinted
/// search's data.
#[derive(Clone, Debug, Default)]
pub struct Prisms {
    /// Per BVH slot.
    pub slots: Vec<PrismSlot>,
}

impl Prisms {
    /// Heap bytes held. O(1).
    pub fn memory_bytes(&self) -> usize {
        self.slots.capacity() * std::mem::size_of::<PrismSlot>()
    }

    /// The exact closest point of `p` on the surface of `bvh` (the tree
    /// the table was built on), searched from triangle `start`: `Ok` with
    /// [`Bvh::closest`]'s answer bit for bit, or `Err` with the last
    /// triangle the walk stood on (`start` when out of range) when the
    /// certificate fails: then ask the BVH, with that triangle as its hint.
    /// O(1): at most `MAX_WALK` (8) steps.
    pub fn closest_from(&self, bvh: &Bvh, p: [f64; 3], start: u32) -> Result<ClosestHit, u32> {
        let Some(&first) = bvh.triangle_prim.get(start as usize) else {
            return Err(start);
        };
        if self.slots.len() != bvh.prim_corners.len() {
            return Err(start);
        }
        let mut slot = first as usize;
        // A hint farther than `FAR_HINT` of its longest edges from p (a
        // scattered point set queried in turn with the last answer as its
        // hint): the walk would cross many edges and p, whose certificate
        // needs it within two longest edges of its own triangle, is far
        // off the surface or far from the hint. The BVH answers at once.
        let c = &bvh.prim_corners[slot];
        if dist2(p, c[0]) > walk_reach2(c) {
            return Err(start);
        }
        let margin = 8.0 * bvh.rounding_scale(&p);
        for _ in 0..MAX_WALK {
            let c = &bvh.prim_corners[slot];
            let info = &self.slots[slot];
            // Barycentric coordinates of p's projection onto the plane,
            // unclamped: the edge with the most negative one is crossed.
            let n2 = cross(sub(c[1], c[0]), sub(c[2], c[0]));
            let a2 = norm2(n2);
            if a2.is_nan() || a2 <= 0.0 {
                break;
            }
            let l = [0, 1, 2].map(|i| {
                let (a, b) = (c[(i + 1) % 3], c[(i + 2) % 3]);
                dot(n2, cross(sub(b, a), sub(p, a)))
            });
            let i = (0..3).fold(0, |m, i| if l[i] < l[m] { i } else { m });
            if l[i] <= 0.0 {
                // Beyond the edge opposite corner i: edge i + 1 joins
                // corners i + 1 and i + 2.
                match info.across[(i + 1) % 3] {
                    NO_SLOT => break,
                    u => {
                        slot = u as usize;
                        continue;
                    }
                }
            }
            let cp = closest_point_triangle(p, c[0], c[1], c[2]);
            let d = cp.dist2.sqrt();
            // d < δ, the distance from the projection to the boundary: each
            // barycentric coordinate times its corner's height
            // (`|n2| / |edge|`), squared.
            let dm2 = (d + margin) * (d + margin);
            let deep = (0..3).all(|i| {
                dm2 * dist2(c[(i + 1) % 3], c[(i + 2) % 3]) < cp.bary[i] * cp.bary[i] * a2
            });
            let t = bvh.prim_triangle[slot];
            return if deep && 2.0 * d + margin < info.clear as f64 {
                Ok(ClosestHit {
                    triangle: t,
                    closest: cp,
                })
            } else {
                Err(t)
            };
        }
        Err(bvh.prim_triangle[slot])
    }
}

/// Squared length of the longest edge of the triangle with corners `c`.
fn longest_edge2(c: &[[f64; 3]; 3]) -> f64 {
    dist2(c[0], c[1])
        .max(dist2(c[1], c[2]))
        .max(dist2(c[2], c[0]))
}

/// Squared radius around the first corner of the triangle with corners `c`
/// (in the BVH's order) beyond which [`Prisms::closest_from`] does not walk
/// from it: [`FAR_HINT`] of its longest edges. O(1).
pub(crate) fn walk_reach2(c: &[[f64; 3]; 3]) -> f64 {
    FAR_HINT * FAR_HINT * longest_edge2(c)
}

/// The least `|height|` over `t`'s plane (through `o`, unit normal `n`) of
/// the part of triangle `u` inside the prism bounded by `sides` (point,
/// outward normal), each shrunk by `eps`; 0 when that part crosses the
/// plane, `None` when there is none or when all of `u` lies `bound` or
/// more from the plane on one side (it cannot lower a bound already
/// found). O(1).
fn height_inside(
    u: &[[f64; 3]; 3],
    sides: &[([f64; 3], [f64; 3]); 3],
    eps: f64,
    o: [f64; 3],
    n: [f64; 3],
    bound: f64,
) -> Option<f64> {
    // Most triangles near t lie wholly beyond one side (its neighbours) or
    // wholly farther from the plane than the bound found so far: no clip.
    if sides
        .iter()
        .any(|&(a, m)| u.iter().all(|&x| dot(sub(x, a), m) + eps > 0.0))
    {
        return None;
    }
    let h = u.map(|x| dot(sub(x, o), n));
    if h.iter().all(|&v| v >= bound) || h.iter().all(|&v| v <= -bound) {
        return None;
    }
    let mut poly: ArrayVec<[f64; 3], 9> = u.iter().copied().collect();
    for &(a, m) in sides {
        // Sutherland–Hodgman against (x − a)·m ≤ −eps.
        let mut out: ArrayVec<[f64; 3], 9> = ArrayVec::new();
        let f = |x: [f64; 3]| dot(sub(x, a), m) + eps;
        for k in 0..poly.len() {
            let (x, y) = (poly[k], poly[(k + 1) % poly.len()]);
            let (fx, fy) = (f(x), f(y));
            if fx <= 0.0 {
                out.push(x);
            }
            if (fx < 0.0 && fy > 0.0) || (fx > 0.0 && fy < 0.0) {
                let w = fx / (fx - fy);
                out.push([0, 1, 2].map(|j| x[j] + w * (y[j] - x[j])));
            }
        }
        poly = out;
        if poly.is_empty() {
            return None;
        }
    }
    let h: ArrayVec<f64, 9> = poly.iter().map(|&x| dot(sub(x, o), n)).collect();
    let (lo, hi) = h
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, g), &v| {
            (l.min(v), g.max(v))
        });
    Some(if lo <= 0.0 && hi >= 0.0 {
        0.0
    } else {
        lo.abs().min(hi.abs())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Topology;
    use crate::test_shapes::{rng, triangle_point, triangle_soup, unit_square};

    /// A test surface with its topology and BVH.
    struct Surface {
        t: Vec<[u32; 3]>,
        topo: Topology,
        bvh: Bvh,
    }

    impl Surface {
        fn new(v: Vec<[f64; 3]>, t: Vec<[u32; 3]>) -> Surface {
            let topo = Topology::build(v.len(), &t);
            let bvh = Bvh::build(&v, &t);
            Surface { t, topo, bvh }
        }

        fn mesh(&self) -> PrismMesh<'_> {
            PrismMesh {
                face_edges: &self.topo.face_edges,
                edge_face_offsets: &self.topo.edge_face_offsets,
                edge_faces: &self.topo.edge_faces,
                bvh: &self.bvh,
            }
        }
    }

    /// A wavy square of `n × n` cells and, `gap` above it, a coarser flat
    /// one (a thin wall's two sides), moved by `shift` and scaled by `s`.
    fn two_sheets(n: usize, gap: f64, shift: f64, s: f64) -> Surface {
        let wave = |x: f64, y: f64| 0.05 * (7.0 * x).sin() * (5.0 * y).cos();
        let (mut v, mut t) = unit_square(n, wave);
        let (v2, t2) = unit_square(n / 2 + 1, |_, _| 0.05 + gap);
        let o = v.len() as u32;
        v.extend(v2);
        t.extend(t2.iter().map(|f| f.map(|k| k + o)));
        let v = v.iter().map(|p| p.map(|c| (c + shift) * s)).collect();
        Surface::new(v, t)
    }

    /// Points near and far from random triangles (some on corners and
    /// edges: ties), searched from their own triangle, a neighbour-ish one
    /// or anywhere; every certified answer must be the BVH's bit for bit.
    /// Returns (certified, asked) over the points inside their triangle
    /// within a twentieth of an edge of it, started from it.
    fn check(s: &Surface, edge: f64, points: usize, seed: u64) -> (usize, usize) {
        let (t, bvh, mesh) = (&s.t, &s.bvh, s.mesh());
        let table = mesh.build(false);
        assert_eq!(table.slots, mesh.build(true).slots, "sequential = parallel");
        let mut seed = seed;
        let (mut certified, mut asked) = (0, 0);
        for i in 0..points {
            let tri = (rng(&mut seed) * t.len() as f64) as usize;
            let c = bvh.prim_corners[bvh.triangle_prim[tri] as usize];
            let on = triangle_point(&c, i, &mut seed);
            let off = edge
                * match i % 5 {
                    0 => 0.0,
                    1 => 2.0 * rng(&mut seed),
                    2 => 40.0 * (rng(&mut seed) - 0.5),
                    _ => 0.1 * (rng(&mut seed) - 0.5),
                };
            let dir = [rng(&mut seed) - 0.5, rng(&mut seed) - 0.5, 1.0];
            let p = [0, 1, 2].map(|k| on[k] + off * dir[k]);
            let start = match i % 3 {
                0 => tri,
                1 => (tri + 1 + i % 5) % t.len(),
                _ => (rng(&mut seed) * t.len() as f64) as usize,
            } as u32;
            let want = bvh.closest(p, None).unwrap();
            // Inside its triangle (not on a corner or an edge: no depth),
            // within a twentieth of an edge of it, started from it.
            let near = i % 4 >= 2 && off.abs() < 0.05 * edge && start as usize == tri;
            asked += near as usize;
            match table.closest_from(bvh, p, start) {
                Ok(got) => {
                    certified += near as usize;
                    assert_eq!(got.triangle, want.triangle, "point {p:?} from {start}");
                    assert_eq!(got.closest.point, want.closest.point);
                    assert_eq!(got.closest.bary, want.closest.bary);
                    assert_eq!(got.closest.dist2.to_bits(), want.closest.dist2.to_bits());
                }
                Err(seed) => assert!((seed as usize) < t.len() || seed == start),
            }
        }
        (certified, asked)
    }

    #[test]
    fn certified_answers_are_the_bvh_answers_bit_for_bit() {
        // A thin wall: the far side 0.3 of an edge above the near one's
        // crests, so clearances there are small and big offsets must fail.
        let n = 24;
        let edge = 1.0 / n as f64;
        for (shift, scale) in [(0.0, 1.0), (1e6, 1.0), (-3e4, 1e-40), (0.0, 1e40)] {
            let s = two_sheets(n, 0.3 * edge, shift, scale);
            let (certified, asked) = check(&s, edge * scale, 6000, 7);
            // Most points near the surface are certified (not those under
            // the thin wall's other side, nor those nearer an edge than
            // the surface).
            assert!(certified * 10 > asked * 8, "{certified} of {asked}");
        }
    }

    #[test]
    fn a_soup_has_rings_of_one_triangle_and_still_answers_exactly() {
        let (v, t) = triangle_soup(400, 5);
        let s = Surface::new(v, t);
        check(&s, 0.02, 4000, 11);
    }

    #[test]
    fn clearance_is_the_gap_to_the_other_side_or_the_cap() {
        // A flat square under a flat sheet `gap` above it: no triangle
        // enters another's prism but the other sheet's, so the lower
        // sheet's clearances are the gap, the upper's too (the lower sheet
        // under it), or the cap (two longest edges) where the gap is wider.
        let n = 8;
        let edge = 1.0 / n as f64;
        let cap = 2.0 * 2f64.sqrt() * edge;
        for gap in [0.3 * edge, 5.0 * edge] {
            let (mut v, mut t) = unit_square(n, |_, _| 0.0);
            let (v2, t2) = unit_square(n, |_, _| gap);
            let o = v.len() as u32;
            v.extend(v2);
            t.extend(t2.iter().map(|f| f.map(|k| k + o)));
            let s = Surface::new(v, t);
            let table = s.mesh().build(false);
            for z in table.slots.iter().map(|x| x.clear as f64) {
                let want = gap.min(cap);
                assert!(z <= want && z > want - 1e-6, "{z} against {want}");
            }
            // Two thirds of the gap above a lower triangle's centroid (deep
            // inside its prism), the upper sheet is nearer: the walk from
            // the lower triangle must not certify it.
            for tri in 0..2 * n * n {
                let c = s.bvh.prim_corners[s.bvh.triangle_prim[tri] as usize];
                let mut p = [0, 1, 2].map(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0);
                p[2] = 2.0 * gap / 3.0;
                let want = s.bvh.closest(p, None).unwrap();
                assert!(want.triangle as usize >= 2 * n * n, "the upper sheet");
                if let Ok(got) = table.closest_from(&s.bvh, p, tri as u32) {
                    assert_eq!(got.triangle, want.triangle);
                }
            }
        }
        // A fold sharper than a right angle: the two halves enter each
        // other's prisms at the fold, so the clearance is about the
        // rounding margin: nothing is certified.
        let v = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 1.0, 0.0],
            [0.5, 0.2, 0.3],
        ];
        let s = Surface::new(v, vec![[0, 1, 2], [1, 0, 3]]);
        assert!(s.mesh().build(false).slots.iter().all(|x| x.clear < 1e-9));
    }

    #[test]
    fn a_grid_too_small_or_large_for_exact_distances_certifies_nothing() {
        // At 1e-120 (1e140) the squared doubled areas under- (over-)flow and
        // the distance falls back to the edges: every query goes to the BVH,
        // same answers.
        let n = 12;
        for scale in [1e-120, 1e140] {
            let s = two_sheets(n, 0.3 / n as f64, 0.0, scale);
            let table = s.mesh().build(false);
            assert!(table.slots.iter().all(|x| x.clear == f32::NEG_INFINITY));
            let (certified, asked) = check(&s, scale / n as f64, 500, 3);
            assert!(certified == 0 && asked > 0);
        }
    }
}
