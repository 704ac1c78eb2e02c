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
/// by the target ([`cut`]: bisection while a piece is longer than the least
/// of its midpoint's target and its ends' mean, then re-spaced by the
/// integral of `1 / target` where that makes fewer pieces within the same
/// bound); new vertices are locked corners with their own target as size
/// and origins numbered from `next_origin` up, shared by the copies of one
/// input edge (the points are computed once per input edge, from the end of
/// lower origin, so every copy is cut at the same points; an edge whose ids
/// would pass `NONE − 1` is left uncut). Returns the number of new pieces,
/// counted in every copy. Cost: O(pieces) target evaluations and splits.
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
        cut(&target, pa, pb, ends, &mut points);
        // Origin ids stay below `NONE`: an edge whose points would need it
        // or more (4 billion new vertices, beyond any memory) is left uncut.
        // (`NONE` is `u32::MAX`: a sum that does not overflow is within it.)
        let Some(end) = u32::try_from(points.len())
            .ok()
            .and_then(|n| origin.checked_add(n))
        else {
            continue;
        };
        if points.is_empty() {
            continue;
        }
        let first = origin;
        origin = end;
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

// `presplit` numbers origins up to `NONE - 1` by checked `u32` sums.
const _: () = assert!(NONE == u32::MAX);

/// Deepest bisection of one locked edge: 2¹⁶ pieces at most.
const MAX_LEVELS: u32 = 16;

/// Relative slack of the piece bound against rounding (a piece exactly at
/// its target, computed a few ulps over it, still passes).
const SLACK: f64 = 1e-9;

/// The points (with their targets) that cut the segment `pa`–`pb`, ends'
/// targets `ends`: [`graded`]'s bisection, then [`spaced`] over its points
/// where that makes fewer pieces that all pass the same bound. Points in
/// order from `pa`. Cost: O(n) target evaluations for n bisection pieces
/// (about four per piece).
fn cut(
    target: &impl Fn([f64; 3]) -> f64,
    pa: [f64; 3],
    pb: [f64; 3],
    ends: [f64; 2],
    out: &mut Vec<([f64; 3], f64)>,
) {
    let mut halves = Vec::new();
    graded(target, pa, pb, ends, 0, &mut halves);
    if !spaced(target, pa, pb, ends, &halves, out) {
        out.extend(halves);
    }
}

