//! Contact lists: for each face that another body comes near
//! ([`Grid::contact_faces`]), the other bodies' faces that can lie within the
//! contact gap of any point of it. The tie rule between bodies (the size
//! queries' and the simplifier's agreed sizes) then reads a short list instead
//! of searching the BVH from the root, once per body found and once more to
//! learn that no further body is there.
//!
//! # Why the list answers exactly
//!
//! For face `t` with centroid `m` and `r` its largest centroid–corner
//! distance, every point `q` of `t` lies within `r` of `m`. A face `u` with
//! `|q − u| ≤ c` (the contact gap) therefore has `|m − u| ≤ r + c`, so the
//! list holds every face of another body whose computed distance to `m` is at
//! most `R = (r + c)(1 + 1e-9) + 8s`, `s` being the BVH's rounding scale
//! (`1e-12` of the largest coordinate magnitude): the margins cover the
//! rounding of `m`, `r`, the distances and of a closest point `q` computed on
//! `t`. A query at such a `q` then evaluates each listed face exactly as the
//! BVH's search does (the same corners, the same point–triangle distance),
//! keeps those within `c`, the best face of each body by (distance, index),
//! and takes the bodies in that order: [`Grid::other_bodies_within`]'s answer
//! bit for bit, for any `q` on `t`.
//!
//! # Sorted by distance, so a lookup stops early
//!
//! Each listed face `u` keeps `ℓ_u`, a lower bound of its distance to `m`
//! (the computed distance less `8s`, rounded down to `f32`), and a list is
//! sorted by `(ℓ_u, u)`. A point `q` at `ρ = |q − m|` has `|q − u| ≥
//! |m − u| − ρ ≥ ℓ_u − ρ`, so once `ℓ_u > ρ + c + 8s` (with a relative margin)
//! no face from `u` on can lie within the gap, nor be *computed* within it
//! (computed distances near `q` err by less than `s`), and the scan ends
//! there: a lookup near one corner of a face reads the part of its list
//! around that corner, and skips the other faces' corners (random reads)
//! altogether. The answer does not depend on the order in which faces are
//! read (each body's best face is chosen by distance, then index), so it
//! stays the BVH's bit for bit.
//!
//! # Cost and ties
//!
//! Built on first use: one bounded BVH range search per contact face, in
//! fixed chunks (so the lists are the same for any thread count), parallel
//! unless first reached on a rayon worker ([`super::on_rayon_worker`]),
//! O(Fc log F). Memory: 4 bytes per face (offsets) plus 8 per listed face
//! (the face and its bound). A
//! list longer than [`MAX_LIST`] (another body's faces far finer than this
//! one's) is not kept: such a face answers through the BVH, as before. A
//! lookup is O(k) point–triangle distances for k listed faces (a few on
//! coincident faces of similar size). Ties the tie rule to the BVH's corners
//! and distance function, and to [`Grid::contact_faces`]' radius.

use super::Grid;
use crate::geometry::closest_point_triangle;
use crate::spatial::Bvh;
use rayon::prelude::*;

/// Longest list kept; a face with more candidates answers through the BVH.
/// Since the lists are sorted (a lookup reads only the part near its point),
/// 128 rather than 64: on the big assemblies the faces whose lists had
/// overflowed at 64 cost more through the BVH than their longer lists do.
pub(crate) const MAX_LIST: usize = 128;

/// Faces per parallel chunk when building (a constant: same lists whatever
/// the thread count).
const CHUNK: usize = 4096;

/// Marks a face whose list overflowed [`MAX_LIST`].
const OVERFLOW: u32 = u32::MAX;

/// Per face, the other bodies' faces that may lie within the contact gap of
/// it (compressed rows; see the module doc).
#[derive(Debug, Clone, Default)]
pub(crate) struct ContactLists {
    /// Start of each face's list in `faces` (one more than the faces).
    offsets: Vec<u32>,
    /// The listed faces, each list by ascending `(bound, face)`; `[OVERFLOW]`
    /// for a face whose list was too long.
    faces: Vec<u32>,
    /// Per listed face: a lower bound of its distance to the centroid of the
    /// face whose list it is in (module doc); `INFINITY` beside `OVERFLOW`.
    bounds: Vec<f32>,
}

/// A face's list: the other bodies' faces, ascending by `bounds`, a lower
/// bound of each one's distance to the face's centroid (see the module doc).
#[derive(Debug, Clone, Copy)]
pub(crate) struct List<'a> {
    /// The listed faces.
    pub faces: &'a [u32],
    /// Lower bounds of their distances to the centroid, ascending.
    pub bounds: &'a [f32],
}

/// A listed face as built: (lower bound of its distance to the centroid,
/// face).
type Entry = (f32, u32);

/// The largest `f32` not above `x`, and not below 0 (a distance bound: a
/// negative `x`, or NaN, gives 0).
fn f32_below(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) > x {
        f32::from_bits(y.to_bits() - 1).max(0.0)
    } else {
        y.max(0.0)
    }
}

