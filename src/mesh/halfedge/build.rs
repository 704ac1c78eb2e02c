//! Building a [`HalfedgeMesh`] from a [`Grid`]: every vertex is split into one
//! copy per *fan* (faces around it joined through consistently oriented manifold
//! edges), so each copy is manifold and bodies touching at vertices or along
//! non-manifold edges come apart. Copies of split vertices are locked; a face
//! that still cannot be linked (two faces claiming one directed edge) is
//! detached with its own locked corners.

use super::{HalfedgeMesh, E_CUT, E_FEATURE, E_LOCKED, NONE, V_CORNER, V_FEATURE, V_LOCKED};
use crate::mesh::features::NON_MANIFOLD;
use crate::mesh::{Features, Grid};
use std::collections::HashMap;

/// What [`HalfedgeMesh::from_grid`] had to do to make the input manifold.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct BuildReport {
    /// Vertices of the input grid.
    pub input_vertices: usize,
    /// Faces of the input grid.
    pub input_faces: usize,
    /// Input vertices whose faces form several fans (non-manifold vertices,
    /// bodies touching); each became several locked copies.
    pub split_vertices: usize,
    /// Copies made in excess of one per input vertex.
    pub extra_copies: usize,
    /// Faces that could not be linked to their neighbours (orientation
    /// conflicts on non-manifold edges); kept as they are, detached and locked.
    pub detached_faces: usize,
    /// Locked edges (non-manifold input edges and edges of detached faces).
    pub locked_edges: usize,
    /// Input vertices referenced by no face (dropped).
    pub unreferenced_vertices: usize,
    /// Input vertices on a cut between pieces of one body
    /// ([`HalfedgeMesh::from_grid_cut`]); their copies are locked, like
    /// those of split vertices, but not counted there.
    pub cut_vertices: usize,
    /// Input edges on such a cut ([`E_CUT`]; not counted in `locked_edges`).
    pub cut_edges: usize,
}

/// Tiny union-find over local indices.
fn find(p: &mut [usize], mut x: usize) -> usize {
    while p[x] != x {
        p[x] = p[p[x]];
        x = p[x];
    }
    x
}

#[inline]
fn key(a: u32, b: u32) -> u64 {
    ((a as u64) << 32) | b as u64
}

impl HalfedgeMesh {
    /// Builds the mesh of `grid`. Feature flags come from `features` (any
    /// feature edge gets [`E_FEATURE`], non-manifold ones also [`E_LOCKED`]);
    /// without it only boundary and non-manifold edges are features. Vertices
    /// get [`V_FEATURE`] when on a feature edge, [`V_CORNER`] when on other than
    /// two, and [`V_LOCKED`] | [`V_CORNER`] when split or at a locked edge. Face
    /// patches come from `features` (0 without). Sizes are 0, hints the index of
    /// an input face at the vertex, origins the input vertex. O(F) expected.
    pub fn from_grid(grid: &Grid, features: Option<&Features>) -> (HalfedgeMesh, BuildReport) {
        HalfedgeMesh::from_grid_cut(grid, features, None)
    }

