//! Touching bodies: one size on a shared interface.
//!
//! An assembly may have bodies that touch along coincident faces (a plate
//! bolted on a block, a conformal interface between materials). A point on
//! such an interface lies on both bodies at once, and a size query there lands
//! on whichever face the search meets first, so the two bodies' sizes must
//! agree there or the field is ambiguous. The mesh of the interface has to
//! satisfy both bodies, so the agreed size is the smaller one: every vertex
//! lying within the contact gap of another body's face takes the minimum of
//! its own size and the other body's interpolated size at the closest point.
//! Bodies that are apart (a gap wider than the contact gap) are untouched:
//! sizes are never mixed across a gap.
//!
//! **The fringe.** A triangle that straddles the edge of a contact (a block's
//! top face running out from under a plate lying on it) has corners on the
//! interface and corners off it, and its interpolated size inside the
//! interface mixes both (on `gmsh_bracket_assembly` the fringe alone took
//! the dense grid's disagreement p95 from 4.5 % to 4.1 %; taking every
//! body within the gap instead of the nearest, where a bolt, a washer and a
//! plate meet, took its max from 42 % to 17 %). So the
//! corners off the interface that share a face with a contact vertex (the
//! fringe) take the same minimum, against the same other body at their own
//! closest point on it (which lies within the edge to the contact vertex plus
//! the gap). Both interpolants then follow one field across the straddling
//! triangles. Likewise the corners of a triangle that a contact vertex of
//! the other body lies on (a coarse triangle under a small plate, with no
//! corner of its own on the plate). The fringe is one ring wide, so sizes
//! beyond the interface are lowered only where a mesher needs the
//! interface's size anyway.

use crate::mesh::Grid;
use rayon::prelude::*;

/// A vertex lying on another body's face (within the contact gap); a vertex
/// on several other bodies has one per body (at most
/// [`crate::query::MAX_TIED_BODIES`] − 1, as the queries' tie rule).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The vertex.
    pub vertex: u32,
    /// The other body's closest triangle.
    pub triangle: u32,
    /// Barycentric coordinates of the closest point on that triangle.
    pub bary: [f64; 3],
    /// The vertex is not on the other body but shares a face with a vertex
    /// that is (the fringe; see the module doc).
    pub fringe: bool,
}

/// Every vertex within `gap` of a face of another body, with that face, and
/// then the fringe (see the module doc): every other vertex that shares a
/// face with one of those or is a corner of the other body's triangle one of
/// those lies on, with its closest face of the body across (the
/// lowest-numbered such contact vertex decides). Empty
/// for a single body. Parallel, deterministic (closest face, ties to the
/// lowest index). O(V log F) for a small `gap`.
pub fn contacts(grid: &Grid, gap: f64) -> Vec<Contact> {
    let topo = grid.topology();
    if topo.body_count < 2 || gap.is_nan() || gap <= 0.0 {
        return Vec::new();
    }
    let v = grid.vertices();
    let body = &topo.face_body;
    let bvh = grid.bvh();
    let on: Vec<Contact> = (0..v.len())
        .into_par_iter()
        .flat_map_iter(|vi| {
            // A vertex's own body: that of any of its faces (welded bodies
            // are split into components, so all its faces share one body).
            let own = topo.faces_of_vertex(vi).first().map(|&f| body[f as usize]);
            // Every other body within the gap, nearest first (the tie rule's
            // search): where three bodies meet, the nearest one alone may not
            // be the smallest.
            own.map(|own| grid.other_bodies_within(v[vi], own, gap))
                .into_iter()
                .flatten()
                .map(move |(triangle, bary)| Contact {
                    vertex: vi as u32,
                    triangle,
                    bary,
                    fringe: false,
                })
        })
        .collect();
    let mut on_contact = vec![false; v.len()];
    for c in &on {
        on_contact[c.vertex as usize] = true;
    }
    // The fringe's anchors: (vertex off the interface, body to project it
    // on, contact vertex) for every contact vertex that (i) shares a face
    // with it, or (ii) lies on a triangle it is a corner of; per vertex and
    // body the lowest-numbered contact vertex decides.
    let tris = grid.triangles();
    let mut anchors: Vec<(u32, u32, u32)> = Vec::new();
    for c in &on {
        let ci = c.vertex as usize;
        let here = body[topo.faces_of_vertex(ci)[0] as usize];
        let there = body[c.triangle as usize];
        for &f in topo.faces_of_vertex(ci) {
            anchors.extend(tris[f as usize].map(|w| (w, there, c.vertex)));
        }
        anchors.extend(tris[c.triangle as usize].map(|w| (w, here, c.vertex)));
    }
    anchors.retain(|&(w, ..)| !on_contact[w as usize]);
    anchors.sort_unstable();
    anchors.dedup_by_key(|a| (a.0, a.1));
    let fringe: Vec<Contact> = anchors
        .par_iter()
        .filter_map(|&(w, other, c)| {
            // The anchor lies on `other` within the gap, so `other` is
            // within this reach of w.
            let reach =
                crate::geometry::norm(crate::geometry::sub(v[w as usize], v[c as usize])) + gap;
            let hit =
                bvh.closest_filtered_within(v[w as usize], reach, |t| body[t as usize] == other)?;
            Some(Contact {
                vertex: w,
                triangle: hit.triangle,
                bary: hit.closest.bary,
                fringe: true,
            })
        })
        .collect();
    let mut all = on;
    all.extend(fringe);
    all
}

