//! Isotropic remeshing of a grid into the dense background grid (DESIGN §3.1),
//! after Botsch & Kobbelt (2004) and Dunyach et al. (2013).
//!
//! Each iteration: split edges longer than 4/3·L, collapse edges shorter than
//! 4/5·L, flip edges towards valence 6 (4 on a boundary), then tangential
//! relaxation with projection onto the **input** surface (exact closest point,
//! restricted to the vertex's own smooth patch, or to its own input feature
//! line for a vertex on a feature). L is the local target length: a uniform
//! length (default diagonal/100) or the sizes of a sizing grid, capped where the
//! surface bends at half the curvature size `π / (κ · n_circle)` (optional).
//!
//! Before the iterations, two coarse levels at 4·L and 2·L
//! (`coarse_levels`), so long input needles (CAD exports) are not split
//! into slivers at L that the collapses then remove again.
//!
//! Features (dihedral angle above 30°, boundaries, non-manifold edges) are kept
//! as constrained polylines; corners (feature valence ≠ 2, or a line turning by
//! more than the corner angle) never move and are never removed. Bodies stay
//! apart; non-manifold edges (touching bodies) are locked, never changed, and
//! their vertices never move, so the output has the same bodies and no new
//! boundary or non-manifold edges. Dirty input (slivers, open surfaces,
//! inconsistent orientation) is handled without panicking; what could not be
//! remeshed is listed in [`RemeshReport::issues`].
//!
//! Cost: O(F log F) per iteration (projection dominates). Parallel (rayon):
//! the parts of the mesh (its bodies, once the build has cut touching ones
//! apart) are remeshed side by side, largest expected output first
//! (`expected_faces`), and within a part
//! relaxation and projection run in parallel; a part's topological passes
//! are sequential, so a single large body gains only from the latter,
//! unless it is large enough for [`RemeshParams::piece_faces`] to cut it
//! along its creases into pieces that are parts of their own ([`pieces`]). The
//! output does not depend on the thread count.

mod field;
mod locked;
pub(crate) mod ops;
pub mod pieces;
pub mod quality;
pub mod reference;
mod smooth;

use crate::error::{Error, Result};
use crate::mesh::halfedge::{BuildReport, HalfedgeMesh, E_CUT, E_LOCKED, V_CORNER, V_FEATURE};
use crate::mesh::{BuildOptions, Features, Grid};
use ops::Limits;
use rayon::prelude::*;
use reference::Reference;
use std::time::Instant;

/// How the uniform target edge length is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TargetLength {
    /// In model units.
    Absolute(f64),
    /// As a fraction of the bounding-box diagonal.
    Relative(f64),
}

/// Parameters of [`remesh`] and [`remesh_sized`]. `Default` gives the documented defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct RemeshParams {
    /// Uniform target edge length L0 (default `Relative(0.01)`: diagonal / 100).
    /// Ignored by [`remesh_sized`].
    pub target: TargetLength,
    /// Dihedral angle above which an edge is a feature, degrees (30).
    pub feature_angle_deg: f64,
    /// A feature line turning by more than this at a vertex has a corner there, degrees (30).
    pub corner_angle_deg: f64,
    /// Split / collapse / flip / relax iterations (10).
    pub iterations: usize,
    /// Relaxation steps per iteration, each followed by projection (2).
    pub relax_steps: usize,
    /// Cap the uniform target locally at half the curvature size,
    /// `π / (κ · n_circle)`, and at the width of narrow strips and creases
    /// (true), so small fillets are resolved. Not used by [`remesh_sized`],
    /// whose target is the size field itself.
    pub curvature_limit: bool,
    /// Elements per full circle in the curvature size (24).
    pub n_circle: f64,
    /// The curvature cap never goes below this fraction of the base length (0.1).
    pub min_length_ratio: f64,
    /// The cap from the curvature of a feature line never goes below this
    /// fraction of the base length (0.02): a tight curve of a feature line
    /// (a wing tip's outline) costs little and is cut badly by long chords.
    pub line_min_length_ratio: f64,
    /// Largest growth of the curvature cap per unit distance (0.3).
    pub gradation: f64,
    /// Largest turn of a face normal an operation may cause, degrees (60).
    pub max_normal_turn_deg: f64,
    /// Smallest angle a collapse may create unless the faces it replaces were
    /// already worse, degrees (10).
    pub sliver_angle_deg: f64,
    /// A collapse may remove a vertex only if it lies within this fraction of
    /// the local target length of the surface (and feature line) left (0.05).
    pub fidelity: f64,
    /// A body expected to make more than twice this many triangles is cut
    /// along its creases into pieces of about this many, remeshed side by
    /// side ([`pieces`]; default [`pieces::DEFAULT_PIECE_FACES`]; infinite:
    /// never cut). The pieces do not depend on the thread count, but the
    /// grid differs from the whole body's; a cut that leaves zero-area
    /// triangles or changes the bodies is undone (remeshed whole, at twice
    /// the cost).
    pub piece_faces: f64,
}

