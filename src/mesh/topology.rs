//! Adjacency of a triangle grid: unique edges, edge→faces, face→edges,
//! vertex→faces, bodies (connected components), boundary and non-manifold edges.
//!
//! Everything is stored in flat compressed-sparse-row arrays, built in
//! O(F log F) by one sort of the 3F half-edges. The result is deterministic.

use rayon::prelude::*;

/// Adjacency tables of a grid. Immutable once built.
#[derive(Debug, Clone, Default)]
pub struct Topology {
    /// Unique undirected edges `[a, b]` with `a < b`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// Faces of edge `e` are `edge_faces[edge_face_offsets[e]..edge_face_offsets[e + 1]]`.
    pub edge_face_offsets: Vec<u32>,
    /// Flat edge→face list (see `edge_face_offsets`), faces ascending per edge.
    pub edge_faces: Vec<u32>,
    /// The three edges of each face: edge `k` joins corners `k` and `(k + 1) % 3`.
    pub face_edges: Vec<[u32; 3]>,
    /// Faces around vertex `v` are `vertex_faces[vertex_face_offsets[v]..vertex_face_offsets[v + 1]]`.
    pub vertex_face_offsets: Vec<u32>,
    /// Flat vertex→face list, faces ascending per vertex.
    pub vertex_faces: Vec<u32>,
    /// Body (connected component through manifold edges) of each face, numbered
    /// 0.. in order of each body's lowest face index.
    pub face_body: Vec<u32>,
    /// Number of bodies.
    pub body_count: u32,
}

impl Topology {
    /// Builds the tables for `triangles` over `vertex_count` vertices.
    /// Triangles must reference valid vertices and have three distinct corners.
    /// O(F log F) time, O(F) memory.
    pub fn build(vertex_count: usize, triangles: &[[u32; 3]]) -> Topology {
        // Half-edges keyed by (min, max, face, corner).
        let mut half: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(triangles.len() * 3);
        for (f, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                half.push((a.min(b), a.max(b), f as u32, k as u8));
            }
        }
        half.par_sort_unstable();
        let mut edges = Vec::new();
        let mut edge_face_offsets = vec![0u32];
        let mut edge_faces = Vec::with_capacity(half.len());
        let mut face_edges = vec![[u32::MAX; 3]; triangles.len()];
        let mut i = 0;
        while i < half.len() {
            let (a, b) = (half[i].0, half[i].1);
            let e = edges.len() as u32;
            edges.push([a, b]);
            while i < half.len() && half[i].0 == a && half[i].1 == b {
                let (f, k) = (half[i].2, half[i].3);
                if edge_faces.len() as u32 == *edge_face_offsets.last().unwrap()
                    || *edge_faces.last().unwrap() != f
                {
                    edge_faces.push(f);
                }
                face_edges[f as usize][k as usize] = e;
                i += 1;
            }
            edge_face_offsets.push(edge_faces.len() as u32);
        }

        // vertex -> faces by counting sort.
        let mut vertex_face_offsets = vec![0u32; vertex_count + 1];
        for t in triangles {
            for &v in t {
                vertex_face_offsets[v as usize + 1] += 1;
            }
        }
        for v in 0..vertex_count {
            vertex_face_offsets[v + 1] += vertex_face_offsets[v];
        }
        let mut fill = vertex_face_offsets.clone();
        let mut vertex_faces = vec![0u32; triangles.len() * 3];
        for (f, t) in triangles.iter().enumerate() {
            for &v in t {
                vertex_faces[fill[v as usize] as usize] = f as u32;
                fill[v as usize] += 1;
            }
        }