/// Lowers each contact vertex's size to the other body's size interpolated at
/// its closest point, all from the sizes as they were on entry (the result
/// does not depend on the order). Returns how many sizes went down by more
/// than `rel` (relative). O(contacts).
pub fn unify(h: &mut [f64], triangles: &[[u32; 3]], contacts: &[Contact], rel: f64) -> usize {
    let mut lowered: Vec<(u32, f64)> = contacts
        .iter()
        .filter_map(|c| {
            let t = triangles[c.triangle as usize];
            let corners = t.map(|k| h[k as usize]);
            // Within the corners' range despite the rounding of the coordinates.
            let other = (0..3)
                .map(|k| c.bary[k] * corners[k])
                .sum::<f64>()
                .max(corners[0].min(corners[1]).min(corners[2]));
            let own = h[c.vertex as usize];
            (other < own).then_some((c.vertex, other))
        })
        .collect();
    // Several entries of one vertex (several bodies): the smallest wins, and
    // the vertex counts once.
    lowered.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    lowered.dedup_by_key(|x| x.0);
    let mut changed = 0;
    for (vi, hv) in lowered {
        let own = &mut h[vi as usize];
        if hv < *own * (1.0 - rel) {
            changed += 1;
        }
        *own = hv;
    }
    changed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{BuildOptions, Grid};

    /// Two unit squares (two triangles each) in the plane z = 0 and z = `dz`,
    /// the second shifted in x by 0.5 so its vertices fall inside the first's
    /// triangles.
    fn two_sheets(dz: f64) -> Grid {
        let mut v = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        v.extend(v.clone().iter().map(|p| [p[0] + 0.5, p[1], dz]));
        let t = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
        Grid::from_arrays(v, t, None, &BuildOptions::default()).unwrap()
    }

    #[test]
    fn coincident_sheets_take_the_smaller_size() {
        let g = two_sheets(0.0);
        assert_eq!(g.topology().body_count, 2);
        let all = contacts(&g, 1e-6);
        // The fringe: every other vertex shares a triangle with one on the
        // other sheet.
        assert_eq!(all.len(), g.vertices().len());
        let c: Vec<Contact> = all.iter().copied().filter(|c| !c.fringe).collect();
        // Sheet 1's vertices at x = 1 and sheet 2's at x = 0.5 lie on the other.
        let mut on: Vec<u32> = c.iter().map(|c| c.vertex).collect();
        on.sort();
        let expect: Vec<u32> = {
            let v = g.vertices();
            let mut e: Vec<u32> = (0..v.len() as u32)
                .filter(|&i| {
                    let p = v[i as usize];
                    (p[0] - 1.0).abs() < 1e-12 || (p[0] - 0.5).abs() < 1e-12
                })
                .collect();
            e.sort();
            e
        };
        assert_eq!(on, expect);
        // Sheet 1 fine (0.1), sheet 2 coarse (1.0): the coarse sheet's vertices
        // on the fine one drop to 0.1, the fine sheet keeps 0.1.
        let v = g.vertices();
        let body = &g.topology().face_body;
        let mut vb = vec![0u32; v.len()];
        for (f, t) in g.triangles().iter().enumerate() {
            for &i in t {
                vb[i as usize] = body[f];
            }
        }
        let mut h: Vec<f64> = vb.iter().map(|&b| if b == 0 { 0.1 } else { 1.0 }).collect();
        let before = h.clone();
        let n = unify(&mut h, g.triangles(), &c, 1e-9);
        assert_eq!(n, 2);
        for i in 0..v.len() {
            let touching = on.binary_search(&(i as u32)).is_ok();
            if touching && vb[i] == 1 {
                assert!((h[i] - 0.1).abs() < 1e-12, "vertex {i}: {}", h[i]);
            } else {
                assert_eq!(h[i], before[i], "vertex {i}");
            }
        }
        // A second pass changes nothing.
        assert_eq!(unify(&mut h, g.triangles(), &c, 1e-9), 0);
    }

    /// A small plate (size 0.1) lying on a coarse square (size 1, two
    /// triangles, no corner under the plate): the square's triangles straddle
    /// the plate's edge.
    #[test]
    fn a_coarse_triangle_under_a_plate_follows_the_plate() {
        let mut v = vec![
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [4.0, 4.0, 0.0],
            [0.0, 4.0, 0.0],
        ];
        v.extend([
            [1.0, 1.0, 0.0],
            [2.0, 1.0, 0.0],
            [2.0, 2.0, 0.0],
            [1.0, 2.0, 0.0],
        ]);
        let t = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
        let g = Grid::from_arrays(v, t, None, &BuildOptions::default()).unwrap();
        let all = contacts(&g, 1e-6);
        let plate = |i: u32| i >= 4;
        assert!(all.iter().all(|c| plate(c.vertex) != c.fringe));
        assert_eq!(all.len(), 8);
        let mut h = vec![1.0, 1.0, 1.0, 1.0, 0.1, 0.1, 0.1, 0.1];
        unify(&mut h, g.triangles(), &all, 0.0);
        // The square's corners took the plate's size at their closest points
        // on it, so inside the plate both interpolate the same 0.1.
        assert_eq!(h, vec![0.1; 8]);
        // Without the fringe the square would still say 1 under the plate.
        let mut h = vec![1.0, 1.0, 1.0, 1.0, 0.1, 0.1, 0.1, 0.1];
        let on: Vec<Contact> = all.iter().copied().filter(|c| !c.fringe).collect();
        unify(&mut h, g.triangles(), &on, 0.0);
        assert_eq!(&h[..4], &[1.0; 4]);
    }

    /// Three bodies meet at a vertex: the nearest other body (coincident) is
    /// not the smallest; the vertex takes the smallest of both.
    #[test]
    fn a_vertex_on_two_other_bodies_takes_the_smallest() {
        let square = |x: f64, y: f64, z: f64| {
            [
                [x, y, z],
                [x + 1.0, y, z],
                [x + 1.0, y + 1.0, z],
                [x, y + 1.0, z],
            ]
        };
        let mut v = square(0.0, 0.0, 0.0).to_vec();
        v.extend(square(0.5, 0.5, 0.0));
        v.extend(square(0.6, 0.4, 1e-7));
        let t = (0..3u32)
            .flat_map(|b| [[4 * b, 4 * b + 1, 4 * b + 2], [4 * b, 4 * b + 2, 4 * b + 3]])
            .collect();
        let g = Grid::from_arrays(v, t, None, &BuildOptions::default()).unwrap();
        assert_eq!(g.topology().body_count, 3);
        let all = contacts(&g, 1e-6);
        // Vertex 2 (1, 1, 0) of the first square lies on both others.
        let on2: Vec<&Contact> = all.iter().filter(|c| c.vertex == 2 && !c.fringe).collect();
        assert_eq!(on2.len(), 2);
        let mut h = [[1.0; 4], [0.5; 4], [0.2; 4]].concat();
        unify(&mut h, g.triangles(), &all, 0.0);
        assert!((h[2] - 0.2).abs() < 1e-12, "{}", h[2]);
    }

    #[test]
    fn a_gap_is_not_a_contact() {
        let g = two_sheets(1e-3);
        assert!(contacts(&g, 1e-4).is_empty());
        assert!(!contacts(&g, 1e-2).is_empty());
    }
}
