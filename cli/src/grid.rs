//! `abgs grid`: isotropic remeshing of a surface into a dense background grid,
//! uniform or size-driven, with an optional acceptance check.

use abgs::remesh::{self, quality, RemeshParams, Remeshed, TargetLength};
use abgs::{Error, Grid, Result};
use std::path::{Path, PathBuf};

/// Samples per surface and per feature set for `--check`.
const CHECK_SAMPLES: usize = 50_000;

/// Options of `abgs grid` (mirrors [`RemeshParams`]).
#[derive(clap::Args, Debug)]
pub struct GridArgs {
    /// Uniform target edge length in model units.
    #[arg(long, conflicts_with = "relative")]
    pub edge_length: Option<f64>,
    /// Uniform target edge length as a fraction of the bounding-box diagonal (default 0.01).
    #[arg(long)]
    pub relative: Option<f64>,
    /// Feature angle in degrees: sharper edges are kept as feature lines.
    #[arg(long, default_value_t = 30.0)]
    pub feature_angle: f64,
    /// Split / collapse / flip / relax iterations.
    #[arg(long, default_value_t = 10)]
    pub iterations: usize,
    /// Do not cap the target length at half the curvature size π / (κ · n_circle).
    #[arg(long)]
    pub no_curvature_limit: bool,
    /// Elements per full circle in the curvature cap.
    #[arg(long, default_value_t = 24.0)]
    pub n_circle: f64,
    /// A body expected to make more than twice this many triangles is cut
    /// along its creases into pieces remeshed side by side ("inf": never;
    /// see README "Large bodies in pieces").
    #[arg(long, default_value_t = abgs::remesh::pieces::DEFAULT_PIECE_FACES)]
    pub piece_faces: f64,
    /// Size-driven mode: target lengths from this grid's sizes (point array `size`,
    /// e.g. the VTK written by `abgs size`).
    #[arg(long, value_name = "GRID", conflicts_with_all = ["edge_length", "relative"])]
    pub size_from: Option<PathBuf>,
    /// Evaluate the result (angles, Hausdorff distances, features, bodies, new
    /// boundary / non-manifold edges; 50k samples; with --size-from also edge
    /// length / h) and exit 1 if a check fails.
    #[arg(long)]
    pub check: bool,
}

impl GridArgs {
    /// The library parameters.
    pub fn params(&self) -> Result<RemeshParams> {
        if self.iterations == 0 {
            return Err(Error::InvalidArgument("--iterations must be >= 1".into()));
        }
        let d = RemeshParams::default();
        Ok(RemeshParams {
            target: match (self.edge_length, self.relative) {
                (Some(l), _) => TargetLength::Absolute(l),
                (None, Some(r)) => TargetLength::Relative(r),
                (None, None) => d.target,
            },
            feature_angle_deg: self.feature_angle,
            iterations: self.iterations,
            curvature_limit: !self.no_curvature_limit,
            n_circle: self.n_circle,
            piece_faces: self.piece_faces,
            ..d
        })
    }
}

/// Runs `abgs grid`: returns false when `--check` found a failure.
pub fn run(input: &Path, output: &Path, args: &GridArgs) -> Result<bool> {
    let params = args.params()?;
    let g = crate::progress::load(input)?;
    let sizing = match &args.size_from {
        Some(p) => {
            let s = crate::progress::load(p)?;
            if s.sizes().is_none() {
                return Err(Error::InvalidArgument(format!(
                    "{} has no sizes (point array 'size'): make one with `abgs size`",
                    p.display()
                )));
            }
            Some(s)
        }
        None => None,
    };
    let pb = crate::progress::spinner(format!(
        "remeshing {} triangles ({} iterations)",
        g.triangles().len(),
        params.iterations
    ));
    let r = match &sizing {
        Some(s) => remesh::remesh_sized(&g, s, &params),
        None => remesh::remesh(&g, &params),
    };
    pb.finish_and_clear();
    let r = r?;
    r.grid.save(output)?;
    print_report(output, &g, &r, args.size_from.as_deref());
    if !args.check {
        return Ok(true);
    }
    let pb = crate::progress::spinner("checking");
    let a = quality::evaluate(
        &g,
        &r.grid,
        Some(&r.feature_edges),
        params.feature_angle_deg,
        CHECK_SAMPLES,
    );
    let ratios = match &sizing {
        Some(s) => quality::length_ratios(&r.grid, |p, hint| s.query_size_hinted(p, hint)),
        None => {
            let l0 = r.report.target_length;
            quality::length_ratios(&r.grid, |_, _| Ok(l0))
        }
    };
    pb.finish_and_clear();
    Ok(print_check(&a, ratios?, sizing.is_some()))
}

