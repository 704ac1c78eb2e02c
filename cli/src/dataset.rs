//! `abgs dataset`: training graphs for the learned simplifier, taken along a
//! whole LBO-ABGS run (see `abgs::gcn::dataset` for the format).

use crate::simplify::SimplifyArgs;
use abgs::gcn::dataset::{trajectory, write, DatasetParams};
use abgs::{Error, Result};
use std::path::Path;

/// Options of `abgs dataset`.
#[derive(clap::Args, Debug, Clone)]
pub struct DatasetArgs {
    /// Most snapshots (graphs) per run, the dense and the final grid included.
    #[arg(long, default_value_t = DatasetParams::default().snapshots)]
    pub snapshots: usize,
    /// A snapshot is taken each time the faces fall below the dense count times this
    /// ratio to the power of the snapshots taken.
    #[arg(long, default_value_t = DatasetParams::default().face_ratio)]
    pub face_ratio: f64,
    /// Simplification parameters of the LBO-ABGS run (the targets' thresholds).
    #[command(flatten)]
    pub simplify: SimplifyArgs,
}

/// Runs `abgs dataset`.
pub fn run(input: &Path, output: &Path, a: &DatasetArgs) -> Result<()> {
    let g = crate::progress::load(input)?;
    if g.sizes().is_none() {
        return Err(Error::InvalidArgument(format!(
            "{} has no sizes (point array 'size'): make one with `abgs size`",
            input.display()
        )));
    }
    let params = a.simplify.params();
    let dp = DatasetParams {
        snapshots: a.snapshots,
        face_ratio: a.face_ratio,
    };
    let pb = crate::progress::spinner(format!(
        "LBO-ABGS run with snapshots on {} faces",
        g.triangles().len()
    ));
    let r = trajectory(&g, &params, &dp);
    pb.finish_and_clear();
    let (snaps, report) = r?;
    let source = input
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let meta = [
        ("source", source),
        ("t_size", params.t_size.to_string()),
        ("beta", params.beta.to_string()),
        ("clearance", params.clearance_fraction.to_string()),
    ];
    write(output, &snaps, &meta)?;
    let edges: usize = snaps.iter().map(|s| s.graph.n_edges).sum();
    eprintln!(
        "wrote {}: {} snapshots ({} edges; faces {}), LBO-ABGS {} -> {} faces in {:.2} s",
        output.display(),
        snaps.len(),
        edges,
        snaps
            .iter()
            .map(|s| s.faces.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        report.faces_in,
        report.faces_out,
        report.seconds
    );
    Ok(())
}
