//! `abgs`: command-line front end of the abgs library.
//!
//! Subcommands: `info`, `convert`, `query`, `bench-query`, `size`,
//! `check-gradation`, `grid`, `eval`, `simplify`, `label`, `dataset`, `run`.
//! Run `abgs --help`.

#![allow(clippy::needless_range_loop)]

mod bench;
mod dataset;
mod eval;
mod grid;
mod info;
mod memory;
mod points;
mod progress;
mod query;
mod render;
mod run;
mod simplify;
mod size;

use clap::{Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "abgs",
    version,
    about = "Adaptive background grids for mesh sizing fields"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Query mode.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum Mode {
    /// Closest point on the grid, barycentric interpolation.
    Surface,
    /// min over the surface of h(y) + ln(beta)·|x − y|.
    Volume,
}

#[derive(Subcommand)]
enum Command {
    /// Load a surface and report counts, defects, bounding box, angles and memory.
    Info {
        /// Input file (stl, obj, off, ply, msh, vtk, vtu, mesh, abgs).
        file: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Convert between formats (chosen by extension); per-vertex arrays are kept where the format allows;
    /// `.abgs` keeps the whole grid in binary (fastest to load).
    Convert {
        /// Input file.
        input: PathBuf,
        /// Output file.
        output: PathBuf,
    },
    /// Query sizes at points read from a file (one `x y z` per line); one size per line out, same order.
    Query {
        /// Grid with sizes.
        grid: PathBuf,
        /// Points file (`-` for standard input).
        #[arg(long)]
        points: PathBuf,
        /// Query mode.
        #[arg(long, value_enum, default_value = "surface")]
        mode: Mode,
        /// Gradation ratio for volume mode.
        #[arg(long, default_value_t = 1.2)]
        beta: f64,
        /// Output file (default: standard output).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Compute sizes (curvature, proximity, features, sources, gradation) and write
    /// them with the arrays size, h0, h_curv, h_prox and lbo.
    Size {
        /// Input grid.
        grid: PathBuf,
        /// Output file (vtk recommended).
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        args: size::SizeArgs,
    },
    /// Check a sized grid: largest face slope against ln(beta), and h <= h0 where h0 is present.
    CheckGradation {
        /// Grid with sizes.
        grid: PathBuf,
        /// Gradation ratio.
        #[arg(long, default_value_t = 1.2)]
        beta: f64,
        /// Slope (overrides --beta).
        #[arg(long)]
        slope: Option<f64>,
    },
    /// Remesh a surface into a dense grid of well-shaped triangles (isotropic remeshing,
    /// feature lines and corners kept): uniform, or size-driven with --size-from.
    Grid {
        /// Input surface.
        input: PathBuf,
        /// Output file (vtk recommended).
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        args: grid::GridArgs,
    },
    /// Measure queries per second on three point sets (near-surface, uniform in the box,
    /// a coherent front-like walk) for plain, hinted and batch queries, 1 thread and all threads.
    BenchQuery {
        /// Grid (without sizes, a linear test field is used).
        grid: PathBuf,
        /// Points per set.
        #[arg(long, default_value_t = 200_000)]
        points: usize,
        /// Seconds to spend per measurement (best of three runs of at least this long).
        #[arg(long, default_value_t = 0.3)]
        seconds: f64,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Compare a simplified grid with the dense grid it came from: reduction, size
    /// deviation, Hausdorff distance, estimated element count, angles.
    Eval {
        #[command(flatten)]
        args: eval::EvalArgs,
    },
    /// Simplify a sized dense grid by LBO-ABGS (sizing-aware edge collapses), or by
    /// plain QEM to a face count (the baseline); the result carries sizes.
    Simplify {
        /// Dense grid with sizes (e.g. from `abgs size`).
        input: PathBuf,
        /// Output file (vtk recommended).
        #[arg(short, long)]
        output: PathBuf,
        /// Method.
        #[arg(long, value_enum, default_value = "lbo")]
        method: simplify::Method,
        /// Face count for --method qem.
        #[arg(long)]
        target_faces: Option<usize>,
        /// Write every parameter, the counts and the per-iteration table as JSON.
        #[arg(long)]
        report: Option<PathBuf>,
        #[command(flatten)]
        args: simplify::SimplifyArgs,
    },
    /// Score every edge of a sized grid as LBO-ABGS's first iteration would (Δs, Δd/h_loc,
    /// valid, y): CSV, one line per edge, the learned simplifier's training labels.
    Label {
        /// Grid with sizes.
        input: PathBuf,
        /// Output CSV.
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        args: simplify::SimplifyArgs,
    },
    /// Training graphs for GCN-ABGS along a whole LBO-ABGS run of a sized grid: model
    /// inputs and the exact estimate's targets (Δs−1, Δd/h_loc) per edge, one safetensors file.
    Dataset {
        /// Grid with sizes.
        input: PathBuf,
        /// Output file (.safetensors).
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        args: dataset::DatasetArgs,
    },
    /// The whole pipeline: dense grid -> sizes -> LBO-ABGS -> evaluation, writing
    /// DIR/dense.vtk, DIR/simplified.vtk, DIR/report.json, DIR/preview.png and
    /// DIR/convergence.png.
    Run {
        /// Input surface (stl, obj, off, ply, msh, vtk, vtu, mesh, abgs).
        input: PathBuf,
        #[command(flatten)]
        args: run::RunArgs,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Info { file, json } => info::run(&file, json),
        Command::Convert { input, output } => info::convert(&input, &output),
        Command::Query {
            grid,
            points,
            mode,
            beta,
            output,
        } => query::run(&grid, &points, mode, beta, output.as_deref()),
        Command::BenchQuery {
            grid,
            points,
            seconds,
            json,
        } => bench::run(&grid, points, seconds, json),
        Command::Size { grid, output, args } => size::run(&grid, &output, &args),
        Command::Eval { args } => eval::run(&args),
        Command::Simplify {
            input,
            output,
            method,
            target_faces,
            report,
            args,
        } => simplify::run(
            &input,
            &output,
            method,
            target_faces,
            &args,
            report.as_ref(),
        ),
        Command::Label {
            input,
            output,
            args,
        } => simplify::label(&input, &output, &args),
        Command::Run { input, args } => run::run(&input, &args),
        Command::Dataset {
            input,
            output,
            args,
        } => dataset::run(&input, &output, &args),
        Command::Grid {
            input,
            output,
            args,
        } => match grid::run(&input, &output, &args) {
            Ok(true) => Ok(()),
            Ok(false) => {
                eprintln!("abgs: the remeshed grid failed a check");
                return ExitCode::FAILURE;
            }
            Err(e) => Err(e),
        },
        Command::CheckGradation { grid, beta, slope } => match size::check(&grid, beta, slope) {
            Ok(true) => Ok(()),
            Ok(false) => {
                eprintln!("abgs: gradation bound violated");
                return ExitCode::FAILURE;
            }
            Err(e) => Err(e),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("abgs: error: {e}");
            ExitCode::FAILURE
        }
    }
}
