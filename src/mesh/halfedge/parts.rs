//! A [`HalfedgeMesh`] taken apart into its connected *parts*, each a mesh of
//! its own, and put back together.
//!
//! [`HalfedgeMesh::from_grid`] already cuts bodies that touch apart (their
//! shared vertices become locked copies), so the parts are the bodies of an
//! assembly, and a local operation on one part never reads or writes another.
//! That makes them the unit of parallel work of the remesher: each part runs
//! its sequential passes on its own thread.
//!
//! Order is what keeps this deterministic and equal to working on the whole
//! mesh: a part keeps its vertices, edges and faces in the order they had in
//! the whole mesh, so any pass that walks elements in index order (or sorts
//! with the index as the tie-break) visits a part's elements in the same
//! relative order either way, and elements a pass appends are appended in the
//! same relative order too. Parts are listed by their lowest vertex index;
//! [`HalfedgeMesh::from_parts`] concatenates them in the order given.
//!
//! Cost: O(V + E + F) time for either direction; memory: the parts, then the
//! whole, each about the size of the other (a part is dropped as soon as it
//! has been appended).

use super::{HalfedgeMesh, NONE};

/// Union-find root of `x`, with path halving.
fn root(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let up = parent[parent[x as usize] as usize];
        parent[x as usize] = up;
        x = up;
    }
    x
}

impl HalfedgeMesh {
    /// The connected parts of the live mesh (vertices joined by live edges),
    /// each with every payload of its elements, listed by lowest vertex index,
    /// elements in their order here. Vertices on no edge belong to no part
    /// (they are on no face either, so no output keeps them). Indices that
    /// name other elements (half-edge links, a vertex's or face's half-edge)
    /// are renumbered; payload indices into other data (`vertex_origin`,
    /// `vertex_hint`, `edge_line`, `face_patch`) are kept as they are.
    /// O(V + E + F).
    pub fn into_parts(self) -> Vec<HalfedgeMesh> {
        let nv = self.n_vertices();
        let mut parent: Vec<u32> = (0..nv as u32).collect();
        let mut on_edge = vec![false; nv];
        for e in self.edges() {
            let [a, b] = self.edge_vertices(e);
            (on_edge[a as usize], on_edge[b as usize]) = (true, true);
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            // The lower index becomes the root, so a root is its part's lowest vertex.
            if ra != rb {
                parent[ra.max(rb) as usize] = ra.min(rb);
            }
        }
        // Part of each vertex root, numbered in order of the lowest vertex.
        let mut part_of_root = vec![NONE; nv];
        let mut vpart = vec![NONE; nv];
        let mut n_parts = 0u32;
        for v in 0..nv as u32 {
            if self.vertex_deleted(v) || !on_edge[v as usize] {
                continue;
            }
            let r = root(&mut parent, v) as usize;
            if part_of_root[r] == NONE {
                part_of_root[r] = n_parts;
                n_parts += 1;
            }
            vpart[v as usize] = part_of_root[r];
        }
        drop((parent, part_of_root, on_edge));
        // Local index of every element in its part.
        let mut counts = vec![[0u32; 3]; n_parts as usize];
        let mut vlocal = vec![NONE; nv];
        for v in 0..nv {
            if vpart[v] != NONE {
                let c = &mut counts[vpart[v] as usize][0];
                vlocal[v] = *c;
                *c += 1;
            }
        }
        let epart = |e: u32| vpart[self.to_vertex(2 * e) as usize];
        let mut elocal = vec![NONE; self.n_edges()];
        for e in self.edges() {
            let c = &mut counts[epart(e) as usize][1];
            elocal[e as usize] = *c;
            *c += 1;
        }
        let fpart = |f: u32| vpart[self.to_vertex(self.face_halfedge(f)) as usize];
        let mut flocal = vec![NONE; self.n_faces()];
        for f in self.faces() {
            let c = &mut counts[fpart(f) as usize][2];
            flocal[f as usize] = *c;
            *c += 1;
        }
        let hmap = |h: u32| {
            if h == NONE {
                NONE
            } else {
                2 * elocal[(h >> 1) as usize] + (h & 1)
            }
        };
        let fmap = |f: u32| if f == NONE { NONE } else { flocal[f as usize] };
        let mut parts: Vec<HalfedgeMesh> = counts
            .iter()
            .map(|&[v, e, f]| {
                let (v, e, f) = (v as usize, e as usize, f as usize);
                HalfedgeMesh {
                    to: Vec::with_capacity(2 * e),
                    next: Vec::with_capacity(2 * e),
                    prev: Vec::with_capacity(2 * e),
                    hface: Vec::with_capacity(2 * e),
                    vout: Vec::with_capacity(v),
                    fhe: Vec::with_capacity(f),
                    vdel: vec![false; v],
                    edel: vec![false; e],
                    fdel: vec![false; f],
                    deleted: [0; 3],
                    positions: Vec::with_capacity(v),
                    vertex_size: Vec::with_capacity(v),
                    vertex_flags: Vec::with_capacity(v),
                    vertex_origin: Vec::with_capacity(v),
                    vertex_hint: Vec::with_capacity(v),
                    edge_flags: Vec::with_capacity(e),
                    edge_line: Vec::with_capacity(e),
                    face_patch: Vec::with_capacity(f),
                }
            })
            .collect();
        for v in 0..nv {
            if vpart[v] == NONE {
                continue;
            }
            let p = &mut parts[vpart[v] as usize];
            p.vout.push(hmap(self.vout[v]));
            p.positions.push(self.positions[v]);
            p.vertex_size.push(self.vertex_size[v]);
            p.vertex_flags.push(self.vertex_flags[v]);
            p.vertex_origin.push(self.vertex_origin[v]);
            p.vertex_hint.push(self.vertex_hint[v]);
        }
        for e in self.edges() {
            let p = &mut parts[epart(e) as usize];
            for h in [2 * e, 2 * e + 1] {
                let h = h as usize;
                p.to.push(vlocal[self.to[h] as usize]);
                p.next.push(hmap(self.next[h]));
                p.prev.push(hmap(self.prev[h]));
                p.hface.push(fmap(self.hface[h]));
            }
            p.edge_flags.push(self.edge_flags[e as usize]);
            p.edge_line.push(self.edge_line[e as usize]);
        }
        for f in self.faces() {
            let p = &mut parts[fpart(f) as usize];
            p.fhe.push(hmap(self.fhe[f as usize]));
            p.face_patch.push(self.face_patch[f as usize]);
        }
        parts
    }

