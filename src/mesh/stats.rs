//! Descriptive statistics of a grid: angles, memory.

use super::Grid;
use crate::geometry::triangle_angles_deg;
use rayon::prelude::*;

/// Distribution of the smallest and largest angle per triangle, in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AngleStats {
    /// Smallest angle of the grid.
    pub min_angle: f64,
    /// 1st percentile of the per-triangle smallest angle.
    pub min_angle_p1: f64,
    /// Mean of the per-triangle smallest angle.
    pub min_angle_mean: f64,
    /// 99th percentile of the per-triangle largest angle.
    pub max_angle_p99: f64,
    /// Largest angle of the grid.
    pub max_angle: f64,
}

/// Counts and memory of a grid.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GridStats {
    /// Vertices.
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// Unique edges.
    pub edges: usize,
    /// Bodies (connected components).
    pub bodies: usize,
    /// Heap bytes of the grid (vertices, triangles, sizes, adjacency).
    pub grid_bytes: usize,
    /// Heap bytes of the BVH (nodes, leaf-ordered triangle copies, maps).
    pub bvh_bytes: usize,
}

impl GridStats {
    /// Bytes per triangle of what a query needs: vertices, triangles, sizes and BVH
    /// (adjacency excluded).
    pub fn query_bytes_per_triangle(&self, grid: &Grid) -> f64 {
        let core = grid.vertices().len() * 24
            + grid.triangles().len() * 12
            + grid.sizes().map_or(0, |s| s.len() * 8)
            + grid.node_min_size().len() * 8;
        (core + self.bvh_bytes) as f64 / self.triangles.max(1) as f64
    }
}

/// Triangles whose smallest angle is below `deg` degrees.
pub(crate) fn count_slivers(v: &[[f64; 3]], t: &[[u32; 3]], deg: f64) -> usize {
    t.par_iter()
        .filter(|t| {
            let a = triangle_angles_deg(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
            a[0].min(a[1]).min(a[2]) < deg
        })
        .count()
}

/// Nearest-rank percentile `q ∈ [0, 1]` of a sorted slice (NaN when empty).
pub(crate) fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((sorted.len() - 1) as f64 * q).round() as usize;
    sorted[i]
}

impl Grid {
    /// The smallest and the largest angle (degrees) of every triangle, each
    /// list sorted ascending. Parallel, deterministic. O(F log F).
    pub(crate) fn sorted_angles(&self) -> (Vec<f64>, Vec<f64>) {
        let v = self.vertices();
        let (mut mins, mut maxs): (Vec<f64>, Vec<f64>) = self
            .triangles()
            .par_iter()
            .map(|t| {
                let a = triangle_angles_deg(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
                (a[0].min(a[1]).min(a[2]), a[0].max(a[1]).max(a[2]))
            })
            .unzip();
        mins.par_sort_unstable_by(f64::total_cmp);
        maxs.par_sort_unstable_by(f64::total_cmp);
        (mins, maxs)
    }

    /// Angle statistics over all triangles. O(F log F).
    pub fn angle_stats(&self) -> AngleStats {
        let (mins, maxs) = self.sorted_angles();
        AngleStats {
            min_angle: mins.first().copied().unwrap_or(f64::NAN),
            min_angle_p1: percentile(&mins, 0.01),
            min_angle_mean: mins.iter().sum::<f64>() / mins.len().max(1) as f64,
            max_angle_p99: percentile(&maxs, 0.99),
            max_angle: maxs.last().copied().unwrap_or(f64::NAN),
        }
    }

    /// Counts and memory use.
    pub fn stats(&self) -> GridStats {
        let topo = self.topology();
        let grid_bytes = self.vertices().len() * 24
            + self.triangles().len() * 12
            + self.sizes().map_or(0, |s| s.len() * 8)
            + self.node_min_size().len() * 8
            + self
                .point_arrays()
                .iter()
                .map(|a| a.values.len() * 8)
                .sum::<usize>()
            + topo.edges.len() * 8
            + topo.edge_face_offsets.len() * 4
            + topo.edge_faces.len() * 4
            + topo.face_edges.len() * 12
            + topo.vertex_face_offsets.len() * 4
            + topo.vertex_faces.len() * 4
            + topo.face_body.len() * 4
            + self.prisms.get().map_or(0, |p| p.memory_bytes());
        GridStats {
            vertices: self.vertices().len(),
            triangles: self.triangles().len(),
            edges: topo.edges.len(),
            bodies: topo.body_count as usize,
            grid_bytes,
            bvh_bytes: self.bvh().memory_bytes(),
        }
    }
}
