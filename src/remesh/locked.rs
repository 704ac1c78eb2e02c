//! Locked edges (non-manifold in the input: bodies touching along them, and
//! the creases where a large body is cut into pieces) are never changed by
//! the local operations, but one longer than its target would force ever
//! flatter triangles against it. So before remeshing each is cut into
//! pieces no longer than the target along it, graded where the target
//! changes (a piece several targets long at one end let splits put free
//! vertices exactly on it, in flat triangles nothing may undo),
//! identically in every body or piece that shares it (same points, same new
//! locked vertex ids), so the copies still merge into one non-manifold
//! polyline, or one seam, on output.

use crate::geometry::{lerp, norm, sub};
use crate::mesh::halfedge::{HalfedgeMesh, E_LOCKED, NONE, V_CORNER, V_FEATURE, V_LOCKED};
use std::collections::BTreeMap;

/// Splits every locked edge longer than `target` along it into pieces graded
/// by the target ([`graded`]: bisection while a piece is longer than the
/// least of its midpoint's target and its ends' mean); new vertices are
/// locked corners with their own target as size and origins numbered from
/// `next_origin` up, shared by the copies of one input edge (the points are
/// computed once per input edge, from the end of lower origin, so every
/// copy is cut at the same points). Returns the number of new pieces.
/// Cost: O(pieces) target evaluations and splits.
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
        let ends = [target(pa), target(pb)];
        let mut points: Vec<([f64; 3], f64)> = Vec::new();
        graded(&target, pa, pb, ends, 0, &mut points);
        if points.is_empty() {
            continue;
        }
        let first = origin;
        origin += points.len() as u32;
        for &e in &edges {
            let [x, y] = mesh.edge_vertices(e);
            let to = if mesh.vertex_origin[x as usize] == o_lo {
                y
            } else {
                x
            };
            let mut cur = e;
            for (&(p, t), id) in points.iter().zip(first..) {
                let v = mesh.split(cur, p);
                mesh.vertex_flags[v as usize] = V_LOCKED | V_CORNER | V_FEATURE;
                mesh.vertex_origin[v as usize] = id;
                mesh.vertex_size[v as usize] = t;
                // Continue with the piece from the new vertex to the far end.
                let Some(h) = mesh.find_halfedge(v, to) else {
                    break;
                };
                cur = mesh.edge(h);
            }
            pieces += points.len();
        }
    }
    pieces
}

/// Deepest bisection of one locked edge: 2¹⁶ pieces at most.
const MAX_LEVELS: u32 = 16;

/// The points (with their targets) that cut the segment `pa`–`pb`, whose
/// ends have the targets `ends`, into pieces each no longer than the least
/// of its ends' mean target and its midpoint's: bisected while a piece is
/// longer, so a long edge across a change of target is graded like a
/// feature line the remesher splits, not cut evenly to its midpoint's
/// target (which left pieces several times the target near one end, and
/// flat triangles against them). Points in order from `pa`.
fn graded(
    target: &impl Fn([f64; 3]) -> f64,
    pa: [f64; 3],
    pb: [f64; 3],
    ends: [f64; 2],
    level: u32,
    out: &mut Vec<([f64; 3], f64)>,
) {
    let mid = lerp(pa, pb, 0.5);
    let tm = target(mid);
    let t = tm.min(0.5 * (ends[0] + ends[1]));
    if level >= MAX_LEVELS || !(t > 0.0 && norm(sub(pa, pb)) > t) {
        return;
    }
    graded(target, pa, mid, [ends[0], tm], level + 1, out);
    out.push((mid, tm));
    graded(target, mid, pb, [tm, ends[1]], level + 1, out);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pieces of a segment, with the targets at its two ends.
    fn pieces(target: impl Fn([f64; 3]) -> f64, len: f64) -> Vec<(f64, f64, f64)> {
        let (pa, pb) = ([0.0; 3], [len, 0.0, 0.0]);
        let mut points = vec![(pa, target(pa))];
        graded(&target, pa, pb, [target(pa), target(pb)], 0, &mut points);
        points.push((pb, target(pb)));
        points
            .windows(2)
            .map(|w| (norm(sub(w[1].0, w[0].0)), w[0].1, w[1].1))
            .collect()
    }

    #[test]
    fn a_locked_edge_is_cut_to_the_target_along_it_not_at_its_midpoint() {
        // The target falls from 4 to 0.25 over a 16-long edge: the even cut
        // to the midpoint's target (2.1) made pieces of 2, eight times the
        // target at the near end.
        let t = |p: [f64; 3]| 0.25 + 3.75 * (p[0] / 16.0);
        let ps = pieces(t, 16.0);
        let total: f64 = ps.iter().map(|x| x.0).sum();
        assert!((total - 16.0).abs() < 1e-12);
        for &(l, ta, tb) in &ps {
            assert!(
                l <= 0.5 * (ta + tb) * (1.0 + 1e-12),
                "{l} against {ta}, {tb}"
            );
        }
        let first = ps[0];
        assert!(first.0 <= 0.5, "first piece {first:?}");
        // No much finer than needed: a piece is halved only when over its
        // bound, which changes little from a piece to its halves here.
        for &(l, ta, tb) in &ps {
            assert!(l > 0.2 * (ta + tb), "{l} against {ta}, {tb}");
        }
    }

    #[test]
    fn an_edge_within_its_target_is_not_cut_and_a_uniform_one_evenly() {
        assert!(pieces(|_| 2.0, 1.5).len() == 1);
        let ps = pieces(|_| 1.0, 3.9);
        assert_eq!(ps.len(), 4);
        assert!(ps.iter().all(|x| (x.0 - 0.975).abs() < 1e-12));
        // A target that is not positive or not finite cuts nothing.
        assert_eq!(pieces(|_| 0.0, 3.0).len(), 1);
        assert_eq!(pieces(|_| f64::NAN, 3.0).len(), 1);
    }
}
