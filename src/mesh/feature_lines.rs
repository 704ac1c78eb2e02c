//! Feature lines of a half-edge mesh: corners (feature vertices whose
//! feature valence is not 2, or where the line turns by more than the corner
//! angle), lines (chains of feature edges between corners, or closed loops)
//! numbered in `edge_line`, and their segments with a BVH for closest-point
//! projections. The constraints the remesher and both simplifiers keep: a
//! feature vertex only moves along its line, a corner never moves.

use crate::geometry::{dot, norm, sub};
use crate::mesh::halfedge::{HalfedgeMesh, E_FEATURE, NONE, V_CORNER, V_FEATURE};
use crate::spatial::{Bvh, ClosestHit};

/// Feature segments of the input, grouped in lines, with a BVH over them
/// (each segment stored as a degenerate triangle `[a, b, b]`).
#[derive(Debug, Clone, Default)]
pub struct FeatureLines {
    /// Line of each segment.
    pub seg_line: Vec<u32>,
    /// Number of lines.
    pub line_count: u32,
    /// The mesh vertices each segment joined when the lines were collected.
    pub seg_vertices: Vec<[u32; 2]>,
    bvh: Bvh,
}

impl FeatureLines {
    /// Closest point of `p` on line `line` (the segment index is the hit's
    /// `triangle`; its `bary[0]` weighs the segment's first end). O(log S)
    /// typically, with `hint` a segment near `p`.
    pub fn closest(&self, p: [f64; 3], line: u32, hint: u32) -> Option<ClosestHit> {
        self.bvh
            .closest_filtered(p, Some(hint), |s| self.seg_line[s as usize] == line)
    }
}

/// Marks as corners the feature vertices whose feature valence is not 2 and
/// those where the line turns by more than `corner_deg`; returns how many
/// turning corners it added. O(V · valence).
pub fn mark_corners(mesh: &mut HalfedgeMesh, corner_deg: f64) -> usize {
    let cos_c = corner_deg.to_radians().cos();
    let mut turned = 0;
    for v in 0..mesh.n_vertices() as u32 {
        let fl = mesh.vertex_flags[v as usize];
        if fl & V_FEATURE == 0 || fl & V_CORNER != 0 || mesh.is_isolated(v) {
            continue;
        }
        let ends: Vec<u32> = mesh
            .outgoing(v)
            .filter(|&h| mesh.edge_flags[mesh.edge(h) as usize] & E_FEATURE != 0)
            .map(|h| mesh.to_vertex(h))
            .collect();
        if ends.len() != 2 {
            mesh.vertex_flags[v as usize] |= V_CORNER;
            continue;
        }
        let p = mesh.positions[v as usize];
        let d1 = sub(p, mesh.positions[ends[0] as usize]);
        let d2 = sub(mesh.positions[ends[1] as usize], p);
        let (l1, l2) = (norm(d1), norm(d2));
        if !(l1 > 0.0 && l2 > 0.0) || dot(d1, d2) < cos_c * l1 * l2 {
            mesh.vertex_flags[v as usize] |= V_CORNER;
            turned += 1;
        }
    }
    turned
}

/// Marks corners (see [`mark_corners`]), then numbers the feature lines
/// (chains of feature edges between corners, or closed loops) in
/// `mesh.edge_line`, and collects them as segments.
/// Returns the lines and the number of turning corners added.
pub fn feature_lines(mesh: &mut HalfedgeMesh, corner_deg: f64) -> (FeatureLines, usize) {
    let turned = mark_corners(mesh, corner_deg);
    let ne = mesh.n_edges();
    for e in 0..ne {
        mesh.edge_line[e] = NONE;
    }
    let mut lines = 0u32;
    let mut stack = Vec::new();
    for e0 in 0..ne as u32 {
        if mesh.edge_flags[e0 as usize] & E_FEATURE == 0 || mesh.edge_line[e0 as usize] != NONE {
            continue;
        }
        mesh.edge_line[e0 as usize] = lines;
        stack.push(e0);
        while let Some(e) = stack.pop() {
            for v in mesh.edge_vertices(e) {
                if mesh.vertex_flags[v as usize] & V_CORNER != 0 {
                    continue;
                }
                let hs: Vec<u32> = mesh.outgoing(v).collect();
                for h in hs {
                    let f = mesh.edge(h);
                    if mesh.edge_flags[f as usize] & E_FEATURE != 0
                        && mesh.edge_line[f as usize] == NONE
                    {
                        mesh.edge_line[f as usize] = lines;
                        stack.push(f);
                    }
                }
            }
        }
        lines += 1;
    }
    let mut pts = Vec::new();
    let mut tris = Vec::new();
    let mut seg_line = Vec::new();
    let mut seg_vertices = Vec::new();
    for e in 0..ne as u32 {
        if mesh.edge_flags[e as usize] & E_FEATURE == 0 {
            continue;
        }
        let [a, b] = mesh.edge_vertices(e);
        let i = pts.len() as u32;
        pts.push(mesh.positions[a as usize]);
        pts.push(mesh.positions[b as usize]);
        tris.push([i, i + 1, i + 1]);
        seg_line.push(mesh.edge_line[e as usize]);
        seg_vertices.push([a, b]);
    }
    let bvh = Bvh::build(&pts, &tris);
    (
        FeatureLines {
            seg_line,
            line_count: lines,
            seg_vertices,
            bvh,
        },
        turned,
    )
}
