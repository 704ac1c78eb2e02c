//! Local repair after a batch of collapses (DESIGN §3.5 step 5): tangential
//! relaxation of the kept vertices (free ones projected back onto their
//! target patch, feature ones sliding along their line) and edge flips that
//! lower the largest angle. Every change is checked like a collapse: no
//! face folds or turns too far, and the sampled size ratio and distance to
//! the target stay within the collapse thresholds (`y < 0.5`), so repair
//! never undoes what the estimation guaranteed. Moved vertices take their
//! size from the target (step 6).

use super::estimate::{face_ok, max_angle_deg, sample_fan, FanTri, Limits};
use super::target::Target;
use crate::geometry::{add, closest_point_triangle, cross, dot, lerp, norm, scale, sub};
use crate::mesh::halfedge::{
    HalfedgeMesh, E_FEATURE, E_LOCKED, NONE, V_CORNER, V_FEATURE, V_LOCKED,
};
use crate::mesh::shape::{flip_sound, min_angle_deg};
use rayon::prelude::*;

/// A proposed move of one vertex.
struct Move {
    v: u32,
    p: [f64; 3],
    size: f64,
    hint: u32,
}

/// Smallest angle over the faces of `v` with `v` at `p`.
fn fan_min_angle(mesh: &HalfedgeMesh, v: u32, p: [f64; 3]) -> f64 {
    mesh.vertex_faces(v)
        .map(|f| {
            let c = mesh.face_vertices(f).map(|x| {
                if x == v {
                    p
                } else {
                    mesh.positions[x as usize]
                }
            });
            min_angle_deg(c[0], c[1], c[2])
        })
        .fold(f64::INFINITY, f64::min)
}

/// Where relaxation would put `v`, checked; `None` when it should stay.
fn propose(mesh: &HalfedgeMesh, target: &Target, v: u32, lim: &Limits) -> Option<Move> {
    let flags = mesh.vertex_flags[v as usize];
    if flags & (V_CORNER | V_LOCKED) != 0 || mesh.is_isolated(v) {
        return None;
    }
    let pv = mesh.positions[v as usize];
    let hit = if flags & V_FEATURE != 0 {
        // Slide towards the size-weighted midpoint of the two line neighbours.
        let mut ends = Vec::with_capacity(2);
        let mut line = NONE;
        for h in mesh.outgoing(v) {
            let e = mesh.edge(h) as usize;
            if mesh.edge_flags[e] & E_FEATURE != 0 {
                ends.push(mesh.to_vertex(h));
                line = mesh.edge_line[e];
            }
        }
        if ends.len() != 2 || line == NONE {
            return None;
        }
        let (s0, s1) = (
            mesh.vertex_size[ends[0] as usize],
            mesh.vertex_size[ends[1] as usize],
        );
        let t = if s0 + s1 > 0.0 { s0 / (s0 + s1) } else { 0.5 };
        let goal = lerp(
            mesh.positions[ends[0] as usize],
            mesh.positions[ends[1] as usize],
            t,
        );
        target.on_line(goal, line, NONE)?
    } else {
        // Density-weighted centroid of the faces (area / size²), tangential.
        let mut acc = [0.0; 3];
        let mut wsum = 0.0;
        let mut nrm = [0.0; 3];
        let mut patch = NONE;
        for f in mesh.vertex_faces(v) {
            let fv = mesh.face_vertices(f);
            let c = fv.map(|x| mesh.positions[x as usize]);
            let n2 = cross(sub(c[1], c[0]), sub(c[2], c[0]));
            let h = (fv
                .iter()
                .map(|&x| mesh.vertex_size[x as usize])
                .sum::<f64>()
                / 3.0)
                .max(1e-300);
            let w = norm(n2) / (h * h);
            acc = add(acc, scale(add(add(c[0], c[1]), c[2]), w / 3.0));
            wsum += w;
            nrm = add(nrm, n2);
            patch = mesh.face_patch[f as usize];
        }
        let ln = norm(nrm);
        if !(wsum > 0.0 && ln > 0.0) {
            return None;
        }
        let n = scale(nrm, 1.0 / ln);
        let d = sub(scale(acc, 1.0 / wsum), pv);
        let goal = add(pv, sub(d, scale(n, dot(d, n))));
        target.on_patch(goal, patch, mesh.vertex_hint[v as usize])?
    };
    let p = hit.point;
    if p == pv || fan_min_angle(mesh, v, p) <= fan_min_angle(mesh, v, pv) + 0.5 {
        return None;
    }
    // Checks: every face sound, the old place close to the new surface,
    // sizes and distances sampled as for a collapse.
    let mut fan = Vec::with_capacity(8);
    let mut h_loc = hit.size;
    for f in mesh.vertex_faces(v) {
        let fv = mesh.face_vertices(f);
        let old = fv.map(|x| mesh.positions[x as usize]);
        let new = fv.map(|x| {
            if x == v {
                p
            } else {
                mesh.positions[x as usize]
            }
        });
        face_ok(old, new, [0.0; 3], lim).ok()?;
        let h = fv.map(|x| {
            if x == v {
                hit.size
            } else {
                mesh.vertex_size[x as usize]
            }
        });
        h_loc = h_loc.min(h[0]).min(h[1]).min(h[2]);
        fan.push(FanTri {
            p: new,
            h,
            patch: mesh.face_patch[f as usize],
        });
    }
    let back = fan
        .iter()
        .map(|t| closest_point_triangle(pv, t.p[0], t.p[1], t.p[2]).dist2)
        .fold(f64::INFINITY, f64::min)
        .sqrt();
    // A line projection's index is a segment, not a target triangle: feature
    // vertices keep their triangle hint.
    let hint = if flags & V_FEATURE == 0 {
        hit.index
    } else {
        mesh.vertex_hint[v as usize]
    };
    let mut sample_hint = hint;
    let mut found = sample_fan(target, &fan, h_loc, lim, 0.5, &mut sample_hint);
    found.distance(
        back,
        target.allowance(mesh.vertex_hint[v as usize], h_loc, h_loc, lim),
    );
    (found.score(lim) < 0.5).then_some(Move {
        v,
        p,
        size: hit.size,
        hint,
    })
}

