//! The simplification loop shared by every scorer (DESIGN §3.5 steps 1–6
//! around the [`super::scorer`] seam), and its unit of parallel work: the
//! *parts* of the mesh.
//!
//! # One iteration
//!
//! [`step`] ranks the edges (the scorer), keeps the best whose closed
//! 1-rings are pairwise disjoint, up to `n·|E|` ([`super::select`]),
//! collapses them, relaxes the kept vertices and flips around them
//! ([`super::repair`]). An iteration that collapses nothing ends the loop.
//!
//! # Parts
//!
//! [`HalfedgeMesh::from_grid`] cuts bodies that touch apart (their shared
//! vertices become locked copies), so the connected parts of the mesh, the
//! bodies of an assembly, never read or write each other: a collapse, a
//! move or a flip changes only the part it is in, and the target it is held
//! to is read-only. When the scorer ranks a part on its own terms
//! ([`EdgeScorer::for_part`]; LBO-ABGS and GCN-ABGS do), each part runs its own
//! iterations with its own scorer, state and `n·|E|` budget, and the parts
//! of one iteration run side by side on the rayon pool, largest first. An
//! iteration ends when every part has done it (the progress callback and the
//! cancel see whole iterations), and a part that collapsed nothing is done.
//! Each part runs exactly as it would as a mesh of its own, so the result
//! does not depend on the thread count; the parts are put back in their
//! order ([`HalfedgeMesh::from_parts`]) before the size fit and the census.
//!
//! What this changes against one loop over the whole mesh: the LBO ranking
//! and the `n·|E|` budget are per body, so a body is not kept waiting for
//! the smoother bodies of the assembly to run out of candidates; GCN-ABGS's
//! forward pass runs on each body's own graph (messages never crossed
//! between bodies, which share no edge, but the model's grid-wide terms are
//! now the body's). A mesh of one part is simplified exactly as one loop
//! over it would (`cmp` on cgal_fandisk and forgescan_abc8). Only the
//! training-data observer, which sees the whole mesh, keeps one loop.
//!
//! Why it pays: within a part the estimates are parallel but the ranking,
//! the claims, the collapses and the flips are sequential, about 40 % of
//! trimesh_fm1_satellite's wall time with one loop on this project's 2-core
//! machine (`perf`: the main thread held 29 % of the samples, the two
//! workers the rest). Parts side by side overlap one part's sequential work
//! with another's. The largest part bounds the gain (its sequential share is
//! the critical path). For GCN-ABGS the model's forward pass, which runs on
//! its caller's thread alone, is about half of the samples (`perf` on
//! gmsh_bracket_assembly): side by side the parts' passes run on every core. Memory: the parts, each about its share of the
//! whole, in place of the whole mesh, plus per part a scorer cache
//! (O(E) of the part).

use super::repair;
use super::scorer::{EdgeScorer, Ranking, Stamps, View};
use super::select;
use super::target::Target;
use super::{own_element_count, Estimate, IterationRecord, Limits, SimplifyParams, StopReason};
use crate::error::Result;
use crate::mesh::halfedge::{HalfedgeMesh, NONE};
use rayon::prelude::*;
use std::time::Instant;

/// What every iteration of every part reads.
pub(super) struct Context<'a> {
    /// The target grid.
    pub target: &'a Target<'a>,
    /// The estimate thresholds.
    pub lim: &'a Limits,
    /// The run's parameters.
    pub params: &'a SimplifyParams,
    /// Cosine of the largest crease a repair flip may make.
    pub cos_crease: f64,
}

/// One mesh the loop simplifies (a part, or everything) with its state
/// between iterations.
struct Piece {
    /// Its place among the parts.
    index: usize,
    /// The mesh.
    mesh: HalfedgeMesh,
    /// When each vertex last changed.
    stamps: Stamps,
    /// One flag per vertex for the ring filter (all false between calls).
    used: Vec<bool>,
    /// A past iteration collapsed nothing.
    done: bool,
    /// The last iteration's record (faces, vertices and element count of
    /// the piece as it is now).
    last: IterationRecord,
}

impl Piece {
    /// `mesh` with fresh state.
    fn new(index: usize, mesh: HalfedgeMesh) -> Piece {
        let n = mesh.n_vertices();
        Piece {
            index,
            mesh,
            stamps: Stamps::new(n),
            used: vec![false; n],
            done: false,
            last: IterationRecord::default(),
        }
    }