impl Default for RemeshParams {
    fn default() -> Self {
        RemeshParams {
            target: TargetLength::Relative(0.01),
            feature_angle_deg: 30.0,
            corner_angle_deg: 30.0,
            iterations: 10,
            relax_steps: 2,
            curvature_limit: true,
            n_circle: 24.0,
            min_length_ratio: 0.1,
            line_min_length_ratio: 0.02,
            gradation: 0.3,
            max_normal_turn_deg: 60.0,
            sliver_angle_deg: 10.0,
            fidelity: 0.05,
            piece_faces: pieces::DEFAULT_PIECE_FACES,
        }
    }
}

/// Counts of one iteration.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IterationReport {
    /// Edges split.
    pub splits: usize,
    /// Edges collapsed.
    pub collapses: usize,
    /// Edges flipped.
    pub flips: usize,
    /// Vertices whose relaxation move was cut back (it would have folded a face).
    pub cut_moves: usize,
    /// Vertices after the iteration.
    pub vertices: usize,
    /// Faces after the iteration.
    pub faces: usize,
    /// Seconds spent, summed over the parts (bodies), which run in parallel.
    pub seconds: f64,
}

/// What [`remesh`] did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RemeshReport {
    /// Vertices of the input.
    pub vertices_in: usize,
    /// Faces of the input.
    pub faces_in: usize,
    /// Vertices of the output.
    pub vertices_out: usize,
    /// Faces of the output.
    pub faces_out: usize,
    /// Uniform target length L0 (NaN in size-driven mode).
    pub target_length: f64,
    /// Smallest and largest target length over the output vertices.
    pub target_range: [f64; 2],
    /// Feature edges of the input.
    pub feature_edges_in: usize,
    /// Feature lines (chains of feature edges between corners, or loops).
    pub feature_lines: usize,
    /// Pieces the large bodies were cut into, remeshed side by side
    /// ([`pieces`]; 0 when no body was cut).
    pub pieces: usize,
    /// Smooth patches narrower than half their target length, remeshed from
    /// their rims only (no vertices inside).
    pub thin_patches: usize,
    /// Corners (fixed vertices), counting copies at non-manifold vertices.
    pub corners: usize,
    /// How the input was made manifold for local operations.
    pub build: BuildReport,
    /// One entry per iteration.
    pub iterations: Vec<IterationReport>,
    /// Flips of the final angle clean-up.
    pub final_flips: usize,
    /// Total seconds.
    pub seconds: f64,
    /// What could not be remeshed, and why (empty when everything was).
    pub issues: Vec<String>,
}

/// A remeshed grid and its report.
#[derive(Debug, Clone)]
pub struct Remeshed {
    /// The new grid (no sizes).
    pub grid: Grid,
    /// The feature edges kept (vertex pairs of `grid`): the constrained
    /// polylines along the input's feature lines, boundaries and non-manifold
    /// edges.
    pub feature_edges: Vec<[u32; 2]>,
    /// What was done.
    pub report: RemeshReport,
}

/// Uniform isotropic remeshing of `input` with target length `params.target`
/// (capped by curvature when `params.curvature_limit`). Errors on invalid
/// parameters or when nothing is left.
pub fn remesh(input: &Grid, params: &RemeshParams) -> Result<Remeshed> {
    let diag = input.bbox().diagonal();
    let l0 = match params.target {
        TargetLength::Absolute(l) => l,
        TargetLength::Relative(r) => r * diag,
    };
    if !(l0.is_finite() && l0 > 0.0) {
        return Err(Error::InvalidArgument(format!(
            "target edge length {l0} must be finite and > 0"
        )));
    }
    run(input, None, Some(l0), params, false)
}

