//! Load time of a grid as `.abgs` against re-reading it from its text file:
//! `cargo run --release --example abgs_load_time -- GRID [REPEATS]`.
//!
//! GRID is any grid file (e.g. a sized `.vtk` from `abgs size`). It is written
//! as `.abgs` with and without the BVH layout (in a temporary directory), then
//! each is loaded REPEATS times (default 5) with `Grid::load`, and the median
//! time is printed, with the stages of an `.abgs` load: reading the file,
//! parsing and checking the buffer, the adjacency, and the BVH (checked from
//! the layout, or built). Every loaded grid is checked to equal the original.

use abgs::io::abgs_bin;
use abgs::mesh::Topology;
use abgs::spatial::Bvh;
use abgs::Grid;
use std::path::Path;
use std::time::Instant;

/// Median of `n` timed runs of `f`, in seconds.
fn median<T>(n: usize, mut f: impl FnMut() -> T) -> f64 {
    let mut t: Vec<f64> = (0..n)
        .map(|_| {
            let t0 = Instant::now();
            std::hint::black_box(f());
            t0.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[n / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 2 {
        eprintln!("usage: abgs_load_time GRID [REPEATS]");
        std::process::exit(2);
    }
    let src = Path::new(&args[1]);
    let n: usize = args.get(2).map_or(Ok(5), |s| s.parse())?;
    let dir = tempfile::tempdir()?;
    let g = Grid::load(src)?;
    let with = dir.path().join("grid.abgs");
    let without = dir.path().join("grid_nobvh.abgs");
    g.save(&with)?;
    std::fs::write(&without, abgs_bin::encode_with(&g, false))?;
    for p in [&with, &without] {
        let back = Grid::load(p)?;
        assert_eq!(
            back.to_parts(true),
            g.to_parts(true),
            "{} differs",
            p.display()
        );
    }
    let size = |p: &Path| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
    println!(
        "{}: {} vertices, {} triangles, {} BVH nodes, arrays: sizes{}",
        src.display(),
        g.vertices().len(),
        g.triangles().len(),
        g.bvh().nodes.len(),
        g.point_arrays()
            .iter()
            .map(|a| format!(", {}", a.name))
            .collect::<String>()
    );
    println!(
        "files: {} {} B, .abgs {} B, .abgs without BVH {} B",
        src.extension().and_then(|e| e.to_str()).unwrap_or("?"),
        size(src),
        size(&with),
        size(&without)
    );
    println!("median of {n} runs (s):");
    let t_src = median(n, || Grid::load(src).map(|g| g.triangles().len()));
    println!("  Grid::load {:<28} {t_src:.4}", src.display().to_string());
    let t_with = median(n, || Grid::load(&with).map(|g| g.triangles().len()));
    println!(
        "  Grid::load .abgs                    {t_with:.4}  ({:.1}x faster)",
        t_src / t_with
    );
    let t_without = median(n, || Grid::load(&without).map(|g| g.triangles().len()));
    println!(
        "  Grid::load .abgs without BVH        {t_without:.4}  ({:.1}x faster)",
        t_src / t_without
    );
    let bytes = std::fs::read(&with)?;
    let t_read = median(n, || std::fs::read(&with).map(|b| b.len()));
    let t_parse = median(n, || {
        abgs_bin::parse(&bytes, "grid").map(|p| p.vertices.len())
    });
    let parts = abgs_bin::parse(&bytes, "grid")?;
    let t_parts = median(n, || {
        Grid::from_parts(parts.clone()).map(|g| g.triangles().len())
    });
    let t_clone = median(n, || parts.clone());
    let (v, t) = (g.vertices(), g.triangles());
    let t_topo = median(n, || Topology::build(v.len(), t).edges.len());
    let layout = g.bvh().layout();
    let t_layout = median(n, || {
        Bvh::from_layout(v, t, layout.clone()).map(|b| b.nodes.len())
    });
    let t_build = median(n, || Bvh::build(v, t).nodes.len());
    println!("stages of the .abgs load:");
    println!("  read the file                       {t_read:.4}");
    println!("  parse (framing, CRC-32, sections)   {t_parse:.4}");
    println!(
        "  Grid::from_parts (checks, adjacency, report, BVH) {:.4}",
        t_parts - t_clone
    );
    println!("    of which adjacency (Topology::build)            {t_topo:.4}");
    println!("    of which BVH from the stored layout             {t_layout:.4}");
    println!("  BVH built instead (Bvh::build)      {t_build:.4}");
    Ok(())
}
