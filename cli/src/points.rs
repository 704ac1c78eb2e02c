//! The three benchmark point sets.

use abgs::sampling;
use abgs::Grid;

/// A named point set.
pub struct PointSet {
    /// Short name for tables.
    pub name: &'static str,
    /// The points.
    pub points: Vec<[f64; 3]>,
}

/// Near-surface (offset up to 0.5 % of the diagonal), uniform in the box (5 %
/// margin), and a coherent walk (steps of 0.2 % of the diagonal).
pub fn standard_sets(grid: &Grid, n: usize) -> Vec<PointSet> {
    let d = grid.bbox().diagonal();
    vec![
        PointSet {
            name: "near-surface",
            points: sampling::near_surface_points(grid, n, 0.005 * d, 1),
        },
        PointSet {
            name: "uniform-box",
            points: sampling::box_points(grid, n, 0.05, 2),
        },
        PointSet {
            name: "front-walk",
            points: sampling::walk_points(grid, n, 0.002 * d, 3),
        },
    ]
}