/// Size-driven remeshing: the target length at a point is the size `sizing`
/// gives there (its surface query), with no other cap: the result has the
/// elements a mesher following that field would make. `sizing` must carry
/// sizes (it may be `input`).
pub fn remesh_sized(input: &Grid, sizing: &Grid, params: &RemeshParams) -> Result<Remeshed> {
    if sizing.sizes().is_none() {
        return Err(Error::InvalidArgument(
            "the sizing grid has no sizes".into(),
        ));
    }
    run(input, Some(sizing), None, params, false)
}

fn check(params: &RemeshParams) -> Result<()> {
    let within = crate::error::check_range;
    within(params.feature_angle_deg, 0.0, 180.0, "feature_angle_deg")?;
    within(params.corner_angle_deg, 0.0, 180.0, "corner_angle_deg")?;
    within(params.n_circle, 1e-9, 1e9, "n_circle")?;
    within(params.min_length_ratio, 0.0, 1.0, "min_length_ratio")?;
    within(
        params.line_min_length_ratio,
        0.0,
        1.0,
        "line_min_length_ratio",
    )?;
    within(params.gradation, 0.0, 1e9, "gradation")?;
    within(
        params.max_normal_turn_deg,
        0.0,
        180.0,
        "max_normal_turn_deg",
    )?;
    within(params.sliver_angle_deg, 0.0, 60.0, "sliver_angle_deg")?;
    within(params.fidelity, 0.0, 1e9, "fidelity")?;
    if params.piece_faces.is_nan() || params.piece_faces < 1.0 {
        return Err(Error::InvalidArgument(format!(
            "piece_faces = {} must be >= 1 (infinite: never cut)",
            params.piece_faces
        )));
    }
    Ok(())
}

