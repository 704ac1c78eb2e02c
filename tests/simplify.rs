//! LBO-ABGS on synthetic shapes: after every iteration no flipped or
//! degenerate face, Euler characteristic, bodies, corners and feature lines
//! kept; a sharp size front is not smeared (banding); the same bits with 1
//! and 2 threads, with either selection; the batched selection estimates
//! less for a grid as good as the global one's; cancelling from the
//! callback leaves a valid grid; the per-edge scores agree with their
//! definition; the size fit removes the interpolation's bias on a graded
//! field.

mod common;

use abgs::geometry::{cross, dot, norm, sub};
use abgs::simplify::{
    edge_scores, simplify, IterationRecord, Selection, SimplifyParams, StopReason,
};
use abgs::Grid;
use common::shapes::{icosphere, Soup};
use common::{euler, with_sizes};

/// Checks `out` against the dense `dense`: no degenerate face, each face's
/// normal within 60° of the dense surface's there, same Euler characteristic
/// and bodies, and every point of `keep` still a vertex.
fn assert_valid(name: &str, dense: &Grid, out: &Grid, keep: &[[f64; 3]]) {
    assert_eq!(
        out.report().dropped_zero_area,
        0,
        "{name}: degenerate faces"
    );
    assert_eq!(euler(out), euler(dense), "{name}: Euler characteristic");
    assert_eq!(
        out.topology().body_count,
        dense.topology().body_count,
        "{name}: bodies"
    );
    let (v, dt) = (out.vertices(), dense.triangles());
    for t in out.triangles() {
        let [a, b, c] = t.map(|i| v[i as usize]);
        let n = cross(sub(b, a), sub(c, a));
        assert!(norm(n) > 0.0, "{name}: degenerate face");
        let centroid = [
            (a[0] + b[0] + c[0]) / 3.0,
            (a[1] + b[1] + c[1]) / 3.0,
            (a[2] + b[2] + c[2]) / 3.0,
        ];
        let hit = dense.closest(centroid, None).unwrap();
        let [p, q, r] = dt[hit.triangle as usize].map(|i| dense.vertices()[i as usize]);
        let m = cross(sub(q, p), sub(r, p));
        assert!(
            dot(n, m) >= 0.5 * norm(n) * norm(m),
            "{name}: a face turned by more than 60° (flipped)"
        );
    }
    for k in keep {
        assert!(
            v.iter().any(|p| p == k),
            "{name}: corner {k:?} is gone or moved"
        );
    }
}

/// Runs with `max_iterations` = 1, 2, … until convergence (the run is
/// deterministic, so each is the state after that many iterations of the
/// full run) and checks every state. Returns the converged result.
fn check_every_iteration(
    name: &str,
    dense: &Grid,
    keep: &[[f64; 3]],
) -> abgs::simplify::Simplified {
    let mut last_faces = usize::MAX;
    for k in 1..200 {
        let params = SimplifyParams {
            max_iterations: k,
            ..Default::default()
        };
        let s = simplify(dense, &params, None).unwrap();
        assert_valid(
            &format!("{name} after {k} iterations"),
            dense,
            &s.grid,
            keep,
        );
        assert!(s.grid.triangles().len() <= last_faces);
        last_faces = s.grid.triangles().len();
        if s.report.stop == StopReason::Converged {
            return s;
        }
    }
    panic!("{name}: did not converge");
}

fn box_grid(n: usize, lo: [f64; 3], hi: [f64; 3]) -> Soup {
    let mut s = Soup::default();
    s.boxed(lo, hi, n, false, false);
    s
}

fn corners(lo: [f64; 3], hi: [f64; 3]) -> Vec<[f64; 3]> {
    let mut c = Vec::new();
    for i in 0..8 {
        c.push([
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]);
    }
    c
}

