//! `abgs run`: the whole pipeline on one surface, dense grid → sizes →
//! simplification → evaluation, with a report and two pictures.

use crate::memory::Meter;
use crate::render::{line_chart_png, preview_png, Panel, Series};
use crate::simplify::{iterations_json, params_json, report_json, run_abgs, write_json, LboArgs};
use abgs::metrics::{evaluate, EvalParams};
use abgs::qem::{decimate, QemParams};
use abgs::remesh::{remesh, RemeshParams, TargetLength};
use abgs::sizing::{self, SizeParams};
use abgs::{Error, Grid, Result};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of `abgs run`.
#[derive(clap::Args, Debug)]
pub struct RunArgs {
    /// Output folder (created if missing).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Dense grid: uniform edge length as a fraction of the diagonal.
    #[arg(long, default_value_t = 0.01)]
    pub relative: f64,
    /// Feature angle in degrees (dense grid, sizes, simplification).
    #[arg(long, default_value_t = 30.0)]
    pub feature_angle: f64,
    /// Elements per full circle (curvature sizes and the dense grid's curvature cap).
    #[arg(long, default_value_t = 24.0)]
    pub n_circle: f64,
    /// Dense grid: a body expected to make more than twice this many
    /// triangles is cut along its creases into pieces remeshed side by side
    /// ("inf": never; see README "Large bodies in pieces").
    #[arg(long, default_value_t = abgs::remesh::pieces::DEFAULT_PIECE_FACES)]
    pub piece_faces: f64,
    /// Elements across a gap or wall.
    #[arg(long, default_value_t = 3.0)]
    pub n_gap: f64,
    /// Gradation ratio β.
    #[arg(long, default_value_t = 1.2)]
    pub beta: f64,
    /// Simplification method: lbo (LBO-ABGS) or gcn (GCN-ABGS, the embedded model).
    #[arg(long, default_value = "lbo", value_parser = ["lbo", "gcn"])]
    pub method: String,
    /// Simplification thresholds.
    #[command(flatten)]
    pub lbo: LboArgs,
    /// Also decimate the dense grid by plain QEM to the same face count (sizes
    /// re-projected) and evaluate it: what sizing-awareness buys.
    #[arg(long)]
    pub qem: bool,
    /// Points sampled for the size deviation and for each side of the Hausdorff distance.
    #[arg(long, default_value_t = 100_000)]
    pub samples: usize,
    /// Do not write preview.png and convergence.png.
    #[arg(long)]
    pub no_images: bool,
}

/// Seconds and peak memory of each stage.
struct Stages {
    times: Vec<(String, f64)>,
    memory: Meter,
}

fn stage<T>(name: &str, stages: &mut Stages, f: impl FnOnce() -> Result<T>) -> Result<T> {
    let pb = crate::progress::spinner(name.to_string());
    let t = Instant::now();
    let r = f();
    pb.finish_and_clear();
    let s = t.elapsed().as_secs_f64();
    stages.times.push((name.to_string(), s));
    stages.memory.end_stage(name);
    if r.is_ok() {
        eprintln!("{name}: {s:.2} s");
    }
    r
}

