//! Adaptive background-grid simplification by edge collapses: LBO-ABGS
//! (DESIGN §3.5), the procedural simplifier of the paper.
//!
//! The input is the *target grid*: a dense grid with its (graded) sizes. A
//! copy is simplified in iterations; each one
//! 1. ranks the edges by the LBO of the size field (smoothest first),
//! 2. takes the best-ranked `2·n·|E|` edges not already known to be
//!    non-collapsible as candidates,
//! 3. estimates candidates exactly as their real collapses would go
//!    ([`estimate`]), in parallel,
//! 4. selects scores `y < 0.5` whose closed 1-rings are pairwise disjoint,
//!    up to `n·|E|`: by default batch by batch of the pool in LBO order,
//!    estimating only edges whose rings are still free and taking each
//!    batch's lowest scores ([`Selection::Batched`]); or over the whole
//!    estimated pool, lowest scores first ([`Selection::Global`], DESIGN
//!    §3.5 as the paper has it),
//! 5. collapses them and repairs locally (relaxation and flips, each checked
//!    like a collapse),
//! 6. re-projects the sizes of moved vertices from the target,
//!
//! and the loop stops when nothing is selected, after `max_iterations`, or
//! when the progress callback asks to. Then the vertex sizes are fitted to
//! the target by element-weighted least squares ([`fit`], on by default:
//! sizes taken at the vertices lie above a convex field between them).
//!
//! An estimate depends only on the closed 1-rings of the edge's two ends, so
//! it is kept between iterations until a vertex there changes: an edge found
//! non-collapsible is not estimated again (nor taken into the pool) until
//! its neighbourhood changes. The result is what re-estimating every
//! candidate every iteration would give, without the cost.
//!
//! The bodies of an assembly (the mesh's connected parts) run their
//! iterations side by side, each with its own ranking and budget
//! (`simplify::iterate`).
//!
//! Deterministic: estimates are computed in parallel but applied in a fixed
//! order, and each part runs as it would alone, so the output bits do not
//! depend on the thread count.

pub mod envelope;
pub mod estimate;
pub mod fit;
mod iterate;
mod repair;
pub mod scorer;
pub mod select;
mod target;

pub use estimate::{Binding, Estimate, Limits};
pub use scorer::{Accurate, EdgeScorer, Ranking, Stamps, View};
pub use target::{Hit, Target};

use crate::error::{Error, Result};
use crate::mesh::feature_lines::{feature_lines, FeatureLines};
use crate::mesh::halfedge::{HalfedgeMesh, NONE, V_CORNER};
use crate::mesh::{BuildOptions, Features, Grid};
use crate::spatial::{LabelForest, StarTables};
use rayon::prelude::*;
use std::time::Instant;

/// Default `T_contact` ([`SimplifyParams::t_contact`]): the default `T_size`,
/// so the interface costs no face by default. Queries at a contact read the
/// smallest body's size (the tie rule of [`crate::query`]), so a mesher gets
/// one size there whatever this is; a tighter `T_contact` makes the bodies'
/// own fields agree as well, which a mesher querying each body on its own
/// needs. Measured on `gmsh_bracket_assembly` (31 % of its surface at a
/// contact, dense disagreement p95 4.5 %): `T_contact` 1.2 / 1.1 / 1.05 /
/// 1.02 give 10.4 k / 14.4 k / 27.3 k / 42.3 k faces and a simplified
/// disagreement p95 of 13.2 / 8.1 / 5.2 / 4.8 %.
pub const DEFAULT_T_CONTACT: f64 = 1.2;