#[test]
fn box_keeps_corners_edges_and_topology_after_every_iteration() {
    let (lo, hi) = ([0.0; 3], [1.0, 0.8, 0.6]);
    let dense = with_sizes(&box_grid(10, lo, hi).grid(), |p| 0.05 + 0.2 * p[0]);
    let s = check_every_iteration("box", &dense, &corners(lo, hi));
    let r = 1.0 - s.grid.triangles().len() as f64 / dense.triangles().len() as f64;
    assert!(r > 0.5, "box: reduction {r}");
    // Feature lines: every dense feature edge's midpoint lies on an output
    // edge that is sharp too.
    let out = &s.grid;
    let feats = abgs::mesh::Features::detect(out, 30.0);
    let dfeats = abgs::mesh::Features::detect(&dense, 30.0);
    let sharp: Vec<[[f64; 3]; 2]> = out
        .topology()
        .edges
        .iter()
        .enumerate()
        .filter(|(e, _)| feats.is_feature(*e))
        .map(|(_, e)| e.map(|i| out.vertices()[i as usize]))
        .collect();
    for (e, ends) in dense.topology().edges.iter().enumerate() {
        if !dfeats.is_feature(e) {
            continue;
        }
        let [a, b] = ends.map(|i| dense.vertices()[i as usize]);
        let m = [
            (a[0] + b[0]) / 2.0,
            (a[1] + b[1]) / 2.0,
            (a[2] + b[2]) / 2.0,
        ];
        let d = sharp
            .iter()
            .map(|s| {
                let t = abgs::geometry::closest_point_on_segment(m, s[0], s[1]);
                norm(sub(m, abgs::geometry::lerp(s[0], s[1], t)))
            })
            .fold(f64::INFINITY, f64::min);
        assert!(d < 1e-12, "box: feature line moved by {d}");
    }
    assert!(feats.feature_edge_count() > 0);
}

#[test]
fn sphere_and_two_bodies_keep_topology_after_every_iteration() {
    let sphere = icosphere(1.0, 3);
    let dense = with_sizes(&sphere, |p| 0.15 + 0.1 * p[2]);
    let s = check_every_iteration("sphere", &dense, &[]);
    assert!(s.grid.triangles().len() < dense.triangles().len());
    // Two boxes 0.1 apart: never merged.
    let mut soup = box_grid(6, [0.0; 3], [1.0; 3]);
    soup.boxed([1.1, 0.0, 0.0], [2.1, 1.0, 1.0], 6, false, false);
    let dense = with_sizes(&soup.grid(), |_| 0.3);
    assert_eq!(dense.topology().body_count, 2);
    let mut keep = corners([0.0; 3], [1.0; 3]);
    keep.extend(corners([1.1, 0.0, 0.0], [2.1, 1.0, 1.0]));
    check_every_iteration("two boxes", &dense, &keep);
}