    /// [`HalfedgeMesh::from_grid`] with the faces in `pieces` (one label per
    /// input face): two faces with different labels are never linked, so the
    /// edges between pieces become a boundary of each, flagged
    /// [`E_FEATURE`] | [`E_LOCKED`] | [`E_CUT`], and their vertices locked
    /// copies ([`V_LOCKED`] | [`V_CORNER`], the input vertex as origin) that
    /// [`HalfedgeMesh::to_arrays`] merges again: the pieces come apart as
    /// parts ([`HalfedgeMesh::into_parts`]) that can be worked on side by
    /// side and put back with no seam. O(F) expected.
    pub fn from_grid_cut(
        grid: &Grid,
        features: Option<&Features>,
        pieces: Option<&[u32]>,
    ) -> (HalfedgeMesh, BuildReport) {
        let tris = grid.triangles();
        let topo = grid.topology();
        let verts = grid.vertices();
        let nf = tris.len();
        let mut report = BuildReport {
            input_vertices: verts.len(),
            input_faces: nf,
            ..Default::default()
        };
        let mut rejected = vec![false; nf];
        let (corner, origin, split, natural) = loop {
            let (corner, origin, split, natural) = fans(grid, &rejected, pieces);
            // Two faces claiming one directed edge cannot both be linked.
            let mut claimed: HashMap<u64, u32> = HashMap::with_capacity(3 * nf);
            let mut conflict = false;
            for f in 0..nf {
                if rejected[f] {
                    continue;
                }
                let c = corner[f];
                let clash = (0..3).any(|k| claimed.contains_key(&key(c[k], c[(k + 1) % 3])));
                if clash {
                    rejected[f] = true;
                    conflict = true;
                } else {
                    for k in 0..3 {
                        claimed.insert(key(c[k], c[(k + 1) % 3]), f as u32);
                    }
                }
            }
            if !conflict {
                break (corner, origin, split, natural);
            }
        };
        report.detached_faces = rejected.iter().filter(|&&r| r).count();
        // An input vertex's copies: several fans of its own (split), or only
        // because a cut runs through it.
        let first_copies = (0..origin.len()).filter(|&i| i == 0 || origin[i - 1] != origin[i]);
        for i in first_copies {
            if split[i] && natural[origin[i] as usize] > 1 {
                report.split_vertices += 1;
            } else if split[i] {
                report.cut_vertices += 1;
            }
        }

        let mut mesh = HalfedgeMesh::new();
        let mut seen_origin = vec![false; verts.len()];
        for (i, &o) in origin.iter().enumerate() {
            let v = mesh.add_vertex(verts[o as usize]);
            mesh.vertex_origin[v as usize] = o;
            if split[i] {
                mesh.vertex_flags[v as usize] = V_LOCKED | V_CORNER;
            }
            if seen_origin[o as usize] && natural[o as usize] > 1 {
                report.extra_copies += 1;
            }
            seen_origin[o as usize] = true;
        }
        report.unreferenced_vertices = seen_origin.iter().filter(|&&s| !s).count();

        let mut edge_of: HashMap<u64, u32> = HashMap::with_capacity(2 * nf);
        for f in 0..nf {
            let c = if rejected[f] {
                tris[f].map(|o| {
                    let v = mesh.add_vertex(verts[o as usize]);
                    mesh.vertex_origin[v as usize] = o;
                    mesh.vertex_flags[v as usize] = V_LOCKED | V_CORNER;
                    report.extra_copies += 1;
                    v
                })
            } else {
                corner[f]
            };
            let patch = features.map_or(0, |ft| ft.face_patch[f]);
            let fid = mesh.new_face(patch);
            let mut hs = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (c[k], c[(k + 1) % 3]);
                let h = match edge_of.get(&key(a.min(b), a.max(b))) {
                    Some(&e) => {
                        if mesh.to[2 * e as usize] == b {
                            2 * e
                        } else {
                            2 * e + 1
                        }
                    }
                    None => {
                        let h = mesh.new_edge(a, b);
                        edge_of.insert(key(a.min(b), a.max(b)), h >> 1);
                        h
                    }
                };
                mesh.hface[h as usize] = fid;
                hs[k] = h;
                mesh.vout[a as usize] = h;
                mesh.vertex_hint[a as usize] = f as u32;
            }
            for k in 0..3 {
                mesh.link(hs[k], hs[(k + 1) % 3]);
            }
            mesh.fhe[fid as usize] = hs[0];
            if rejected[f] {
                for h in hs {
                    mesh.edge_flags[(h >> 1) as usize] = E_FEATURE | E_LOCKED;
                }
            }
        }
        // Boundary half-edges: make them the stored ones, then chain them.
        let nh = mesh.to.len() as u32;
        for h in 0..nh {
            if mesh.hface[h as usize] == NONE {
                let a = mesh.from_vertex(h);
                mesh.vout[a as usize] = h;
            }
        }
        for h in 0..nh {
            if mesh.hface[h as usize] == NONE {
                let b = mesh.to[h as usize];
                let n = mesh.vout[b as usize];
                mesh.link(h, n);
            }
        }
        // Edge flags from the input edges.
        for e in 0..mesh.n_edges() as u32 {
            let [a, b] = mesh.edge_vertices(e);
            let (oa, ob) = (
                mesh.vertex_origin[a as usize],
                mesh.vertex_origin[b as usize],
            );
            let Some(ie) = topo.find_edge(oa, ob) else {
                continue;
            };
            let nfaces = topo.faces_of_edge(ie).len();
            let mut flags = mesh.edge_flags[e as usize];
            match features {
                Some(ft) => {
                    if ft.edge_flags[ie] != 0 {
                        flags |= E_FEATURE;
                    }
                    if ft.edge_flags[ie] & NON_MANIFOLD != 0 {
                        flags |= E_LOCKED;
                    }
                }
                None => {
                    if nfaces != 2 {
                        flags |= E_FEATURE;
                    }
                    if nfaces > 2 {
                        flags |= E_LOCKED;
                    }
                }
            }
            // A boundary here that was not one in the input: a cut between
            // pieces, or else an orientation seam.
            if mesh.is_boundary_edge(e) && nfaces != 1 {
                flags |= E_FEATURE | E_LOCKED;
                let ef = topo.faces_of_edge(ie);
                if let (Some(p), 2) = (pieces, nfaces) {
                    if p[ef[0] as usize] != p[ef[1] as usize] {
                        flags |= E_CUT;
                    }
                }
            }
            mesh.edge_flags[e as usize] = flags;
        }
        let mut valence = vec![0u32; mesh.n_vertices()];
        for e in 0..mesh.n_edges() as u32 {
            let fl = mesh.edge_flags[e as usize];
            if fl & E_CUT != 0 {
                report.cut_edges += 1;
            } else if fl & E_LOCKED != 0 {
                report.locked_edges += 1;
            }
            for v in mesh.edge_vertices(e) {
                if fl & E_FEATURE != 0 {
                    valence[v as usize] += 1;
                }
                if fl & E_LOCKED != 0 {
                    mesh.vertex_flags[v as usize] |= V_LOCKED | V_CORNER;
                }
            }
        }
        for (v, &k) in valence.iter().enumerate() {
            if k > 0 {
                mesh.vertex_flags[v] |= V_FEATURE;
            }
            if k > 0 && k != 2 {
                mesh.vertex_flags[v] |= V_CORNER;
            }
        }
        (mesh, report)
    }
}