/// Default largest angle of a new triangle ([`SimplifyParams::max_angle_deg`],
/// degrees).
///
/// What the limit guards, and what it does not:
/// - **Not the sizes.** The samples of the size test lie on a lattice whose
///   spacing follows the longest side (see [`estimate::divisions`]), so a
///   cap's interpolated sizes are measured as densely as any triangle's.
/// - **Not the query's landing.** The distance envelope bounds a sample's
///   distance whatever the face's tilt (see [`envelope`]), and the wrong-sheet
///   share checks orientation after the fact.
/// - **The normal.** A cap (largest angle `A`, longest side `L`) is at most
///   `½·L·tan((180° − A)/2)` high, and a corner off its plane by `ε` tilts its
///   normal by about `ε / height`. At 170° an isosceles cap is 4.4 % of its
///   longest side high (at 150°, 13 %): a corner 1 % of `L` off its plane (a
///   chord `L` on a radius `12.5·L`) tilts it by about 13°. Faces lower than
///   1 % of their longest side have noise for a normal and are refused as
///   degenerate ([`crate::mesh::shape::reliable_normal`]: an isosceles cap of
///   about 177.7°). A tilt the cap's shape allows is caught where it
///   matters: every sample of a cap (past [`estimate::CAP_ANGLE_DEG`]) checks
///   the cap's normal against the target's where it lands, within the normal-turn limit (the check
///   against the face it replaces alone let caps drift from a sphere's
///   surface over several collapses at 170°, `tests/simplify.rs`).
/// - **Contacts.** Where bodies touch, two independent triangulations must
///   agree at every point, not only at the samples, and between samples
///   they drift apart with each interpolant's gradient, which a cap makes
///   steep (a size difference over its small height). A cap with a sample on
///   two bodies is refused (as the angle rule's): at 170° without this,
///   `tests/contact.rs`'s shaft in a bore disagreed by 5.4 % at most
///   against the 5.0 % it allows.
///
/// Measured against 150° on the shared models below 250k dense faces
/// (README, "Largest angle"): the angle rule bound 11–27 % of the final
/// edges at 150° and 1–8 % at 170°; elements per cell 0.99–1.24× (t20
/// 33.1 → 34.4, cessna 49.6 → 61.6, crankarm 107.7 → 118.7), size deviation
/// p95 ≤ 1.132 and wrong-sheet share ≤ 3e-5 on every one.
pub const DEFAULT_MAX_ANGLE_DEG: f64 = 170.0;

/// Which scorer ranks the edges (see [`scorer`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// LBO-ABGS: the accurate estimate of each candidate (DESIGN §3.5).
    #[default]
    Lbo,
    /// GCN-ABGS: the embedded graph network's predictions (DESIGN §3.6).
    Gcn,
}

/// How LBO-ABGS picks an iteration's collapses from its candidate pool
/// (see [`scorer::Accurate`] for each one's cost).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Selection {
    /// The pool in LBO order, in batches of [`scorer::batch_size`] edges
    /// (a 1024th of the pool, 32 to 512): an
    /// edge whose closed 1-ring meets a collapse already chosen this
    /// iteration is skipped without being estimated, the others are
    /// estimated in parallel, and the batch's collapsible ones are taken by
    /// lowest score while their rings stay disjoint. Estimates only what can
    /// still be chosen.
    #[default]
    Batched,
    /// DESIGN §3.5 step 4 as the paper has it: the whole pool estimated,
    /// then the lowest scores taken while their rings stay disjoint. About
    /// 20 estimates per collapse on a fine grid, most of them of edges
    /// whose neighbourhood changes before they could be chosen.
    Global,
}