    /// What an observer sees of this piece at iteration `it`.
    fn view<'a>(&'a self, cx: &'a Context, it: u32, last: bool) -> View<'a> {
        View {
            mesh: &self.mesh,
            target: cx.target,
            lim: cx.lim,
            params: cx.params,
            stamps: &self.stamps,
            iteration: it,
            last,
        }
    }
}

/// Iteration `it` on `mesh` with `scorer`: rank, select, collapse, repair.
/// The record's `seconds` is left to the caller. O(E log E + C·S log F) for
/// C estimates of S samples (see [`super::scorer`]).
fn step(
    mesh: &mut HalfedgeMesh,
    scorer: &mut dyn EdgeScorer,
    stamps: &mut Stamps,
    used: &mut [bool],
    cx: &Context,
    it: u32,
) -> Result<IterationRecord> {
    let live = mesh.edge_count();
    let view = View {
        mesh,
        target: cx.target,
        lim: cx.lim,
        params: cx.params,
        stamps,
        iteration: it,
        last: false,
    };
    // An empty ranking that is not exhausted means every edge of this
    // pool was found not collapsible: rank again, further on (those are
    // now known), within the same iteration.
    let mut ranking = scorer.rank(&view)?;
    while ranking.ranked.is_empty() && !ranking.exhausted {
        let more = scorer.rank(&view)?;
        ranking = Ranking {
            candidates: ranking.candidates + more.candidates,
            estimated: ranking.estimated + more.estimated,
            ..more
        };
    }
    let ranked_edges: Vec<u32> = ranking.ranked.iter().map(|x| x.0).collect();
    let limit = ((cx.params.fraction * live as f64).floor() as usize).max(1);
    let chosen = select::disjoint_rings(mesh, &ranked_edges, limit, used);
    let mut rec = IterationRecord {
        iteration: it as usize,
        candidates: ranking.candidates,
        estimated: ranking.estimated,
        collapsible: ranking.ranked.len(),
        ..Default::default()
    };
    let by_edge: std::collections::HashMap<u32, Estimate> =
        ranking.ranked.iter().copied().collect();
    let mut kept = Vec::with_capacity(chosen.len());
    for e in &chosen {
        let Some(&est) = by_edge.get(e) else {
            continue;
        };
        let w = mesh.to_vertex(est.halfedge);
        let moved = est.position != mesh.positions[w as usize];
        if mesh.collapse(est.halfedge, est.position).is_err() {
            continue;
        }
        mesh.vertex_size[w as usize] = est.size;
        if est.hint != NONE {
            mesh.vertex_hint[w as usize] = est.hint;
        }
        if moved {
            stamps.mark_moved(mesh, w, it);
        }
        stamps.ring[w as usize] = it;
        for u in mesh.neighbors(w) {
            stamps.ring[u as usize] = it;
        }
        kept.push(w);
        rec.accepted += 1;
    }
    if cx.params.repair && !kept.is_empty() {
        let moved = repair::relax(mesh, cx.target, &kept, cx.lim);
        rec.moved = moved.len();
        for &v in &moved {
            stamps.mark_moved(mesh, v, it);
        }
        let flipped = repair::flip_around(mesh, cx.target, &kept, cx.lim, cx.cos_crease);
        rec.flips = flipped.len() / 4;
        for v in flipped {
            stamps.ring[v as usize] = it;
        }
    }
    rec.faces = mesh.face_count();
    rec.vertices = mesh.vertex_count();
    rec.element_count = own_element_count(mesh);
    Ok(rec)
}

/// What the loop did.
pub(super) struct Looped {
    /// The simplified mesh (parts put back together).
    pub mesh: HalfedgeMesh,
    /// One record per iteration.
    pub iterations: Vec<IterationRecord>,
    /// Why it stopped.
    pub stop: StopReason,
}