/// One copy per (vertex, fan), a fan never crossing from one piece to
/// another. Returns the copy at each face corner, the input vertex of each
/// copy, whether that input vertex has several copies, and per input vertex
/// how many fans it has regardless of the pieces.
type Fans = (Vec<[u32; 3]>, Vec<u32>, Vec<bool>, Vec<u32>);

fn fans(grid: &Grid, rejected: &[bool], pieces: Option<&[u32]>) -> Fans {
    let tris = grid.triangles();
    let topo = grid.topology();
    let mut corner = vec![[NONE; 3]; tris.len()];
    let mut origin = Vec::with_capacity(grid.vertices().len());
    let mut split = Vec::with_capacity(grid.vertices().len());
    let mut fs: Vec<u32> = Vec::new();
    let mut parent: Vec<usize> = Vec::new();
    // The fans as they would be without the pieces (only with pieces).
    let mut whole: Vec<usize> = Vec::new();
    let mut natural = vec![
        1u32;
        if pieces.is_some() {
            grid.vertices().len()
        } else {
            0
        }
    ];
    let mut label: Vec<u32> = Vec::new();
    for v in 0..grid.vertices().len() {
        fs.clear();
        fs.extend(
            topo.faces_of_vertex(v)
                .iter()
                .copied()
                .filter(|&f| !rejected[f as usize]),
        );
        if fs.is_empty() {
            continue;
        }
        parent.clear();
        parent.extend(0..fs.len());
        whole.clear();
        whole.extend(0..fs.len());
        let v32 = v as u32;
        for (i, &f) in fs.iter().enumerate() {
            let t = tris[f as usize];
            let k = t.iter().position(|&x| x == v32).unwrap_or(0);
            // Outgoing edge v → t[k+1] is face edge k; incoming t[k+2] → v is edge k+2.
            for (slot, w, outgoing) in [
                (k, t[(k + 1) % 3], true),
                ((k + 2) % 3, t[(k + 2) % 3], false),
            ] {
                let e = topo.face_edges[f as usize][slot] as usize;
                let ef = topo.faces_of_edge(e);
                if ef.len() != 2 {
                    continue;
                }
                let g = if ef[0] == f { ef[1] } else { ef[0] };
                if rejected[g as usize] {
                    continue;
                }
                let tg = tris[g as usize];
                let Some(j) = tg.iter().position(|&x| x == v32) else {
                    continue;
                };
                // Consistent orientation: g runs the edge the other way.
                let ok = if outgoing {
                    tg[(j + 2) % 3] == w
                } else {
                    tg[(j + 1) % 3] == w
                };
                if !ok {
                    continue;
                }
                let Some(gi) = fs.iter().position(|&x| x == g) else {
                    continue;
                };
                let (wa, wb) = (find(&mut whole, i), find(&mut whole, gi));
                if wa != wb {
                    whole[wa.max(wb)] = wa.min(wb);
                }
                if pieces.is_some_and(|p| p[f as usize] != p[g as usize]) {
                    continue;
                }
                let (ra, rb) = (find(&mut parent, i), find(&mut parent, gi));
                if ra != rb {
                    parent[ra.max(rb)] = ra.min(rb);
                }
            }
        }
        label.clear();
        label.resize(fs.len(), NONE);
        let first = origin.len() as u32;
        let mut count = 0u32;
        for i in 0..fs.len() {
            let r = find(&mut parent, i);
            if label[r] == NONE {
                label[r] = first + count;
                count += 1;
                origin.push(v32);
            }
            let f = fs[i] as usize;
            let k = tris[f].iter().position(|&x| x == v32).unwrap_or(0);
            corner[f][k] = label[r];
        }
        split.extend(std::iter::repeat_n(count > 1, count as usize));
        if let Some(n) = natural.get_mut(v) {
            *n = (0..fs.len()).filter(|&i| find(&mut whole, i) == i).count() as u32;
        }
    }
    if pieces.is_none() {
        // Without pieces the fans are the natural ones.
        natural = vec![0; grid.vertices().len()];
        for &o in &origin {
            natural[o as usize] += 1;
        }
    }
    (corner, origin, split, natural)
}