/// Parameters of LBO-ABGS and GCN-ABGS (defaults from DESIGN §3.5–3.6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimplifyParams {
    /// The scorer (default LBO-ABGS).
    pub method: Method,
    /// GCN-ABGS: edges whose predicted score is at or above this are not
    /// tried (`T_score`, default 0.5: "predicted not collapsible").
    pub t_score: f64,
    /// GCN-ABGS: run the accurate estimate on the edges the model proposes
    /// and drop those that fail it (default false).
    pub verify: bool,
    /// Largest share of the edges collapsed per iteration (`n`, default 0.10).
    pub fraction: f64,
    /// Candidate pool size as a multiple of `n·|E|` (default 2).
    pub pool_factor: f64,
    /// LBO-ABGS: how an iteration's collapses are picked from the pool
    /// (default [`Selection::Batched`]).
    pub selection: Selection,
    /// Largest size ratio a collapse may cause (`T_size`, default 1.2).
    pub t_size: f64,
    /// Largest size ratio a collapse may cause where bodies touch
    /// (`T_contact`, default [`DEFAULT_T_CONTACT`] = 1.2, the default
    /// `T_size`): each body follows the agreed (smaller) size there within
    /// it, so touching bodies agree within about `T_contact²` (see
    /// `target`); tighter costs faces (see [`DEFAULT_T_CONTACT`]).
    pub t_contact: f64,
    /// Fixed distance rule `Δd ≤ τ_d·h_loc` in place of the derived
    /// misprojection term (`None`, the default: `Δd ≤ ½·ln(T_size)·h / ln β`,
    /// see [`envelope`]). The paper's rule is `Some(0.05)`.
    pub tau_d: Option<f64>,
    /// Gradation ratio β the sizes were graded with (default 1.2, the sizing
    /// default): the field's slope `ln β` bounds how much a misprojection
    /// changes a size.
    pub beta: f64,
    /// Each side of a thin wall or gap may move at most this fraction of the
    /// gap's width (`κ`, default 0.25; `f64::INFINITY` turns the clearance
    /// term off).
    pub clearance_fraction: f64,
    /// Largest distance to the target in model units (`None`: no limit).
    pub max_distance: Option<f64>,
    /// Most iterations (default 1000): a cap against a loop that does not
    /// end, not the stop rule (nothing selected). At 200 it cut 5 of the 15
    /// shared models below 250k faces short while each iteration still
    /// collapsed a few edges; all 17 converge within 245.
    pub max_iterations: usize,
    /// Dihedral angle (degrees) above which an edge is a feature (default 30).
    pub feature_angle_deg: f64,
    /// A feature line turning by more than this (degrees) has a corner there
    /// (default 30).
    pub corner_angle_deg: f64,
    /// Largest turn of a face normal a collapse, move or flip may cause
    /// (degrees, default 60): against the face it replaces, and for a cap
    /// (largest angle past [`estimate::CAP_ANGLE_DEG`]) also against the
    /// target's normal at each of its samples.
    pub max_normal_turn_deg: f64,
    /// Largest angle of a new triangle (degrees, default
    /// [`DEFAULT_MAX_ANGLE_DEG`] = 170) unless the triangle it replaces
    /// already had a larger one.
    pub max_angle_deg: f64,
    /// Local repair after each batch (relaxation and flips; default true).
    pub repair: bool,
    /// Fit the vertex sizes to the target after the last iteration
    /// (default true; see [`fit`]): the simplified field then errs both
    /// ways instead of lying above the target where elements are small.
    /// `false` keeps the target's size at each vertex (the paper's rule).
    pub fit_sizes: bool,
}

impl Default for SimplifyParams {
    fn default() -> Self {
        SimplifyParams {
            method: Method::Lbo,
            t_score: 0.5,
            verify: false,
            fraction: 0.10,
            pool_factor: 2.0,
            selection: Selection::Batched,
            t_size: 1.2,
            t_contact: DEFAULT_T_CONTACT,
            tau_d: None,
            beta: 1.2,
            clearance_fraction: envelope::DEFAULT_CLEARANCE_FRACTION,
            max_distance: None,
            max_iterations: 1000,
            feature_angle_deg: 30.0,
            corner_angle_deg: 30.0,
            max_normal_turn_deg: 60.0,
            max_angle_deg: DEFAULT_MAX_ANGLE_DEG,
            repair: true,
            fit_sizes: true,
        }
    }
}