        let mut topo = Topology {
            edges,
            edge_face_offsets,
            edge_faces,
            face_edges,
            vertex_face_offsets,
            vertex_faces,
            face_body: Vec::new(),
            body_count: 0,
        };
        topo.label_bodies(triangles.len());
        topo
    }

    /// Union-find over faces joined by manifold edges (exactly two faces).
    fn label_bodies(&mut self, face_count: usize) {
        let (labels, count) = self.label_face_components(face_count, |_| true);
        self.face_body = labels;
        self.body_count = count;
    }

    /// Connected components of the faces, joining the two faces of every
    /// manifold edge `e` for which `joins(e)` is true. Components are numbered
    /// 0.. in order of their lowest face index; returns (label per face, count).
    /// O(F α(F)).
    pub fn label_face_components(
        &self,
        face_count: usize,
        joins: impl Fn(usize) -> bool,
    ) -> (Vec<u32>, u32) {
        let mut parent: Vec<u32> = (0..face_count as u32).collect();
        for e in 0..self.edges.len() {
            let fs = self.faces_of_edge(e);
            if fs.len() == 2 && joins(e) {
                union(&mut parent, fs[0], fs[1]);
            }
        }
        let mut label = vec![u32::MAX; face_count];
        let mut out = vec![0u32; face_count];
        let mut count = 0;
        for f in 0..face_count {
            let r = find(&mut parent, f as u32) as usize;
            if label[r] == u32::MAX {
                label[r] = count;
                count += 1;
            }
            out[f] = label[r];
        }
        (out, count)
    }

    /// Faces incident to edge `e`. O(1).
    #[inline]
    pub fn faces_of_edge(&self, e: usize) -> &[u32] {
        let (s, t) = (self.edge_face_offsets[e], self.edge_face_offsets[e + 1]);
        &self.edge_faces[s as usize..t as usize]
    }

    /// Faces incident to vertex `v`. O(1).
    #[inline]
    pub fn faces_of_vertex(&self, v: usize) -> &[u32] {
        let (s, t) = (self.vertex_face_offsets[v], self.vertex_face_offsets[v + 1]);
        &self.vertex_faces[s as usize..t as usize]
    }

    /// Number of edges with exactly one incident face.
    pub fn boundary_edge_count(&self) -> usize {
        (0..self.edges.len())
            .filter(|&e| self.faces_of_edge(e).len() == 1)
            .count()
    }

    /// Number of edges with more than two incident faces.
    pub fn non_manifold_edge_count(&self) -> usize {
        (0..self.edges.len())
            .filter(|&e| self.faces_of_edge(e).len() > 2)
            .count()
    }

    /// Index of edge `{a, b}` by binary search, if it exists. O(log E).
    pub fn find_edge(&self, a: u32, b: u32) -> Option<usize> {
        let key = [a.min(b), a.max(b)];
        self.edges.binary_search(&key).ok()
    }
}

/// Union-find root of `x` with path halving.
pub(crate) fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let g = parent[parent[x as usize] as usize];
        parent[x as usize] = g;
        x = g;
    }
    x
}

/// Joins the sets of `a` and `b`; the lower root becomes the root.
pub(crate) fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb) as usize] = ra.min(rb);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two tetrahedra sharing nothing, plus a lone triangle.
    fn sample() -> Vec<[u32; 3]> {
        let tet = |o: u32| {
            vec![
                [o, o + 2, o + 1],
                [o, o + 1, o + 3],
                [o + 1, o + 2, o + 3],
                [o, o + 3, o + 2],
            ]
        };
        let mut t = tet(0);
        t.extend(tet(4));
        t.push([8, 9, 10]);
        t
    }

    #[test]
    fn counts_and_bodies() {
        let t = sample();
        let topo = Topology::build(11, &t);
        assert_eq!(topo.edges.len(), 6 + 6 + 3);
        assert_eq!(topo.boundary_edge_count(), 3);
        assert_eq!(topo.non_manifold_edge_count(), 0);
        assert_eq!(topo.body_count, 3);
        assert_eq!(&topo.face_body[..5], &[0, 0, 0, 0, 1]);
        assert_eq!(topo.faces_of_vertex(0), &[0, 1, 3]);
        for (f, fe) in topo.face_edges.iter().enumerate() {
            for &e in fe {
                assert!(topo.faces_of_edge(e as usize).contains(&(f as u32)));
            }
        }
        assert_eq!(topo.find_edge(3, 0), Some(topo.face_edges[1][2] as usize));
    }

    #[test]
    fn non_manifold_edge_separates_bodies() {
        // Three triangles on edge (0,1).
        let (_, t) = crate::test_shapes::three_fins(1.0);
        let topo = Topology::build(5, &t);
        assert_eq!(topo.non_manifold_edge_count(), 1);
        assert_eq!(topo.body_count, 3);
    }
}