/// Runs the iterations on `mesh`: part by part side by side when `scorer`
/// offers a scorer per part and there is no observer, else as one mesh with
/// `scorer` itself (see the module doc). `observer` sees the whole mesh
/// before each iteration's ranking and once more at the end; its error
/// stops the loop.
pub(super) fn run(
    mesh: HalfedgeMesh,
    scorer: &mut dyn EdgeScorer,
    cx: &Context,
    mut progress: Option<&mut dyn FnMut(&IterationRecord) -> bool>,
    mut observer: Option<super::Observer>,
) -> Result<Looped> {
    // One scorer per part, beside the parts; or the whole mesh as one piece
    // with `scorer` itself (`whole`).
    let by_parts = observer.is_none() && scorer.for_part().is_some();
    let (mut pieces, mut scorers, mut whole): (Vec<Piece>, Vec<_>, _) = if by_parts {
        let mut p: Vec<Piece> = mesh
            .into_parts()
            .into_iter()
            .enumerate()
            .map(|(i, m)| Piece::new(i, m))
            .collect();
        p.sort_by_key(|x| (std::cmp::Reverse(x.mesh.n_faces()), x.index));
        let scorer: &dyn EdgeScorer = scorer;
        let s: Vec<Box<dyn EdgeScorer + Send + '_>> =
            p.iter().filter_map(|_| scorer.for_part()).collect();
        (p, s, None)
    } else {
        (vec![Piece::new(0, mesh)], Vec::new(), Some(scorer))
    };
    let mut iterations = Vec::new();
    let mut stop = StopReason::MaxIterations;
    for it in 1..=cx.params.max_iterations as u32 {
        let t = Instant::now();
        let mut rec = IterationRecord {
            iteration: it as usize,
            ..Default::default()
        };
        if let Some(scorer) = whole.as_deref_mut() {
            let p = &mut pieces[0];
            if let Some(obs) = observer.as_mut() {
                obs(&p.view(cx, it, false))?;
            }
            rec = step(&mut p.mesh, scorer, &mut p.stamps, &mut p.used, cx, it)?;
        } else {
            let done: Vec<IterationRecord> = pieces
                .par_iter_mut()
                .zip(scorers.par_iter_mut())
                .with_max_len(1)
                .filter(|(p, _)| !p.done)
                .map(|(p, s)| {
                    let r = step(&mut p.mesh, &mut **s, &mut p.stamps, &mut p.used, cx, it)?;
                    p.done = r.accepted == 0;
                    p.last = r;
                    Ok(r)
                })
                .collect::<Result<_>>()?;
            for r in done {
                rec.candidates += r.candidates;
                rec.estimated += r.estimated;
                rec.collapsible += r.collapsible;
                rec.accepted += r.accepted;
                rec.moved += r.moved;
                rec.flips += r.flips;
            }
            for p in &pieces {
                rec.faces += p.last.faces;
                rec.vertices += p.last.vertices;
                rec.element_count += p.last.element_count;
            }
        }
        rec.seconds = t.elapsed().as_secs_f64();
        iterations.push(rec);
        if rec.accepted == 0 {
            stop = StopReason::Converged;
            break;
        }
        if let Some(cb) = progress.as_mut() {
            if !cb(&rec) {
                stop = StopReason::Cancelled;
                break;
            }
        }
    }
    pieces.sort_unstable_by_key(|p| p.index);
    if let (Some(obs), [p]) = (observer.as_mut(), pieces.as_slice()) {
        obs(&p.view(cx, iterations.len() as u32 + 1, true))?;
    }
    let mut meshes: Vec<HalfedgeMesh> = pieces.into_iter().map(|p| p.mesh).collect();
    let mesh = match meshes.len() {
        // One piece is the mesh itself: no copy.
        1 => meshes.pop().unwrap_or_default(),
        _ => HalfedgeMesh::from_parts(meshes),
    };
    Ok(Looped {
        mesh,
        iterations,
        stop,
    })
}

#[cfg(test)]
mod tests {
    use super::super::{simplify, SimplifyParams};
    use crate::mesh::{BuildOptions, Grid};
    use crate::test_shapes::{canonical_triangles, unit_square};

    /// A triangle soup: vertices and triangles.
    type Soup = (Vec<[f64; 3]>, Vec<[u32; 3]>);
    /// Canonical triangles, and vertex positions with their sizes, as bits.
    type Content = (Vec<[[u64; 3]; 3]>, Vec<([u64; 3], u64)>);

