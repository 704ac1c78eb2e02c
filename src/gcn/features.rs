//! The model's inputs (DESIGN §3.7): two features per vertex, eight per
//! edge, and padded neighbour lists, computed from a grid being simplified.
//! One function, [`graph`], serves training-data export
//! ([`super::dataset`]) and inference ([`super::scorer`]), so both see
//! exactly the same numbers.
//!
//! Every feature is unit-free (the same shape at any scale gives the same
//! features) and symmetric in the edge's two ends (ends are sorted or
//! combined symmetrically), so the model cannot depend on the scale of the
//! part or on the direction an edge is stored in.
//!
//! **Node features** for vertex `v` with size `h_v`:
//! 1. `ln(h_v / h_ref)`, `h_ref` the median size over the live vertices;
//! 2. `LBO_v · h_v`, `LBO_v = |Σ_j ½(cot α_ij + cot β_ij)(h_j − h_v)| / A_v`
//!    (cotangent weights, mixed Voronoi area; [`crate::sizing::lbo`]).
//!
//! **Edge features** for edge `ab` of length `L`, with faces `f₁`, `f₂` and
//! their apexes `c₁`, `c₂` (a boundary edge repeats its one face):
//! 1. `LBO_e · h_e`, `LBO_e = ½(LBO_a + LBO_b)`, `h_e = ½(h_a + h_b)`;
//! 2. the dihedral angle `acos(n₁·n₂)` in radians (0 where flat);
//! 3. 4. the opposite angles at `c₁` and `c₂`, sorted (min, max), radians;
//! 5. 6. the heights of `c₁` and `c₂` over the edge divided by `L`, sorted;
//! 7. `L / L̄`, `L̄` the mean length of the live edges;
//! 8. the angle between the area-weighted vertex normals at `a` and `b`,
//!    radians.
//!
//! **Neighbour lists**: `K` = the largest valence; for node `i`, slot `k <
//! valence` holds a neighbour and the edge to it (in the order of the
//! vertex's outgoing half-edges), padding slots hold `i` itself, edge 0 and
//! mask 0. The model aggregates with Gather and a masked sum (deterministic
//! operations; no scatter).
//!
//! Cost: O(F + E + N·K), parallel over vertices and edges (rayon); the
//! result does not depend on the thread count (per-element work collected
//! in order; sums over the grid in a fixed order).

use super::runtime::{GraphInputs, EDGE_FEATURES};
use crate::error::{Error, Result};
use crate::geometry::{add, cross, dot, norm, sub};
use crate::mesh::halfedge::{HalfedgeMesh, NONE};
use crate::sizing::lbo::vertex_lbo;
use rayon::prelude::*;

/// The model's inputs for the live part of `mesh`, with the mesh edge of
/// each graph edge and the mesh vertex of each node (both ascending).
#[derive(Debug, Clone, Default)]
pub struct Graph {
    /// The tensors.
    pub inputs: GraphInputs,
    /// Mesh edge id of graph edge `i`.
    pub edges: Vec<u32>,
    /// Mesh vertex id of node `i`.
    pub nodes: Vec<u32>,
}

/// Unit normal of `n` (zero stays zero).
fn unit_or_zero(n: [f64; 3]) -> [f64; 3] {
    let l = norm(n);
    if l > 0.0 {
        [n[0] / l, n[1] / l, n[2] / l]
    } else {
        [0.0; 3]
    }
}

/// Angle between two vectors in radians (0 when either is zero).
fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    let (la, lb) = (norm(a), norm(b));
    if la == 0.0 || lb == 0.0 {
        return 0.0;
    }
    // atan2 of |a×b| and a·b is accurate at both ends of the range.
    norm(cross(a, b)).atan2(dot(a, b))
}

