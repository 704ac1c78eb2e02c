//! GCN-ABGS's scorer (DESIGN §3.6): the model predicts every edge's two
//! unit-free errors in one forward pass; the loop's thresholds turn them
//! into scores, and only the best predictions get the cheap exact checks.
//!
//! The loop runs one such scorer per part of the mesh (each body of an
//! assembly, side by side: [`EdgeScorer::for_part`]), so "the grid" below is
//! the part's. Per iteration:
//! 1. [`super::features::graph`] of the current grid, one forward pass:
//!    `p = (Δs − 1, Δd / h_loc)` per edge;
//! 2. the predicted score `ŷ = min(1, ½·max(p₀/(T_size − 1), p₁·h_loc/a_e,
//!    p₁·h_loc/max_distance))`, with `a_e` the distance envelope at the
//!    edge ([`edge_allowance`]): the same formula as the accurate score, so
//!    `T_size`, `β`, `κ` and `max_distance` stay run-time parameters;
//! 3. edges with `ŷ < T_score`, lowest first (ties by edge index), at most
//!    `pool_factor·n·|E|` of them, go through the shared 1-ring filter
//!    *before* they are checked, in rounds: each round the filter picks edges
//!    whose closed rings are disjoint from each other and from those already
//!    accepted, and only those get a light exact check — the placement and
//!    validity checks of the accurate estimate (link condition, feature
//!    rules, normal turn, largest angle, the removed vertex's exact distance
//!    to the new faces) and its size and distance test on the coarsest
//!    lattice, 6 samples per new triangle ([`Limits::light`],
//!    [`estimate::LIGHT_DIVISIONS`]), instead of samples about `h_min/2`
//!    apart (up to 105); with `verify`, the full accurate estimate. An edge that
//!    fails frees its ring for the next round; rounds end at `n·|E|` accepted
//!    edges or when no candidate is free. (Checking the whole pool first
//!    wasted nine checks in ten on CAD grids, where the rings of the accepted
//!    edges block most of the pool. Without the light samples, confident
//!    mistakes of the model at the end of a run went through: on
//!    occt_crankarm size deviation max 3.4 and −9.8 % elements against
//!    LBO-ABGS's 1.24 and −1 %.)
//!
//! 4. the tail: when step 3 accepts nothing (no edge predicted below
//!    `T_score`, or every such edge refused), the edges with
//!    `T_score ≤ ŷ < 1` ([`TAIL_SCORE`]: not predicted at least twice over a
//!    limit) go through the same rounds, lowest `ŷ` first, under the full
//!    accurate estimate: the model only ranks them, the estimate decides.
//!
//! **Reuse.** A forward pass's predictions serve later iterations too, for
//! every edge whose closed 1-ring has not changed since
//! ([`crate::simplify::Stamps::unchanged`], the rule that keeps LBO-ABGS's
//! estimates); an edge whose ring changed waits for the next pass. The model
//! runs again when more than [`Learned::stale_share`] of the edges wait, or
//! when the edges still predicted give no collapse (before the tail, or
//! before the loop would end). The prediction of an unchanged edge also
//! reads the grid two and three rings out, which may have changed: it is
//! then a ranking a little out of date, and the exact checks still decide.
//! Why: the 1-ring filter lets one iteration collapse only a few per cent of
//! the edges, so a pass per iteration ran the model over the whole grid
//! some hundred times (occt_crankarm: 182 passes over its two bodies for 102
//! iterations, 18.4 s of model time in a 15.1 s run; with reuse 104 passes,
//! 10.8 s, same face count within 2 %, size deviation p95 1.127 for 1.127).
//!
//! An edge the checks refuse is not checked again until its neighbourhood
//! changes. The loop then applies the shared 1-ring filter and collapses. The
//! loop ends when neither stage accepts an edge (every candidate of both was
//! refused and nothing around it changed). Why the tail: the model is
//! conservative on nearly converged grids (held-out precision 0.42 and recall
//! 0.79 at the last snapshot of the LBO-ABGS runs, `models/MODEL_CARD.md`),
//! and without the tail GCN-ABGS stopped with 26–59 % more faces than
//! LBO-ABGS on 4 of the 14 shared models under 1M faces, where LBO-ABGS goes
//! on for 140–175 iterations of small batches. The tail costs accurate
//! estimates only on a grid already an order of magnitude coarser than the
//! dense one ([`Learned::tail`] turns it off).
//!
//! Cost per forward pass: the features O(F + E + N·K), the model
//! O(E·D² + N·K·D) for hidden width D; per iteration O(E) for the reuse
//! test, and the checks O(C·(valence² + valence·log F)) for C ≤ pool edges (with
//! `verify`, and in the tail, O(C·S log F)). Deterministic: the model runs single-threaded on
//! inputs that do not depend on the thread count, the checks are collected
//! in edge order.

