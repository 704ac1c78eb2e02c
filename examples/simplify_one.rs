//! Simplifies one sized grid by LBO-ABGS and prints the iterations:
//! `cargo run --release --example simplify_one -- SIZED.vtk [OUT.vtk]`.

use abgs::mesh::Grid;
use abgs::simplify::{simplify, SimplifyParams};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let grid = Grid::load(Path::new(&args[1]))?;
    let mut cb = |r: &abgs::simplify::IterationRecord| {
        if r.iteration % 10 == 1 {
            eprintln!(
            "it {:3} faces {:7} cand {:6} est {:6} coll {:6} acc {:5} moved {:5} flips {:5} N {:.0} {:.3}s",
            r.iteration, r.faces, r.candidates, r.estimated, r.collapsible, r.accepted, r.moved, r.flips, r.element_count, r.seconds
        );
        }
        true
    };
    let mut params = SimplifyParams::default();
    if let Ok(t) = std::env::var("TAU_D") {
        params.tau_d = Some(t.parse()?);
    }
    let s = simplify(&grid, &params, Some(&mut cb))?;
    let r = &s.report;
    println!(
        "{} -> {} faces ({:.1} % reduction), {} iterations, {:?}, {:.2} s, N {:.0} -> {:.0}",
        r.faces_in,
        r.faces_out,
        100.0 * (1.0 - r.faces_out as f64 / r.faces_in as f64),
        r.iterations.len(),
        r.stop,
        r.seconds,
        r.element_count_in,
        r.iterations.last().map_or(0.0, |x| x.element_count)
    );
    let diag = grid.bbox().diagonal();
    let h = abgs::remesh::quality::hausdorff(&grid, &s.grid, 100_000, 1);
    println!("hausdorff / diag = {:.2e}", h / diag);
    if let Some(out) = args.get(2) {
        s.grid.save(Path::new(out))?;
    }
    Ok(())
}
