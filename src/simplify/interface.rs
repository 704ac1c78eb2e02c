//! Interfaces between touching bodies, once the loop is done.
//!
//! Where two bodies of an assembly touch, each body carries its own
//! triangulation of the interface and its own vertex sizes. The loop already
//! gives every vertex it places at a contact the agreed size (the smallest
//! of the touching bodies' dense sizes there, [`super::Target::on_patch`]),
//! but the two bodies are coarsened independently, so between their vertices
//! each body interpolates over triangles the other does not share and the
//! two fields drift apart (up to the size tolerance on each side).
//!
//! This pass lowers, at every vertex lying on another body (a face of it
//! within the contact gap), the vertex's size to the other bodies' sizes
//! interpolated at that point: `h_v ← min(h_v, h_B(v))`. Rounds repeat
//! (Jacobi: every vertex reads the sizes of the round before, so the result
//! does not depend on the order or the thread count) until no size drops by
//! more than one part in 10⁶, or [`MAX_ROUNDS`]. Each round only lowers
//! sizes, toward a field that is itself graded, so gradation is kept (the
//! minimum of two fields of slope ≤ g has slope ≤ g), and no face is added.
//! What remains is the second-order part: where one body's piecewise-linear
//! field bends inside a triangle of the other.
//!
//! Cost: one bounded search per vertex to find the contact vertices
//! (O(V log F)), then O(k · b log F) per round for k contact vertices with b
//! other bodies each; parallel. Nothing on a grid of one body.

use crate::error::Result;
use crate::mesh::Grid;
use crate::query::interpolate;
use rayon::prelude::*;

/// Most rounds of [`unify`].
pub const MAX_ROUNDS: usize = 8;

/// Another body's closest triangle to a vertex, and the barycentric
/// coordinates of that closest point.
type Found = (u32, [f64; 3]);

/// Relative drop below which a round changes nothing.
const STILL: f64 = 1e-6;

/// Lowers the sizes at contact vertices of `grid` to the touching bodies'
/// interpolated sizes (module doc). Returns the number of vertices lowered.
/// Errors only if the lowered sizes are refused (they cannot be: they are
/// minima of valid sizes).
pub fn unify(grid: &mut Grid) -> Result<usize> {
    let topo = grid.topology();
    let Some(sizes) = grid.sizes() else {
        return Ok(0);
    };
    if topo.body_count < 2 {
        return Ok(0);
    }
    let gap = grid.contact_gap();
    let body = &topo.face_body;
    let tris = grid.triangles();
    let verts = grid.vertices();
    // Body of each vertex (any face of it: bodies share no vertex).
    let mut vbody = vec![u32::MAX; verts.len()];
    for (f, t) in tris.iter().enumerate() {
        for &v in t {
            vbody[v as usize] = body[f];
        }
    }
    // Per contact vertex, the other bodies' closest triangles and their
    // barycentric coordinates (fixed: positions do not move).
    let contacts: Vec<(u32, Vec<Found>)> = (0..verts.len() as u32)
        .into_par_iter()
        .filter_map(|v| {
            let own = vbody[v as usize];
            if own == u32::MAX {
                return None;
            }
            let found = grid.other_bodies_within(verts[v as usize], own, gap);
            (!found.is_empty()).then_some((v, found.to_vec()))
        })
        .collect();
    if contacts.is_empty() {
        return Ok(0);
    }
    let mut h = sizes.to_vec();
    let mut lowered = vec![false; h.len()];
    for _ in 0..MAX_ROUNDS {
        let next: Vec<(u32, f64)> = contacts
            .par_iter()
            .filter_map(|(v, others)| {
                let own = h[*v as usize];
                let low = others
                    .iter()
                    .map(|&(t, b)| interpolate(tris[t as usize].map(|k| h[k as usize]), b))
                    .fold(own, f64::min);
                (low < own * (1.0 - STILL)).then_some((*v, low))
            })
            .collect();
        if next.is_empty() {
            break;
        }
        for (v, low) in next {
            h[v as usize] = low;
            lowered[v as usize] = true;
        }
    }
    let count = lowered.iter().filter(|&&x| x).count();
    grid.set_sizes(h)?;
    Ok(count)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::BuildOptions;

    /// Two unit squares, one on top of the other (z = 0), triangulated
    /// differently: the lower one's sizes 1, the upper one's 0.5 except one
    /// corner at 2.
    fn stacked() -> Grid {
        let v = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let t = vec![[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6]];
        let s = vec![1.0, 1.0, 1.0, 1.0, 0.5, 2.0, 0.5, 0.5];
        let opts = BuildOptions {
            weld_relative_tolerance: None,
            orient: false,
        };
        let g = Grid::from_arrays(v, t, Some(s), &opts).unwrap();
        assert_eq!(g.topology().body_count, 2);
        g
    }

    #[test]
    fn contact_vertices_take_the_smaller_size() {
        let mut g = stacked();
        let n = unify(&mut g).unwrap();
        let h = g.sizes().unwrap();
        // Every vertex of the lower square lies on the upper one: lowered to
        // the upper's size there; the upper's corner at 2 to the lower's 1.
        assert_eq!(&h[..4], &[0.5, 1.0, 0.5, 0.5]);
        assert_eq!(&h[4..], &[0.5, 1.0, 0.5, 0.5]);
        assert_eq!(n, 4);
        // A second pass changes nothing.
        assert_eq!(unify(&mut g).unwrap(), 0);
    }

    #[test]
    fn one_body_is_left_alone() {
        let opts = BuildOptions::default();
        let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let mut g =
            Grid::from_arrays(v, vec![[0, 1, 2]], Some(vec![1.0, 2.0, 3.0]), &opts).unwrap();
        assert_eq!(unify(&mut g).unwrap(), 0);
        assert_eq!(g.sizes().unwrap(), &[1.0, 2.0, 3.0]);
    }
}