use super::features::graph;
use super::runtime::Model;
use crate::error::Result;
use crate::mesh::halfedge::{HalfedgeMesh, E_LOCKED};
use crate::simplify::estimate::{self, Estimate, Limits};
use crate::simplify::scorer::{EdgeScorer, Ranking, View};
use crate::simplify::select;
use crate::simplify::Target;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::Arc;

/// The distance envelope at edge `e` in model units: the smaller of the
/// envelopes at the target triangles its two ends were projected from, for
/// `h_loc` the smaller size at the ends. O(1).
pub fn edge_allowance(mesh: &HalfedgeMesh, target: &Target, e: u32, lim: &Limits) -> f64 {
    let [a, b] = mesh.edge_vertices(e);
    let h_loc = mesh.vertex_size[a as usize].min(mesh.vertex_size[b as usize]);
    [a, b]
        .map(|v| target.allowance(mesh.vertex_hint[v as usize], h_loc, h_loc, lim))
        .into_iter()
        .fold(f64::INFINITY, f64::min)
}

/// The predicted score of an edge from the model's `(Δs − 1, Δd / h_loc)`,
/// by the accurate score's own formula ([`estimate::score`]).
pub fn predicted_score(p: [f32; 2], h_loc: f64, allowance: f64, lim: &Limits) -> f64 {
    let ds = 1.0 + p[0].max(0.0) as f64;
    let dd = p[1].max(0.0) as f64 * h_loc;
    let de = if allowance > 0.0 {
        dd / allowance
    } else {
        f64::INFINITY
    };
    estimate::score(ds, de, dd, lim)
}

/// GCN-ABGS's scorer over a loaded model (see the module doc).
pub struct Learned<'m> {
    model: &'m Model,
    /// Per edge slot: the iteration whose checks refused it (0 = none); it
    /// is not checked again until its neighbourhood changes.
    refused: Vec<u32>,
    ring: Vec<u32>,
    /// Per vertex slot: inside the closed ring of an accepted edge (scratch,
    /// all false between calls).
    used: Vec<bool>,
    /// Forward-pass time and tail estimates, shared with the scorers of the
    /// parts ([`Learned::model_seconds`], [`Learned::tail_checks`]).
    tally: Arc<Tally>,
    /// Run the tail (stage 2, see the module doc) when the model's own
    /// choices run out (default true; false ends the loop there, as the
    /// paper's GCN-ABGS does).
    pub tail: bool,
    /// Per edge slot: the predicted score `ŷ` of the last forward pass
    /// (∞ where none), kept across iterations ([`Learned::stale_share`]).
    y: Vec<f64>,
    /// The iteration of the last forward pass (0 = none yet).
    predicted_at: u32,
    /// Largest share of the live edges (counted with the locked ones, which
    /// are never candidates) whose prediction may be stale (an unlocked edge
    /// whose closed ring changed since the last forward pass) before an
    /// iteration runs the model again (default [`STALE_SHARE`]; 0 runs
    /// it every iteration).
    pub stale_share: f64,
}

/// What the scorers of one run count, summed over its parts.
#[derive(Debug, Default)]
struct Tally {
    model_nanos: AtomicU64,
    tail_checks: AtomicUsize,
    passes: AtomicUsize,
}

/// The tail's upper bound on the predicted score: `ŷ` is clamped to 1, so
/// the tail tries every edge the model does not predict at least twice over
/// a limit (`ŷ = ½·max(error / limit)`).
pub const TAIL_SCORE: f64 = 1.0;

/// Default [`Learned::stale_share`]: the model runs again once nine edges in
/// ten have changed around them since its last pass (see the module doc,
/// *Reuse*). One iteration's collapses change the rings of about half of
/// the edges on a fine grid, so a lower share (0.25, 0.5 tried) still ran
/// the model nearly every iteration (occt_crankarm: 157 and 148 passes
/// against 182); 1.0 (a pass only when no current prediction is left) saved
/// a little more (88) but let Hausdorff grow by a third there (0.99 % of the
/// diagonal against 0.75 %).
pub const STALE_SHARE: f64 = 0.9;