impl ContactLists {
    /// The lists of `grid`'s contact faces (empty on one body). O(Fc log F).
    pub(crate) fn build(grid: &Grid) -> ContactLists {
        let contact = grid.contact_faces();
        if contact.is_empty() {
            return ContactLists::default();
        }
        let (bvh, t) = (grid.bvh(), grid.triangles());
        let body = &grid.topology().face_body;
        let nodes = grid.node_bodies();
        let gap = grid.contact_gap();
        let list_chunk = |fs: &[usize]| {
            let (mut lens, mut items) = (Vec::with_capacity(fs.len()), Vec::new());
            for &f in fs {
                let before = items.len();
                if contact[f] {
                    let (m, r) = grid.centroid_ball(f);
                    let s = bvh.rounding_scale(&m);
                    let reach = (r + gap) * (1.0 + 1e-9) + 8.0 * s;
                    let own = body[f];
                    let full = within(
                        bvh,
                        m,
                        reach * reach,
                        8.0 * s,
                        |u| body[u as usize] != own,
                        |n| nodes[n] != own,
                        &mut items,
                    );
                    if full {
                        items[before..]
                            .sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
                    } else {
                        items.truncate(before);
                        items.push((f32::INFINITY, OVERFLOW));
                    }
                }
                lens.push((items.len() - before) as u32);
            }
            (lens, items)
        };
        let all: Vec<usize> = (0..t.len()).collect();
        let chunks: Vec<(Vec<u32>, Vec<Entry>)> = if super::on_rayon_worker() {
            all.chunks(CHUNK).map(list_chunk).collect()
        } else {
            all.par_chunks(CHUNK).map(list_chunk).collect()
        };
        let total: usize = chunks.iter().map(|c| c.1.len()).sum();
        if u32::try_from(total).is_err() {
            // Past 4-byte offsets (tens of millions of contact faces): no
            // lists, every face asks the BVH.
            return ContactLists::default();
        }
        let mut offsets = Vec::with_capacity(t.len() + 1);
        offsets.push(0u32);
        let mut faces = Vec::with_capacity(total);
        let mut bounds = Vec::with_capacity(total);
        for (lens, items) in chunks {
            for l in lens {
                offsets.push(offsets.last().copied().unwrap_or(0) + l);
            }
            faces.extend(items.iter().map(|i| i.1));
            bounds.extend(items.iter().map(|i| i.0));
        }
        ContactLists {
            offsets,
            faces,
            bounds,
        }
    }

    /// The list of face `f`: `None` when there is none kept (not a contact
    /// face, an overflowing list, or an index out of range). O(1).
    pub(crate) fn get(&self, f: u32) -> Option<List<'_>> {
        let f = f as usize;
        let (a, b) = (
            *self.offsets.get(f)? as usize,
            *self.offsets.get(f + 1)? as usize,
        );
        let faces = &self.faces[a..b];
        (!faces.is_empty() && faces[0] != OVERFLOW).then_some(List {
            faces,
            bounds: &self.bounds[a..b],
        })
    }
}

/// Appends to `out` every triangle accepted by `keep` whose computed squared
/// distance to `p` is at most `r2`, as (lower bound of its distance: the
/// computed one less `margin`, rounded down to `f32`; triangle), in the order
/// [`Bvh::visit_within`] meets them, below nodes that `keep_node` accepts.
/// False (with `out` partly filled) once more than [`MAX_LIST`] were found.
fn within(
    bvh: &Bvh,
    p: [f64; 3],
    r2: f64,
    margin: f64,
    keep: impl Fn(u32) -> bool,
    keep_node: impl Fn(usize) -> bool,
    out: &mut Vec<Entry>,
) -> bool {
    let start = out.len();
    let overflowed = bvh.visit_within(p, r2, keep_node, |slot| {
        let u = bvh.prim_triangle[slot];
        let c = &bvh.prim_corners[slot];
        if !keep(u) {
            return false;
        }
        let d2 = closest_point_triangle(p, c[0], c[1], c[2]).dist2;
        if d2 <= r2 {
            if out.len() - start == MAX_LIST {
                return true;
            }
            out.push((f32_below(d2.sqrt() - margin), u));
        }
        false
    });
    !overflowed
}

#[cfg(test)]
mod tests {
    use crate::mesh::{BuildOptions, Grid};
    use crate::test_shapes::{rng, unit_square};

    /// Five wavy unit squares, each its own body, stacked within the contact
    /// gap of each other (so a point meets up to four other bodies, one more
    /// than a query reads) at resolutions 3 to 48 (so coarse faces overflow
    /// their lists and fine faces keep short ones), and a sixth one apart.
    fn stack() -> Grid {
        let (mut v, mut t) = (Vec::new(), Vec::new());
        let layers = [
            (6, 0.0),
            (48, 1.5e-4),
            (3, 3.1e-4),
            (17, 2.2e-4),
            (9, 0.9e-4),
            (5, 0.1),
        ];
        for (n, dz) in layers {
            let (lv, lt) = unit_square(n, |x, y| dz + 0.02 * (3.0 * x).sin() * (2.0 * y).cos());
            let base = v.len() as u32;
            v.extend(lv);
            t.extend(lt.iter().map(|f| f.map(|i| i + base)));
        }
        Grid::from_arrays(v, t, None, &BuildOptions::default()).unwrap()
    }

