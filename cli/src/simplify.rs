//! `abgs simplify` (LBO-ABGS or the QEM baseline) and `abgs label` (per-edge
//! scores, the learned simplifier's training labels).

use abgs::gcn::{Learned, Model};
use abgs::qem::{decimate, QemParams};
use abgs::simplify::{
    edge_scores, simplify, simplify_with, IterationRecord, Method as LibMethod, Simplified,
    SimplifyParams, StopReason,
};
use abgs::{Error, Grid, Result};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::{json, Value};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Simplification method of `abgs simplify`.
#[derive(Clone, Copy, Debug, clap::ValueEnum, PartialEq, Eq)]
pub enum Method {
    /// LBO-ABGS: sizing-aware edge collapses, each estimated exactly.
    Lbo,
    /// GCN-ABGS: the same loop with the embedded graph network's predictions
    /// in place of the exact estimates (--verify checks its choices exactly).
    Gcn,
    /// Plain quadric-error decimation to `--target-faces` (the baseline), sizes re-projected.
    Qem,
}

/// How LBO-ABGS picks an iteration's collapses (`--selection`).
#[derive(Clone, Copy, Debug, clap::ValueEnum, PartialEq, Eq)]
pub enum Selection {
    /// Batch by batch of the pool in LBO order, estimating only edges whose
    /// rings are still free (the default; far fewer estimates).
    Batched,
    /// The whole pool estimated, then the lowest scores (DESIGN §3.5 as the paper has it).
    Global,
}

/// The LBO-ABGS thresholds shared by `abgs simplify` and `abgs run` (fields of
/// [`SimplifyParams`]).
#[derive(clap::Args, Debug, Clone)]
pub struct LboArgs {
    /// Largest share of the edges collapsed per iteration (n).
    #[arg(long, default_value_t = SimplifyParams::default().fraction)]
    pub fraction: f64,
    /// Largest size ratio a collapse may cause (T_size).
    #[arg(long, default_value_t = SimplifyParams::default().t_size)]
    pub t_size: f64,
    /// How each iteration picks its collapses from the candidate pool.
    #[arg(long, value_enum, default_value_t = Selection::Batched)]
    pub selection: Selection,
    /// Fixed distance rule Δd ≤ τ_d·h_loc (the paper's is 0.05) in place of
    /// the derived Δd ≤ ½·ln(T_size)·h / ln β (default: derived).
    #[arg(long)]
    pub tau_d: Option<f64>,
    /// Largest size ratio where bodies touch (T_contact): touching bodies
    /// agree within about its square.
    #[arg(long, default_value_t = SimplifyParams::default().t_contact)]
    pub t_contact: f64,
    /// Each side of a thin wall or gap may move at most this fraction of its
    /// width (κ; 0 turns the clearance term off).
    #[arg(long, default_value_t = SimplifyParams::default().clearance_fraction)]
    pub clearance: f64,
    /// Largest distance to the dense grid in model units (default: no limit).
    #[arg(long)]
    pub max_distance: Option<f64>,
    /// Most iterations.
    #[arg(long = "max-iter", default_value_t = SimplifyParams::default().max_iterations)]
    pub max_iterations: usize,
    /// Largest angle of a new triangle, degrees.
    #[arg(long, default_value_t = SimplifyParams::default().max_angle_deg)]
    pub max_angle: f64,
    /// Largest turn of a face normal per collapse, move or flip, degrees.
    #[arg(long, default_value_t = SimplifyParams::default().max_normal_turn_deg)]
    pub max_normal_turn: f64,
    /// Keep the dense field's size at each simplified vertex instead of
    /// fitting the vertex sizes to the dense field at the end (the paper's
    /// rule; the fit removes the interpolation's bias toward larger sizes).
    #[arg(long)]
    pub no_fit_sizes: bool,
    /// GCN-ABGS: edges whose predicted score is at or above this are not tried (T_score).
    #[arg(long, default_value_t = SimplifyParams::default().t_score)]
    pub t_score: f64,
    /// GCN-ABGS: check the model's choices with the exact estimate and drop those that fail.
    #[arg(long)]
    pub verify: bool,
    /// GCN-ABGS: an ONNX model file in place of the embedded one (same inputs and output).
    #[arg(long)]
    pub model: Option<PathBuf>,
}

impl LboArgs {
    /// The library parameters, with the feature angle, the sizes' gradation
    /// ratio and the repair switch given.
    pub fn params(&self, feature_angle_deg: f64, beta: f64, repair: bool) -> SimplifyParams {
        SimplifyParams {
            fraction: self.fraction,
            selection: match self.selection {
                Selection::Batched => abgs::simplify::Selection::Batched,
                Selection::Global => abgs::simplify::Selection::Global,
            },
            t_size: self.t_size,
            t_contact: self.t_contact,
            tau_d: self.tau_d,
            beta,
            clearance_fraction: if self.clearance > 0.0 {
                self.clearance
            } else {
                f64::INFINITY
            },
            max_distance: self.max_distance,
            max_iterations: self.max_iterations,
            max_angle_deg: self.max_angle,
            max_normal_turn_deg: self.max_normal_turn,
            feature_angle_deg,
            repair,
            t_score: self.t_score,
            verify: self.verify,
            fit_sizes: !self.no_fit_sizes,
            ..Default::default()
        }
    }
}

