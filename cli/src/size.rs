//! `abgs size` and `abgs check-gradation`.

use abgs::sizing::{self, Gradation, SizeParams, SizeSource, SourceShape};
use abgs::{Error, Result};
use std::path::Path;

/// Options of `abgs size` (mirrors [`SizeParams`]).
#[derive(clap::Args, Debug)]
pub struct SizeArgs {
    /// Elements per full circle (curvature sizes).
    #[arg(long, default_value_t = 24.0)]
    pub n_circle: f64,
    /// Elements across a gap or wall (proximity sizes).
    #[arg(long, default_value_t = 3.0)]
    pub n_gap: f64,
    /// Smallest size (default: diagonal / 2000).
    #[arg(long)]
    pub hmin: Option<f64>,
    /// Largest size (default: diagonal / 10).
    #[arg(long)]
    pub hmax: Option<f64>,
    /// Gradation ratio β.
    #[arg(long, default_value_t = 1.2)]
    pub beta: f64,
    /// Gradation slope (overrides --beta).
    #[arg(long)]
    pub slope: Option<f64>,
    /// Skip gradation (write H0 as the size).
    #[arg(long)]
    pub no_gradation: bool,
    /// Feature angle in degrees.
    #[arg(long, default_value_t = 30.0)]
    pub feature_angle: f64,
    /// Size on feature-edge vertices (off by default).
    #[arg(long)]
    pub feature_size: Option<f64>,
    /// Ignore curvature.
    #[arg(long)]
    pub no_curvature: bool,
    /// Ignore proximity.
    #[arg(long)]
    pub no_proximity: bool,
    /// Bodies nearer than this touch (one size there, no gap size between them);
    /// default n_gap·hmin between bodies, hmin for the walls of one body.
    #[arg(long)]
    pub contact_gap: Option<f64>,
    /// A user source: "point X Y Z SIZE RADIUS", "segment X1 Y1 Z1 X2 Y2 Z2 SIZE RADIUS"
    /// or "triangle X1 .. Z3 SIZE RADIUS" (repeatable).
    #[arg(long = "source")]
    pub sources: Vec<String>,
}

fn parse_source(s: &str) -> Result<SizeSource> {
    let w: Vec<&str> = s.split_whitespace().collect();
    let bad = || Error::InvalidArgument(format!("bad --source '{s}'"));
    let nums: Vec<f64> = w
        .iter()
        .skip(1)
        .map(|x| x.parse::<f64>().map_err(|_| bad()))
        .collect::<Result<_>>()?;
    let p = |k: usize| [nums[3 * k], nums[3 * k + 1], nums[3 * k + 2]];
    let (shape, n) = match w.first().copied() {
        Some("point") if nums.len() == 5 => (SourceShape::Point(p(0)), 3),
        Some("segment") if nums.len() == 8 => (SourceShape::Segment(p(0), p(1)), 6),
        Some("triangle") if nums.len() == 11 => (SourceShape::Triangle(p(0), p(1), p(2)), 9),
        _ => return Err(bad()),
    };
    Ok(SizeSource {
        shape,
        size: nums[n],
        radius: nums[n + 1],
    })
}

impl SizeArgs {
    /// The library parameters.
    pub fn params(&self) -> Result<SizeParams> {
        Ok(SizeParams {
            n_circle: self.n_circle,
            n_gap: self.n_gap,
            hmin: self.hmin,
            hmax: self.hmax,
            feature_angle_deg: self.feature_angle,
            feature_size: self.feature_size,
            curvature: !self.no_curvature,
            proximity: !self.no_proximity,
            gradation: if self.no_gradation {
                None
            } else {
                Some(
                    self.slope
                        .map_or(Gradation::Beta(self.beta), Gradation::Slope),
                )
            },
            sources: self
                .sources
                .iter()
                .map(|s| parse_source(s))
                .collect::<Result<_>>()?,
            ..Default::default()
        })
    }
}

/// Runs `abgs size`.
pub fn run(input: &Path, output: &Path, args: &SizeArgs) -> Result<()> {
    let params = args.params()?;
    let mut g = crate::progress::load(input)?;
    let pb = crate::progress::spinner("computing sizes");
    let f = sizing::compute(&g, &params)?;
    pb.finish_and_clear();
    let r = &f.report;
    let shown = |v: &[f64]| {
        v.iter()
            .map(|&x| x.clamp(r.hmin, r.hmax))
            .collect::<Vec<f64>>()
    };
    g.set_point_array("h0", f.h0.clone())?;
    g.set_point_array("h_curv", shown(&f.h_curv))?;
    g.set_point_array("h_prox", shown(&f.h_prox))?;
    g.set_sizes(f.h.clone())?;
    g.set_point_array("lbo", g.lbo()?.vertex)?;
    g.save(output)?;
    let l = r.limited_by;
    let nv = f.h.len();
    let pct = |n: usize| 100.0 * n as f64 / nv.max(1) as f64;
    eprintln!(
        "wrote {} ({} vertices, {} triangles)",
        output.display(),
        nv,
        g.triangles().len()
    );
    eprintln!(
        "hmin {:.6}  hmax {:.6}  slope {}  feature edges {}  patches {}",
        r.hmin,
        r.hmax,
        r.slope.map_or("off".into(), |s| format!("{s:.6}")),
        r.feature_edges,
        r.patches
    );
    eprintln!(
        "H0 set by: curvature {:.1}%  proximity {:.1}%  features {:.1}%  sources {:.1}%  hmax {:.1}%  (clamped to hmin {:.1}%)",
        pct(l.curvature),
        pct(l.proximity),
        pct(l.feature),
        pct(l.source),
        pct(l.hmax),
        pct(l.hmin)
    );
    eprintln!(
        "gradation: {} faces fixed, max slope ratio {:.3} before fix, {:.9} after",
        r.gradation.faces_fixed,
        r.gradation.max_slope_ratio_before_fix,
        r.gradation.max_slope_ratio
    );
    if r.contact_vertices > 0 {
        eprintln!(
            "touching bodies: {} vertices share their size with another body",
            r.contact_vertices
        );
    }
    let (lo, hi) =
        f.h.iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
    eprintln!("size range {lo:.6} .. {hi:.6}");
    eprintln!(
        "time: features {:.3} s  curvature {:.3} s  proximity {:.3} s  gradation {:.3} s",
        r.seconds_features, r.seconds_curvature, r.seconds_proximity, r.seconds_gradation
    );
    Ok(())
}

/// Runs `abgs check-gradation`: returns false when a bound is violated.
pub fn check(grid: &Path, beta: f64, slope: Option<f64>) -> Result<bool> {
    let g = crate::progress::load(grid)?;
    let s = slope
        .map_or(Gradation::Beta(beta), Gradation::Slope)
        .slope()?;
    let h = g.sizes().ok_or(Error::NoSizes)?;
    let (max, over) = sizing::gradation::max_face_slope(g.vertices(), g.triangles(), h, s);
    println!("largest face slope / slope: {:.9}", max / s);
    println!(
        "faces above 1 + 1e-9:       {over} of {}",
        g.triangles().len()
    );
    let mut ok = over == 0;
    match g.point_arrays().iter().find(|a| a.name == "h0") {
        Some(h0) => {
            let above = h.iter().zip(&h0.values).filter(|(a, b)| a > b).count();
            println!(
                "h <= h0:                    {} ({above} vertices above)",
                if above == 0 { "yes" } else { "NO" }
            );
            ok &= above == 0;
        }
        None => println!("h <= h0:                    not checked (no h0 array)"),
    }
    Ok(ok)
}