/// Runs `abgs run`.
pub fn run(input: &Path, a: &RunArgs) -> Result<()> {
    std::fs::create_dir_all(&a.output).map_err(|e| Error::io(&a.output, e))?;
    let start = Instant::now();
    let mut stages = Stages {
        times: Vec::new(),
        memory: Meter::new(),
    };
    let surface = stage("load", &mut stages, || Grid::load(input))?;
    let rp = RemeshParams {
        target: TargetLength::Relative(a.relative),
        feature_angle_deg: a.feature_angle,
        n_circle: a.n_circle,
        piece_faces: a.piece_faces,
        ..Default::default()
    };
    let remeshed = stage("dense grid", &mut stages, || remesh(&surface, &rp))?;
    let remeshed_pieces = remeshed.report.pieces;
    let mut dense = remeshed.grid;
    let sp = SizeParams {
        n_circle: a.n_circle,
        n_gap: a.n_gap,
        feature_angle_deg: a.feature_angle,
        gradation: Some(sizing::Gradation::Beta(a.beta)),
        ..Default::default()
    };
    let fields = stage("sizes", &mut stages, || sizing::compute(&dense, &sp))?;
    dense.set_sizes(fields.h.clone())?;
    let mut params = a.lbo.params(a.feature_angle, a.beta, true);
    if a.method == "gcn" {
        params.method = abgs::simplify::Method::Gcn;
    }
    let t = Instant::now();
    let simplified = run_abgs(&dense, &params, a.lbo.model.as_deref())?;
    stages
        .times
        .push(("simplify".into(), t.elapsed().as_secs_f64()));
    stages.memory.end_stage("simplify");
    eprintln!(
        "simplify: {:.2} s ({} -> {} faces, {} iterations)",
        t.elapsed().as_secs_f64(),
        simplified.report.faces_in,
        simplified.report.faces_out,
        simplified.report.iterations.len()
    );
    let ep = EvalParams {
        samples: a.samples,
        hausdorff_samples: a.samples,
        ..Default::default()
    };
    let eval = stage("evaluate", &mut stages, || {
        evaluate(&dense, &simplified.grid, &ep)
    })?;
    let dense_path = a.output.join("dense.vtk");
    let simp_path = a.output.join("simplified.vtk");
    stage("write grids", &mut stages, || {
        dense.save(&dense_path)?;
        simplified.grid.save(&simp_path)
    })?;
    let qem = if a.qem {
        let q = stage("qem baseline", &mut stages, || {
            decimate(
                &dense,
                &QemParams {
                    target_faces: simplified.grid.triangles().len(),
                    feature_angle_deg: a.feature_angle,
                    ..Default::default()
                },
            )
        })?;
        let qe = stage("evaluate qem", &mut stages, || {
            evaluate(&dense, &q.grid, &ep)
        })?;
        q.grid.save(&a.output.join("qem.vtk"))?;
        Some((q, qe))
    } else {
        None
    };
    if !a.no_images {
        stage("images", &mut stages, || {
            images(&a.output, &dense, &simplified)
        })?;
    }
    let mut report = json!({
        "input": input,
        "outputs": {
            "dense": dense_path, "simplified": simp_path,
            "report": a.output.join("report.json"),
        },
        "parameters": {
            "dense_grid": {"relative_length": a.relative, "feature_angle_deg": a.feature_angle,
                           "n_circle": a.n_circle, "curvature_limit": rp.curvature_limit,
                           "iterations": rp.iterations, "piece_faces": rp.piece_faces,
                           "pieces": remeshed_pieces},
            "sizes": {"n_circle": a.n_circle, "n_gap": a.n_gap, "beta": a.beta,
                      "hmin": fields.report.hmin, "hmax": fields.report.hmax,
                      "feature_angle_deg": a.feature_angle},
            "simplify": params_json(&params),
            "evaluation": {"samples": ep.samples, "hausdorff_samples": ep.hausdorff_samples, "seed": ep.seed},
        },
        "counts": {
            "input_faces": surface.triangles().len(),
            "dense_faces": dense.triangles().len(),
            "dense_vertices": dense.vertices().len(),
            "contact_vertices": fields.report.contact_vertices,
            "simplified_faces": simplified.grid.triangles().len(),
            "simplified_vertices": simplified.grid.vertices().len(),
        },
        "simplify": report_json(&simplified),
        "metrics": crate::eval::evaluation_json(&eval),
        "iterations": iterations_json(&simplified.report.iterations),
    });
    if let Some((q, qe)) = &qem {
        report["qem"] = json!({
            "faces": q.grid.triangles().len(), "collapses": q.collapses, "seconds": q.seconds,
            "metrics": crate::eval::evaluation_json(qe),
        });
    }
    let total = start.elapsed().as_secs_f64();
    let mut st: serde_json::Map<String, Value> = stages
        .times
        .iter()
        .map(|(k, v)| (k.clone(), json!(v)))
        .collect();
    st.insert("total".into(), json!(total));
    report["seconds"] = Value::Object(st);
    report["memory"] = stages.memory.json(dense.triangles().len());
    write_json(&a.output.join("report.json"), &report)?;
    print_summary(&eval, qem.as_ref().map(|x| &x.1), total);
    if let Some(peak) = stages.memory.overall() {
        eprintln!(
            "peak memory {:.0} MB ({:.0} bytes per dense face)",
            peak as f64 / (1 << 20) as f64,
            peak as f64 / dense.triangles().len().max(1) as f64
        );
    }
    Ok(())
}