/// Options of `abgs simplify` for LBO-ABGS.
#[derive(clap::Args, Debug, Clone)]
pub struct SimplifyArgs {
    /// Thresholds.
    #[command(flatten)]
    pub lbo: LboArgs,
    /// Feature angle in degrees.
    #[arg(long, default_value_t = SimplifyParams::default().feature_angle_deg)]
    pub feature_angle: f64,
    /// No local repair (relaxation, flips) after each batch.
    #[arg(long)]
    pub no_repair: bool,
    /// Gradation ratio β the sizes were graded with.
    #[arg(long, default_value_t = SimplifyParams::default().beta)]
    pub beta: f64,
}

impl SimplifyArgs {
    /// The library parameters.
    pub fn params(&self) -> SimplifyParams {
        self.lbo
            .params(self.feature_angle, self.beta, !self.no_repair)
    }
}

/// Every parameter as JSON.
pub fn params_json(p: &SimplifyParams) -> Value {
    json!({
        "method": match p.method { LibMethod::Lbo => "lbo", LibMethod::Gcn => "gcn" },
        "t_score": p.t_score, "verify": p.verify,
        "fraction": p.fraction, "pool_factor": p.pool_factor, "t_size": p.t_size,
        "selection": match p.selection { abgs::simplify::Selection::Batched => "batched", abgs::simplify::Selection::Global => "global" },
        "t_contact": p.t_contact, "tau_d": p.tau_d, "beta": p.beta,
        "clearance_fraction": if p.clearance_fraction.is_finite() { json!(p.clearance_fraction) } else { Value::Null },
        "max_distance": p.max_distance, "max_iterations": p.max_iterations,
        "feature_angle_deg": p.feature_angle_deg, "corner_angle_deg": p.corner_angle_deg,
        "max_normal_turn_deg": p.max_normal_turn_deg, "max_angle_deg": p.max_angle_deg,
        "repair": p.repair, "fit_sizes": p.fit_sizes,
    })
}

/// The per-iteration table as JSON rows.
pub fn iterations_json(its: &[IterationRecord]) -> Value {
    Value::Array(
        its.iter()
            .map(|r| {
                json!({
                    "iteration": r.iteration, "faces": r.faces, "vertices": r.vertices,
                    "candidates": r.candidates, "estimated": r.estimated,
                    "collapsible": r.collapsible, "accepted": r.accepted, "moved": r.moved,
                    "flips": r.flips, "element_count": r.element_count, "seconds": r.seconds,
                })
            })
            .collect(),
    )
}

/// What a simplification did, as JSON.
pub fn report_json(s: &Simplified) -> Value {
    let r = &s.report;
    json!({
        "faces_in": r.faces_in, "vertices_in": r.vertices_in,
        "faces_out": r.faces_out, "vertices_out": r.vertices_out,
        "feature_lines": r.feature_lines, "corners": r.corners,
        "element_count_in": r.element_count_in,
        "stop": match r.stop {
            StopReason::Converged => "converged",
            StopReason::MaxIterations => "max_iterations",
            StopReason::Cancelled => "cancelled",
        },
        "seconds": r.seconds,
        "fit": {
            "samples": r.fit.samples, "steps": r.fit.steps, "clamped": r.fit.clamped, "frozen": r.fit.frozen,
            "seconds": r.fit_seconds,
        },
        "binding": {
            "free": r.binding.free, "topology": r.binding.topology, "feature": r.binding.feature,
            "degenerate": r.binding.degenerate, "normal_turn": r.binding.normal_turn,
            "max_angle": r.binding.max_angle, "size": r.binding.size,
            "contact": r.binding.contact,
            "distance": r.binding.distance, "max_distance": r.binding.max_distance,
        },
        "iterations": iterations_json(&r.iterations),
    })
}

