//! Tangential relaxation with projection onto the reference, in parallel
//! (Jacobi: every new position is computed from the old ones, then all are
//! applied), so the result does not depend on the thread count.
//!
//! - A free vertex moves to the density-weighted centroid of its faces
//!   (weights area / size², i.e. area-weighted for a uniform target), with the
//!   normal component removed, then onto the closest point of its input patch.
//! - A feature vertex moves along its line towards the size-weighted midpoint
//!   of its two line neighbours, then onto the closest point of its input line.
//! - Corners and locked vertices stay.
//!
//! A move that would turn a face normal by more than the limit is halved (up
//! to three times), else the vertex is only projected.

use super::reference::{Projected, Reference};
use crate::geometry::{add, cross, dot, norm, scale, sub};
use crate::mesh::halfedge::{HalfedgeMesh, E_FEATURE, NONE, V_CORNER, V_FEATURE, V_LOCKED};
use crate::mesh::shape::{keeps_shape, reliable_normal};
use rayon::prelude::*;

/// A projection onto the vertex's own part of the reference.
type ProjectFn<'a> = dyn Fn([f64; 3]) -> Option<Projected> + 'a;

/// Unit normals of the faces (zero for removed faces and for those whose
/// normal is not trustworthy, see [`reliable_normal`]).
fn face_normals(mesh: &HalfedgeMesh) -> Vec<[f64; 3]> {
    (0..mesh.n_faces() as u32)
        .into_par_iter()
        .map(|f| {
            if mesh.face_deleted(f) {
                return [0.0; 3];
            }
            let [a, b, c] = mesh.face_vertices(f).map(|x| mesh.positions[x as usize]);
            reliable_normal(a, b, c).unwrap_or([0.0; 3])
        })
        .collect()
}

/// True when moving `v` to `p` keeps every face around it within the turn
/// limit of its old normal (or, for a face whose old normal is noise, of the
/// area-weighted normal of `v`'s faces).
fn move_ok(mesh: &HalfedgeMesh, normals: &[[f64; 3]], v: u32, p: [f64; 3], cos_turn: f64) -> bool {
    let mut star = [0.0; 3];
    for f in mesh.vertex_faces(v) {
        star = add(star, mesh.face_normal2(f));
    }
    let ls = norm(star);
    let star = if ls > 0.0 {
        scale(star, 1.0 / ls)
    } else {
        [0.0; 3]
    };
    mesh.vertex_faces(v).all(|f| {
        let c = mesh.face_vertices(f).map(|x| {
            if x == v {
                p
            } else {
                mesh.positions[x as usize]
            }
        });
        let n = cross(sub(c[1], c[0]), sub(c[2], c[0]));
        let l = norm(n);
        if l.is_nan() || l <= 0.0 {
            return false;
        }
        let before = mesh.face_vertices(f).map(|x| mesh.positions[x as usize]);
        if !keeps_shape(before, c) {
            return false;
        }
        let mut old = normals[f as usize];
        if old == [0.0; 3] {
            old = star;
        }
        old == [0.0; 3] || dot(n, old) >= cos_turn * l
    })
}

/// Projects vertex `v` (just made by a split) onto its patch or line and moves
/// it there when that folds nothing; in any case takes the size and hint of
/// the projection.
pub fn place_new_vertex(mesh: &mut HalfedgeMesh, reference: &Reference, v: u32, cos_turn: f64) {
    let p = mesh.positions[v as usize];
    let hint = mesh.vertex_hint[v as usize];
    let pr = if mesh.vertex_flags[v as usize] & V_FEATURE != 0 {
        let line = mesh
            .outgoing(v)
            .map(|h| mesh.edge(h) as usize)
            .find(|&e| mesh.edge_flags[e] & E_FEATURE != 0)
            .map_or(NONE, |e| mesh.edge_line[e]);
        reference.project_line(p, line, hint)
    } else {
        let patch = mesh
            .vertex_faces(v)
            .next()
            .map_or(NONE, |f| mesh.face_patch[f as usize]);
        reference.project_patch(p, patch, hint)
    };
    let Some(pr) = pr else {
        return;
    };
    mesh.vertex_hint[v as usize] = pr.hint;
    mesh.vertex_size[v as usize] = pr.size;
    let normals: Vec<(u32, [f64; 3])> = mesh
        .vertex_faces(v)
        .map(|f| {
            let [a, b, c] = mesh.face_vertices(f).map(|x| mesh.positions[x as usize]);
            (f, reliable_normal(a, b, c).unwrap_or([0.0; 3]))
        })
        .collect();
    let ok = normals.iter().all(|&(f, old)| {
        let before = mesh.face_vertices(f).map(|x| mesh.positions[x as usize]);
        let c = mesh.face_vertices(f).map(|x| {
            if x == v {
                pr.point
            } else {
                mesh.positions[x as usize]
            }
        });
        let n = cross(sub(c[1], c[0]), sub(c[2], c[0]));
        let l = norm(n);
        l > 0.0 && keeps_shape(before, c) && (old == [0.0; 3] || dot(n, old) >= cos_turn * l)
    });
    if ok && !pr.on_rim {
        mesh.positions[v as usize] = pr.point;
    }
}

/// Where a vertex should go before projection, and how it is projected.
enum Plan {
    Free { target: [f64; 3], patch: u32 },
    Line { target: [f64; 3], line: u32 },
}

