//! The three topological passes of one remeshing iteration: split long edges,
//! collapse short ones, flip to improve valence. Each walks the edges in index
//! order (new edges are appended and visited in the same pass), so the result
//! is deterministic.

use super::reference::Reference;
use super::smooth::place_new_vertex;
use crate::geometry::{closest_point_triangle, cross, dot, lerp, norm, norm2, sub};
use crate::mesh::halfedge::{
    HalfedgeMesh, E_FEATURE, E_LOCKED, NONE, V_CORNER, V_FEATURE, V_LOCKED,
};
use crate::mesh::shape::{self, flatness, min_angle_deg, reliable_normal, unit};

/// Geometric limits of the passes.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// Cosine of the largest turn of a face normal a collapse or flip may cause.
    pub cos_turn: f64,
    /// A collapse may not make a face with a smaller angle (degrees) than this,
    /// unless the faces it replaces were already worse.
    pub sliver_deg: f64,
    /// A removed vertex must lie within this fraction of the local target
    /// length of the surface (and feature line) that replaces it.
    pub fidelity: f64,
    /// Cosine of the largest dihedral angle a flip may create (if it was not
    /// already there).
    pub cos_crease: f64,
    /// Length scale of the splits and of the longest edge a collapse may
    /// make: 1 in the remeshing iterations, more in a coarse level
    /// ([`super::coarse_levels`]). The collapse threshold (4/5 of the target)
    /// and the fidelity tolerance never scale.
    pub scale: f64,
}

/// Mean target length of an edge's ends.
#[inline]
fn target(mesh: &HalfedgeMesh, a: u32, b: u32) -> f64 {
    0.5 * (mesh.vertex_size[a as usize] + mesh.vertex_size[b as usize])
}

/// Splits every unlocked edge longer than 4/3 of its target at its midpoint,
/// longest (relative to its target) first, so triangles are bisected across
/// their longest side and never degenerate; the new vertex is projected onto
/// the reference at once and takes its target length from there. Repeats
/// until no edge is long (at most 10 sweeps). Returns the number of splits.
pub fn split_long(mesh: &mut HalfedgeMesh, reference: &Reference, lim: &Limits) -> usize {
    let mut count = 0;
    for _ in 0..10 {
        let in_strip = |e: u32| {
            mesh.edge_flags[e as usize] & E_FEATURE == 0
                && [2 * e, 2 * e + 1].iter().any(|&h| {
                    let f = mesh.face(h);
                    f != NONE
                        && reference
                            .thin_patch
                            .get(mesh.face_patch[f as usize] as usize)
                            .copied()
                            .unwrap_or(false)
                })
        };
        let mut long: Vec<(f64, u32)> = (0..mesh.n_edges() as u32)
            .filter(|&e| {
                !mesh.edge_deleted(e) && mesh.edge_flags[e as usize] & E_LOCKED == 0 && !in_strip(e)
            })
            .filter_map(|e| {
                let [a, b] = mesh.edge_vertices(e);
                let l = target(mesh, a, b) * 4.0 / 3.0 * lim.scale;
                let r = mesh.edge_length(e) / l;
                (r > 1.0).then_some((r, e))
            })
            .collect();
        if long.is_empty() {
            break;
        }
        long.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
        // The first sweeps on a tessellation of long needles split hundreds
        // of thousands of edges: room for exactly this sweep, not a doubling.
        mesh.reserve_splits(long.len());
        for (_, e) in long {
            let [a, b] = mesh.edge_vertices(e);
            let l = target(mesh, a, b) * 4.0 / 3.0 * lim.scale;
            let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            if norm2(sub(pa, pb)) <= l * l {
                continue;
            }
            let v = mesh.split(e, lerp(pa, pb, 0.5));
            // A feature split takes the segment hint of a feature end, a free
            // one the triangle hint of a free end.
            let fa = mesh.vertex_flags[a as usize];
            let fb = mesh.vertex_flags[b as usize];
            mesh.vertex_hint[v as usize] = if mesh.vertex_flags[v as usize] & V_FEATURE != 0 {
                if fa & V_CORNER == 0 {
                    mesh.vertex_hint[a as usize]
                } else if fb & V_CORNER == 0 {
                    mesh.vertex_hint[b as usize]
                } else {
                    NONE
                }
            } else if fa & V_FEATURE == 0 {
                mesh.vertex_hint[a as usize]
            } else if fb & V_FEATURE == 0 {
                mesh.vertex_hint[b as usize]
            } else {
                NONE
            };
            place_new_vertex(mesh, reference, v, lim.cos_turn);
            count += 1;
        }
    }
    count
}