/// Features of `mesh` as it is now (live vertices, edges and faces; sizes
/// from `mesh.vertex_size`). Errors when the mesh has no live edge or a
/// size is not a finite number > 0. O(F + E + N·K), parallel.
pub fn graph(mesh: &HalfedgeMesh) -> Result<Graph> {
    let nodes: Vec<u32> = mesh.vertices().filter(|&v| !mesh.is_isolated(v)).collect();
    let edges: Vec<u32> = mesh.edges().collect();
    if edges.is_empty() {
        return Err(Error::Empty("no edge to score".into()));
    }
    let mut node_of = vec![u32::MAX; mesh.n_vertices()];
    for (i, &v) in nodes.iter().enumerate() {
        node_of[v as usize] = i as u32;
    }
    let mut edge_of = vec![u32::MAX; mesh.n_edges()];
    for (i, &e) in edges.iter().enumerate() {
        edge_of[e as usize] = i as u32;
    }
    let h = &mesh.vertex_size;
    if nodes
        .iter()
        .any(|&v| !(h[v as usize].is_finite() && h[v as usize] > 0.0))
    {
        return Err(Error::InvalidSize(
            "a vertex of the grid has no valid size".into(),
        ));
    }
    let mut sorted: Vec<f64> = nodes.iter().map(|&v| h[v as usize]).collect();
    sorted.sort_by(f64::total_cmp);
    let h_ref = sorted[sorted.len() / 2];
    let lbo = vertex_lbo(
        &mesh.positions,
        mesh.faces().map(|f| mesh.face_vertices(f)),
        h,
    );
    // Area-weighted vertex normals (sums in the fixed order of each star).
    let vnormal: Vec<[f64; 3]> = nodes
        .par_iter()
        .map(|&v| {
            let mut n = [0.0; 3];
            for f in mesh.vertex_faces(v) {
                n = add(n, mesh.face_normal2(f));
            }
            n
        })
        .collect();
    let mean_len = edges.iter().map(|&e| mesh.edge_length(e)).sum::<f64>() / edges.len() as f64;
    let k = nodes
        .iter()
        .map(|&v| mesh.valence(v))
        .max()
        .unwrap_or(1)
        .max(1);

    let node_x: Vec<f32> = nodes
        .par_iter()
        .flat_map_iter(|&v| {
            let hv = h[v as usize];
            [(hv / h_ref).ln() as f32, (lbo[v as usize] * hv) as f32]
        })
        .collect();
    let per_edge: Vec<([f32; EDGE_FEATURES], [i64; 2])> = edges
        .par_iter()
        .map(|&e| {
            let [a, b] = mesh.edge_vertices(e);
            let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            let ab = sub(pb, pa);
            let len = norm(ab);
            let he = 0.5 * (h[a as usize] + h[b as usize]);
            let lbo_e = 0.5 * (lbo[a as usize] + lbo[b as usize]);
            // Per face: unit normal, opposite angle, height / length.
            let mut sides = Vec::with_capacity(2);
            for hh in [2 * e, 2 * e + 1] {
                let f = mesh.face(hh);
                if f == NONE {
                    continue;
                }
                let c = mesh.positions[mesh.to_vertex(mesh.next(hh)) as usize];
                let n2 = mesh.face_normal2(f);
                let opp = angle(sub(pa, c), sub(pb, c));
                let height = if len > 0.0 { norm(n2) / len } else { 0.0 };
                let ratio = if len > 0.0 { height / len } else { 0.0 };
                sides.push((unit_or_zero(n2), opp, ratio));
            }
            if sides.len() == 1 {
                sides.push(sides[0]);
            }
            let (s0, s1) = match sides.as_slice() {
                [x, y] => (*x, *y),
                _ => (([0.0; 3], 0.0, 0.0), ([0.0; 3], 0.0, 0.0)),
            };
            let dihedral = angle(s0.0, s1.0);
            let na = node_of[a as usize] as usize;
            let nb = node_of[b as usize] as usize;
            let normals = angle(vnormal[na], vnormal[nb]);
            let x = [
                lbo_e * he,
                dihedral,
                s0.1.min(s1.1),
                s0.1.max(s1.1),
                s0.2.min(s1.2),
                s0.2.max(s1.2),
                if mean_len > 0.0 { len / mean_len } else { 0.0 },
                normals,
            ]
            .map(|x| x as f32);
            (x, [na as i64, nb as i64])
        })
        .collect();
    let mut edge_x = Vec::with_capacity(edges.len() * EDGE_FEATURES);
    let mut edge_ends = Vec::with_capacity(edges.len() * 2);
    for (x, ends) in &per_edge {
        edge_x.extend_from_slice(x);
        edge_ends.extend_from_slice(ends);
    }
    let slots: Vec<(Vec<i64>, Vec<i64>, Vec<f32>)> = nodes
        .par_iter()
        .enumerate()
        .map(|(i, &v)| {
            let mut nn = vec![i as i64; k];
            let mut ne = vec![0i64; k];
            let mut nm = vec![0f32; k];
            for (s, o) in mesh.outgoing(v).enumerate().take(k) {
                nn[s] = node_of[mesh.to_vertex(o) as usize] as i64;
                ne[s] = edge_of[mesh.edge(o) as usize] as i64;
                nm[s] = 1.0;
            }
            (nn, ne, nm)
        })
        .collect();
    let n = nodes.len();
    let mut nbr_node = Vec::with_capacity(n * k);
    let mut nbr_edge = Vec::with_capacity(n * k);
    let mut nbr_mask = Vec::with_capacity(n * k);
    for (nn, ne, nm) in slots {
        nbr_node.extend(nn);
        nbr_edge.extend(ne);
        nbr_mask.extend(nm);
    }
    let inputs = GraphInputs {
        n_nodes: n,
        n_edges: edges.len(),
        k,
        node_x,
        edge_x,
        edge_ends,
        nbr_node,
        nbr_edge,
        nbr_mask,
    };
    inputs.check()?;
    Ok(Graph {
        inputs,
        edges,
        nodes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{BuildOptions, Grid};

    fn sized_mesh(scale: f64) -> HalfedgeMesh {
        let (v, t) = crate::test_shapes::unit_square(12, |x, y| 0.3 * (x * 3.0).sin() * y);
        let v: Vec<[f64; 3]> = v.iter().map(|p| p.map(|x| x * scale)).collect();
        let h: Vec<f64> = v
            .iter()
            .map(|p| scale * (0.1 + 0.05 * p[0] / scale))
            .collect();
        let g = Grid::from_arrays(v, t, Some(h.clone()), &BuildOptions::default()).unwrap();
        let (mut m, _) = HalfedgeMesh::from_grid(&g, None);
        for i in 0..m.n_vertices() {
            m.vertex_size[i] = h[m.vertex_origin[i] as usize];
        }
        m
    }

    #[test]
    fn features_are_unit_free_and_finite() {
        let a = graph(&sized_mesh(1.0)).unwrap();
        let b = graph(&sized_mesh(1e6)).unwrap();
        assert_eq!(a.inputs.n_edges, b.inputs.n_edges);
        for (x, y) in a.inputs.edge_x.iter().zip(&b.inputs.edge_x) {
            assert!((x - y).abs() <= 1e-4 * (1.0 + x.abs()), "{x} vs {y}");
        }
        for (x, y) in a.inputs.node_x.iter().zip(&b.inputs.node_x) {
            assert!((x - y).abs() <= 1e-4 * (1.0 + x.abs()), "{x} vs {y}");
        }
        a.inputs.check().unwrap();
        assert!(a.inputs.k >= 6);
    }

    #[test]
    fn neighbour_lists_match_the_edges() {
        let g = graph(&sized_mesh(1.0)).unwrap();
        let gi = &g.inputs;
        for i in 0..gi.n_nodes {
            for s in 0..gi.k {
                if gi.nbr_mask[i * gi.k + s] == 0.0 {
                    assert_eq!(gi.nbr_node[i * gi.k + s], i as i64);
                    continue;
                }
                let e = gi.nbr_edge[i * gi.k + s] as usize;
                let ends = [gi.edge_ends[2 * e], gi.edge_ends[2 * e + 1]];
                assert!(ends.contains(&(i as i64)));
                assert!(ends.contains(&gi.nbr_node[i * gi.k + s]));
            }
        }
    }

    #[test]
    fn same_bits_on_one_and_two_threads() {
        let m = sized_mesh(1.0);
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| graph(&m).unwrap());
        let two = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap()
            .install(|| graph(&m).unwrap());
        assert_eq!(one.inputs, two.inputs);
    }
}
