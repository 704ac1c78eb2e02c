//! The scorer seam of the simplification loop (DESIGN §3.5 steps 1–3 and
//! §3.6): which edges an iteration tries to collapse, in which order, and
//! where each collapse puts its kept vertex.
//!
//! Everything else in the loop is shared by every scorer: the 1-ring filter
//! ([`super::select::disjoint_rings`]), the collapses, the local repair, the
//! re-projection of sizes and the stop rule (an iteration that collapses
//! nothing ends the loop). A scorer only ranks: it hands the loop the edges
//! it finds collapsible, best first, each with an [`Estimate`] whose
//! placement (half-edge, position, size, hint) the collapse uses.
//!
//! Implementations, with their cost per iteration (E live edges, C
//! candidates, S samples per accurate estimate, F target faces):
//!
//! - [`Accurate`] (LBO-ABGS): ranks the edges by the LBO of the size field,
//!   estimates the best-ranked `2·n·|E|` exactly as their collapses would go
//!   (sampled sizes and distances, [`super::estimate`]). O(E log E + C·S log F),
//!   with estimates kept until their neighbourhood changes; by default only
//!   the candidates whose rings are still free when their batch comes up
//!   are estimated ([`super::Selection`]).
//! - `gcn::scorer::Learned` (GCN-ABGS): a forward pass of the embedded
//!   graph network predicts every edge's two unit-free errors (kept for the
//!   following iterations where an edge's ring is unchanged); only the
//!   placement and the cheap validity checks (link condition, normal turn,
//!   angles, the removed vertex's distance) are computed, on the best
//!   predictions. O(E·K·D²) per model pass, O(E log E + C·valence²) per
//!   iteration.
//!
//! Both give the same bits for any thread count: parallel work is collected
//! in edge order and ranked with ties broken by edge index.

use super::estimate::{self, Estimate, Limits};
use super::select;
use super::target::Target;
use super::{Selection, SimplifyParams};
use crate::error::Result;
use crate::mesh::halfedge::{HalfedgeMesh, E_LOCKED};
use rayon::prelude::*;

/// What a scorer sees of one iteration: the grid being simplified, the
/// target it must stay faithful to, the thresholds, and when each vertex last
/// changed.
pub struct View<'a> {
    /// The grid being simplified (its current state).
    pub mesh: &'a HalfedgeMesh,
    /// The dense target grid with its patches, lines and envelope.
    pub target: &'a Target<'a>,
    /// The thresholds of one estimate.
    pub lim: &'a Limits,
    /// The run's parameters.
    pub params: &'a SimplifyParams,
    /// When each vertex last changed.
    pub stamps: &'a Stamps,
    /// The iteration (1-based).
    pub iteration: u32,
    /// The loop has ended (an observer's last look at the result).
    pub last: bool,
}

/// A scorer's answer for one iteration.
#[derive(Debug, Clone, Default)]
pub struct Ranking {
    /// Edges to collapse, best first, each with the estimate whose placement
    /// its collapse uses; all collapsible.
    pub ranked: Vec<(u32, Estimate)>,
    /// Edges considered (the candidate pool).
    pub candidates: usize,
    /// Edges estimated or checked afresh this iteration.
    pub estimated: usize,
    /// No edge left out of this ranking can be collapsible as far as the
    /// scorer knows: every edge was either considered or is known not to be
    /// collapsible. An empty ranking that does not hold this is asked for
    /// again within the same iteration (the loop ends only on an empty,
    /// exhausted ranking).
    pub exhausted: bool,
}

/// A strategy that ranks the edges of one iteration (the seam between
/// LBO-ABGS and GCN-ABGS; see the module doc for each one's cost).
pub trait EdgeScorer {
    /// Ranks the edges of `view.mesh` for this iteration. Errors only when
    /// the scorer itself fails (e.g. a model that cannot be run).
    fn rank(&mut self, view: &View) -> Result<Ranking>;

    /// A fresh scorer of the same kind for one part of the mesh (a body cut
    /// apart from the others; the loop's module `simplify::iterate`), when
    /// this scorer ranks a part on its own terms: the loop then simplifies
    /// the parts side by side, each with its own (it may borrow from this
    /// one, a model say). `None` (the default) when its ranking needs the
    /// whole mesh at once: the loop then runs on the whole mesh with this
    /// scorer. Every call must answer alike (all `Some` or all `None`): the
    /// loop asks once per part.
    fn for_part(&self) -> Option<Box<dyn EdgeScorer + Send + '_>> {
        None
    }
}

/// When each vertex last changed, as iteration numbers (0 = never): `ring`
/// (its set of neighbours) and `moved_near` (its or a neighbour's position
/// or size).
pub struct Stamps {
    /// Last iteration that changed its neighbours.
    pub ring: Vec<u32>,
    /// Last iteration that moved the vertex or one of its neighbours of the
    /// time, or changed their size (set by [`Stamps::mark_moved`]).
    pub moved_near: Vec<u32>,
}