/// May `from(h)` be removed into `to(h)`? Checks flags, the link condition,
/// face normals, slivers, new edge lengths and fidelity to the surface.
pub fn collapse_ok(mesh: &HalfedgeMesh, h: u32, lim: &Limits) -> bool {
    let v = mesh.from_vertex(h);
    let w = mesh.to_vertex(h);
    let e = mesh.edge(h);
    let fv = mesh.vertex_flags[v as usize];
    let ef = mesh.edge_flags[e as usize];
    if fv & (V_CORNER | V_LOCKED) != 0 || ef & E_LOCKED != 0 {
        return false;
    }
    if (fv & V_FEATURE != 0) != (ef & E_FEATURE != 0) {
        return false;
    }
    if !mesh.can_collapse(h) {
        return false;
    }
    let wl = mesh.vertex_flags[w as usize] & V_LOCKED != 0;
    let pv = mesh.positions[v as usize];
    let pw = mesh.positions[w as usize];
    let tol = lim.fidelity * target(mesh, v, w);
    // Faces of v that survive, with v moved onto w.
    let mut q_old = f64::INFINITY;
    let mut q_new = f64::INFINITY;
    let mut dev = f64::INFINITY;
    let mut other_on_line = NONE;
    // Area-weighted normal of v's faces per patch: the reference for faces
    // whose own normal is not trustworthy.
    let mut star: Vec<(u32, [f64; 3])> = Vec::new();
    for f in mesh.vertex_faces(v) {
        let p = mesh.face_patch[f as usize];
        let n = mesh.face_normal2(f);
        match star.iter_mut().find(|x| x.0 == p) {
            Some(x) => x.1 = crate::geometry::add(x.1, n),
            None => star.push((p, n)),
        }
    }
    for hh in mesh.outgoing(v) {
        let u = mesh.to_vertex(hh);
        if u != w {
            if wl && mesh.vertex_flags[u as usize] & V_LOCKED != 0 {
                return false;
            }
            let pu = mesh.positions[u as usize];
            let l_new = norm(sub(pu, pw));
            let l_old = norm(sub(pu, pv));
            if l_new > (4.0 / 3.0 * lim.scale * target(mesh, w, u)).max(l_old) {
                return false;
            }
            if mesh.edge_flags[mesh.edge(hh) as usize] & E_FEATURE != 0 {
                other_on_line = u;
            }
        }
        let f = mesh.face(hh);
        if f == NONE {
            continue;
        }
        let [a, b, c] = mesh.face_vertices(f).map(|x| mesh.positions[x as usize]);
        q_old = q_old.min(min_angle_deg(a, b, c));
        let fvs = mesh.face_vertices(f);
        if fvs.contains(&w) {
            continue;
        }
        let np = fvs.map(|x| {
            if x == v {
                pw
            } else {
                mesh.positions[x as usize]
            }
        });
        let n_new = cross(sub(np[1], np[0]), sub(np[2], np[0]));
        let Some(n_new) = unit(n_new) else {
            return false;
        };
        let patch = mesh.face_patch[f as usize];
        let reference = reliable_normal(a, b, c)
            .or_else(|| star.iter().find(|x| x.0 == patch).and_then(|x| unit(x.1)));
        if let Some(n_old) = reference {
            if dot(n_new, n_old) < lim.cos_turn {
                return false;
            }
        }
        q_new = q_new.min(min_angle_deg(np[0], np[1], np[2]));
        dev = dev.min(closest_point_triangle(pv, np[0], np[1], np[2]).dist2);
    }
    if q_new < q_old.min(lim.sliver_deg) {
        return false;
    }
    if dev.is_finite() && dev > tol * tol {
        return false;
    }
    if fv & V_FEATURE != 0 && other_on_line != NONE {
        // The line's new chord w–u must stay close to the removed vertex.
        let pu = mesh.positions[other_on_line as usize];
        let t = crate::geometry::closest_point_on_segment(pv, pw, pu);
        let d = norm(sub(pv, lerp(pw, pu, t)));
        if d > tol {
            return false;
        }
    }
    true
}