/// Runs LBO-ABGS or GCN-ABGS (`params.method`; GCN-ABGS with the model file
/// `model` in place of the embedded model when given) with a progress bar on
/// stderr (faces so far; hidden when stderr is not a terminal).
pub fn run_abgs(dense: &Grid, params: &SimplifyParams, model: Option<&Path>) -> Result<Simplified> {
    let loaded = match (params.method, model) {
        (LibMethod::Gcn, Some(path)) => Some(Model::from_file(path)?),
        _ => None,
    };
    let pb = ProgressBar::new(dense.triangles().len() as u64);
    pb.set_style(
        ProgressStyle::with_template("simplifying {bar:30} {msg} [{elapsed}]")
            .expect("valid template"),
    );
    let mut cb = |r: &IterationRecord| {
        pb.set_position((dense.triangles().len() - r.faces) as u64);
        pb.set_message(format!("iteration {} · {} faces", r.iteration, r.faces));
        true
    };
    let s = match &loaded {
        Some(m) => simplify_with(dense, params, &mut Learned::new(m), Some(&mut cb)),
        None => simplify(dense, params, Some(&mut cb)),
    };
    pb.finish_and_clear();
    s
}

/// Runs `abgs simplify`.
pub fn run(
    input: &Path,
    output: &Path,
    method: Method,
    target_faces: Option<usize>,
    args: &SimplifyArgs,
    report: Option<&PathBuf>,
) -> Result<()> {
    let dense = crate::progress::load(input)?;
    if dense.sizes().is_none() {
        return Err(Error::InvalidArgument(format!(
            "{} has no sizes (point array 'size'): make one with `abgs size`",
            input.display()
        )));
    }
    let value = match method {
        Method::Lbo | Method::Gcn => {
            let mut params = args.params();
            if method == Method::Gcn {
                params.method = LibMethod::Gcn;
            }
            let s = run_abgs(&dense, &params, args.lbo.model.as_deref())?;
            s.grid.save(output)?;
            let r = &s.report;
            eprintln!(
                "wrote {} ({} vertices, {} triangles)",
                output.display(),
                r.vertices_out,
                r.faces_out
            );
            eprintln!(
                "faces {} -> {} ({:.1} % fewer) in {} iterations ({:?}), {:.2} s",
                r.faces_in,
                r.faces_out,
                100.0 * (1.0 - r.faces_out as f64 / r.faces_in.max(1) as f64),
                r.iterations.len(),
                r.stop,
                r.seconds
            );
            json!({"input": input, "output": output, "parameters": params_json(&params), "report": report_json(&s)})
        }
        Method::Qem => {
            let Some(faces) = target_faces else {
                return Err(Error::InvalidArgument(
                    "--method qem needs --target-faces".into(),
                ));
            };
            let p = QemParams {
                target_faces: faces,
                feature_angle_deg: args.feature_angle,
                ..Default::default()
            };
            let d = decimate(&dense, &p)?;
            d.grid.save(output)?;
            eprintln!(
                "wrote {} ({} triangles, {} collapses, {:.2} s)",
                output.display(),
                d.grid.triangles().len(),
                d.collapses,
                d.seconds
            );
            json!({"input": input, "output": output, "parameters": {"method": "qem", "target_faces": faces,
                   "feature_angle_deg": p.feature_angle_deg}, "report": {"faces_in": dense.triangles().len(),
                   "faces_out": d.grid.triangles().len(), "collapses": d.collapses, "seconds": d.seconds}})
        }
    };
    if let Some(path) = report {
        write_json(path, &value)?;
    }
    Ok(())
}

/// Writes pretty JSON to `path`.
pub fn write_json(path: &Path, v: &Value) -> Result<()> {
    let text = serde_json::to_string_pretty(v).expect("JSON values serialise");
    std::fs::write(path, text + "\n").map_err(|e| Error::io(path, e))
}

/// Runs `abgs label`: one line per edge, `a b ds dd_rel de valid y` (CSV with
/// a header), in the grid's edge order.
pub fn label(input: &Path, output: &Path, args: &SimplifyArgs) -> Result<()> {
    let g = crate::progress::load(input)?;
    let pb = crate::progress::spinner(format!("scoring {} edges", g.topology().edges.len()));
    let scores = edge_scores(&g, &args.params());
    pb.finish_and_clear();
    let scores = scores?;
    let io = |e: std::io::Error| Error::io(output, e);
    let f = std::fs::File::create(output).map_err(io)?;
    let mut w = std::io::BufWriter::new(f);
    writeln!(w, "a,b,ds,dd_rel,de,valid,y").map_err(io)?;
    let num = |x: f64| {
        if x.is_nan() {
            String::new()
        } else {
            format!("{x:.9e}")
        }
    };
    for s in &scores {
        writeln!(
            w,
            "{},{},{},{},{},{},{:.9e}",
            s.vertices[0],
            s.vertices[1],
            num(s.ds),
            num(s.dd_rel),
            num(s.de),
            u8::from(s.valid),
            s.y
        )
        .map_err(io)?;
    }
    w.flush().map_err(io)?;
    let coll = scores.iter().filter(|s| s.y < 0.5).count();
    let valid = scores.iter().filter(|s| s.valid).count();
    eprintln!(
        "wrote {} ({} edges: {} valid, {} collapsible)",
        output.display(),
        scores.len(),
        valid,
        coll
    );
    Ok(())
}
