//! The sizing field (DESIGN §3.2–3.4): initial sizes H0 from curvature,
//! proximity, features and user sources, clamped to [hmin, hmax]; gradation to
//! `|∇h| ≤ ln β` on every triangle; and the Laplace–Beltrami operator of a field.
//!
//! Stages and costs: features O(F); curvature O(V·ring), proximity O(V log F)
//! (both parallel); gradation O(V log V) (sequential, Dijkstra-ordered).

pub mod contact;
pub mod curvature;
pub mod gradation;
pub mod lbo;
pub mod normals;
pub mod proximity;
pub mod sources;

pub use curvature::Curvature;
pub use gradation::GradationReport;
pub use lbo::Lbo;
pub use sources::{SizeSource, SourceShape};

use crate::error::{Error, Result};
use crate::mesh::{Features, Grid};
use std::f64::consts::PI;
use std::time::Instant;

/// Default `hmin` as a fraction of the bounding-box diagonal (1/2000); also
/// the default contact gap: sheets closer than this are in contact, not a gap.
pub const DEFAULT_HMIN_FRACTION: f64 = crate::mesh::CONTACT_FRACTION;

/// Most rounds of (share sizes at contacts, grade again) after the first gradation.
const CONTACT_ROUNDS: usize = 4;
/// A contact size lowered by less than this (relative) does not call for another round.
const CONTACT_REL: f64 = 1e-3;

/// How gradation is specified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gradation {
    /// Largest ratio of neighbouring sizes β > 1 (slope ln β).
    Beta(f64),
    /// Largest size slope |∇h| > 0 directly.
    Slope(f64),
}

impl Gradation {
    /// The slope bound `s` (ln β for a ratio).
    pub fn slope(&self) -> Result<f64> {
        match *self {
            Gradation::Beta(b) => crate::query::volume::slope_from_beta(b),
            Gradation::Slope(s) if s.is_finite() && s > 0.0 => Ok(s),
            Gradation::Slope(s) => Err(Error::InvalidArgument(format!(
                "gradation slope {s} must be finite and > 0"
            ))),
        }
    }
}

/// Parameters of [`compute`]. `Default` gives the documented defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct SizeParams {
    /// Elements per full circle for curvature sizes, `h = 2π / (κ·n_circle)` (24).
    pub n_circle: f64,
    /// Elements across a gap or wall, `h = g / n_gap` (3).
    pub n_gap: f64,
    /// Smallest size; `None` = diagonal / 2000.
    pub hmin: Option<f64>,
    /// Largest size; `None` = diagonal / 10.
    pub hmax: Option<f64>,
    /// Dihedral angle above which an edge is a feature, degrees (30).
    pub feature_angle_deg: f64,
    /// Size imposed on feature-edge vertices; `None` = no feature refinement.
    pub feature_size: Option<f64>,
    /// Use curvature sizes (true).
    pub curvature: bool,
    /// Use proximity sizes (true).
    pub proximity: bool,
    /// Gradation after H0; `None` leaves H0 as it is (default β = 1.2).
    pub gradation: Option<Gradation>,
    /// User sources.
    pub sources: Vec<SizeSource>,
    /// Bodies nearer than this touch (a gap the field cannot resolve, and the
    /// tessellation noise between coincident faces tessellated apart): where
    /// they touch both take the smaller of their sizes (see [`contact`]) and
    /// no gap size is set between them. `None` = `n_gap · hmin` for another
    /// body (a narrower gap would need elements below hmin) and hmin for
    /// the walls of one body; a value given applies to both.
    pub contact_gap: Option<f64>,
}

impl Default for SizeParams {
    fn default() -> Self {
        SizeParams {
            n_circle: 24.0,
            n_gap: 3.0,
            hmin: None,
            hmax: None,
            feature_angle_deg: 30.0,
            feature_size: None,
            curvature: true,
            proximity: true,
            gradation: Some(Gradation::Beta(1.2)),
            sources: Vec::new(),
            contact_gap: None,
        }
    }
}