/// Collapses every unlocked edge shorter than 4/5 of its target where
/// [`collapse_ok`] allows one of its two directions (the end of lower valence
/// goes when both may). Returns the number of collapses.
pub fn collapse_short(mesh: &mut HalfedgeMesh, lim: &Limits) -> usize {
    let mut count = 0;
    for e in 0..mesh.n_edges() as u32 {
        if mesh.edge_deleted(e) || mesh.edge_flags[e as usize] & E_LOCKED != 0 {
            continue;
        }
        let [a, b] = mesh.edge_vertices(e);
        let l = target(mesh, a, b) * 0.8;
        if norm2(sub(mesh.positions[a as usize], mesh.positions[b as usize])) >= l * l {
            continue;
        }
        let h = 2 * e; // a → b: removes a
        let ok_a = collapse_ok(mesh, h, lim);
        let ok_b = collapse_ok(mesh, h + 1, lim);
        let pick = match (ok_a, ok_b) {
            (true, true) => {
                if mesh.valence(b) < mesh.valence(a) {
                    h + 1
                } else {
                    h
                }
            }
            (true, false) => h,
            (false, true) => h + 1,
            (false, false) => continue,
        };
        let keep = mesh.to_vertex(pick);
        let p = mesh.positions[keep as usize];
        if mesh.collapse(pick, p).is_ok() {
            count += 1;
        }
    }
    count
}

/// Ideal valence of a vertex (`None` for corners, which have no ideal).
#[inline]
fn ideal_valence(mesh: &HalfedgeMesh, v: u32) -> Option<i64> {
    if mesh.vertex_flags[v as usize] & (V_CORNER | V_LOCKED) != 0 {
        None
    } else if mesh.is_boundary_vertex(v) {
        Some(4)
    } else {
        Some(6)
    }
}

/// Is flipping edge `e` geometrically sound under these limits (see
/// [`shape::flip_sound`])?
pub fn flip_geometry_ok(mesh: &HalfedgeMesh, e: u32, lim: &Limits, floor_deg: f64) -> bool {
    shape::flip_sound(mesh, e, lim.cos_turn, lim.cos_crease, floor_deg)
}

/// Edge `e` may be flipped (live, not a feature or locked, topologically
/// flippable, not joining two locked vertices): its ends and apexes `[a, b, c, d]`.
fn flip_candidate(mesh: &HalfedgeMesh, e: u32) -> Option<[u32; 4]> {
    if mesh.edge_deleted(e)
        || mesh.edge_flags[e as usize] & (E_FEATURE | E_LOCKED) != 0
        || !mesh.is_flip_ok(e)
    {
        return None;
    }
    let [a, b] = mesh.edge_vertices(e);
    let [c, d] = mesh.flip_apexes(e);
    let locked = |v: u32| mesh.vertex_flags[v as usize] & V_LOCKED != 0;
    (!(locked(c) && locked(d))).then_some([a, b, c, d])
}

/// Flips every interior non-feature edge whose flip brings the valences of its
/// four vertices closer to ideal (6 inside, 4 on a boundary) without worsening
/// angles. Returns the number of flips.
pub fn flip_valence(mesh: &mut HalfedgeMesh, lim: &Limits) -> usize {
    let mut count = 0;
    for e in 0..mesh.n_edges() as u32 {
        let Some([a, b, c, d]) = flip_candidate(mesh, e) else {
            continue;
        };
        let mut before = 0;
        let mut after = 0;
        for (v, delta) in [(a, -1), (b, -1), (c, 1), (d, 1)] {
            if let Some(t) = ideal_valence(mesh, v) {
                let val = mesh.valence(v) as i64;
                before += (val - t).abs();
                after += (val + delta - t).abs();
            }
        }
        if after >= before || !flip_geometry_ok(mesh, e, lim, 20.0) {
            continue;
        }
        if mesh.flip(e).is_ok() {
            count += 1;
        }
    }
    count
}