    /// Three wavy sheets of different sizes and shapes, 3 apart in `y`:
    /// each alone, and all three as one grid.
    fn sheets() -> (Vec<Grid>, Grid) {
        let bodies: Vec<Soup> = (0..3)
            .map(|k| {
                let f = 1.0 + k as f64;
                let (v, t) = unit_square(14 + 4 * k, |x, y| {
                    0.08 * (f * 3.0 * x).sin() * (2.0 * y).cos()
                });
                let v = v
                    .into_iter()
                    .map(|p| [p[0], p[1] + 3.0 * k as f64, p[2]])
                    .collect();
                (v, t)
            })
            .collect();
        let size = |p: &[f64; 3]| 0.05 + 0.1 * p[0] + 0.02 * (p[1] - p[1].floor());
        let opts = BuildOptions {
            weld_relative_tolerance: None,
            orient: false,
        };
        let grid = |v: Vec<[f64; 3]>, t: Vec<[u32; 3]>| {
            let s = v.iter().map(size).collect();
            Grid::from_arrays(v, t, Some(s), &opts).expect("valid sheet")
        };
        let alone = bodies
            .iter()
            .map(|(v, t)| grid(v.clone(), t.clone()))
            .collect();
        let (mut v, mut t) = (Vec::new(), Vec::new());
        for (bv, bt) in bodies {
            let o = v.len() as u32;
            v.extend(bv);
            t.extend(bt.into_iter().map(|f| f.map(|i| i + o)));
        }
        (alone, grid(v, t))
    }

    /// The triangles and the vertices' sizes, order-free.
    fn content(g: &Grid) -> Content {
        let sizes = g.sizes().expect("sizes");
        let mut s: Vec<([u64; 3], u64)> = g
            .vertices()
            .iter()
            .zip(sizes)
            .map(|(p, h)| (p.map(f64::to_bits), h.to_bits()))
            .collect();
        s.sort_unstable();
        (canonical_triangles(g.vertices(), g.triangles()), s)
    }

    #[test]
    fn bodies_simplified_side_by_side_are_each_simplified_alone() {
        side_by_side_as_alone(super::super::Method::Lbo);
    }

    /// GCN-ABGS's parts, too: each body's forward pass on its own graph.
    #[cfg(feature = "gcn")]
    #[test]
    fn gcn_bodies_simplified_side_by_side_are_each_simplified_alone() {
        side_by_side_as_alone(super::super::Method::Gcn);
    }

    /// Three sheets simplified as one grid by `method`, with 1 and 3
    /// threads, give each sheet simplified alone: the same triangles and
    /// sizes, and per iteration the sums of the parts' counts.
    fn side_by_side_as_alone(method: super::super::Method) {
        let (alone, whole) = sheets();
        assert_eq!(whole.topology().body_count, 3);
        // Without the size fit: its solver's stop rule reads the whole
        // system (the positions do not depend on it).
        let params = SimplifyParams {
            fit_sizes: false,
            method,
            ..Default::default()
        };
        let run = |g: &Grid, threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool")
                .install(|| simplify(g, &params, None).expect("simplified"))
        };
        let parts: Vec<_> = alone.iter().map(|g| run(g, 1)).collect();
        let mut want = (Vec::new(), Vec::new());
        for p in &parts {
            let (t, s) = content(&p.grid);
            want.0.extend(t);
            want.1.extend(s);
        }
        want.0.sort_unstable();
        want.1.sort_unstable();
        // Per iteration, the parts' counts add up (a finished part adds
        // its faces and nothing else).
        let n = parts.iter().map(|p| p.report.iterations.len()).max();
        let mut iterations: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n.unwrap_or(0)];
        for p in &parts {
            for (k, slot) in iterations.iter_mut().enumerate() {
                let r = &p.report.iterations;
                slot.push(
                    r.get(k)
                        .map_or((0, r[r.len() - 1].faces), |x| (x.accepted, x.faces)),
                );
            }
        }
        for threads in [1, 3] {
            let got = run(&whole, threads);
            assert!(got.report.faces_out < whole.triangles().len() / 4);
            assert_eq!(content(&got.grid), want, "{threads} threads");
            assert_eq!(got.report.iterations.len(), iterations.len());
            for (rec, per) in got.report.iterations.iter().zip(&iterations) {
                let accepted: usize = per.iter().map(|x| x.0).sum();
                let faces: usize = per.iter().map(|x| x.1).sum();
                assert_eq!((rec.accepted, rec.faces), (accepted, faces));
            }
        }
    }
}