impl SizeParams {
    /// Checks every parameter; returns (hmin, hmax, slope) resolved for `diagonal`.
    pub fn resolve(&self, diagonal: f64) -> Result<(f64, f64, Option<f64>)> {
        let pos = |x: f64, what: &str| -> Result<()> {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err(Error::InvalidArgument(format!(
                    "{what} = {x} must be finite and > 0"
                )))
            }
        };
        pos(self.n_circle, "n_circle")?;
        pos(self.n_gap, "n_gap")?;
        let hmin = self.hmin.unwrap_or(diagonal * DEFAULT_HMIN_FRACTION);
        let hmax = self.hmax.unwrap_or(diagonal / 10.0);
        pos(hmin, "hmin")?;
        pos(hmax, "hmax")?;
        if hmin > hmax {
            return Err(Error::InvalidArgument(format!(
                "hmin = {hmin} exceeds hmax = {hmax}"
            )));
        }
        if !(self.feature_angle_deg.is_finite() && (0.0..=180.0).contains(&self.feature_angle_deg))
        {
            return Err(Error::InvalidArgument(format!(
                "feature angle {} must be in [0, 180] degrees",
                self.feature_angle_deg
            )));
        }
        if let Some(f) = self.feature_size {
            pos(f, "feature_size")?;
        }
        if let Some(c) = self.contact_gap {
            if !(c.is_finite() && c >= 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "contact gap {c} must be finite and >= 0"
                )));
            }
        }
        for s in &self.sources {
            s.validate()?;
        }
        let slope = self.gradation.map(|g| g.slope()).transpose()?;
        Ok((hmin, hmax, slope))
    }
}

/// Which term set each vertex's H0 (counts).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LimitCounts {
    /// Curvature was the smallest term.
    pub curvature: usize,
    /// Proximity was the smallest term.
    pub proximity: usize,
    /// Feature refinement was the smallest term.
    pub feature: usize,
    /// A user source was the smallest term.
    pub source: usize,
    /// Clamped up to hmin.
    pub hmin: usize,
    /// Nothing smaller than hmax (clamped down to hmax).
    pub hmax: usize,
}

/// What [`compute`] did, with timings.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SizeReport {
    /// Smallest size used.
    pub hmin: f64,
    /// Largest size used.
    pub hmax: f64,
    /// Gradation slope (None when gradation was off).
    pub slope: Option<f64>,
    /// Feature edges found.
    pub feature_edges: usize,
    /// Smooth patches found.
    pub patches: usize,
    /// Which term limited H0, per vertex.
    pub limited_by: LimitCounts,
    /// Gradation report (default when off).
    pub gradation: GradationReport,
    /// Vertices lying on another body (within the contact gap), whose size is
    /// shared with it (see [`contact`]).
    pub contact_vertices: usize,
    /// Seconds: features and patch normals.
    pub seconds_features: f64,
    /// Seconds: curvature.
    pub seconds_curvature: f64,
    /// Seconds: proximity.
    pub seconds_proximity: f64,
    /// Seconds: finding the vertices where bodies touch.
    pub seconds_contacts: f64,
    /// Seconds: gradation (with the contact rounds).
    pub seconds_gradation: f64,
}

/// Every field computed by [`compute`], one value per vertex.
#[derive(Debug, Clone)]
pub struct SizeFields {
    /// Final sizes (graded H0, or H0 when gradation is off).
    pub h: Vec<f64>,
    /// Initial sizes after clamping, shared where bodies touch.
    pub h0: Vec<f64>,
    /// Curvature sizes `2π/(κ n_circle)` (`+inf` where flat or off).
    pub h_curv: Vec<f64>,
    /// Proximity sizes `g / n_gap` (`+inf` where no gap or off).
    pub h_prox: Vec<f64>,
    /// Principal curvatures (empty when curvature is off).
    pub curvature: Vec<Curvature>,
    /// What was done.
    pub report: SizeReport,
}