impl SimplifyParams {
    /// Errors with a message naming the first parameter out of range.
    pub fn check(&self) -> Result<()> {
        let within = crate::error::check_range;
        within(self.fraction, 1e-9, 1.0, "fraction")?;
        within(self.t_score, 0.0, 1.0, "t_score")?;
        within(self.pool_factor, 1.0, 1e6, "pool_factor")?;
        within(self.t_size, 1.0 + 1e-9, 1e9, "t_size")?;
        within(self.t_contact, 1.0 + 1e-9, 1e9, "t_contact")?;
        if let Some(t) = self.tau_d {
            within(t, 1e-12, 1e9, "tau_d")?;
        }
        within(self.beta, 1.0 + 1e-9, 1e9, "beta")?;
        if self.clearance_fraction != f64::INFINITY {
            within(self.clearance_fraction, 1e-9, 1e9, "clearance_fraction")?;
        }
        if let Some(d) = self.max_distance {
            within(d, f64::MIN_POSITIVE, f64::MAX, "max_distance")?;
        }
        within(self.feature_angle_deg, 0.0, 180.0, "feature_angle_deg")?;
        within(self.corner_angle_deg, 0.0, 180.0, "corner_angle_deg")?;
        within(self.max_normal_turn_deg, 0.0, 180.0, "max_normal_turn_deg")?;
        within(self.max_angle_deg, 60.0, 180.0, "max_angle_deg")
    }

    /// The thresholds of one estimate.
    pub fn limits(&self) -> Limits {
        let size_term = match self.tau_d {
            Some(t) => envelope::SizeTerm::Fixed(t),
            None => envelope::SizeTerm::Derived {
                budget: 0.5 * self.t_size.ln(),
                slope: self.beta.ln(),
            },
        };
        Limits {
            t_size: self.t_size,
            t_contact: self.t_contact,
            size_term,
            kappa: self.clearance_fraction,
            max_distance: self.max_distance.unwrap_or(f64::INFINITY),
            cos_turn: self.max_normal_turn_deg.to_radians().cos(),
            max_angle_deg: self.max_angle_deg,
            light: false,
        }
    }
}

/// What one iteration did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct IterationRecord {
    /// Iteration number (1-based).
    pub iteration: usize,
    /// Faces after the iteration.
    pub faces: usize,
    /// Vertices after the iteration.
    pub vertices: usize,
    /// Candidates in the pool.
    pub candidates: usize,
    /// Candidates estimated afresh (the others were known from earlier
    /// iterations and their neighbourhoods had not changed).
    pub estimated: usize,
    /// Candidates found collapsible (`y < 0.5`).
    pub collapsible: usize,
    /// Collapses done.
    pub accepted: usize,
    /// Vertices moved by relaxation.
    pub moved: usize,
    /// Edges flipped.
    pub flips: usize,
    /// `(4/√3)∫h⁻²dA` over the grid's own surface with its own sizes: the
    /// element count its field asks for (cheap; the metrics module measures
    /// the official one over the dense surface).
    pub element_count: f64,
    /// Seconds spent.
    pub seconds: f64,
}

/// Why the loop stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StopReason {
    /// Nothing could be selected.
    #[default]
    Converged,
    /// `max_iterations` reached.
    MaxIterations,
    /// The progress callback asked to stop (the grid is valid).
    Cancelled,
}

/// For the edges of a simplified grid, what keeps each from collapsing (see
/// [`Binding`]): the census that says which check set the grid's coarseness.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BindingCounts {
    /// Still collapsible (left by the iteration limit or a cancel).
    pub free: usize,
    /// Mesh rules (link condition, locked, boundary).
    pub topology: usize,
    /// Feature rules (corners, vertices on two lines).
    pub feature: usize,
    /// A new face would be degenerate.
    pub degenerate: usize,
    /// A face normal would turn past `max_normal_turn_deg`.
    pub normal_turn: usize,
    /// A new face's largest angle would pass `max_angle_deg`.
    pub max_angle: usize,
    /// The sampled size ratio.
    pub size: usize,
    /// The sampled size ratio where bodies touch.
    pub contact: usize,
    /// The distance envelope.
    pub distance: usize,
    /// The absolute distance limit.
    pub max_distance: usize,
}

