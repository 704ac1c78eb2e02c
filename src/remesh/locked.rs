//! Locked edges (non-manifold in the input: bodies touching along them) are
//! never changed by the local operations, but one longer than its target
//! would force ever flatter triangles against it. So before remeshing each is
//! cut into pieces no longer than its target, identically in every body that
//! shares it (same points, same new locked vertex ids), so the copies still
//! merge into one non-manifold polyline on output.

use crate::geometry::{lerp, norm, sub};
use crate::mesh::halfedge::{HalfedgeMesh, E_LOCKED, NONE, V_CORNER, V_FEATURE, V_LOCKED};
use std::collections::BTreeMap;

/// Splits every locked edge longer than `target` (at its midpoint) into equal
/// pieces; new vertices are locked corners with origins numbered from
/// `next_origin` up, shared by the copies of one input edge. Returns the
/// number of new pieces.
pub fn presplit(
    mesh: &mut HalfedgeMesh,
    target: impl Fn([f64; 3]) -> f64,
    next_origin: u32,
) -> usize {
    // Copies of one input edge share the origins of their ends.
    let mut groups: BTreeMap<(u32, u32), Vec<u32>> = BTreeMap::new();
    for e in 0..mesh.n_edges() as u32 {
        if mesh.edge_deleted(e) || mesh.edge_flags[e as usize] & E_LOCKED == 0 {
            continue;
        }
        let [a, b] = mesh.edge_vertices(e);
        let (oa, ob) = (
            mesh.vertex_origin[a as usize],
            mesh.vertex_origin[b as usize],
        );
        if oa == NONE || ob == NONE {
            continue;
        }
        groups.entry((oa.min(ob), oa.max(ob))).or_default().push(e);
    }
    let mut origin = next_origin;
    let mut pieces = 0;
    for ((o_lo, _), edges) in groups {
        // Geometry from the first copy, oriented from the end of lower origin.
        let [a, b] = mesh.edge_vertices(edges[0]);
        let (pa, pb) = if mesh.vertex_origin[a as usize] == o_lo {
            (mesh.positions[a as usize], mesh.positions[b as usize])
        } else {
            (mesh.positions[b as usize], mesh.positions[a as usize])
        };
        let len = norm(sub(pa, pb));
        let t = target(lerp(pa, pb, 0.5));
        if !(t > 0.0 && len > t) {
            continue;
        }
        let k = ((len / t).ceil() as usize).clamp(2, 1 << 16);
        let points: Vec<[f64; 3]> = (1..k).map(|i| lerp(pa, pb, i as f64 / k as f64)).collect();
        let ids: Vec<u32> = (0..k as u32 - 1).map(|i| origin + i).collect();
        origin += k as u32 - 1;
        for &e in &edges {
            let [x, y] = mesh.edge_vertices(e);
            let (mut from, to) = if mesh.vertex_origin[x as usize] == o_lo {
                (x, y)
            } else {
                (y, x)
            };
            let mut cur = e;
            for (p, &id) in points.iter().zip(&ids) {
                let v = mesh.split(cur, *p);
                mesh.vertex_flags[v as usize] = V_LOCKED | V_CORNER | V_FEATURE;
                mesh.vertex_origin[v as usize] = id;
                mesh.vertex_size[v as usize] = t;
                // Continue with the piece from the new vertex to the far end.
                let Some(h) = mesh.find_halfedge(v, to) else {
                    break;
                };
                from = v;
                cur = mesh.edge(h);
            }
            let _ = from;
            pieces += k - 1;
        }
    }
    pieces
}
