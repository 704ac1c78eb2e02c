//! Gradation part by part: the connected pieces of a grid graded side by
//! side, with the values of grading the grid as one.
//!
//! # Why it is the same field
//!
//! Every step of [`super::grade`] moves information only along the grid's
//! edges and faces: the fast marchings finalise a vertex and update the
//! corners of its faces, the speed requests spread by edge hops, the fixes
//! lower the corners of one face and re-check the faces around them, the
//! raise reads a vertex's faces. So two pieces that share no vertex never
//! read each other's values. Each piece keeps its vertices and faces in
//! ascending order of their indices in the grid, so every heap, sort and
//! face list that breaks ties by index sees a piece's elements in the order
//! it sees them in the whole grid, and every value is computed by the same
//! operations: the field is the whole grid's bit for bit (unit test). Two
//! global choices are made for the whole grid, as [`super::grade`] makes
//! them: nothing is done when no face of the grid is too steep, and
//! otherwise every piece runs every step (a piece without a steep face
//! marches again with unit speed factors, which gives its first marching's
//! values again). One bound is per piece: the fixes' safety cap (16 per
//! face plus 1024) counts a piece's faces, where the whole grid's counts
//! all of them; it is reached only on fields no marching can grade, and
//! then only the fixes after it differ.
//!
//! # Ties and cost
//!
//! Pieces are vertex-connected (bodies touching at a shared vertex are one
//! piece), found by union–find over the triangles' corners. Building them
//! costs O(F log F) once (each piece's [`Topology`]) and a copy of the
//! positions and triangles; grading them is O(F log F) in all, the pieces
//! largest first on the rayon pool, so a grid of many bodies grades in
//! about its largest piece's time or its total over the threads. The
//! output does not depend on the thread count.

use super::{grade_with, graded_already, max_face_slope, GradationReport};
use crate::mesh::topology::{find, union};
use crate::mesh::Topology;
use rayon::prelude::*;

/// One vertex-connected piece of a grid.
struct Piece {
    /// The piece's vertices' indices in the grid, ascending.
    vertices: Vec<u32>,
    /// Their positions.
    positions: Vec<[f64; 3]>,
    /// The piece's triangles, in the grid's order, over local indices.
    triangles: Vec<[u32; 3]>,
    /// Their topology.
    topo: Topology,
}

/// A grid cut into its vertex-connected pieces, ready to be graded side by
/// side ([`Pieces::grade`]) as often as needed.
pub struct Pieces {
    pieces: Vec<Piece>,
    vertex_count: usize,
}

impl Pieces {
    /// The pieces of the grid `(vertices, triangles)`; `None` when it has
    /// fewer than two (nothing to gain). Triangles must reference valid
    /// vertices. O(F log F).
    pub fn new(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Option<Pieces> {
        let n = vertices.len();
        let mut parent: Vec<u32> = (0..n as u32).collect();
        for t in triangles {
            union(&mut parent, t[0], t[1]);
            union(&mut parent, t[0], t[2]);
        }
        // Piece of each vertex on a triangle, numbered by lowest vertex.
        let mut on_triangle = vec![false; n];
        for t in triangles {
            for &c in t {
                on_triangle[c as usize] = true;
            }
        }
        let mut piece_of_root = vec![u32::MAX; n];
        let mut piece = vec![u32::MAX; n];
        let mut count = 0u32;
        for v in 0..n {
            if !on_triangle[v] {
                continue;
            }
            let r = find(&mut parent, v as u32) as usize;
            if piece_of_root[r] == u32::MAX {
                piece_of_root[r] = count;
                count += 1;
            }
            piece[v] = piece_of_root[r];
        }
        if count < 2 {
            return None;
        }
        let mut local = vec![0u32; n];
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); count as usize];
        for v in 0..n {
            if piece[v] != u32::MAX {
                let m = &mut members[piece[v] as usize];
                local[v] = m.len() as u32;
                m.push(v as u32);
            }
        }
        let mut tris: Vec<Vec<[u32; 3]>> = vec![Vec::new(); count as usize];
        for t in triangles {
            tris[piece[t[0] as usize] as usize].push(t.map(|c| local[c as usize]));
        }
        let pieces = members
            .into_par_iter()
            .zip(tris)
            .map(|(vs, ts)| Piece {
                positions: vs.iter().map(|&v| vertices[v as usize]).collect(),
                topo: Topology::build(vs.len(), &ts),
                vertices: vs,
                triangles: ts,
            })
            .collect();
        Some(Pieces {
            pieces,
            vertex_count: n,
        })
    }

    /// Number of pieces.
    pub fn len(&self) -> usize {
        self.pieces.len()
    }

    /// Never true: a [`Pieces`] has at least two.
    pub fn is_empty(&self) -> bool {
        self.pieces.is_empty()
    }

    /// [`super::grade`] of the whole grid, piece by piece side by side (see
    /// the module doc): the same values and report. `vertices` and
    /// `triangles` are the grid's, as given to [`Pieces::new`].
    pub fn grade(
        &self,
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        h0: &[f64],
        s: f64,
    ) -> (Vec<f64>, GradationReport) {
        assert_eq!(h0.len(), self.vertex_count, "one initial size per vertex");
        assert!(s.is_finite() && s > 0.0, "slope {s} must be finite and > 0");
        let (max0, bad0) = max_face_slope(vertices, triangles, h0, s);
        if bad0 == 0 {
            return graded_already(h0, max0 / s);
        }
        let mut order: Vec<usize> = (0..self.pieces.len()).collect();
        order.sort_by_key(|&i| (std::cmp::Reverse(self.pieces[i].triangles.len()), i));
        let mut done: Vec<(usize, Vec<f64>, GradationReport)> = order
            .into_par_iter()
            .with_max_len(1)
            .map(|i| {
                let p = &self.pieces[i];
                let h: Vec<f64> = p.vertices.iter().map(|&v| h0[v as usize]).collect();
                let (h, r) = grade_with(&p.positions, &p.triangles, &p.topo, &h, s, false);
                (i, h, r)
            })
            .collect();
        done.sort_unstable_by_key(|x| x.0);
        let mut h = h0.to_vec();
        let mut report = GradationReport::default();
        for (i, hp, r) in done {
            for (&v, x) in self.pieces[i].vertices.iter().zip(hp) {
                h[v as usize] = x;
            }
            report.faces_fixed += r.faces_fixed;
            report.vertices_lowered += r.vertices_lowered;
            report.max_slope_ratio_before_fix = report
                .max_slope_ratio_before_fix
                .max(r.max_slope_ratio_before_fix);
            report.max_slope_ratio = report.max_slope_ratio.max(r.max_slope_ratio);
        }
        (h, report)
    }
}