impl BindingCounts {
    fn add(&mut self, b: Binding) {
        let slot = match b {
            Binding::Free => &mut self.free,
            Binding::Topology => &mut self.topology,
            Binding::Feature => &mut self.feature,
            Binding::Degenerate => &mut self.degenerate,
            Binding::NormalTurn => &mut self.normal_turn,
            Binding::MaxAngle => &mut self.max_angle,
            Binding::Size => &mut self.size,
            Binding::Contact => &mut self.contact,
            Binding::Distance => &mut self.distance,
            Binding::MaxDistance => &mut self.max_distance,
        };
        *slot += 1;
    }
}

/// What a simplification did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SimplifyReport {
    /// Faces of the target.
    pub faces_in: usize,
    /// Vertices of the target.
    pub vertices_in: usize,
    /// Faces of the result.
    pub faces_out: usize,
    /// Vertices of the result.
    pub vertices_out: usize,
    /// Feature lines of the target.
    pub feature_lines: usize,
    /// Corners (never moved).
    pub corners: usize,
    /// Element count of the target's own field (as [`IterationRecord::element_count`]).
    pub element_count_in: f64,
    /// One record per iteration.
    pub iterations: Vec<IterationRecord>,
    /// Why it stopped.
    pub stop: StopReason,
    /// What keeps each edge of the result from collapsing (every edge
    /// estimated once more at the end, as the loop does: the first term
    /// found over its bound).
    pub binding: BindingCounts,
    /// The size fit's work (zeros when [`SimplifyParams::fit_sizes`] is off).
    pub fit: fit::FitReport,
    /// Seconds in the size fit.
    pub fit_seconds: f64,
    /// Seconds in all.
    pub seconds: f64,
}

/// A simplified grid with its report.
#[derive(Debug, Clone)]
pub struct Simplified {
    /// The simplified grid, with sizes.
    pub grid: Grid,
    /// What was done.
    pub report: SimplifyReport,
}

/// The per-edge estimate of the first iteration: the training label of the
/// learned simplifier.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeScore {
    /// The edge's two grid vertices.
    pub vertices: [u32; 2],
    /// `Δs` (NaN when invalid).
    pub ds: f64,
    /// `Δd / h_loc` (NaN when invalid).
    pub dd_rel: f64,
    /// Largest distance relative to the envelope (≤ 1 inside; NaN when invalid).
    pub de: f64,
    /// The collapse passes the topological and geometric checks.
    pub valid: bool,
    /// The score `y` (1 when invalid).
    pub y: f64,
}

/// What projections onto a target grid need besides the grid: its features
/// and feature lines with their end sizes.
struct TargetParts {
    features: Features,
    lines: FeatureLines,
    seg_sizes: Vec<[f64; 2]>,
    envelope: envelope::Envelope,
    /// Per target vertex: its reach (see
    /// [`crate::spatial::StarMesh`]).
    reach: Vec<f64>,
    /// The star search's slot-ordered stars (see
    /// [`crate::spatial::StarTables`]).
    stars: StarTables,
    /// A BVH per target patch.
    patches: LabelForest,
}

impl TargetParts {
    /// The target: `grid` (the grid these parts were made from) with them.
    fn target<'a>(&'a self, grid: &'a Grid) -> Target<'a> {
        Target {
            grid,
            sizes: grid.sizes().unwrap_or(&[]),
            face_patch: &self.features.face_patch,
            lines: &self.lines,
            seg_sizes: &self.seg_sizes,
            envelope: &self.envelope,
            contact: grid.contact_faces(),
            reach: &self.reach,
            stars: &self.stars,
            patches: &self.patches,
        }
    }
}

