//! The reference (input) surface the remesher projects onto: the input grid's
//! triangles restricted to one smooth patch, the input feature segments
//! restricted to one feature line, and the target edge length carried along.

use super::field::SourceField;
use crate::geometry::{dist2, dot, norm, sub};
use crate::mesh::halfedge::{HalfedgeMesh, E_FEATURE, NONE, V_CORNER, V_FEATURE};
use crate::mesh::Grid;
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
pub(crate) fn mark_corners(mesh: &mut HalfedgeMesh, corner_deg: f64) -> usize {
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

/// A free vertex closer than this fraction of its target length to the rim of
/// its patch counts as on the rim (it would make flat faces with the rim).
pub const RIM_GAP: f64 = 0.05;

/// Where a vertex landed on the reference, with the target length there.
#[derive(Debug, Clone, Copy)]
pub struct Projected {
    /// The projected position.
    pub point: [f64; 3],
    /// The triangle or segment found (the next hint).
    pub hint: u32,
    /// Target edge length at the point.
    pub size: f64,
    /// The point is on (within [`RIM_GAP`] target lengths of) the rim of its
    /// patch, an input feature edge: a free vertex there has left its patch or
    /// is about to make flat faces with the rim.
    pub on_rim: bool,
}

/// The surface the remesher projects onto and the target length on it.
pub struct Reference<'a> {
    /// The input grid.
    pub grid: &'a Grid,
    /// Patch of each input triangle.
    pub face_patch: &'a [u32],
    /// Per input edge: is it a feature edge?
    pub edge_is_feature: &'a [bool],
    /// Per patch: too narrow for vertices inside (see `thin_patches`).
    pub thin_patch: &'a [bool],
    /// Input feature lines.
    pub lines: &'a FeatureLines,
    /// Uniform target length (`None` in size-driven mode).
    pub base: Option<f64>,
    /// Cap on the target length (curvature and creases, graded).
    pub cap: &'a SourceField,
    /// Size-driven mode: the grid whose sizes give the target length.
    pub sizing: Option<&'a Grid>,
}

impl Reference<'_> {
    /// Target length at `p`.
    pub fn target(&self, p: [f64; 3]) -> f64 {
        let cap = self.cap.eval(p);
        let base = match (self.base, self.sizing) {
            (Some(b), _) => b,
            (None, Some(g)) => match g.closest(p, None) {
                Ok(h) if h.size.is_finite() && h.size > 0.0 => h.size,
                _ => f64::INFINITY,
            },
            (None, None) => f64::INFINITY,
        };
        let t = base.min(cap);
        if t.is_finite() {
            t
        } else {
            self.grid.bbox().diagonal() / 100.0
        }
    }

    /// Closest point of `p` on patch `patch` of the input (any triangle if the
    /// patch has none near). `None` only for an empty grid.
    pub fn project_patch(&self, p: [f64; 3], patch: u32, hint: u32) -> Option<Projected> {
        let bvh = self.grid.bvh();
        let hit = bvh
            .closest_filtered(p, Some(hint), |t| self.face_patch[t as usize] == patch)
            .or_else(|| bvh.closest(p, None))?;
        let b = hit.closest.bary;
        let t = hit.triangle as usize;
        let fe = &self.grid.topology().face_edges[t];
        let c = self.grid.triangles()[t].map(|i| self.grid.vertices()[i as usize]);
        let size = self.target(hit.closest.point);
        // Distance to the edge opposite corner k is b[k] times the height over
        // it; that edge is face edge (k + 1) % 3.
        let twice_area = norm(crate::geometry::triangle_normal2(c[0], c[1], c[2]));
        let on_rim = (0..3).any(|k| {
            let e = fe[(k + 1) % 3] as usize;
            if !self.edge_is_feature[e] {
                return false;
            }
            let len = norm(sub(c[(k + 1) % 3], c[(k + 2) % 3]));
            b[k] == 0.0 || (len > 0.0 && b[k] * twice_area / len < RIM_GAP * size)
        });
        Some(Projected {
            point: hit.closest.point,
            hint: hit.triangle,
            size,
            on_rim,
        })
    }

    /// Closest point of `p` on feature line `line` of the input.
    pub fn project_line(&self, p: [f64; 3], line: u32, hint: u32) -> Option<Projected> {
        let hit = self
            .lines
            .bvh
            .closest_filtered(p, Some(hint), |s| self.lines.seg_line[s as usize] == line)?;
        Some(Projected {
            point: hit.closest.point,
            hint: hit.triangle,
            size: self.target(hit.closest.point),
            on_rim: false,
        })
    }

    /// Distance from `p` to the nearest segment of line `line` (∞ if none).
    pub fn distance_to_line(&self, p: [f64; 3], line: u32, hint: u32) -> f64 {
        self.lines
            .bvh
            .closest_filtered(p, Some(hint), |s| self.lines.seg_line[s as usize] == line)
            .map_or(f64::INFINITY, |h| dist2(h.closest.point, p).sqrt())
    }
}