/// Sizes 0.02 left of x = 0.5 and 0.1 right of x = 0.52 (a front far steeper
/// than any gradation): coarsening must not smear it.
#[test]
fn sharp_size_front_is_not_smeared() {
    let mut soup = Soup::default();
    soup.quad([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 80, 80);
    let front = |p: [f64; 3]| {
        let t = ((p[0] - 0.5) / 0.02).clamp(0.0, 1.0);
        0.02 + t * 0.08
    };
    let dense = with_sizes(&soup.grid(), front);
    let s = simplify(&dense, &SimplifyParams::default(), None).unwrap();
    let out = &s.grid;
    let reduction = 1.0 - out.triangles().len() as f64 / dense.triangles().len() as f64;
    assert!(reduction > 0.6, "reduction {reduction}");
    // Dense samples on both sides and across the front.
    let mut ratios = Vec::new();
    for i in 0..400 {
        for j in 0..50 {
            let p = [(i as f64 + 0.5) / 400.0, (j as f64 + 0.5) / 50.0, 0.0];
            let a = dense.query_size(p).unwrap();
            let b = out.query_size(p).unwrap();
            ratios.push((a / b).max(b / a));
        }
    }
    ratios.sort_by(f64::total_cmp);
    let p95 = ratios[ratios.len() * 95 / 100];
    let max = *ratios.last().unwrap();
    assert!(
        p95 <= 1.2 && max <= 1.35,
        "front smeared: p95 {p95}, max {max}"
    );
    // The fine side stays fine right up to the front.
    for y in [0.1, 0.5, 0.9] {
        let h = out.query_size([0.49, y, 0.0]).unwrap();
        assert!(h <= 0.02 * 1.2, "size {h} just left of the front");
    }
}

/// A graded cone of sizes around a small spot (what a fillet or a gap makes:
/// `h = h₀ + ln β · distance`) is convex along the surface, so sizes taken
/// at the simplified vertices lie above it between them, and most where
/// elements are small. The size fit (the default) removes that bias: the
/// element-weighted mean log ratio of simplified to dense sizes moves to
/// about 0, the estimated element count toward the dense grid's, and the
/// grid itself (vertices, triangles) is the same; no size moves by more
/// than `T_size`.
#[test]
fn size_fit_removes_the_interpolation_bias_of_a_graded_field() {
    let mut soup = Soup::default();
    soup.quad([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 80, 80);
    let slope = 1.2f64.ln();
    let cone = move |p: [f64; 3]| 0.01 + slope * norm(sub(p, [0.5, 0.5, 0.0]));
    let dense = with_sizes(&soup.grid(), cone);
    let run = |fit_sizes| {
        let params = SimplifyParams {
            fit_sizes,
            ..Default::default()
        };
        simplify(&dense, &params, None).unwrap()
    };
    let (fit, plain) = (run(true), run(false));
    assert_eq!(fit.grid.vertices(), plain.grid.vertices());
    assert_eq!(fit.grid.triangles(), plain.grid.triangles());
    assert!(fit.report.fit.samples > 0 && fit.report.fit.steps > 0);
    assert_eq!(plain.report.fit.samples, 0);
    for (a, b) in fit
        .grid
        .sizes()
        .unwrap()
        .iter()
        .zip(plain.grid.sizes().unwrap())
    {
        assert!((a / b).max(b / a) <= 1.2 * (1.0 + 1e-12), "{a} vs {b}");
    }
    // Plate vertices stand for equal areas: weight 1/h² is the element density.
    let bias = |g: &Grid| {
        let (mut sum, mut weight) = (0.0, 0.0);
        for (p, &h) in dense.vertices().iter().zip(dense.sizes().unwrap()) {
            let w = 1.0 / (h * h);
            sum += w * (g.query_size(*p).unwrap() / h).ln();
            weight += w;
        }
        sum / weight
    };
    let (bf, bp) = (bias(&fit.grid), bias(&plain.grid));
    assert!(
        bp > 0.01,
        "sizes at the vertices lie above a convex field: {bp}"
    );
    assert!(bf.abs() < 0.5 * bp, "fitted bias {bf} against {bp}");
    let count = |g: &Grid| abgs::metrics::estimated_element_count(&dense, Some(g)).unwrap();
    let n0 = count(&dense);
    let (cf, cp) = (count(&fit.grid) / n0 - 1.0, count(&plain.grid) / n0 - 1.0);
    assert!(
        cf.abs() < cp.abs(),
        "element count change {cf} against {cp}"
    );
}

fn bits(g: &Grid) -> (Vec<[u64; 3]>, Vec<[u32; 3]>, Vec<u64>) {
    (
        g.vertices().iter().map(|p| p.map(f64::to_bits)).collect(),
        g.triangles().to_vec(),
        g.sizes().unwrap().iter().map(|x| x.to_bits()).collect(),
    )
}

#[test]
fn same_bits_with_one_and_two_threads() {
    let dense = with_sizes(&icosphere(1.0, 4), |p| {
        0.1 + 0.05 * (3.0 * p[0]).sin().abs()
    });
    let run = |threads: usize, selection: Selection| {
        let params = SimplifyParams {
            selection,
            ..Default::default()
        };
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| simplify(&dense, &params, None).unwrap())
    };
    for selection in [Selection::Batched, Selection::Global] {
        let (a, b) = (run(1, selection), run(2, selection));
        assert_eq!(bits(&a.grid), bits(&b.grid), "{selection:?}");
        assert_eq!(a.report.iterations.len(), b.report.iterations.len());
    }
    let sa = edge_scores(&dense, &SimplifyParams::default()).unwrap();
    let sb = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(|| edge_scores(&dense, &SimplifyParams::default()).unwrap());
    assert_eq!(
        sa.iter().map(|s| s.y.to_bits()).collect::<Vec<_>>(),
        sb.iter().map(|s| s.y.to_bits()).collect::<Vec<_>>()
    );
}

/// The batched selection (the default) spends its estimates on edges that
/// can still be chosen: far fewer estimates than the global selection's,
/// for a valid grid of about as many faces and as faithful sizes.
#[test]
fn batched_selection_estimates_less_for_an_equal_grid() {
    let dense = with_sizes(&icosphere(1.0, 5), |p| {
        0.05 + 0.04 * (2.0 * p[0]).sin().abs()
    });
    let run = |selection| {
        let params = SimplifyParams {
            selection,
            ..Default::default()
        };
        simplify(&dense, &params, None).unwrap()
    };
    let (batched, global) = (run(Selection::Batched), run(Selection::Global));
    let estimated = |s: &abgs::simplify::Simplified, first: bool| {
        let it = &s.report.iterations;
        if first {
            it[0].estimated
        } else {
            it.iter().map(|r| r.estimated).sum()
        }
    };
    // The pool is 3,072 edges in 96 batches of 32: the first batch is
    // estimated whole, the later ones only where no collapse was claimed
    // yet.
    assert!(
        estimated(&batched, true) * 2 < estimated(&global, true),
        "first iteration: {} vs {}",
        estimated(&batched, true),
        estimated(&global, true)
    );
    assert!(estimated(&batched, false) < estimated(&global, false));
    assert_valid("batched", &dense, &batched.grid, &[]);
    let (nb, ng) = (
        batched.grid.triangles().len() as f64,
        global.grid.triangles().len() as f64,
    );
    assert!((nb / ng - 1.0).abs() < 0.15, "faces {nb} vs {ng}");
    // Sizes on the sphere agree with the dense grid's as well as the
    // global selection's do (within the same T_size budget).
    let worst = |g: &Grid| {
        let mut w: f64 = 1.0;
        for i in 0..2000 {
            let (t, z) = (i as f64 * 2.399_963, 1.0 - (2.0 * i as f64 + 1.0) / 2000.0);
            let r = (1.0 - z * z).sqrt();
            let p = [r * t.cos(), r * t.sin(), z];
            let (a, b) = (dense.query_size(p).unwrap(), g.query_size(p).unwrap());
            w = w.max((a / b).max(b / a));
        }
        w
    };
    let (wb, wg) = (worst(&batched.grid), worst(&global.grid));
    assert!(
        wb <= 1.3 && wb <= wg + 0.05,
        "worst size ratio {wb} vs {wg}"
    );
}

#[test]
fn cancel_from_the_callback_leaves_a_valid_grid() {
    let dense = with_sizes(&icosphere(1.0, 4), |p| 0.15 + 0.1 * p[0]);
    let mut seen = Vec::new();
    let mut cb = |r: &IterationRecord| {
        seen.push(r.faces);
        r.iteration < 2
    };
    let s = simplify(&dense, &SimplifyParams::default(), Some(&mut cb)).unwrap();
    assert_eq!(s.report.stop, StopReason::Cancelled);
    assert_eq!(s.report.iterations.len(), 2);
    assert_eq!(seen.len(), 2);
    assert_eq!(s.grid.triangles().len(), seen[1]);
    assert!(s.grid.triangles().len() < dense.triangles().len());
    assert_valid("cancelled", &dense, &s.grid, &[]);
}

#[test]
fn edge_scores_follow_their_definition() {
    let (lo, hi) = ([0.0; 3], [1.0, 1.0, 1.0]);
    let dense = with_sizes(&box_grid(8, lo, hi).grid(), |p| 0.1 + 0.3 * p[0]);
    let p = SimplifyParams::default();
    let scores = edge_scores(&dense, &p).unwrap();
    assert_eq!(scores.len(), dense.topology().edges.len());
    let corner = corners(lo, hi);
    let mut collapsible = 0;
    for s in &scores {
        if !s.valid {
            assert_eq!(s.y, 1.0);
            continue;
        }
        let y = (0.5 * ((s.ds - 1.0) / (p.t_size - 1.0)).max(s.de)).min(1.0);
        assert!((y - s.y).abs() < 1e-12, "{s:?}");
        assert_eq!(s.y < 0.5, s.ds < p.t_size && s.de < 1.0);
        // The envelope is at most the derived size term, ½·ln(T)/ln(β)·h
        // (= h/2 at the defaults), with h at most 0.4 here.
        if s.dd_rel > 0.0 {
            assert!(s.de * 0.5 * 0.4 >= s.dd_rel * 0.1 * 0.999, "{s:?}");
        }
        collapsible += usize::from(s.y < 0.5);
        // An edge between two corners is never valid.
        let [a, b] = s.vertices.map(|i| dense.vertices()[i as usize]);
        assert!(!(corner.contains(&a) && corner.contains(&b)));
    }
    assert!(collapsible > 0);
    // Flat faces: collapses inside a face are exact, so Δd is 0 there.
    assert!(scores.iter().any(|s| s.valid && s.dd_rel == 0.0));
}

#[test]
fn bad_input_is_an_error() {
    let g = icosphere(1.0, 1);
    assert!(
        simplify(&g, &SimplifyParams::default(), None).is_err(),
        "no sizes"
    );
    let g = with_sizes(&g, |_| 0.3);
    for bad in [
        SimplifyParams {
            fraction: 0.0,
            ..Default::default()
        },
        SimplifyParams {
            t_size: 1.0,
            ..Default::default()
        },
        SimplifyParams {
            tau_d: Some(f64::NAN),
            ..Default::default()
        },
        SimplifyParams {
            beta: 1.0,
            ..Default::default()
        },
        SimplifyParams {
            clearance_fraction: 0.0,
            ..Default::default()
        },
        SimplifyParams {
            max_distance: Some(-1.0),
            ..Default::default()
        },
    ] {
        assert!(simplify(&g, &bad, None).is_err(), "{bad:?}");
        assert!(edge_scores(&g, &bad).is_err(), "{bad:?}");
    }
}