/// The half-edge mesh of a target grid (sizes, corners and lines set) and
/// the parts of its target.
fn setup(grid: &Grid, params: &SimplifyParams) -> Result<(HalfedgeMesh, TargetParts)> {
    params.check()?;
    let Some(sizes) = grid.sizes() else {
        return Err(Error::InvalidArgument(
            "the grid has no sizes (compute or set them first)".into(),
        ));
    };
    let features = Features::detect(grid, params.feature_angle_deg);
    let (mut mesh, _) = HalfedgeMesh::from_grid(grid, Some(&features));
    for v in 0..mesh.n_vertices() {
        let o = mesh.vertex_origin[v];
        mesh.vertex_size[v] = if o == NONE { 0.0 } else { sizes[o as usize] };
    }
    let (lines, _) = feature_lines(&mut mesh, params.corner_angle_deg);
    let seg_sizes = lines
        .seg_vertices
        .iter()
        .map(|s| s.map(|v| mesh.vertex_size[v as usize]))
        .collect();
    let lim = params.limits();
    let envelope = envelope::Envelope::compute(grid, sizes, &features, lim.size_term, lim.kappa);
    let stars = StarTables::build(
        grid.triangles(),
        &grid.topology().vertex_faces,
        &features.face_patch,
        grid.bvh(),
    );
    let reach = Target::star_mesh(grid, &features.face_patch, &stars).reaches();
    let patches = LabelForest::build(
        grid.vertices(),
        grid.triangles(),
        &features.face_patch,
        features.patch_count,
    );
    // The tie rule's contact faces and lists, built here in parallel rather
    // than lazily (and sequentially) inside the parallel estimates.
    if grid.topology().body_count > 1 {
        grid.contact_lists();
    }
    Ok((
        mesh,
        TargetParts {
            features,
            lines,
            seg_sizes,
            envelope,
            reach,
            stars,
            patches,
        },
    ))
}

/// `(4/√3)∫h⁻²dA` over the live faces with linearly interpolated sizes
/// (7-point degree-5 rule), summed in face order. O(F).
fn own_element_count(mesh: &HalfedgeMesh) -> f64 {
    let rule = crate::metrics::quadrature();
    let mut total = 0.0;
    for f in mesh.faces() {
        let h = mesh.face_vertices(f).map(|v| mesh.vertex_size[v as usize]);
        let area = 0.5 * crate::geometry::norm(mesh.face_normal2(f));
        let integral: f64 = rule
            .iter()
            .map(|(b, w)| {
                let s = b[0] * h[0] + b[1] * h[1] + b[2] * h[2];
                w / (s * s)
            })
            .sum();
        total += area * integral;
    }
    total * 4.0 / 3f64.sqrt()
}

/// Simplifies the target grid `grid` (which must carry sizes) by the
/// method of `params.method`: LBO-ABGS (the accurate estimate) or GCN-ABGS
/// (the embedded model; see `abgs::gcn`, cargo feature `gcn`). `progress` is called after every
/// iteration that collapsed something (not after the final one that found
/// nothing); returning `false` stops the loop, leaving a valid grid. Errors on
/// invalid parameters, a grid without sizes, or a model that cannot run.
/// LBO-ABGS costs about O(I · (E log E + C · S log F)) for I iterations, C
/// candidates estimated afresh and S samples per estimate; GCN-ABGS replaces
/// the C · S log F term by forward passes of the model (at most one per
/// iteration, reused while most of the grid is unchanged).
pub fn simplify(
    grid: &Grid,
    params: &SimplifyParams,
    progress: Option<&mut dyn FnMut(&IterationRecord) -> bool>,
) -> Result<Simplified> {
    match params.method {
        Method::Lbo => simplify_with(grid, params, &mut Accurate::default(), progress),
        #[cfg(feature = "gcn")]
        Method::Gcn => {
            let model = crate::gcn::embedded_model()?;
            let mut scorer = crate::gcn::Learned::new(model);
            simplify_with(grid, params, &mut scorer, progress)
        }
        #[cfg(not(feature = "gcn"))]
        Method::Gcn => Err(crate::error::Error::Model(
            "GCN-ABGS is not in this build of the library (cargo feature `gcn`, on by default)"
                .into(),
        )),
    }
}