/// Computes H0 and (optionally) the graded field on `grid`'s vertices.
pub fn compute(grid: &Grid, params: &SizeParams) -> Result<SizeFields> {
    let diag = grid.bbox().diagonal();
    let (hmin, hmax, slope) = params.resolve(diag)?;
    let nv = grid.vertices().len();
    let mut report = SizeReport {
        hmin,
        hmax,
        slope,
        ..Default::default()
    };
    let t = Instant::now();
    let features = Features::detect(grid, params.feature_angle_deg);
    let normals = normals::PatchNormals::compute(grid, &features);
    report.feature_edges = features.feature_edge_count();
    report.patches = features.patch_count as usize;
    report.seconds_features = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let (h_curv, curv) = if params.curvature {
        let c = curvature::principal_curvatures(grid, &features, &normals);
        let h = c
            .iter()
            .map(|c| {
                let k = c.max_abs();
                if k > 0.0 {
                    2.0 * PI / (k * params.n_circle)
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        (h, c)
    } else {
        (vec![f64::INFINITY; nv], Vec::new())
    };
    report.seconds_curvature = t.elapsed().as_secs_f64();

    // Rays ignore hits nearer than `ray_min` (hmin: tessellation noise);
    // another body nearer than `contact_gap` (n_gap·hmin: a gap the field
    // cannot resolve, what coincident faces tessellated apart look like)
    // touches this one (see `proximity` and `contact`).
    let ray_min = params.contact_gap.unwrap_or(hmin).max(1e-12 * diag);
    let contact_gap = params
        .contact_gap
        .unwrap_or(params.n_gap * hmin)
        .max(ray_min);
    let t = Instant::now();
    let h_prox: Vec<f64> = if params.proximity {
        let g = proximity::gaps(grid, &normals, ray_min, contact_gap, hmax * params.n_gap);
        g.into_iter().map(|g| g / params.n_gap).collect()
    } else {
        vec![f64::INFINITY; nv]
    };
    report.seconds_proximity = t.elapsed().as_secs_f64();

    let v = grid.vertices();
    let mut h0 = vec![hmax; nv];
    let lim = &mut report.limited_by;
    for i in 0..nv {
        let mut best = (hmax, 0u8);
        let mut consider = |h: f64, tag: u8| {
            if h < best.0 {
                best = (h, tag);
            }
        };
        consider(h_curv[i], 1);
        consider(h_prox[i], 2);
        if let Some(fs) = params.feature_size {
            if features.on_feature(i) {
                consider(fs, 3);
            }
        }
        for s in &params.sources {
            if s.distance(v[i]) <= s.radius {
                consider(s.size, 4);
            }
        }
        match best.1 {
            0 => lim.hmax += 1,
            1 => lim.curvature += 1,
            2 => lim.proximity += 1,
            3 => lim.feature += 1,
            _ => lim.source += 1,
        }
        if best.0 < hmin {
            lim.hmin += 1;
        }
        h0[i] = best.0.clamp(hmin, hmax);
    }

    // Touching bodies agree on their interface (the smaller size), before and
    // after gradation, until gradation no longer separates them.
    let t = Instant::now();
    let contacts = contact::contacts(grid, contact_gap);
    report.contact_vertices = contacts.iter().filter(|c| !c.fringe).count();
    contact::unify(&mut h0, grid.triangles(), &contacts, 0.0);
    report.seconds_contacts = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let h = match slope {
        Some(s) => {
            // Bodies apart grade side by side (the same field, see
            // `gradation::parts`); the pieces are cut once for all rounds.
            let pieces = gradation::parts::Pieces::new(grid.vertices(), grid.triangles());
            let grade = |h: &[f64]| match &pieces {
                Some(p) => p.grade(grid.vertices(), grid.triangles(), h, s),
                None => gradation::grade(grid.vertices(), grid.triangles(), grid.topology(), h, s),
            };
            let (mut h, mut r) = grade(&h0);
            for _ in 0..CONTACT_ROUNDS {
                if contact::unify(&mut h, grid.triangles(), &contacts, CONTACT_REL) == 0 {
                    break;
                }
                (h, r) = grade(&h);
            }
            report.gradation = r;
            h
        }
        None => h0.clone(),
    };
    report.seconds_gradation = t.elapsed().as_secs_f64();
    // Every stage keeps sizes within [min H0, H0]; a violation is a bug, and
    // an error rather than a field no mesher could use.
    if let Some(i) = h.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
        return Err(Error::InvalidSize(format!(
            "internal error: vertex {i} got size {} (please report it with the model)",
            h[i]
        )));
    }
    Ok(SizeFields {
        h,
        h0,
        h_curv,
        h_prox,
        curvature: curv,
        report,
    })
}

impl Grid {
    /// Computes sizes with `params` and installs them; returns the report.
    pub fn compute_sizes(&mut self, params: &SizeParams) -> Result<SizeReport> {
        let f = compute(self, params)?;
        self.set_sizes(f.h)?;
        Ok(f.report)
    }

    /// Grades the current sizes in place (they act as H0) to slope `g`.
    pub fn apply_gradation(&mut self, g: Gradation) -> Result<GradationReport> {
        let s = g.slope()?;
        let h0 = self.sizes().ok_or(Error::NoSizes)?.to_vec();
        let (h, r) = gradation::grade(self.vertices(), self.triangles(), self.topology(), &h0, s);
        self.set_sizes(h)?;
        Ok(r)
    }

    /// LBO of the current sizes. Errors without sizes. O(F).
    pub fn lbo(&self) -> Result<Lbo> {
        Ok(lbo::lbo(self, self.sizes().ok_or(Error::NoSizes)?))
    }
}
