//! `abgs info` and `abgs convert`.

use abgs::Result;
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// Prints counts, defects, bounding box, angle statistics and memory of `file`.
pub fn run(file: &Path, as_json: bool) -> Result<()> {
    let t0 = Instant::now();
    let g = crate::progress::load(file)?;
    let load_s = t0.elapsed().as_secs_f64();
    let r = g.report();
    let st = g.stats();
    let a = g.angle_stats();
    let b = g.bbox();
    let bpt = st.query_bytes_per_triangle(&g);
    let sizes = g.sizes().map(|s| {
        let lo = s.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = s.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    });
    if as_json {
        let v = json!({
            "file": file.display().to_string(),
            "vertices": st.vertices, "triangles": st.triangles, "edges": st.edges,
            "bodies": r.bodies, "open_bodies": r.open_bodies,
            "boundary_edges": r.boundary_edges, "non_manifold_edges": r.non_manifold_edges,
            "non_manifold_vertices": r.non_manifold_vertices,
            "input_vertices": r.input_vertices, "input_triangles": r.input_triangles,
            "welded_vertices": r.welded_vertices, "unreferenced_vertices": r.unreferenced_vertices,
            "dropped_repeated_index": r.dropped_repeated_index, "dropped_zero_area": r.dropped_zero_area,
            "duplicate_triangles": r.duplicate_triangles, "flipped_triangles": r.flipped_triangles,
            "non_orientable_bodies": r.non_orientable_bodies, "sliver_triangles": r.sliver_triangles,
            "bbox_min": b.min, "bbox_max": b.max, "diagonal": b.diagonal(),
            "angles": {"min": a.min_angle, "min_p1": a.min_angle_p1, "min_mean": a.min_angle_mean,
                       "max_p99": a.max_angle_p99, "max": a.max_angle},
            "sizes": sizes.map(|(lo, hi)| json!({"min": lo, "max": hi})),
            "grid_bytes": st.grid_bytes, "bvh_bytes": st.bvh_bytes,
            "query_bytes_per_triangle": bpt, "bvh_depth": g.bvh().depth(),
            "defects": r.defects(), "load_seconds": load_s,
        });
        println!("{}", serde_json::to_string_pretty(&v).expect("json"));
        return Ok(());
    }
    println!("file          {}", file.display());
    println!(
        "vertices      {}   triangles {}   edges {}",
        st.vertices, st.triangles, st.edges
    );
    println!("bodies        {}  ({} open)", r.bodies, r.open_bodies);
    println!(
        "edges         boundary {}   non-manifold {}   non-manifold vertices {}",
        r.boundary_edges, r.non_manifold_edges, r.non_manifold_vertices
    );
    println!(
        "input         {} vertices, {} triangles; welded {}, degenerate dropped {} (repeated vertex {}, zero area {})",
        r.input_vertices,
        r.input_triangles,
        r.welded_vertices,
        r.dropped_repeated_index + r.dropped_zero_area,
        r.dropped_repeated_index,
        r.dropped_zero_area
    );
    println!(
        "bbox          {:?} .. {:?}   diagonal {:.6}",
        b.min,
        b.max,
        b.diagonal()
    );
    println!(
        "angles (deg)  min {:.3}   min p1 {:.2}   mean min {:.2}   max p99 {:.2}   max {:.3}",
        a.min_angle, a.min_angle_p1, a.min_angle_mean, a.max_angle_p99, a.max_angle
    );
    match sizes {
        Some((lo, hi)) => println!("sizes         {lo:.6} .. {hi:.6}"),
        None => println!("sizes         none"),
    }
    println!(
        "memory        grid {} B, BVH {} B (depth {});  query data {:.1} bytes/triangle",
        st.grid_bytes,
        st.bvh_bytes,
        g.bvh().depth(),
        bpt
    );
    let d = r.defects();
    if d.is_empty() {
        println!("defects       none");
    } else {
        println!("defects");
        for line in d {
            println!("  - {line}");
        }
    }
    println!("load time     {load_s:.3} s");
    Ok(())
}

/// Converts `input` to `output` (formats by extension).
pub fn convert(input: &Path, output: &Path) -> Result<()> {
    let g = crate::progress::load(input)?;
    g.save(output)?;
    eprintln!(
        "wrote {} ({} vertices, {} triangles{})",
        output.display(),
        g.vertices().len(),
        g.triangles().len(),
        if g.sizes().is_some() { ", sizes" } else { "" }
    );
    Ok(())
}