/// [`simplify`] with any scorer (the loop's seam: see [`scorer`]);
/// `params.method` is not read.
pub fn simplify_with(
    grid: &Grid,
    params: &SimplifyParams,
    scorer: &mut dyn EdgeScorer,
    progress: Option<&mut dyn FnMut(&IterationRecord) -> bool>,
) -> Result<Simplified> {
    run_loop(grid, params, scorer, progress, None)
}

/// What `run_loop` shows an observer: the state before each iteration's
/// ranking, and once more at the end.
pub type Observer<'o> = &'o mut dyn FnMut(&View) -> Result<()>;

/// The loop shared by every scorer. `observer` sees the grid before each
/// iteration's ranking and the final grid (with `iteration` one past the
/// last); its error stops the loop.
pub(crate) fn run_loop(
    grid: &Grid,
    params: &SimplifyParams,
    scorer: &mut dyn EdgeScorer,
    progress: Option<&mut dyn FnMut(&IterationRecord) -> bool>,
    observer: Option<Observer>,
) -> Result<Simplified> {
    let start = Instant::now();
    let (mesh, parts) = setup(grid, params)?;
    let target = parts.target(grid);
    let lim = params.limits();
    let mut report = SimplifyReport {
        faces_in: grid.triangles().len(),
        vertices_in: grid.vertices().len(),
        feature_lines: parts.lines.line_count as usize,
        corners: mesh
            .vertices()
            .filter(|&v| mesh.vertex_flags[v as usize] & V_CORNER != 0)
            .count(),
        element_count_in: own_element_count(&mesh),
        ..Default::default()
    };
    let cx = iterate::Context {
        target: &target,
        lim: &lim,
        params,
        cos_crease: repair::crease_limit(params.feature_angle_deg),
    };
    let looped = iterate::run(mesh, scorer, &cx, progress, observer)?;
    report.iterations = looped.iterations;
    report.stop = looped.stop;
    let mut mesh = looped.mesh;
    if params.fit_sizes {
        let t = Instant::now();
        report.fit = fit::fit_sizes(&mut mesh, &target, lim.t_size);
        report.fit_seconds = t.elapsed().as_secs_f64();
    }
    report.binding = census(&mesh, &target, &lim);
    let out = finish(&mesh)?;
    report.faces_out = out.triangles().len();
    report.vertices_out = out.vertices().len();
    report.seconds = start.elapsed().as_secs_f64();
    Ok(Simplified { grid: out, report })
}

/// Every live edge's binding (estimates stop at the first term over its
/// bound, as in the loop). Parallel; O(E · S log F).
fn census(mesh: &HalfedgeMesh, target: &Target, lim: &Limits) -> BindingCounts {
    let edges: Vec<u32> = mesh.edges().collect();
    let found: Vec<Binding> = edges
        .par_iter()
        .map(|&e| estimate::estimate(mesh, target, e, lim, 0.5).binding)
        .collect();
    let mut counts = BindingCounts::default();
    for b in found {
        counts.add(b);
    }
    counts
}

/// The live mesh as a grid with sizes (locked copies merged back).
fn finish(mesh: &HalfedgeMesh) -> Result<Grid> {
    let (verts, tris, map) = mesh.to_arrays(true);
    let mut sizes = vec![0.0; verts.len()];
    for v in mesh.vertices() {
        let k = map[v as usize];
        if k != NONE {
            sizes[k as usize] = mesh.vertex_size[v as usize];
        }
    }
    Grid::from_arrays(
        verts,
        tris,
        Some(sizes),
        &BuildOptions {
            weld_relative_tolerance: None,
            orient: false,
        },
    )
}

