//! Ranking and selection (DESIGN §3.5 steps 1, 2 and 4): edges ordered by
//! the LBO of the size field, and the greedy choice of the lowest scores
//! whose closed 1-rings are pairwise disjoint.

use crate::mesh::halfedge::HalfedgeMesh;
use crate::sizing::lbo::vertex_lbo;

/// Per-edge LBO value `½(LBO_v(a) + LBO_v(b))` for every edge slot (∞ for
/// removed edges), from the mesh's current positions and sizes. O(F + E).
pub fn edge_lbo(mesh: &HalfedgeMesh) -> Vec<f64> {
    let faces = mesh.faces().map(|f| mesh.face_vertices(f));
    let lv = vertex_lbo(&mesh.positions, faces, &mesh.vertex_size);
    (0..mesh.n_edges() as u32)
        .map(|e| {
            if mesh.edge_deleted(e) {
                f64::INFINITY
            } else {
                let [a, b] = mesh.edge_vertices(e);
                0.5 * (lv[a as usize] + lv[b as usize])
            }
        })
        .collect()
}

/// The closed 1-ring of an edge: its ends and all their neighbours.
pub fn closed_ring(mesh: &HalfedgeMesh, e: u32, out: &mut Vec<u32>) {
    out.clear();
    for v in mesh.edge_vertices(e) {
        out.push(v);
        out.extend(mesh.neighbors(v));
    }
}

/// Greedy selection: walks `ranked` (edges in the order to prefer) and keeps
/// an edge when its closed 1-ring shares no vertex with the closed 1-ring of
/// an edge already kept, up to `limit` edges. `used` has one flag per vertex
/// slot: a vertex flagged on entry blocks every ring through it (GCN-ABGS's
/// rounds pass the rings of edges already accepted that way); the function's
/// own flags are cleared again on return, so `used` leaves as it came.
/// O(Σ ring sizes).
pub fn disjoint_rings(
    mesh: &HalfedgeMesh,
    ranked: &[u32],
    limit: usize,
    used: &mut [bool],
) -> Vec<u32> {
    let mut chosen = Vec::new();
    let mut ring = Vec::new();
    let mut marked = Vec::new();
    for &e in ranked {
        if chosen.len() >= limit {
            break;
        }
        closed_ring(mesh, e, &mut ring);
        if ring.iter().any(|&v| used[v as usize]) {
            continue;
        }
        for &v in &ring {
            used[v as usize] = true;
            marked.push(v);
        }
        chosen.push(e);
    }
    for v in marked {
        used[v as usize] = false;
    }
    chosen
}