fn print_report(output: &Path, input: &Grid, r: &Remeshed, size_from: Option<&Path>) {
    let p = &r.report;
    eprintln!(
        "wrote {} ({} vertices, {} triangles)",
        output.display(),
        p.vertices_out,
        p.faces_out
    );
    let diag = input.bbox().diagonal();
    let mode = match size_from {
        Some(s) => format!("size-driven from {}", s.display()),
        None => format!(
            "uniform, L0 {:.6} (diagonal / {:.0})",
            p.target_length,
            diag / p.target_length
        ),
    };
    eprintln!(
        "input {} vertices, {} triangles; {mode}; target length {:.6} .. {:.6}",
        p.vertices_in, p.faces_in, p.target_range[0], p.target_range[1]
    );
    eprintln!(
        "feature edges {} in, {} kept; feature lines {}  corners {}  thin patches {}",
        p.feature_edges_in,
        r.feature_edges.len(),
        p.feature_lines,
        p.corners,
        p.thin_patches
    );
    if let Some(last) = p.iterations.last() {
        eprintln!(
            "iterations {}; last: {} splits, {} collapses, {} flips; final flips {}",
            p.iterations.len(),
            last.splits,
            last.collapses,
            last.flips,
            p.final_flips
        );
    }
    if p.pieces > 0 {
        eprintln!(
            "large bodies cut into {} pieces along {} crease edges, remeshed side by side",
            p.pieces, p.build.cut_edges
        );
    }
    eprintln!("time {:.3} s", p.seconds);
    if p.issues.is_empty() {
        eprintln!("issues: none");
    } else {
        eprintln!("issues: {}", p.issues.len());
        for i in &p.issues {
            eprintln!("  - {i}");
        }
    }
}

/// Prints the acceptance numbers on stdout; returns false when a check fails.
/// Uniform mode: the dense-grid acceptance (angles, Hausdorff distances,
/// features, bodies, new edges). Size-driven mode: the lengths follow h
/// (mean of length / h in [0.85, 1.2], at least 90 % of edges in [0.6, 1.5])
/// with the same angles, bodies and edges; the Hausdorff distances are then
/// informational (a coarse field does not promise 0.1 % of the diagonal).
fn print_check(a: &quality::Acceptance, (mean, within): (f64, f64), sized: bool) -> bool {
    let info = if sized { " (info)" } else { "" };
    println!(
        "faces in / out:             {} / {}",
        a.faces_in, a.faces_out
    );
    println!(
        "min-angle p1:               {:.2}°  (>= 25°)",
        a.min_angle_p1
    );
    println!(
        "max-angle p99:              {:.2}°  (<= 110°)",
        a.max_angle_p99
    );
    println!(
        "Hausdorff / diagonal:       {:.3e}  (<= 1e-3){info}",
        a.hausdorff
    );
    println!(
        "feature Hausdorff / diag:   {:.3e}  (<= 1e-3){info}",
        a.feature_hausdorff
    );
    println!(
        "bodies in / out:            {} / {}",
        a.bodies_in, a.bodies_out
    );
    println!("new boundary edges:         {}", a.new_boundary_edges);
    println!("new non-manifold edges:     {}", a.new_non_manifold_edges);
    println!("new creases (info):         {}", a.new_creases);
    let mut f = a.failures();
    if sized {
        f.retain(|x| !x.contains("Hausdorff"));
        println!(
            "edge length / h(midpoint):  mean {mean:.3} (in [0.85, 1.2]), {:.1}% in [0.6, 1.5] (>= 90%)",
            100.0 * within
        );
        if !(0.85..=1.2).contains(&mean) {
            f.push(format!("mean length / h {mean:.3} outside [0.85, 1.2]"));
        }
        if within.is_nan() || within < 0.9 {
            f.push(format!(
                "{:.1}% of edges within [0.6, 1.5]·h < 90%",
                100.0 * within
            ));
        }
    } else {
        println!(
            "edge length / L0 (info):    mean {mean:.3}, {:.1}% in [0.6, 1.5]",
            100.0 * within
        );
    }
    if f.is_empty() {
        println!("acceptance: pass");
    } else {
        println!("acceptance: FAIL ({})", f.join("; "));
    }
    f.is_empty()
}