fn run(
    input: &Grid,
    sizing: Option<&Grid>,
    l0: Option<f64>,
    params: &RemeshParams,
    // Remesh the mesh as one, not part by part (the tests' reference).
    whole: bool,
) -> Result<Remeshed> {
    check(params)?;
    let start = Instant::now();
    let features = Features::detect(input, params.feature_angle_deg);
    let base: Vec<f64> = match (l0, sizing) {
        (Some(l), _) => vec![l; input.vertices().len()],
        (None, Some(g)) => input
            .vertices()
            .iter()
            .map(|&p| g.closest(p, None).map_or(f64::INFINITY, |h| h.size))
            .collect(),
        (None, None) => vec![f64::INFINITY; input.vertices().len()],
    };
    let widths = field::patch_widths(input, &features);
    let cap = field::length_cap(
        input,
        &features,
        &widths,
        &field::CapSettings {
            base,
            crease_tolerance: params.fidelity,
            // Size-driven: L = h exactly (h carries its own curvature term).
            curvature: params.curvature_limit && l0.is_some(),
            n_circle: params.n_circle,
            min_ratio: params.min_length_ratio,
            line_min_ratio: params.line_min_length_ratio,
            corner_deg: params.corner_angle_deg,
        },
    );
    // Only caps below the uniform length matter.
    let cap: Vec<field::Source> = cap
        .into_iter()
        .filter(|c| !l0.is_some_and(|l| c.1 >= l))
        .collect();
    let cap = field::SourceField::new(&cap, params.gradation);
    let edge_is_feature: Vec<bool> = features.edge_flags.iter().map(|&f| f != 0).collect();
    let no_lines = reference::FeatureLines::default();
    let sizes = Reference {
        grid: input,
        face_patch: &features.face_patch,
        edge_is_feature: &edge_is_feature,
        thin_patch: &[],
        lines: &no_lines,
        base: l0,
        cap: &cap,
        sizing,
    };
    // Large bodies come apart in pieces along their creases (see `pieces`).
    let vertex_target: Vec<f64> = input
        .vertices()
        .par_iter()
        .map(|&p| sizes.target(p))
        .collect();
    let least = least_target(input, &features, widths.len(), &vertex_target);
    let thin = narrower_than(&widths, &least, THIN_RATIO);
    let cut = params
        .piece_faces
        .is_finite()
        .then(|| {
            let narrow = narrower_than(&widths, &least, pieces::NARROW_RATIO);
            pieces::pieces(
                input,
                &features,
                &narrow,
                &vertex_target,
                params.piece_faces,
            )
        })
        .flatten();
    let (mut mesh, build) =
        HalfedgeMesh::from_grid_cut(input, Some(&features), cut.as_ref().map(|c| &c.piece[..]));
    {
        locked::presplit(
            &mut mesh,
            |p| sizes.target(p),
            input.vertices().len() as u32,
        );
    }
    let (lines, _) = reference::feature_lines(&mut mesh, params.corner_angle_deg);
    let mut reference = Reference {
        grid: input,
        face_patch: &features.face_patch,
        edge_is_feature: &edge_is_feature,
        thin_patch: &[],
        lines: &lines,
        base: l0,
        cap: &cap,
        sizing,
    };
    reference.thin_patch = &thin;
    let thin_patches = thin.iter().filter(|&&x| x).count();
    let lim = Limits {
        cos_turn: params.max_normal_turn_deg.to_radians().cos(),
        sliver_deg: params.sliver_angle_deg,
        fidelity: params.fidelity,
        cos_crease: params.feature_angle_deg.min(20.0).to_radians().cos(),
        scale: 1.0,
    };
    // Sizes of corners (fixed) and everyone else (by projection).
    for v in 0..mesh.n_vertices() {
        mesh.vertex_size[v] = reference.target(mesh.positions[v]);
    }
    smooth::relax_and_project(&mut mesh, &reference, false, lim.cos_turn);

    let mut report = RemeshReport {
        vertices_in: input.vertices().len(),
        faces_in: input.triangles().len(),
        target_length: l0.unwrap_or(f64::NAN),
        feature_edges_in: features.feature_edge_count(),
        feature_lines: lines.line_count as usize,
        pieces: cut.as_ref().map_or(0, |c| c.pieces),
        thin_patches,
        corners: mesh
            .vertices()
            .filter(|&v| mesh.vertex_flags[v as usize] & V_CORNER != 0)
            .count(),
        build,
        ..Default::default()
    };
    // Bodies are parts of their own (the build cut touching ones apart at
    // locked copies): each runs its passes on its own thread, largest first.
    // A part's passes read and write only the part, and it keeps its
    // elements' relative order (see `HalfedgeMesh::into_parts`), so every
    // part comes out as it would in the whole mesh, for any thread count.
    let mesh = if whole {
        let mut mesh = mesh;
        let done = iterate(&mut mesh, &reference, &lim, params);
        report.add(done);
        mesh
    } else {
        // Longest first by the work each will do (its output's size, not
        // its input's: a part of a few long input triangles may become
        // the largest), so the last to finish starts early.
        let mut jobs: Vec<(f64, usize, HalfedgeMesh)> = mesh
            .into_parts()
            .into_iter()
            .enumerate()
            .map(|(i, m)| (expected_faces(&m), i, m))
            .collect();
        jobs.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let mut done: Vec<(usize, HalfedgeMesh, PartReport)> = jobs
            .into_par_iter()
            .with_max_len(1)
            .map(|(_, i, mut m)| {
                let r = iterate(&mut m, &reference, &lim, params);
                (i, m, r)
            })
            .collect();
        done.sort_unstable_by_key(|x| x.0);
        let mut parts = Vec::with_capacity(done.len());
        for (_, m, r) in done {
            parts.push(m);
            report.add(r);
        }
        HalfedgeMesh::from_parts(parts)
    };

    let sizes: Vec<f64> = mesh
        .vertices()
        .map(|v| mesh.vertex_size[v as usize])
        .collect();
    report.target_range = [
        sizes.iter().copied().fold(f64::INFINITY, f64::min),
        sizes.iter().copied().fold(0.0, f64::max),
    ];
    report.issues = issues(&mesh, &report);
    let (verts, tris, map) = mesh.to_arrays(true);
    let feature_edges: Vec<[u32; 2]> = mesh
        .edges()
        .filter(|&e| mesh.edge_flags[e as usize] & crate::mesh::halfedge::E_FEATURE != 0)
        .map(|e| mesh.edge_vertices(e).map(|v| map[v as usize]))
        .collect();
    // The working mesh is done: its memory is not the output grid's peak too.
    drop((mesh, map, sizes));
    let grid = Grid::from_arrays(
        verts,
        tris,
        None,
        &BuildOptions {
            weld_relative_tolerance: None,
            orient: false,
        },
    )?;
    // The safety net of the cut (see `pieces`): a seam that left zero-area
    // triangles or changed the bodies is undone by remeshing whole.
    let bodies = |g: &Grid| g.topology().body_count;
    if cut.is_some() && (grid.report().dropped_zero_area > 0 || bodies(&grid) != bodies(input)) {
        let why = format!(
            "cutting large bodies into {} pieces left {} zero-area triangles and {} bodies \
             (not {}): remeshed whole instead",
            report.pieces,
            grid.report().dropped_zero_area,
            bodies(&grid),
            bodies(input)
        );
        drop(grid);
        let whole_params = RemeshParams {
            piece_faces: f64::INFINITY,
            ..params.clone()
        };
        let mut again = run(input, sizing, l0, &whole_params, whole)?;
        again.report.issues.push(why);
        again.report.seconds = start.elapsed().as_secs_f64();
        return Ok(again);
    }
    if grid.report().dropped_zero_area > 0 {
        report.issues.push(format!(
            "{} zero-area triangles were dropped from the output",
            grid.report().dropped_zero_area
        ));
    }
    report.vertices_out = grid.vertices().len();
    report.faces_out = grid.triangles().len();
    report.seconds = start.elapsed().as_secs_f64();
    Ok(Remeshed {
        grid,
        feature_edges,
        report,
    })
}