impl<'m> Learned<'m> {
    /// A scorer running `model`.
    pub fn new(model: &'m Model) -> Learned<'m> {
        Learned {
            model,
            refused: Vec::new(),
            ring: Vec::new(),
            used: Vec::new(),
            tally: Arc::default(),
            tail: true,
            y: Vec::new(),
            predicted_at: 0,
            stale_share: STALE_SHARE,
        }
    }

    /// Seconds spent in the forward passes (features included) by this
    /// scorer and the scorers of its parts, summed over the parts.
    pub fn model_seconds(&self) -> f64 {
        self.tally.model_nanos.load(Ordering::Relaxed) as f64 * 1e-9
    }

    /// Accurate estimates made in the tail so far, by this scorer and the
    /// scorers of its parts.
    pub fn tail_checks(&self) -> usize {
        self.tally.tail_checks.load(Ordering::Relaxed)
    }

    /// Forward passes made so far, by this scorer and the scorers of its
    /// parts.
    pub fn passes(&self) -> usize {
        self.tally.passes.load(Ordering::Relaxed)
    }

    /// Predicted scores `ŷ` for every edge slot of `view.mesh` (∞ for
    /// removed edges). One forward pass.
    pub fn predict(&mut self, view: &View) -> Result<Vec<f64>> {
        let t = std::time::Instant::now();
        let mesh = view.mesh;
        let g = graph(mesh)?;
        let pred = self.model.predict(&g.inputs)?;
        let mut y = vec![f64::INFINITY; mesh.n_edges()];
        let scored: Vec<f64> = g
            .edges
            .par_iter()
            .zip(pred.par_iter())
            .map(|(&e, &p)| {
                let [a, b] = mesh.edge_vertices(e);
                let h_loc = mesh.vertex_size[a as usize].min(mesh.vertex_size[b as usize]);
                let allow = edge_allowance(mesh, view.target, e, view.lim);
                predicted_score(p, h_loc, allow, view.lim)
            })
            .collect();
        for (&e, s) in g.edges.iter().zip(scored) {
            y[e as usize] = s;
        }
        let nanos = t.elapsed().as_nanos().min(u64::MAX as u128) as u64;
        self.tally.model_nanos.fetch_add(nanos, Ordering::Relaxed);
        Ok(y)
    }
}

impl EdgeScorer for Learned<'_> {
    /// GCN-ABGS, too, simplifies the parts of a mesh side by side: the model
    /// runs on each part's own graph (the bodies of an assembly share no
    /// edge, so a part's messages never cross to another; its global terms,
    /// the mean pool and the mean edge length, are then the part's), each
    /// part on a session of its own ([`Model`]).
    fn for_part(&self) -> Option<Box<dyn EdgeScorer + Send + '_>> {
        let mut part = Learned::new(self.model);
        part.tail = self.tail;
        part.stale_share = self.stale_share;
        part.tally = Arc::clone(&self.tally);
        Some(Box::new(part))
    }

    fn rank(&mut self, view: &View) -> Result<Ranking> {
        let mesh = view.mesh;
        if self.refused.len() < mesh.n_edges() {
            self.refused.resize(mesh.n_edges(), 0);
        }
        // Reuse: the last pass's predictions serve the edges whose closed
        // ring has not changed since, until too many have.
        let stale = self.stale_edges(view);
        let live = mesh.edge_count().max(1);
        if self.predicted_at == 0 || stale as f64 > self.stale_share * live as f64 {
            self.refresh(view)?;
        }
        let out = self.stages(view);
        if out.ranked.is_empty() && self.predicted_at < view.iteration && stale > 0 {
            // Nothing among the edges still predicted: predict the changed
            // ones too before the tail or the end.
            self.refresh(view)?;
            return Ok(self.stages(view));
        }
        Ok(out)
    }
}