    /// The parts concatenated in the order given (vertices, edges and faces
    /// of the first part first), with their tombstones. Each part is dropped
    /// once it has been appended. O(V + E + F).
    pub fn from_parts(parts: Vec<HalfedgeMesh>) -> HalfedgeMesh {
        let total = |f: fn(&HalfedgeMesh) -> usize| parts.iter().map(f).sum::<usize>();
        let (nv, ne, nf) = (
            total(HalfedgeMesh::n_vertices),
            total(HalfedgeMesh::n_edges),
            total(HalfedgeMesh::n_faces),
        );
        let mut m = HalfedgeMesh::new();
        m.reserve_exact(nv, ne, nf);
        for p in parts {
            let (dv, dh, df) = (
                m.n_vertices() as u32,
                2 * m.n_edges() as u32,
                m.n_faces() as u32,
            );
            let shift = |x: u32, d: u32| if x == NONE { NONE } else { x + d };
            m.to.extend(p.to.iter().map(|&v| shift(v, dv)));
            m.next.extend(p.next.iter().map(|&h| shift(h, dh)));
            m.prev.extend(p.prev.iter().map(|&h| shift(h, dh)));
            m.hface.extend(p.hface.iter().map(|&f| shift(f, df)));
            m.vout.extend(p.vout.iter().map(|&h| shift(h, dh)));
            m.fhe.extend(p.fhe.iter().map(|&h| shift(h, dh)));
            m.vdel.extend_from_slice(&p.vdel);
            m.edel.extend_from_slice(&p.edel);
            m.fdel.extend_from_slice(&p.fdel);
            for k in 0..3 {
                m.deleted[k] += p.deleted[k];
            }
            m.positions.extend_from_slice(&p.positions);
            m.vertex_size.extend_from_slice(&p.vertex_size);
            m.vertex_flags.extend_from_slice(&p.vertex_flags);
            m.vertex_origin.extend_from_slice(&p.vertex_origin);
            m.vertex_hint.extend_from_slice(&p.vertex_hint);
            m.edge_flags.extend_from_slice(&p.edge_flags);
            m.edge_line.extend_from_slice(&p.edge_line);
            m.face_patch.extend_from_slice(&p.face_patch);
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_shapes::{canonical_triangles, touching_sheets};

    #[test]
    fn parts_put_back_together_are_the_mesh() {
        let g = touching_sheets();
        let (mut mesh, _) = HalfedgeMesh::from_grid(&g, None);
        // Tombstones and a payload that differs per element.
        let e = mesh
            .edges()
            .find(|&e| mesh.edge_flags[e as usize] == 0)
            .unwrap();
        let [a, b] = mesh.edge_vertices(e);
        let mid =
            crate::geometry::lerp(mesh.positions[a as usize], mesh.positions[b as usize], 0.5);
        let v = mesh.split(e, mid);
        mesh.collapse(
            mesh.find_halfedge(v, a).unwrap(),
            mesh.positions[a as usize],
        )
        .unwrap();
        for v in 0..mesh.n_vertices() {
            mesh.vertex_size[v] = v as f64;
            mesh.vertex_hint[v] = 3 * v as u32;
        }
        mesh.check().unwrap();
        let whole = mesh.clone();
        let parts = mesh.into_parts();
        // Touching sheets come apart at their locked copies: one part each.
        assert_eq!(parts.len(), 4);
        for p in &parts {
            p.check().unwrap();
            assert!(p.face_count() > 0);
        }
        let back = HalfedgeMesh::from_parts(parts);
        back.check().unwrap();
        let (va, ta, _) = whole.to_arrays(true);
        let (vb, tb, _) = back.to_arrays(true);
        assert_eq!(canonical_triangles(&va, &ta), canonical_triangles(&vb, &tb));
        assert_eq!(va.len(), vb.len());
        // Payload travels with its element.
        let key = |m: &HalfedgeMesh| {
            let mut s: Vec<_> = m
                .vertices()
                .map(|v| {
                    let i = v as usize;
                    (
                        m.positions[i].map(f64::to_bits),
                        m.vertex_size[i].to_bits(),
                        m.vertex_hint[i],
                        m.vertex_flags[i],
                        m.vertex_origin[i],
                        m.valence(v),
                    )
                })
                .collect();
            s.sort();
            s
        };
        assert_eq!(key(&whole), key(&back));
    }

    #[test]
    fn an_empty_mesh_has_no_parts() {
        assert!(HalfedgeMesh::new().into_parts().is_empty());
        assert_eq!(HalfedgeMesh::from_parts(Vec::new()).n_vertices(), 0);
    }
}
