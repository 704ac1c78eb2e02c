//! Time of each sizing stage (features, curvature, proximity, gradation) on a
//! 64,800-face torus and on the shared models given on the command line
//! (default: trimesh_cycloidal). Best of five runs each.
//!
//! `cargo bench --bench sizing_stages [-- MODEL...]`

use abgs::sizing::{self, SizeParams};
use abgs::Grid;
use std::path::PathBuf;

#[path = "../tests/common/shapes.rs"]
mod shapes;
use shapes::torus;

fn report(name: &str, g: &Grid) {
    let p = SizeParams::default();
    let mut best = [f64::INFINITY; 5];
    let mut fixed = 0;
    for _ in 0..5 {
        let t0 = std::time::Instant::now();
        let f = sizing::compute(g, &p).unwrap();
        let total = t0.elapsed().as_secs_f64();
        let r = f.report;
        fixed = r.gradation.faces_fixed;
        for (b, x) in best.iter_mut().zip([
            r.seconds_features,
            r.seconds_curvature,
            r.seconds_proximity,
            r.seconds_gradation,
            total,
        ]) {
            *b = b.min(x);
        }
    }
    println!(
        "{:<28} {:>8} {:>10.1} {:>10.1} {:>10.1} {:>10.1} {:>10.1} {:>8}",
        name,
        g.triangles().len(),
        best[0] * 1e3,
        best[1] * 1e3,
        best[2] * 1e3,
        best[3] * 1e3,
        best[4] * 1e3,
        fixed
    );
}

fn main() {
    let threads = rayon::current_num_threads();
    println!("sizing stages, best of 5, milliseconds ({threads} threads)");
    println!(
        "{:<28} {:>8} {:>10} {:>10} {:>10} {:>10} {:>10} {:>8}",
        "grid", "faces", "features", "curvature", "proximity", "gradation", "total", "fixed"
    );
    report("torus 180x180", &torus(180, 180));
    let root = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/meshes"));
    let mut models: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    if models.is_empty() {
        models.push("trimesh_cycloidal.stl".into());
    }
    for m in models {
        let path = if std::path::Path::new(&m).exists() {
            PathBuf::from(&m)
        } else {
            root.join(&m)
        };
        match Grid::load(&path) {
            Ok(g) => report(&m, &g),
            Err(e) => eprintln!("{m}: {e}"),
        }
    }
}