impl Learned<'_> {
    /// Runs the model on the whole grid (part) and keeps its predictions,
    /// stamped with this iteration.
    fn refresh(&mut self, view: &View) -> Result<()> {
        self.y = self.predict(view)?;
        self.predicted_at = view.iteration;
        self.tally.passes.fetch_add(1, Ordering::Relaxed);
        Ok(())
    }

    /// Is the prediction of live edge `e` current: made at this iteration,
    /// or its closed ring unchanged since ([`crate::simplify::Stamps::unchanged`])?
    fn current(&self, view: &View, e: u32) -> bool {
        self.predicted_at == view.iteration
            || (self.predicted_at != 0 && view.stamps.unchanged(view.mesh, e, self.predicted_at))
    }

    /// Live unlocked edges whose prediction is not current. O(E).
    fn stale_edges(&self, view: &View) -> usize {
        let mesh = view.mesh;
        mesh.edges()
            .filter(|&e| mesh.edge_flags[e as usize] & E_LOCKED == 0 && !self.current(view, e))
            .count()
    }

    /// Stage 1, then the tail if stage 1 found nothing (see the module doc).
    fn stages(&mut self, view: &View) -> Ranking {
        let y = std::mem::take(&mut self.y);
        let out = self.stages_with(view, &y);
        self.y = y;
        out
    }

    /// [`Self::stages`] over the predictions `y`.
    fn stages_with(&mut self, view: &View, y: &[f64]) -> Ranking {
        let p = view.params;
        // Stage 1: the model's choices (ŷ < T_score), light checks.
        let light = Limits {
            light: !p.verify,
            ..*view.lim
        };
        let first = self.stage(view, y, f64::NEG_INFINITY, p.t_score, &light);
        if !first.ranked.is_empty() || !first.exhausted || !self.tail {
            return first;
        }
        // Stage 2, the tail: the model only ranks (T_score ≤ ŷ < 1), the
        // accurate estimate decides.
        let exact = Limits {
            light: false,
            ..*view.lim
        };
        let tail = self.stage(view, y, p.t_score, TAIL_SCORE, &exact);
        self.tally
            .tail_checks
            .fetch_add(tail.estimated, Ordering::Relaxed);
        Ranking {
            candidates: first.candidates + tail.candidates,
            estimated: first.estimated + tail.estimated,
            ..tail
        }
    }

    /// One stage of [`EdgeScorer::rank`]: the unlocked edges with
    /// `lo ≤ ŷ < hi` not refused since their neighbourhood last changed,
    /// lowest `ŷ` first (ties by edge index), at most `pool_factor·n·|E|` of
    /// them, selected and checked under `lim` by [`Self::select_checked`].
    fn stage(&mut self, view: &View, y: &[f64], lo: f64, hi: f64, lim: &Limits) -> Ranking {
        let mesh = view.mesh;
        let p = view.params;
        let mut order: Vec<(f64, u32)> = Vec::new();
        for e in mesh.edges() {
            let ye = y.get(e as usize).copied().unwrap_or(f64::INFINITY);
            if mesh.edge_flags[e as usize] & E_LOCKED != 0
                || ye < lo
                || ye >= hi
                || !self.current(view, e)
            {
                continue;
            }
            let made = self.refused[e as usize];
            if made != 0 && view.stamps.unchanged(mesh, e, made) {
                continue;
            }
            order.push((ye, e));
        }
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let pool = (p.pool_factor * p.fraction * mesh.edge_count() as f64).ceil() as usize;
        let exhausted = order.len() <= pool;
        order.truncate(pool);
        let limit = ((p.fraction * mesh.edge_count() as f64).floor() as usize).max(1);
        let mut pending: Vec<u32> = order.iter().map(|x| x.1).collect();
        let (ranked, checked) = self.select_checked(view, lim, &mut pending, limit);
        Ranking {
            ranked,
            candidates: order.len(),
            estimated: checked,
            // Every candidate was checked or blocked by an accepted edge's
            // ring; with nothing accepted, every candidate was refused.
            exhausted: exhausted || checked == order.len(),
        }
    }

    /// Selection before checking: rounds of the shared greedy 1-ring filter
    /// over the `pending` edges (best prediction first), each round checking
    /// only the edges it chose (in parallel) and keeping the rings of those
    /// that pass; a refused edge frees its ring for the next round, and is
    /// remembered as refused. Ends when `limit` edges passed or no pending
    /// edge is free. Returns the accepted edges in edge order (pairwise
    /// disjoint closed rings, so the loop's filter keeps them all) and the
    /// number of checks. Checks O(accepted + refused) instead of the whole
    /// pool: about a tenth of the pool on CAD grids, where rings block most
    /// of it.
    fn select_checked(
        &mut self,
        view: &View,
        lim: &Limits,
        pending: &mut Vec<u32>,
        limit: usize,
    ) -> (Vec<(u32, Estimate)>, usize) {
        let mesh = view.mesh;
        if self.used.len() < mesh.n_vertices() {
            self.used.resize(mesh.n_vertices(), false);
        }
        let mut accepted: Vec<(u32, Estimate)> = Vec::new();
        let mut kept_marks: Vec<u32> = Vec::new();
        let mut checks = 0;
        while accepted.len() < limit && !pending.is_empty() {
            // Edges free of the accepted rings, greedily disjoint among
            // themselves; the rest wait for the next round.
            let chosen =
                select::disjoint_rings(mesh, pending, limit - accepted.len(), &mut self.used);
            if chosen.is_empty() {
                break;
            }
            let results: Vec<Estimate> = chosen
                .par_iter()
                .map(|&e| estimate::estimate(mesh, view.target, e, lim, 0.5))
                .collect();
            checks += chosen.len();
            for (&e, est) in chosen.iter().zip(results) {
                if est.collapsible() {
                    select::closed_ring(mesh, e, &mut self.ring);
                    for &v in &self.ring {
                        self.used[v as usize] = true;
                        kept_marks.push(v);
                    }
                    accepted.push((e, est));
                } else {
                    self.refused[e as usize] = view.iteration;
                }
            }
            let done: std::collections::HashSet<u32> = chosen.into_iter().collect();
            pending.retain(|e| !done.contains(e));
        }
        for v in kept_marks {
            self.used[v as usize] = false;
        }
        accepted.sort_by_key(|&(e, _)| e);
        (accepted, checks)
    }
}
