//! The reference (input) surface the remesher projects onto: the input grid's
//! triangles restricted to one smooth patch, the input feature segments
//! restricted to one feature line, and the target edge length carried along.

use super::field::SourceField;
use crate::geometry::{dist2, norm, sub};
pub use crate::mesh::feature_lines::{feature_lines, FeatureLines};
use crate::mesh::Grid;

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
        let hit = self.lines.closest(p, line, hint)?;
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
            .closest(p, line, hint)
            .map_or(f64::INFINITY, |h| dist2(h.closest.point, p).sqrt())
    }
}