    #[test]
    fn lists_answer_as_the_bvh_bit_for_bit() {
        let g = stack();
        assert_eq!(g.topology().body_count, 6);
        let gap = g.contact_gap();
        let (contact, lists) = (g.contact_faces(), g.contact_lists());
        let listed = (0..g.triangles().len() as u32)
            .filter(|&f| lists.get(f).is_some())
            .count();
        let flagged = contact.iter().filter(|&&c| c).count();
        // Both kinds occur: kept lists and overflowing (or empty) ones.
        assert!(listed > 1000 && listed < flagged, "{listed} of {flagged}");
        let body = &g.topology().face_body;
        let mut seed = 11u64;
        let (mut compared, mut most) = (0, 0);
        for i in 0..20000 {
            let f = (rng(&mut seed) * g.triangles().len() as f64) as usize;
            if !contact[f] {
                continue;
            }
            // Corners, edge points and inner points of the face, as its
            // closest points: how the tie rule calls it.
            let c = g.triangles()[f].map(|k| g.vertices()[k as usize]);
            let (a, b) = match i % 3 {
                0 => (1.0, 0.0),
                1 => (rng(&mut seed), 0.0),
                _ => (rng(&mut seed) * 0.5, rng(&mut seed) * 0.5),
            };
            let p = [0, 1, 2].map(|k| c[0][k] + a * (c[1][k] - c[0][k]) + b * (c[2][k] - c[0][k]));
            let q = g
                .bvh()
                .closest_filtered(p, None, |u| u == f as u32)
                .unwrap();
            let fast = g.other_bodies_at(q.closest.point, f as u32);
            let slow = g.other_bodies_within(q.closest.point, body[f], gap);
            assert_eq!(fast.len(), slow.len(), "face {f}");
            for (x, y) in fast.iter().zip(&slow) {
                assert_eq!(x.0, y.0, "face {f}");
                assert_eq!(x.1.map(f64::to_bits), y.1.map(f64::to_bits), "face {f}");
            }
            compared += usize::from(lists.get(f as u32).is_some());
            most = most.max(fast.len());
        }
        assert!(compared > 1000, "{compared}");
        // The cap of three other bodies was reached and kept.
        assert_eq!(most, 3);
    }

    #[test]
    fn lists_are_sorted_by_bounds_below_the_distances() {
        let g = stack();
        let lists = g.contact_lists();
        let (bvh, t) = (g.bvh(), g.triangles());
        let mut checked = 0;
        for f in 0..t.len() {
            let Some(list) = lists.get(f as u32) else {
                continue;
            };
            assert_eq!(list.faces.len(), list.bounds.len());
            let m = g.centroid(f);
            for (k, (&u, &b)) in list.faces.iter().zip(list.bounds).enumerate() {
                if k > 0 {
                    let (pu, pb) = (list.faces[k - 1], list.bounds[k - 1]);
                    assert!(pb < b || (pb == b && pu < u), "face {f}: not sorted");
                }
                let c = &bvh.prim_corners[bvh.triangle_prim[u as usize] as usize];
                let d = crate::geometry::closest_point_triangle(m, c[0], c[1], c[2])
                    .dist2
                    .sqrt();
                assert!((b as f64) <= d && b >= 0.0, "face {f}: bound {b} over {d}");
                // Not uselessly loose: within the margins of the distance.
                assert!(
                    d - b as f64 <= 1e-6 * d.max(1e-3),
                    "face {f}: {b} against {d}"
                );
                checked += 1;
            }
        }
        assert!(checked > 10_000, "{checked}");
    }

    #[test]
    fn built_on_a_worker_or_not_the_same() {
        let (g, h) = (stack(), stack());
        // This test's thread is no rayon worker: a parallel build.
        assert!(!crate::mesh::on_rayon_worker());
        let (a, fa) = (g.contact_lists().clone(), g.contact_faces().to_vec());
        // Inside `join` the closure runs on a worker: a sequential build.
        let ((b, fb), _) = rayon::join(
            || {
                assert!(crate::mesh::on_rayon_worker());
                (h.contact_lists().clone(), h.contact_faces().to_vec())
            },
            || (),
        );
        assert_eq!(fa, fb);
        assert_eq!(a.offsets, b.offsets);
        assert_eq!(a.faces, b.faces);
        assert_eq!(
            a.bounds.iter().map(|b| b.to_bits()).collect::<Vec<_>>(),
            b.bounds.iter().map(|b| b.to_bits()).collect::<Vec<_>>()
        );
        assert!(!a.faces.is_empty());
    }

    #[test]
    fn one_body_has_no_lists() {
        let (v, t) = unit_square(4, |_, _| 0.0);
        let g = Grid::from_arrays(v, t, None, &BuildOptions::default()).unwrap();
        assert!(g.contact_lists().get(0).is_none());
        assert!(g.contact_lists().faces.is_empty());
    }
}
