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

use crate::mesh::Grid;
use rayon::prelude::*;

/// A vertex lying on another body's face (within the contact gap).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The vertex.
    pub vertex: u32,
    /// The other body's closest triangle.
    pub triangle: u32,
    /// Barycentric coordinates of the closest point on that triangle.
    pub bary: [f64; 3],
}

/// Every vertex within `gap` of a face of another body, with that face.
/// Empty for a single body. Parallel, deterministic (closest face, ties to the
/// lowest index). O(V log F) for a small `gap`.
pub fn contacts(grid: &Grid, gap: f64) -> Vec<Contact> {
    let topo = grid.topology();
    if topo.body_count < 2 || gap.is_nan() || gap <= 0.0 {
        return Vec::new();
    }
    let v = grid.vertices();
    let body = &topo.face_body;
    let bvh = grid.bvh();
    (0..v.len())
        .into_par_iter()
        .filter_map(|vi| {
            // A vertex's own body: that of any of its faces (welded bodies are
            // split into components, so all its faces share one body).
            let own = body[*topo.faces_of_vertex(vi).first()? as usize];
            let hit = bvh.closest_filtered_within(v[vi], gap, |t| body[t as usize] != own)?;
            Some(Contact {
                vertex: vi as u32,
                triangle: hit.triangle,
                bary: hit.closest.bary,
            })
        })
        .collect()
}

/// Lowers each contact vertex's size to the other body's size interpolated at
/// its closest point, all from the sizes as they were on entry (the result
/// does not depend on the order). Returns how many sizes went down by more
/// than `rel` (relative). O(contacts).
pub fn unify(h: &mut [f64], triangles: &[[u32; 3]], contacts: &[Contact], rel: f64) -> usize {
    let lowered: Vec<(u32, f64)> = contacts
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
        let c = contacts(&g, 1e-6);
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

    #[test]
    fn a_gap_is_not_a_contact() {
        let g = two_sheets(1e-3);
        assert!(contacts(&g, 1e-4).is_empty());
        assert!(!contacts(&g, 1e-2).is_empty());
    }
}