/// Re-cuts `pa`–`pb`, already cut by bisection at `halves`, where the
/// integral of `1 / target` along it reaches equal shares: the fewest
/// pieces with an integral of at most 1 each, the spacing a graded feature
/// line gets, each piece about its target long (a uniform target cuts an
/// edge 4.1 targets long into five pieces of 0.82, where bisection made
/// eight of 0.51). The integral is the trapezoid rule over the bisection's
/// points, whose pieces are each within their target (so the samples
/// follow the target where it changes, and for a convex `1 / target` the
/// rule overestimates: pieces err short). Writes the points and returns
/// true only if they are fewer than the bisection's and every piece passes
/// [`graded`]'s bound (at most the least of its midpoint's target and its
/// ends' mean, within [`SLACK`]); else writes nothing (a target that jumps
/// faster than the samples see keeps the bisection). Cost: O(n) target
/// evaluations for n bisection pieces.
fn spaced(
    target: &impl Fn([f64; 3]) -> f64,
    pa: [f64; 3],
    pb: [f64; 3],
    ends: [f64; 2],
    halves: &[([f64; 3], f64)],
    out: &mut Vec<([f64; 3], f64)>,
) -> bool {
    let len = norm(sub(pa, pb));
    if halves.len() < 2 || !(len > 0.0 && len.is_finite()) {
        return false;
    }
    // Samples (position along the segment in [0, 1], 1 / target) and the
    // cumulative integral at each.
    let samples: Vec<(f64, f64)> = std::iter::once((0.0, ends[0]))
        .chain(halves.iter().map(|&(p, t)| (norm(sub(p, pa)) / len, t)))
        .chain(std::iter::once((1.0, ends[1])))
        .map(|(s, t)| (s, 1.0 / t))
        .collect();
    if samples
        .iter()
        .any(|&(_, inv)| !(inv > 0.0 && inv.is_finite()))
    {
        return false;
    }
    let mut total = 0.0;
    let cum: Vec<f64> = std::iter::once(0.0)
        .chain(samples.windows(2).map(|w| {
            total += 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0) * len;
            total
        }))
        .collect();
    let n = (total * (1.0 - SLACK)).ceil();
    if !(n >= 2.0 && n < (halves.len() + 1) as f64) {
        return false;
    }
    let n = n as usize;
    let mut points = Vec::with_capacity(n - 1);
    let mut j = 0;
    for k in 1..n {
        let level = total * k as f64 / n as f64;
        while j + 2 < cum.len() && cum[j + 1] < level {
            j += 1;
        }
        let f = ((level - cum[j]) / (cum[j + 1] - cum[j])).clamp(0.0, 1.0);
        let s = samples[j].0 + f * (samples[j + 1].0 - samples[j].0);
        let p = lerp(pa, pb, s);
        points.push((p, target(p)));
    }
    let mut from = (pa, ends[0]);
    for &(p, t) in points.iter().chain(std::iter::once(&(pb, ends[1]))) {
        let bound = target(lerp(from.0, p, 0.5)).min(0.5 * (from.1 + t));
        // False for a NaN target too.
        let within = norm(sub(p, from.0)) <= bound * (1.0 + SLACK);
        if !within {
            return false;
        }
        from = (p, t);
    }
    out.extend(points);
    true
}

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
        cut(&target, pa, pb, [target(pa), target(pb)], &mut points);
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

        // Not finer than needed: spaced by the integral of 1 / target, each
        // piece is over 95 % of its ends' mean target, 12 pieces where the
        // integral is 11.8 (bisection alone: 17 pieces, down to 50 %).
        assert_eq!(ps.len(), 12);
        for &(l, ta, tb) in &ps {
            assert!(l > 0.95 * 0.5 * (ta + tb), "{l} against {ta}, {tb}");
        }
    }

    #[test]
    fn a_target_that_jumps_falls_back_to_bisection_within_its_bound() {
        // The integral's even shares put a piece across the jump longer than
        // the small side's target: bisection cuts it, every piece within
        // its bound, the coarse side in pieces of 4 and 2, the fine in 0.25.
        let step = |p: [f64; 3]| if p[0] < 8.0 { 4.0 } else { 0.25 };
        let ps = pieces(step, 16.0);
        for &(l, ta, tb) in &ps {
            assert!(l <= 0.5 * (ta + tb) * (1.0 + 1e-12), "{l}: {ta}, {tb}");
        }
        assert_eq!(ps.iter().filter(|x| x.0 > 1.0).count(), 3);
        assert_eq!(ps.iter().filter(|x| x.0 == 0.25).count(), 32);
    }

    #[test]
    fn an_edge_within_its_target_is_not_cut_and_a_uniform_one_evenly() {
        assert!(pieces(|_| 2.0, 1.5).len() == 1);
        let ps = pieces(|_| 1.0, 3.9);
        assert_eq!(ps.len(), 4);
        assert!(ps.iter().all(|x| (x.0 - 0.975).abs() < 1e-12));
        // Evenly into the fewest pieces: bisection made eight of 0.5125.
        let ps = pieces(|_| 1.0, 4.1);
        assert_eq!(ps.len(), 5);
        assert!(ps.iter().all(|x| (x.0 - 0.82).abs() < 1e-12));
        // Exactly four targets long: four pieces, not five.
        assert_eq!(pieces(|_| 0.5, 2.0).len(), 4);
        // A target that is not positive or not finite cuts nothing.
        assert_eq!(pieces(|_| 0.0, 3.0).len(), 1);
        assert_eq!(pieces(|_| f64::NAN, 3.0).len(), 1);
    }

    #[test]
    fn random_smooth_targets_keep_the_bound_with_no_more_pieces_than_bisection() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(44);
        let mut fewer = 0;
        for _ in 0..500 {
            // A positive target with a trend and a wave, over a random length.
            let (a, b, w, ph) = (
                rng.gen_range(0.05..2.0),
                rng.gen_range(0.05..2.0),
                rng.gen_range(0.0..3.0),
                rng.gen_range(0.0..6.3),
            );
            let len = rng.gen_range(0.1..40.0);
            let t = move |p: [f64; 3]| {
                let s = p[0] / len;
                (a + (b - a) * s) * (1.0 + 0.4 * (w * s * 6.3 + ph).sin())
            };
            let ps = pieces(t, len);
            let total: f64 = ps.iter().map(|x| x.0).sum();
            assert!((total - len).abs() < 1e-9 * len);
            for &(l, ta, tb) in &ps {
                assert!(l <= 0.5 * (ta + tb) * (1.0 + 1e-9), "{l}: {ta}, {tb}");
            }
            let mut halves = Vec::new();
            let (pa, pb) = ([0.0; 3], [len, 0.0, 0.0]);
            graded(&t, pa, pb, [t(pa), t(pb)], 0, &mut halves);
            assert!(ps.len() <= halves.len() + 1);
            fewer += usize::from(ps.len() < halves.len() + 1);
        }
        // The re-spacing saved pieces on 268 of the 500 edges (seed 44).
        assert!(fewer > 200, "{fewer}");
    }

    /// Three triangles on one edge of length 10 (a non-manifold, locked
    /// edge), as a half-edge mesh.
    fn book() -> HalfedgeMesh {
        let (v, t) = crate::test_shapes::three_fins(10.0);
        let opts = crate::mesh::BuildOptions::default();
        let g = crate::mesh::Grid::from_arrays(v, t, None, &opts).unwrap();
        HalfedgeMesh::from_grid(&g, None).0
    }

    #[test]
    fn origin_ids_never_reach_none() {
        // Target 1: 10 pieces, 9 new points, numbered from 5, in each of the
        // three copies of the edge.
        let mut m = book();
        assert_eq!(presplit(&mut m, |_| 1.0, 5), 3 * 9);
        let top = m.vertex_origin.iter().filter(|&&o| o != NONE).max();
        assert_eq!(top, Some(&13));
        // Ids that would pass NONE - 1: the edge is left uncut, no overflow.
        let mut m = book();
        let before = m.n_edges();
        assert_eq!(presplit(&mut m, |_| 1.0, NONE - 8), 0);
        assert_eq!(m.n_edges(), before);
        // Exactly enough ids: the last new vertex gets NONE - 1.
        assert_eq!(presplit(&mut m, |_| 1.0, NONE - 9), 3 * 9);
        let top = m.vertex_origin.iter().filter(|&&o| o != NONE).max();
        assert_eq!(top, Some(&(NONE - 1)));
    }
}