impl Stamps {
    /// No vertex of an `n`-vertex mesh changed yet.
    pub fn new(n: usize) -> Stamps {
        Stamps {
            ring: vec![0; n],
            moved_near: vec![0; n],
        }
    }

    /// Vertex `v` moved (or its size changed) at iteration `it`: stamps it
    /// and its neighbours in `moved_near`. O(valence).
    pub fn mark_moved(&mut self, mesh: &HalfedgeMesh, v: u32, it: u32) {
        self.moved_near[v as usize] = it;
        for u in mesh.neighbors(v) {
            self.moved_near[u as usize] = it;
        }
    }

    /// Is an estimate of edge `e` made at iteration `made` still exact? It
    /// reads the faces around the two ends (their rings, and the positions
    /// and sizes of every vertex there) and the valence of the two apexes.
    /// O(1): when neither end's ring changed since `made`, its neighbours
    /// are those it had at every move since, so a move anywhere in the
    /// closed ring of `e` stamped `moved_near` of an end.
    pub fn unchanged(&self, mesh: &HalfedgeMesh, e: u32, made: u32) -> bool {
        let [a, b] = mesh.edge_vertices(e);
        if self.ring[a as usize] >= made || self.ring[b as usize] >= made {
            return false;
        }
        for h in [2 * e, 2 * e + 1] {
            if mesh.face(h) != crate::mesh::halfedge::NONE
                && self.ring[mesh.to_vertex(mesh.next(h)) as usize] >= made
            {
                return false;
            }
        }
        self.moved_near[a as usize] < made && self.moved_near[b as usize] < made
    }
}

/// LBO-ABGS's scorer: LBO ranking, then the accurate estimate of the
/// best-ranked `pool_factor·n·|E|` edges not already known to be
/// non-collapsible. An estimate is kept until a vertex of its closed 1-ring
/// changes, so an unchanged edge is never estimated twice. Memory O(E).
///
/// With [`Selection::Global`] every candidate is estimated and the loop's
/// 1-ring filter takes the lowest scores. On a fine grid nearly every
/// candidate is collapsible but disjoint rings admit only about one in 20
/// (trimesh_fm1_satellite's first iteration: 440,415 estimated, 414,230
/// collapsible, 18,791 collapsed), and the collapses change the
/// neighbourhood of nearly all the others, so they are estimated again next
/// iteration: about 20 estimates per collapse.
///
/// With [`Selection::Batched`] (the default) the pool is walked in LBO order
/// in batches of [`batch_size`] edges; an edge whose closed 1-ring meets one
/// already claimed this iteration is skipped unestimated, the rest of the
/// batch is estimated in parallel, and its collapsible edges claim their
/// rings lowest score first. Estimates are then spent on edges that can
/// still be chosen; occt_crankarm's first iteration estimates 1,394 edges
/// for 940 collapses, against 17,396 for 966. The choice differs from the
/// global one only in which of two overlapping collapses goes first (LBO
/// order between batches, the score within one). The claims mark the
/// claimed rings and their neighbours, so whether an edge's ring is free is
/// two reads (its ends), not a walk around its ring.
#[derive(Debug, Default)]
pub struct Accurate {
    cache: Vec<Option<(u32, Estimate)>>,
}

/// Most edges of the pool handled per batch by [`Selection::Batched`]:
/// enough parallel work for any thread count (a batch's estimates take tens
/// of milliseconds on the big shared models), few against a large pool, so
/// that little is estimated before the claims of the batches ahead of it.
pub const BATCH: usize = 512;

/// Fewest edges per batch (see [`batch_size`]).
pub const MIN_BATCH: usize = 32;

/// Edges per batch for a pool of `pool_size` edges: a 1024th of the pool,
/// within [`MIN_BATCH`]..=[`BATCH`]. A batch's edges are all estimated
/// before any of them claims its ring, and the pool's edges lie close
/// together (the smoothest fifth of a part), so a batch that is a large
/// share of the pool estimates many edges that its own claims then block.
/// trimesh_fm1_satellite's simplification made 5.90 M estimates with 512
/// always, 4.55 M with a 64th and 4.29 M with a 1024th of the pool. A
/// function of the pool alone, so the choice does not depend on the thread
/// count.
pub fn batch_size(pool_size: usize) -> usize {
    (pool_size / 1024).clamp(MIN_BATCH, BATCH)
}

/// Lowest score first, ties by edge index.
fn by_score(a: &(u32, Estimate), b: &(u32, Estimate)) -> std::cmp::Ordering {
    a.1.y.total_cmp(&b.1.y).then(a.0.cmp(&b.0))
}