/// Coarse levels before the iterations, against the churn of long input
/// needles: at L, a needle of length ℓ and width w ≪ L is split into about
/// 2ℓ/L slivers whose cross edges (length ≈ w) the collapses then remove
/// again. A level at scale s splits only what is longer than 4/3·s·L and
/// lets a collapse of an edge shorter than 4/5·L make edges up to 4/3·s·L
/// (still held to the surface by the unscaled fidelity tolerance), then
/// flips and projects; levels s = 4, then 2. On a mesh already near its
/// target a level splits nothing, and its collapses take the short edges
/// the first iteration would take, and some it would refuse for the
/// longer edges they make (which the iterations then split again). Every
/// part runs both (a per-part choice would make a
/// part's result depend on the rest of the mesh whenever parts are
/// remeshed as one). O(F log F) per level.
fn coarse_levels(mesh: &mut HalfedgeMesh, reference: &Reference, lim: &Limits) {
    for scale in [4.0, 2.0] {
        let level = Limits { scale, ..*lim };
        ops::split_long(mesh, reference, &level);
        ops::collapse_short(mesh, &level);
        ops::repair_flat(mesh, &level, 0.02);
        ops::flip_valence(mesh, &level);
        mesh.compact();
        smooth::relax_and_project(mesh, reference, true, level.cos_turn);
    }
}

/// The faces a remeshed part will have, roughly: its area over the area of
/// an equilateral triangle of the target length, face by face with the
/// mean of the corners' targets (`vertex_size`; a non-finite or zero target
/// counts nothing). A scheduling key only: the parts' work is about linear in
/// their output, while their input faces say little of it (on
/// trimesh_fm1_satellite a part of 6,502 input faces becomes 256,534, one of
/// 22,876 becomes 175,762). O(F).
fn expected_faces(mesh: &HalfedgeMesh) -> f64 {
    mesh.faces()
        .map(|f| {
            let l = mesh
                .face_vertices(f)
                .map(|v| mesh.vertex_size[v as usize])
                .iter()
                .sum::<f64>()
                / 3.0;
            pieces::expected(0.5 * crate::geometry::norm(mesh.face_normal2(f)), l)
        })
        .sum()
}

/// What [`iterate`] did to one part.
struct PartReport {
    iterations: Vec<IterationReport>,
    final_flips: usize,
}

impl RemeshReport {
    /// Adds one part's counts (and seconds) to the report.
    fn add(&mut self, part: PartReport) {
        if self.iterations.len() < part.iterations.len() {
            self.iterations
                .resize(part.iterations.len(), IterationReport::default());
        }
        for (sum, it) in self.iterations.iter_mut().zip(part.iterations) {
            sum.splits += it.splits;
            sum.collapses += it.collapses;
            sum.flips += it.flips;
            sum.cut_moves += it.cut_moves;
            sum.vertices += it.vertices;
            sum.faces += it.faces;
            sum.seconds += it.seconds;
        }
        self.final_flips += part.final_flips;
    }
}

