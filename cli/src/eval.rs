//! `abgs eval`: a simplified grid (candidate) against the dense grid it came
//! from (reference), with the metrics of [`abgs::metrics`].

use abgs::metrics::{evaluate, AngleStats, ContactAgreement, EvalParams, Evaluation};
use abgs::Result;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Options of `abgs eval`.
#[derive(clap::Args, Debug)]
pub struct EvalArgs {
    /// The dense grid with sizes (reference).
    #[arg(long)]
    pub reference: PathBuf,
    /// The grid under test with sizes (candidate).
    #[arg(long)]
    pub candidate: PathBuf,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Points sampled on the reference for the size deviation.
    #[arg(long, default_value_t = EvalParams::default().samples)]
    pub samples: usize,
    /// Points sampled on each surface for the Hausdorff distance.
    #[arg(long, default_value_t = EvalParams::default().hausdorff_samples)]
    pub hausdorff_samples: usize,
    /// Seed of the samplings.
    #[arg(long, default_value_t = EvalParams::default().seed)]
    pub seed: u64,
}

fn angles_json(a: &AngleStats) -> Value {
    json!({
        "min": a.min, "min_p1": a.min_p1, "min_p5": a.min_p5,
        "max_p99": a.max_p99, "max": a.max, "mean_min": a.mean_min,
    })
}

/// The evaluation as one JSON object (the same keys as the fields of
/// [`Evaluation`], nested for the size deviation and the angles); NaN becomes null.
pub fn evaluation_json(e: &Evaluation) -> Value {
    let d = &e.size_deviation;
    json!({
        "faces_reference": e.faces_reference,
        "faces_candidate": e.faces_candidate,
        "vertices_reference": e.vertices_reference,
        "vertices_candidate": e.vertices_candidate,
        "reduction": e.reduction,
        "size_deviation": {"mean": d.mean, "p95": d.p95, "p99": d.p99, "max": d.max,
                           "samples": d.samples},
        "wrong_sheet": d.wrong_sheet,
        "elements_per_cell": e.elements_per_cell,
        "elements_per_cell_reference": e.elements_per_cell_reference,
        "hausdorff": e.hausdorff,
        "hausdorff_relative": e.hausdorff_relative,
        "diagonal": e.diagonal,
        "element_count_reference": e.element_count_reference,
        "element_count_candidate": e.element_count_candidate,
        "element_count_change": e.element_count_change,
        "contact_reference": contact_json(&e.contact_reference),
        "contact_candidate": contact_json(&e.contact_candidate),
        "angles_reference": angles_json(&e.angles_reference),
        "angles_candidate": angles_json(&e.angles_candidate),
        "seconds": e.seconds,
    })
}

fn contact_json(c: &ContactAgreement) -> Value {
    json!({
        "share": c.share, "samples": c.samples, "p50": c.p50, "p95": c.p95,
        "max": c.max, "over_10": c.over_10,
    })
}

fn angle_row(name: &str, a: &AngleStats) {
    println!(
        "  {name:<10} {:>8.3} {:>8.2} {:>8.2} {:>9.2} {:>8.2} {:>8.3}",
        a.min, a.min_p1, a.min_p5, a.mean_min, a.max_p99, a.max
    );
}

/// Loads both grids, evaluates and prints a table or (`json`) one JSON object
/// with the file names added.
pub fn run(args: &EvalArgs) -> Result<()> {
    let reference = crate::progress::load(&args.reference)?;
    let candidate = crate::progress::load(&args.candidate)?;
    let params = EvalParams {
        samples: args.samples,
        hausdorff_samples: args.hausdorff_samples,
        seed: args.seed,
    };
    let pb = crate::progress::spinner("evaluating");
    let e = evaluate(&reference, &candidate, &params);
    pb.finish_and_clear();
    let e = e?;
    if args.json {
        let mut v = evaluation_json(&e);
        v["reference"] = json!(args.reference.display().to_string());
        v["candidate"] = json!(args.candidate.display().to_string());
        println!("{}", serde_json::to_string_pretty(&v).expect("json"));
        return Ok(());
    }
    print_table(&args.reference, &args.candidate, &e);
    Ok(())
}

fn print_table(reference: &Path, candidate: &Path, e: &Evaluation) {
    let d = &e.size_deviation;
    println!(
        "reference       {}   {} faces, {} vertices",
        reference.display(),
        e.faces_reference,
        e.vertices_reference
    );
    println!(
        "candidate       {}   {} faces, {} vertices",
        candidate.display(),
        e.faces_candidate,
        e.vertices_candidate
    );
    println!("reduction       {:.2} %", 100.0 * e.reduction);
    println!(
        "size deviation  mean {:.4}   p95 {:.4}   p99 {:.4}   max {:.4}   ({} samples; max(hc/hr, hr/hc))",
        d.mean, d.p95, d.p99, d.max, d.samples
    );
    println!(
        "wrong sheet     {:.3e} of the samples (query on another body or a face turned away)",
        d.wrong_sheet
    );
    println!(
        "hausdorff       {:.4e}   {:.4} % of the diagonal {:.6}",
        e.hausdorff,
        100.0 * e.hausdorff_relative,
        e.diagonal
    );
    println!(
        "element count   reference {:.0}   candidate {:.0}   change {:+.2} %   ((4/√3) ∫ h⁻² dA on the reference)",
        e.element_count_reference,
        e.element_count_candidate,
        100.0 * e.element_count_change
    );
    println!(
        "elements/cell   reference {:.2}   candidate {:.2}   (candidate's element count / faces)",
        e.elements_per_cell_reference, e.elements_per_cell
    );
    let c = (&e.contact_reference, &e.contact_candidate);
    if c.0.samples > 0 {
        println!(
            "contact         {:.2} % of the surface lies on two bodies; their sizes differ (max/min - 1) by",
            100.0 * c.0.share
        );
        for (name, a) in [("reference", c.0), ("candidate", c.1)] {
            println!(
                "  {name:<10}   p50 {:.2} %   p95 {:.2} %   max {:.2} %   over 10 %: {:.2} % of them",
                100.0 * a.p50,
                100.0 * a.p95,
                100.0 * a.max,
                100.0 * a.over_10
            );
        }
    }
    println!(
        "angles (deg)   {:>8} {:>8} {:>8} {:>9} {:>8} {:>8}",
        "min", "min p1", "min p5", "mean min", "max p99", "max"
    );
    angle_row("reference", &e.angles_reference);
    angle_row("candidate", &e.angles_candidate);
    println!("time            {:.3} s", e.seconds);
}
