//! Time of GCN-ABGS's per-iteration work on a sized grid: the features
//! ([`abgs::gcn::features::graph`]) and one forward pass of the model
//! ([`abgs::gcn::Model::predict`]), best of five, for the embedded model and
//! for any ONNX files given with `--model` (same inputs and output), so an
//! export change is measured side by side with the model it replaces. Also
//! prints the largest difference of each extra model's predictions from the
//! embedded one's.
//!
//! `cargo bench --bench gcn_inference -- SIZED.vtk [--model F.onnx]...`
//! (SIZED: a grid with sizes, e.g. from `abgs size`; default: a sized torus
//! of 64,800 faces).

use abgs::mesh::halfedge::HalfedgeMesh;
use abgs::sizing::SizeParams;
use abgs::Grid;
use std::time::Instant;

#[path = "../tests/common/shapes.rs"]
mod shapes;
use shapes::torus;

fn best_of<T>(n: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..n {
        let t = Instant::now();
        let r = f();
        best = best.min(t.elapsed().as_secs_f64());
        out = Some(r);
    }
    (best, out.unwrap())
}

fn main() {
    let mut args = std::env::args().skip(1).filter(|a| a != "--bench");
    let mut grid_path = None;
    let mut models = Vec::new();
    while let Some(a) = args.next() {
        if a == "--model" {
            models.push(args.next().expect("--model FILE"));
        } else {
            grid_path = Some(a);
        }
    }
    let mut grid = match &grid_path {
        Some(p) => Grid::load(std::path::Path::new(p)).unwrap(),
        None => torus(360, 90),
    };
    if grid.sizes().is_none() {
        grid.compute_sizes(&SizeParams::default()).unwrap();
    }
    let (mut mesh, _) = HalfedgeMesh::from_grid(&grid, None);
    for v in 0..mesh.n_vertices() {
        mesh.vertex_size[v] = grid.sizes().unwrap()[mesh.vertex_origin[v] as usize];
    }
    let (t_feat, g) = best_of(5, || abgs::gcn::features::graph(&mesh).unwrap());
    let i = &g.inputs;
    println!(
        "{}: {} faces, {} nodes, {} edges, K = {}",
        grid_path.as_deref().unwrap_or("torus"),
        grid.triangles().len(),
        i.n_nodes,
        i.n_edges,
        i.k
    );
    println!("features {:8.3} s", t_feat);
    let embedded = abgs::gcn::embedded_model().unwrap();
    let (t, base) = best_of(5, || embedded.predict(i).unwrap());
    println!(
        "model    {:8.3} s  embedded ({:.0} ns per edge)",
        t,
        1e9 * t / i.n_edges as f64
    );
    for m in &models {
        let model = abgs::gcn::Model::from_file(std::path::Path::new(m)).unwrap();
        let (t, p) = best_of(5, || model.predict(i).unwrap());
        let diff = p
            .iter()
            .flatten()
            .zip(base.iter().flatten())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        println!(
            "model    {:8.3} s  {m} ({:.0} ns per edge, max |Δ| {diff:.2e} from the embedded model)",
            t,
            1e9 * t / i.n_edges as f64
        );
    }
}