/// Relaxes the vertices `verts` (their closed fans must not overlap: moves
/// are computed in parallel from the old positions, then applied). Returns
/// the vertices moved.
pub fn relax(mesh: &mut HalfedgeMesh, target: &Target, verts: &[u32], lim: &Limits) -> Vec<u32> {
    let moves: Vec<Move> = {
        let m: &HalfedgeMesh = mesh;
        verts
            .par_iter()
            .filter_map(|&v| propose(m, target, v, lim))
            .collect()
    };
    let mut moved = Vec::with_capacity(moves.len());
    for mv in moves {
        mesh.positions[mv.v as usize] = mv.p;
        mesh.vertex_size[mv.v as usize] = mv.size;
        mesh.vertex_hint[mv.v as usize] = mv.hint;
        moved.push(mv.v);
    }
    moved
}

/// Flips the non-feature edges around `verts` where that lowers the largest
/// angle of the two faces by more than 1°, keeps normals and creases
/// (creases up to `cos_crease`, see [`crease_limit`]) and passes the sampled size and distance check.
/// Sequential, in the order given. Returns the vertices whose rings changed.
pub fn flip_around(
    mesh: &mut HalfedgeMesh,
    target: &Target,
    verts: &[u32],
    lim: &Limits,
    cos_crease: f64,
) -> Vec<u32> {
    let mut edges = Vec::new();
    for &v in verts {
        if mesh.vertex_deleted(v) {
            continue;
        }
        for h in mesh.outgoing(v) {
            edges.push(mesh.edge(h));
            if mesh.face(h) != NONE {
                edges.push(mesh.edge(mesh.next(h)));
            }
        }
    }
    edges.sort_unstable();
    edges.dedup();
    let mut touched = Vec::new();
    for e in edges {
        if mesh.edge_deleted(e)
            || mesh.edge_flags[e as usize] & (E_FEATURE | E_LOCKED) != 0
            || !mesh.is_flip_ok(e)
        {
            continue;
        }
        let [a, b] = mesh.edge_vertices(e);
        let [c, d] = mesh.flip_apexes(e);
        let locked = |x: u32| mesh.vertex_flags[x as usize] & V_LOCKED != 0;
        if locked(c) && locked(d) {
            continue;
        }
        let [pa, pb, pc, pd] = [a, b, c, d].map(|x| mesh.positions[x as usize]);
        let old = max_angle_deg([pa, pb, pc]).max(max_angle_deg([pb, pa, pd]));
        let new = max_angle_deg([pa, pd, pc]).max(max_angle_deg([pd, pb, pc]));
        if new >= old - 1.0 || !flip_sound(mesh, e, lim.cos_turn, cos_crease, 0.0) {
            continue;
        }
        let [sa, sb, sc, sd] = [a, b, c, d].map(|x| mesh.vertex_size[x as usize]);
        let patch = mesh.face_patch[mesh.face(2 * e) as usize];
        let fan = [
            FanTri {
                p: [pa, pd, pc],
                h: [sa, sd, sc],
                patch,
            },
            FanTri {
                p: [pd, pb, pc],
                h: [sd, sb, sc],
                patch,
            },
        ];
        let h_loc = sa.min(sb).min(sc).min(sd);
        let mut hint = mesh.vertex_hint[a as usize];
        let found = sample_fan(target, &fan, h_loc, lim, 0.5, &mut hint);
        if found.score(lim) >= 0.5 || mesh.flip(e).is_err() {
            continue;
        }
        touched.extend([a, b, c, d]);
    }
    touched
}

/// Cosine of the largest crease a repair flip may create: min(feature angle,
/// 20°), as the remesher's flips.
pub fn crease_limit(feature_angle_deg: f64) -> f64 {
    feature_angle_deg.min(20.0).to_radians().cos()
}