/// Flips interior non-feature edges where that lowers the largest angle of the
/// two faces (a Delaunay-like clean-up); at most `sweeps` sweeps. Returns the
/// number of flips.
pub fn flip_angles(mesh: &mut HalfedgeMesh, lim: &Limits, sweeps: usize) -> usize {
    let max_angle = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
        let t = crate::geometry::triangle_angles_deg(a, b, c);
        t[0].max(t[1]).max(t[2])
    };
    let mut count = 0;
    for _ in 0..sweeps {
        let mut any = false;
        for e in 0..mesh.n_edges() as u32 {
            let Some([a, b, c, d]) = flip_candidate(mesh, e) else {
                continue;
            };
            let [pa, pb, pc, pd] = [a, b, c, d].map(|x| mesh.positions[x as usize]);
            let old = max_angle(pa, pb, pc).max(max_angle(pb, pa, pd));
            let new = max_angle(pa, pd, pc).max(max_angle(pd, pb, pc));
            if new < old - 1.0 && flip_geometry_ok(mesh, e, lim, 0.0) && mesh.flip(e).is_ok() {
                count += 1;
                any = true;
            }
        }
        if !any {
            break;
        }
    }
    count
}

/// Removes flat faces (flatness below `q_bad`, see [`flatness`]): a cap loses
/// its longest edge by a flip when that makes both faces less flat, otherwise
/// one of its edges is collapsed where [`collapse_ok`] allows (shortest
/// first, either direction). A few sweeps. Returns the number of changes.
pub fn repair_flat(mesh: &mut HalfedgeMesh, lim: &Limits, q_bad: f64) -> usize {
    let face_q = |mesh: &HalfedgeMesh, f: u32| {
        let [a, b, c] = mesh.face_vertices(f).map(|v| mesh.positions[v as usize]);
        flatness(a, b, c)
    };
    let mut count = 0;
    for _ in 0..3 {
        let mut any = false;
        for f in 0..mesh.n_faces() as u32 {
            if mesh.face_deleted(f) || face_q(mesh, f) >= q_bad {
                continue;
            }
            let mut hs = mesh.face_halfedges(f);
            hs.sort_by(|&x, &y| {
                mesh.edge_length(mesh.edge(y))
                    .total_cmp(&mesh.edge_length(mesh.edge(x)))
                    .then(x.cmp(&y))
            });
            // 1. Flip the longest edge.
            let e = mesh.edge(hs[0]);
            if mesh.edge_flags[e as usize] & (E_FEATURE | E_LOCKED) == 0 && mesh.is_flip_ok(e) {
                let [a, b] = mesh.edge_vertices(e);
                let [c, d] = mesh.flip_apexes(e);
                let both_locked = [c, d]
                    .iter()
                    .all(|&x| mesh.vertex_flags[x as usize] & V_LOCKED != 0);
                let [pa, pb, pc, pd] = [a, b, c, d].map(|x| mesh.positions[x as usize]);
                let q_old = flatness(pa, pb, pc).min(flatness(pb, pa, pd));
                let q_new = flatness(pa, pd, pc).min(flatness(pd, pb, pc));
                let n1 = cross(sub(pd, pa), sub(pc, pa));
                let n2 = cross(sub(pb, pd), sub(pc, pd));
                let agree = match (unit(n1), unit(n2)) {
                    (Some(x), Some(y)) => dot(x, y) >= lim.cos_turn,
                    _ => false,
                };
                if !both_locked && q_new > q_old && agree && mesh.flip(e).is_ok() {
                    count += 1;
                    any = true;
                    continue;
                }
            }
            // 2. Collapse an edge, shortest first.
            for &h in hs.iter().rev() {
                let pick = [h, h ^ 1].into_iter().find(|&x| collapse_ok(mesh, x, lim));
                if let Some(x) = pick {
                    let keep = mesh.to_vertex(x);
                    let p = mesh.positions[keep as usize];
                    if mesh.collapse(x, p).is_ok() {
                        count += 1;
                        any = true;
                        break;
                    }
                }
            }
        }
        if !any {
            break;
        }
    }
    count
}