fn print_summary(
    e: &abgs::metrics::Evaluation,
    qem: Option<&abgs::metrics::Evaluation>,
    total: f64,
) {
    let row = |name: &str, e: &abgs::metrics::Evaluation| {
        eprintln!(
            "{name:<9} faces {:>9} -> {:>8}  elements/cell {:.1}  size deviation mean {:.3} p95 {:.3} p99 {:.3} max {:.3}  wrong sheet {:.1e}  hausdorff {:.3} %  elements {:+.2} %",
            e.faces_reference,
            e.faces_candidate,
            e.elements_per_cell,
            e.size_deviation.mean,
            e.size_deviation.p95,
            e.size_deviation.p99,
            e.size_deviation.max,
            e.size_deviation.wrong_sheet,
            100.0 * e.hausdorff_relative,
            100.0 * e.element_count_change
        );
    };
    row("lbo-abgs", e);
    if let Some(q) = qem {
        row("qem", q);
    }
    let c = (&e.contact_reference, &e.contact_candidate);
    if c.0.samples > 0 {
        eprintln!(
            "contact   {:.2} % of the surface; sizes differ p95 {:.2} % max {:.2} % (dense), p95 {:.2} % max {:.2} % (simplified)",
            100.0 * c.0.share,
            100.0 * c.0.p95,
            100.0 * c.0.max,
            100.0 * c.1.p95,
            100.0 * c.1.max
        );
    }
    eprintln!("total {total:.2} s");
}

fn images(dir: &Path, dense: &Grid, s: &abgs::simplify::Simplified) -> Result<()> {
    let io = |m: String| Error::InvalidArgument(format!("image: {m}"));
    let (dh, sh) = (dense.sizes().unwrap_or(&[]), s.grid.sizes().unwrap_or(&[]));
    let nd = dense.triangles().len();
    let ns = s.grid.triangles().len();
    let panels = [
        Panel {
            title: format!("dense: {nd} faces"),
            vertices: dense.vertices(),
            triangles: dense.triangles(),
            values: dh,
        },
        Panel {
            title: format!(
                "LBO-ABGS: {ns} faces (-{:.1} %)",
                100.0 * (1.0 - ns as f64 / nd.max(1) as f64)
            ),
            vertices: s.grid.vertices(),
            triangles: s.grid.triangles(),
            values: sh,
        },
    ];
    preview_png(&panels, "size h", 1600, 800, &dir.join("preview.png")).map_err(io)?;
    let mut faces = vec![s.report.faces_in as f64];
    let mut elems = vec![s.report.element_count_in];
    for r in &s.report.iterations {
        faces.push(r.faces as f64);
        elems.push(r.element_count);
    }
    line_chart_png(
        "LBO-ABGS convergence",
        "iteration",
        &[
            Series {
                name: "grid faces".into(),
                values: &faces,
            },
            Series {
                name: "estimated elements (4/sqrt3 int h^-2)".into(),
                values: &elems,
            },
        ],
        1000,
        600,
        &dir.join("convergence.png"),
    )
    .map_err(io)
}