impl Accurate {
    /// Estimates `edges` in parallel and keeps the estimates, stamped with
    /// this iteration.
    fn estimate_afresh(&mut self, view: &View, edges: &[u32]) {
        let estimates: Vec<Estimate> = edges
            .par_iter()
            .map(|&e| estimate::estimate(view.mesh, view.target, e, view.lim, 0.5))
            .collect();
        for (&e, est) in edges.iter().zip(estimates) {
            self.cache[e as usize] = Some((view.iteration, est));
        }
    }

    /// The collapsible ones of `edges` by their kept estimates, lowest score
    /// first (see [`by_score`]).
    fn collapsible(&self, edges: impl Iterator<Item = u32>) -> Vec<(u32, Estimate)> {
        let mut out: Vec<(u32, Estimate)> = edges
            .filter_map(|e| {
                let (_, est) = self.cache[e as usize]?;
                est.collapsible().then_some((e, est))
            })
            .collect();
        out.sort_by(by_score);
        out
    }

    /// [`Selection::Batched`] over `pool` (see [`Accurate`]). The edges
    /// returned have pairwise disjoint closed 1-rings, lowest score first.
    /// O(Σ ring sizes + estimates).
    fn rank_batched(&mut self, view: &View, pool: &[(u32, bool)], pool_size: usize) -> Ranking {
        let mesh = view.mesh;
        // The claimed rings and every neighbour of them: the closed ring of
        // an edge meets a claimed ring exactly when one of its two ends is
        // in here (adjacency is symmetric), so a check is two reads.
        let mut blocked = vec![false; mesh.n_vertices()];
        let mut ranked: Vec<(u32, Estimate)> = Vec::new();
        let mut estimated = 0;
        let mut ring = Vec::new();
        let free = |e: u32, blocked: &[bool]| {
            let [a, b] = mesh.edge_vertices(e);
            !blocked[a as usize] && !blocked[b as usize]
        };
        for batch in pool.chunks(batch_size(pool_size)) {
            let mut open = Vec::with_capacity(batch.len());
            let mut fresh = Vec::new();
            for &(e, stale) in batch {
                if free(e, &blocked) {
                    open.push(e);
                    if stale {
                        fresh.push(e);
                    }
                }
            }
            self.estimate_afresh(view, &fresh);
            estimated += fresh.len();
            for (e, est) in self.collapsible(open.iter().copied()) {
                if free(e, &blocked) {
                    select::closed_ring(mesh, e, &mut ring);
                    for &v in &ring {
                        blocked[v as usize] = true;
                        for u in mesh.neighbors(v) {
                            blocked[u as usize] = true;
                        }
                    }
                    ranked.push((e, est));
                }
            }
        }
        ranked.sort_by(by_score);
        Ranking {
            ranked,
            candidates: pool.len(),
            estimated,
            exhausted: pool.len() < pool_size || estimated == 0,
        }
    }
}

impl EdgeScorer for Accurate {
    /// LBO-ABGS ranks each part by its own LBO order and budget.
    fn for_part(&self) -> Option<Box<dyn EdgeScorer + Send + '_>> {
        Some(Box::new(Accurate::default()))
    }

    fn rank(&mut self, view: &View) -> Result<Ranking> {
        let mesh = view.mesh;
        if self.cache.len() < mesh.n_edges() {
            self.cache.resize(mesh.n_edges(), None);
        }
        let live = mesh.edge_count();
        let lbo = select::edge_lbo(mesh);
        // Keys beside the edges: the sort reads them in place (a total
        // order, ties by edge index, so an unstable sort gives the one order).
        let mut order: Vec<(f64, u32)> = mesh
            .edges()
            .filter(|&e| mesh.edge_flags[e as usize] & E_LOCKED == 0)
            .map(|e| (lbo[e as usize], e))
            .collect();
        order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let p = view.params;
        let pool_size = (p.pool_factor * p.fraction * live as f64).ceil() as usize;
        // The pool, each edge with whether its estimate must be made afresh.
        let mut pool = Vec::with_capacity(pool_size);
        for (_, e) in order {
            if pool.len() >= pool_size {
                break;
            }
            let known =
                self.cache[e as usize].filter(|(made, _)| view.stamps.unchanged(mesh, e, *made));
            match known {
                Some((_, est)) if !est.collapsible() => continue,
                Some(_) => pool.push((e, false)),
                None => pool.push((e, true)),
            }
        }
        if p.selection == Selection::Batched {
            return Ok(self.rank_batched(view, &pool, pool_size));
        }
        let fresh: Vec<u32> = pool.iter().filter(|x| x.1).map(|x| x.0).collect();
        self.estimate_afresh(view, &fresh);
        let ranked = self.collapsible(pool.iter().map(|x| x.0));
        Ok(Ranking {
            ranked,
            candidates: pool.len(),
            estimated: fresh.len(),
            exhausted: pool.len() < pool_size || fresh.is_empty(),
        })
    }
}