/// Every edge's estimate on `grid` as it is (the first iteration's view, with
/// exact `Δs` and `Δd`: no early exit), in `grid.topology().edges` order:
/// the labels the learned simplifier is trained on. Edges that are not
/// manifold in the grid are reported invalid. Parallel; O(E · S log F).
pub fn edge_scores(grid: &Grid, params: &SimplifyParams) -> Result<Vec<EdgeScore>> {
    let (mesh, parts) = setup(grid, params)?;
    let target = parts.target(grid);
    let lim = params.limits();
    let topo = grid.topology();
    let mut out: Vec<EdgeScore> = topo
        .edges
        .iter()
        .map(|&vertices| EdgeScore {
            vertices,
            ds: f64::NAN,
            dd_rel: f64::NAN,
            de: f64::NAN,
            valid: false,
            y: 1.0,
        })
        .collect();
    let found: Vec<Option<(usize, Estimate)>> = (0..mesh.n_edges() as u32)
        .into_par_iter()
        .map(|e| {
            let [a, b] = mesh
                .edge_vertices(e)
                .map(|v| mesh.vertex_origin[v as usize]);
            if a == NONE || b == NONE {
                return None;
            }
            let k = topo.find_edge(a, b)?;
            if topo.faces_of_edge(k).len() > 2 {
                return None;
            }
            Some((
                k,
                estimate::estimate(&mesh, &target, e, &lim, f64::INFINITY),
            ))
        })
        .collect();
    for (k, est) in found.into_iter().flatten() {
        let s = &mut out[k];
        s.valid = est.valid;
        s.y = est.y;
        if est.valid {
            s.ds = est.ds;
            s.dd_rel = est.dd / est.h_loc;
            s.de = est.de;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::BuildOptions;
    use crate::test_shapes::unit_square;

    /// The light check (GCN-ABGS's check of the model's choices) is the
    /// accurate estimate sampled on the coarsest lattice
    /// ([`estimate::LIGHT_DIVISIONS`]): the same estimate, bit for bit, on
    /// every edge where the sizes are large against the new triangles (the
    /// full lattice is that one too), and a different one on some edges
    /// where they are small (the full lattice is then denser).
    #[test]
    fn light_check_is_the_accurate_estimate_on_the_coarsest_lattice() {
        let opts = BuildOptions {
            weld_relative_tolerance: None,
            orient: false,
        };
        for (h, same) in [(10.0, true), (0.01, false)] {
            let (v, t) = unit_square(12, |x, y| 0.05 * (3.0 * x).sin() * (2.0 * y).cos());
            let s = v
                .iter()
                .map(|p| h * (1.0 + 0.5 * p[0] + 0.3 * p[1]))
                .collect();
            let grid = Grid::from_arrays(v, t, Some(s), &opts).expect("valid sheet");
            let params = SimplifyParams::default();
            let (mesh, parts) = setup(&grid, &params).expect("target");
            let target = parts.target(&grid);
            let full = params.limits();
            let light = Limits {
                light: true,
                ..full
            };
            let (mut edges, mut differ) = (0, 0);
            for e in mesh.edges() {
                let a = estimate::estimate(&mesh, &target, e, &full, f64::INFINITY);
                let b = estimate::estimate(&mesh, &target, e, &light, f64::INFINITY);
                // Debug prints each f64 so that it reads back to the same
                // bits, and NaN (an invalid estimate's) equal to itself.
                let (a, b) = (format!("{a:?}"), format!("{b:?}"));
                edges += 1;
                if same {
                    assert_eq!(a, b, "h = {h}, edge {e}");
                } else if a != b {
                    differ += 1;
                }
            }
            assert!(edges > 300, "{edges} edges");
            assert!(same || differ > 0, "h = {h}: no estimate differs");
        }
    }
}
