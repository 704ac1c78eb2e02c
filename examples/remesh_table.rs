//! Remeshes every model in `../shared/meshes` (or the files given) with the
//! default uniform parameters and prints the acceptance table.
//!
//! `cargo run --release --example remesh_table [-- FILE...]`

use abgs::remesh::{quality, remesh, RemeshParams};
use abgs::Grid;
use std::path::PathBuf;
use std::time::Instant;

fn main() {
    let args: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    let files = if args.is_empty() {
        let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/meshes"));
        let mut v: Vec<PathBuf> = match std::fs::read_dir(&dir) {
            Ok(d) => d.filter_map(|e| e.ok().map(|e| e.path())).collect(),
            Err(_) => {
                eprintln!("no models at {}", dir.display());
                return;
            }
        };
        v.retain(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("stl" | "obj" | "off")
            )
        });
        v.sort();
        v
    } else {
        args
    };
    let mut params = RemeshParams::default();
    if let Some(r) = std::env::var("MIN_RATIO").ok().and_then(|s| s.parse().ok()) {
        params.min_length_ratio = r;
    }
    if let Some(r) = std::env::var("LINE_MIN_RATIO")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        params.line_min_length_ratio = r;
    }
    if let Some(r) = std::env::var("GRADATION").ok().and_then(|s| s.parse().ok()) {
        params.gradation = r;
    }
    if let Some(r) = std::env::var("ITERATIONS")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        params.iterations = r;
    }
    println!(
        "| model | faces in | faces out | min∠ p1 | max∠ p99 | Hausdorff/diag | feature H./diag | bodies in→out | new bnd / nm | new creases | s | verdict |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for p in files {
        let name = p
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        let input = match Grid::load(&p) {
            Ok(g) => g,
            Err(e) => {
                println!("| {name} | load error: {e} |");
                continue;
            }
        };
        let t = Instant::now();
        let out = match remesh(&input, &params) {
            Ok(o) => o,
            Err(e) => {
                println!("| {name} | remesh error: {e} |");
                continue;
            }
        };
        let secs = t.elapsed().as_secs_f64();
        let a = quality::evaluate(
            &input,
            &out.grid,
            Some(&out.feature_edges),
            params.feature_angle_deg,
            50_000,
        );
        let fails = a.failures();
        println!(
            "| {name} | {} | {} | {:.1} | {:.1} | {:.2e} | {:.2e} | {}→{} | {} / {} | {} | {:.1} | {} |",
            a.faces_in,
            a.faces_out,
            a.min_angle_p1,
            a.max_angle_p99,
            a.hausdorff,
            a.feature_hausdorff,
            a.bodies_in,
            a.bodies_out,
            a.new_boundary_edges,
            a.new_non_manifold_edges,
            a.new_creases,
            secs,
            if fails.is_empty() { "pass".to_string() } else { fails.join("; ") }
        );
        if std::env::var_os("REMESH_VERBOSE").is_some() {
            eprintln!("{name}: {:#?}", out.report);
        }
    }
}