/// The remeshing iterations and the final clean-up of one mesh (a part, or
/// everything), compacted at the end. O(F log F) per iteration.
fn iterate(
    mesh: &mut HalfedgeMesh,
    reference: &Reference,
    lim: &Limits,
    params: &RemeshParams,
) -> PartReport {
    coarse_levels(mesh, reference, lim);
    let mut iterations = Vec::with_capacity(params.iterations);
    for _ in 0..params.iterations {
        let t = Instant::now();
        let splits = ops::split_long(mesh, reference, lim);
        let collapses = ops::collapse_short(mesh, lim);
        let repaired = ops::repair_flat(mesh, lim, 0.02);
        let flips = ops::flip_valence(mesh, lim);
        // Free the slots the collapses left before relaxing: the first
        // iteration's splits of long input needles leave several times the
        // final mesh in slots, and relaxation's per-slot temporaries would
        // come on top. Compaction keeps the order of what lives and
        // relaxation is per vertex, so the result is the same.
        mesh.compact();
        let mut it = IterationReport {
            splits,
            collapses: collapses + repaired,
            flips,
            ..Default::default()
        };
        for k in 0..params.relax_steps.max(1) {
            let relax = params.relax_steps > 0 || k > 0;
            it.cut_moves += smooth::relax_and_project(mesh, reference, relax, lim.cos_turn);
        }
        it.vertices = mesh.vertex_count();
        it.faces = mesh.face_count();
        it.seconds = t.elapsed().as_secs_f64();
        iterations.push(it);
    }
    let mut final_flips = ops::flip_angles(mesh, lim, 3);
    final_flips += ops::repair_flat(mesh, lim, 0.02);
    smooth::relax_and_project(mesh, reference, false, lim.cos_turn);
    mesh.compact();
    PartReport {
        iterations,
        final_flips,
    }
}

/// Patches narrower than this many of their least target lengths (twice the
/// area over the perimeter) are thin: such a strip cannot hold vertices
/// inside (they would sit on its rims and make flat faces), so it is
/// remeshed from its rims only.
const THIN_RATIO: f64 = 0.5;

/// The least target length at the input vertices of each of the `patches`.
/// O(F).
fn least_target(input: &Grid, features: &Features, patches: usize, vt: &[f64]) -> Vec<f64> {
    let mut least = vec![f64::INFINITY; patches];
    for (f, tri) in input.triangles().iter().enumerate() {
        let p = features.face_patch[f] as usize;
        for &i in tri {
            least[p] = least[p].min(vt[i as usize]);
        }
    }
    least
}

/// Patches narrower than `ratio` times their least target length.
fn narrower_than(width: &[f64], least: &[f64], ratio: f64) -> Vec<bool> {
    width
        .iter()
        .zip(least)
        .map(|(&w, &t)| w < ratio * t)
        .collect()
}

/// The list of what was left as it was, and why.
fn issues(mesh: &HalfedgeMesh, report: &RemeshReport) -> Vec<String> {
    let mut out = Vec::new();
    let b = &report.build;
    if b.split_vertices > 0 {
        out.push(format!(
            "{} non-manifold vertices (bodies touching) were split into {} extra copies; \
             they never move",
            b.split_vertices, b.extra_copies
        ));
    }
    // Cuts between pieces are locked too, but merge with no trace.
    let locked = mesh
        .edges()
        .filter(|&e| mesh.edge_flags[e as usize] & (E_LOCKED | E_CUT) == E_LOCKED)
        .count();
    if locked > 0 {
        out.push(format!(
            "{locked} locked edges (non-manifold in the input: bodies touching along them, \
             or orientation seams) were kept as they are"
        ));
    }
    if report.thin_patches > 0 {
        out.push(format!(
            "{} smooth patches are narrower than half the target length (strips): they \
             hold no vertices inside, so their triangles are as long as the strip is narrow",
            report.thin_patches
        ));
    }
    if b.detached_faces > 0 {
        out.push(format!(
            "{} faces conflicting in orientation with a neighbour were kept as they are",
            b.detached_faces
        ));
    }
    let bad = mesh
        .faces()
        .filter(|&f| {
            let [a, bb, c] = mesh.face_vertices(f).map(|v| mesh.positions[v as usize]);
            crate::mesh::shape::min_angle_deg(a, bb, c) < 5.0
        })
        .count();
    if bad > 0 {
        let at_features = mesh
            .faces()
            .filter(|&f| {
                let vs = mesh.face_vertices(f);
                let [a, bb, c] = vs.map(|v| mesh.positions[v as usize]);
                crate::mesh::shape::min_angle_deg(a, bb, c) < 5.0
                    && vs
                        .iter()
                        .all(|&v| mesh.vertex_flags[v as usize] & V_FEATURE != 0)
            })
            .count();
        out.push(format!(
            "{bad} faces have an angle below 5° ({at_features} of them between feature \
             vertices only, where short feature segments or acute corners force them)"
        ));
    }
    out
}

#[cfg(test)]
mod tests;