fn plan(mesh: &HalfedgeMesh, normals: &[[f64; 3]], v: u32) -> Option<Plan> {
    let fl = mesh.vertex_flags[v as usize];
    if fl & (V_CORNER | V_LOCKED) != 0 || mesh.is_isolated(v) {
        return None;
    }
    let p = mesh.positions[v as usize];
    if fl & V_FEATURE != 0 {
        let mut ends = [NONE; 2];
        let mut k = 0;
        let mut line = NONE;
        for h in mesh.outgoing(v) {
            let e = mesh.edge(h) as usize;
            if mesh.edge_flags[e] & E_FEATURE != 0 {
                if k < 2 {
                    ends[k] = mesh.to_vertex(h);
                }
                k += 1;
                line = mesh.edge_line[e];
            }
        }
        if k != 2 || line == NONE {
            return None;
        }
        let (a, b) = (ends[0] as usize, ends[1] as usize);
        let (sa, sb) = (mesh.vertex_size[a], mesh.vertex_size[b]);
        let w = if sa + sb > 0.0 { sa / (sa + sb) } else { 0.5 };
        let (pa, pb) = (mesh.positions[a], mesh.positions[b]);
        return Some(Plan::Line {
            target: add(pa, scale(sub(pb, pa), w)),
            line,
        });
    }
    let mut acc = [0.0; 3];
    let mut wsum = 0.0;
    let mut nrm = [0.0; 3];
    let mut patch = NONE;
    for f in mesh.vertex_faces(v) {
        let [a, b, c] = mesh.face_vertices(f);
        let [pa, pb, pc] = [a, b, c].map(|x| mesh.positions[x as usize]);
        let area = 0.5 * norm(cross(sub(pb, pa), sub(pc, pa)));
        let s = (mesh.vertex_size[a as usize]
            + mesh.vertex_size[b as usize]
            + mesh.vertex_size[c as usize])
            / 3.0;
        let w = if s > 0.0 { area / (s * s) } else { area };
        acc = add(acc, scale(add(add(pa, pb), pc), w / 3.0));
        wsum += w;
        nrm = add(nrm, scale(normals[f as usize], area));
        patch = mesh.face_patch[f as usize];
    }
    if wsum.is_nan() || wsum <= 0.0 || patch == NONE {
        return Some(Plan::Free { target: p, patch });
    }
    let c = scale(acc, 1.0 / wsum);
    let mut u = sub(c, p);
    let ln = norm(nrm);
    if ln > 0.0 {
        let n = scale(nrm, 1.0 / ln);
        u = sub(u, scale(n, dot(n, u)));
    }
    Some(Plan::Free {
        target: add(p, u),
        patch,
    })
}

/// One relaxation step (when `relax`) or a projection only, for every vertex.
/// Updates positions, hints and sizes. Returns the number of vertices whose
/// move had to be cut back.
pub fn relax_and_project(
    mesh: &mut HalfedgeMesh,
    reference: &Reference,
    relax: bool,
    cos_turn: f64,
) -> usize {
    let normals = face_normals(mesh);
    let m: &HalfedgeMesh = mesh;
    let results: Vec<Option<(Projected, bool)>> = (0..m.n_vertices() as u32)
        .into_par_iter()
        .map(|v| {
            if m.vertex_deleted(v) {
                return None;
            }
            let plan = plan(m, &normals, v)?;
            let p = m.positions[v as usize];
            let hint = m.vertex_hint[v as usize];
            let (target, project): (_, Box<ProjectFn>) = match plan {
                Plan::Free { target, patch } => (
                    target,
                    Box::new(move |q| reference.project_patch(q, patch, hint)),
                ),
                Plan::Line { target, line } => (
                    target,
                    Box::new(move |q| reference.project_line(q, line, hint)),
                ),
            };
            let step = if relax { sub(target, p) } else { [0.0; 3] };
            let mut cut = false;
            for k in 0..4 {
                let q = add(p, scale(step, 0.5f64.powi(k)));
                let pr = project(q)?;
                if !pr.on_rim && move_ok(m, &normals, v, pr.point, cos_turn) {
                    return Some((pr, cut));
                }
                cut = true;
            }
            // Stay put; still take the size and hint of the closest point.
            let pr = project(p)?;
            let keep_here = pr.on_rim || !move_ok(m, &normals, v, pr.point, cos_turn);
            Some((
                Projected {
                    point: if keep_here { p } else { pr.point },
                    ..pr
                },
                true,
            ))
        })
        .collect();
    let old: Vec<[f64; 3]> = mesh.positions.clone();
    let mut cut = 0;
    for (v, r) in results.into_iter().enumerate() {
        if let Some((pr, c)) = r {
            mesh.positions[v] = pr.point;
            mesh.vertex_hint[v] = pr.hint;
            mesh.vertex_size[v] = pr.size;
            cut += c as usize;
        }
    }
    // Neighbours moved together may still fold a face: put the vertices of
    // such faces back (a few rounds, since reverting one may expose another).
    for _ in 0..4 {
        let m: &HalfedgeMesh = mesh;
        let bad: Vec<u32> = (0..m.n_faces() as u32)
            .into_par_iter()
            .filter(|&f| {
                if m.face_deleted(f) {
                    return false;
                }
                let vs = m.face_vertices(f);
                let now = vs.map(|x| m.positions[x as usize]);
                let before = vs.map(|x| old[x as usize]);
                if !keeps_shape(before, now) {
                    return true;
                }
                let o = normals[f as usize];
                if o == [0.0; 3] {
                    return false;
                }
                let n = m.face_normal2(f);
                let l = norm(n);
                !(l > 0.0 && dot(n, o) >= cos_turn * l)
            })
            .collect();
        if bad.is_empty() {
            break;
        }
        let mut any = false;
        for f in bad {
            for v in mesh.face_vertices(f) {
                if mesh.positions[v as usize] != old[v as usize] {
                    mesh.positions[v as usize] = old[v as usize];
                    cut += 1;
                    any = true;
                }
            }
        }
        if !any {
            break;
        }
    }
    cut
}
