//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod shapes;

use std::path::PathBuf;

/// The third-party models folder (`../shared/meshes` beside the checkout).
/// A test that needs it fails when it is missing: a model test that passes
/// without its model would prove nothing.
pub fn shared_meshes() -> PathBuf {
    let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/meshes"));
    assert!(
        dir.is_dir(),
        "{} is missing: the tests need ../shared beside the checkout",
        dir.display()
    );
    dir
}

/// A positive linear field a·x + b·y + c·z + d over the grid's bounding box.
pub fn linear_field(bmin: [f64; 3], diag: f64) -> impl Fn([f64; 3]) -> f64 + Sync {
    move |p: [f64; 3]| {
        0.05 * diag + 0.3 * (p[0] - bmin[0]) - 0.2 * (p[1] - bmin[1])
            + 0.1 * (p[2] - bmin[2])
            + 0.2 * diag
    }
}

/// `grid` with sizes `f(p)` at its vertices.
pub fn with_sizes(grid: &abgs::Grid, f: impl Fn([f64; 3]) -> f64) -> abgs::Grid {
    let h = grid.vertices().iter().map(|&p| f(p)).collect();
    abgs::Grid::from_arrays(
        grid.vertices().to_vec(),
        grid.triangles().to_vec(),
        Some(h),
        &abgs::BuildOptions {
            weld_relative_tolerance: None,
            orient: false,
        },
    )
    .unwrap()
}

pub fn euler(g: &abgs::Grid) -> i64 {
    g.vertices().len() as i64 - g.topology().edges.len() as i64 + g.triangles().len() as i64
}
