//! Proximity (thin walls, slots, gaps between bodies) by ray casting.
//!
//! From every vertex, for each of its patch normals n (and, on feature lines,
//! their bisector), rays along −n (through
//! the material: wall thickness) and +n (across empty space: gaps to other
//! sheets and to other bodies) find the nearest triangle that *faces back*
//! (`n · n_hit < −0.2`, i.e. an opposite wall, not a perpendicular one seen
//! edge-on). Ignored: the vertex's own faces, hits closer than the contact gap
//! (touching bodies, and the tessellation noise between coincident curved faces:
//! a conformal interface, not a gap), and hits beyond `max_gap`. The gap is the smallest such distance.
//!
//! **Gaps to another body the field cannot resolve.** Sizing asks for
//! `n_gap` elements across a gap, so a gap narrower than `n_gap · hmin`
//! would need elements below `hmin` and gets `hmin` at best: the field cannot
//! resolve it. Between two *bodies* such a gap is also what independently
//! tessellated coincident faces look like: two faceted cylinders of one
//! radius (a shaft in its bore) stand apart by anything from 0 to the facets'
//! sagitta `r·(1 − cos(π/n))` (0.14 mm for r = 4 mm and 12 facets, twice the
//! bracket assembly's contact gap), so the distance flickers across the
//! contact gap from vertex to vertex, and sizes would jump between the
//! contact's and `hmin` along the interface. [`gaps`] therefore ignores
//! another body's faces nearer than `unresolved` (sizing passes
//! `n_gap · hmin`): at the field's resolution the two bodies touch there, and
//! the contact rule ([`super::contact`]) gives them one size. A thin wall or
//! slot of one body is not affected.

use super::normals::PatchNormals;
use crate::geometry::*;
use crate::mesh::Grid;
use rayon::prelude::*;

/// Cosine below which a hit face counts as facing back.
pub(crate) const FACING_BACK: f64 = -0.2;

/// Smallest gap per vertex (`+inf` where no opposite wall lies within `max_gap`),
/// another body's faces nearer than `unresolved` left out (module doc).
/// O(V log F), parallel over vertices.
pub fn gaps(
    grid: &Grid,
    normals: &PatchNormals,
    contact_gap: f64,
    unresolved: f64,
    max_gap: f64,
) -> Vec<f64> {
    gaps_with(grid, normals, contact_gap, unresolved, |_| max_gap, false)
}

/// Clearance per vertex: [`gaps`] with a limit per vertex (`limit[v]`: rays
/// from `v` stop there), where a face of another body counts whichever way
/// it faces (two bodies' parallel sheets, one inside the other, are still two
/// sheets a query can confuse), and so does the nearest point of another
/// body in any direction (not closer than the contact gap). O(V log F),
/// parallel over vertices.
pub fn clearances(
    grid: &Grid,
    normals: &PatchNormals,
    contact_gap: f64,
    limit: &[f64],
) -> Vec<f64> {
    gaps_with(grid, normals, contact_gap, contact_gap, |v| limit[v], true)
}

fn gaps_with(
    grid: &Grid,
    normals: &PatchNormals,
    contact_gap: f64,
    unresolved: f64,
    max_gap: impl Fn(usize) -> f64 + Sync,
    other_bodies: bool,
) -> Vec<f64> {
    let v = grid.vertices();
    let topo = grid.topology();
    let bvh = grid.bvh();
    (0..v.len())
        .into_par_iter()
        .map(|vi| {
            let own = topo.faces_of_vertex(vi);
            let body = own.first().map(|&f| topo.face_body[f as usize]);
            let max_gap = max_gap(vi);
            let mut best = f64::INFINITY;
            let range = normals.range(vi);
            // On a feature line or corner, rays along one patch normal graze the
            // other patches; the bisector of the patch normals sees the wall
            // diagonally instead.
            let bisector = if range.len() > 1 {
                let s = range
                    .clone()
                    .fold([0.0; 3], |a, e| add(a, normals.normal[e]));
                let l = norm(s);
                (l > 1e-9).then(|| scale(s, 1.0 / l))
            } else {
                None
            };
            let dirs = range.map(|e| normals.normal[e]).chain(bisector);
            for n in dirs {
                if norm2(n) == 0.0 {
                    continue;
                }
                for dir in [scale(n, -1.0), n] {
                    let limit = best.min(max_gap);
                    let hit = bvh.first_hit(v[vi], dir, contact_gap, limit, |tri, t| {
                        let other = Some(topo.face_body[tri as usize]) != body;
                        own.binary_search(&tri).is_err()
                            && !(other && t < unresolved)
                            && (dot(n, normals.face_normal[tri as usize]) < FACING_BACK
                                || (other_bodies && other))
                    });
                    if let Some((_, t)) = hit {
                        best = best.min(t);
                    }
                }
            }
            // Another body beside the vertex, in any direction (an edge or a
            // corner of it near a face of this one is missed by the rays).
            if let (true, Some(body)) = (other_bodies, body) {
                let near = bvh.closest_filtered_within(v[vi], best.min(max_gap), |t| {
                    topo.face_body[t as usize] != body
                });
                if let Some(h) = near {
                    let d = h.closest.dist2.sqrt();
                    if d >= contact_gap {
                        best = best.min(d);
                    }
                }
            }
            best
        })
        .collect()
}
