//! Sizing on synthetic shapes: curvature sizes on spheres and cylinders,
//! proximity on parallel plates and a thin-walled cup, and the full pipeline.

mod common;

use abgs::sizing::{self, Gradation, SizeParams};
use common::shapes::{cylinder, icosphere, Soup};
use std::f64::consts::PI;

fn params_no_grad() -> SizeParams {
    SizeParams {
        gradation: None,
        proximity: false,
        ..Default::default()
    }
}

/// Proximity alone, ungraded, hmax 0.5.
fn proximity_only() -> SizeParams {
    SizeParams {
        gradation: None,
        curvature: false,
        hmax: Some(0.5),
        hmin: Some(1e-4),
        ..Default::default()
    }
}

#[test]
fn sphere_curvature_size_at_three_resolutions() {
    for (r, level) in [(1.0, 2), (3.0, 3), (0.5, 4)] {
        let g = icosphere(r, level);
        let mut p = params_no_grad();
        p.hmin = Some(1e-6);
        p.hmax = Some(100.0);
        let f = sizing::compute(&g, &p).unwrap();
        let expect = 2.0 * PI * r / 24.0;
        for (i, &h) in f.h_curv.iter().enumerate() {
            assert!(
                (h / expect - 1.0).abs() < 0.05,
                "r {r} level {level} vertex {i}: {h} vs {expect}"
            );
        }
        assert_eq!(f.report.feature_edges, 0);
    }
}

#[test]
fn cylinder_side_curvature_and_flat_caps() {
    let (r, h) = (2.0, 5.0);
    let g = cylinder(r, h, 48, 12, 4);
    let mut p = params_no_grad();
    p.hmax = Some(1.0);
    let f = sizing::compute(&g, &p).unwrap();
    let mut side = 0;
    let mut cap = 0;
    for (i, v) in g.vertices().iter().enumerate() {
        let rad = (v[0] * v[0] + v[1] * v[1]).sqrt();
        if (rad - r).abs() < 1e-9 {
            // On the side (rim vertices included): k_max = 1/r.
            let k = f.curvature[i].max_abs();
            assert!((k * r - 1.0).abs() < 0.05, "side vertex {i}: k = {k}");
            side += 1;
        } else {
            // Cap interior: flat, so the size is hmax.
            assert!(
                f.curvature[i].max_abs() < 1e-9,
                "cap vertex {i}: {:?}",
                f.curvature[i]
            );
            assert_eq!(f.h0[i], 1.0);
            cap += 1;
        }
    }
    assert!(side > 0 && cap > 0);
    assert_eq!(f.report.patches, 3, "side and two caps");
}

#[test]
fn two_parallel_plates_gap() {
    let gap = 0.3;
    let mut s = Soup::default();
    s.boxed([0.0, 0.0, -2.0], [10.0, 10.0, 0.0], 20, false, false);
    s.boxed([0.0, 0.0, gap], [10.0, 10.0, gap + 2.0], 20, false, false);
    let g = s.grid();
    assert_eq!(g.report().bodies, 2);
    let f = sizing::compute(&g, &proximity_only()).unwrap();
    let expect = gap / 3.0;
    for (i, v) in g.vertices().iter().enumerate() {
        let facing_gap = v[2] == 0.0 || v[2] == gap;
        if facing_gap {
            assert!(
                (f.h_prox[i] / expect - 1.0).abs() < 0.1,
                "vertex {i} {v:?}: {}",
                f.h_prox[i]
            );
            assert!((f.h0[i] / expect - 1.0).abs() < 0.1);
        } else {
            assert!(
                f.h_prox[i].is_infinite(),
                "vertex {i} {v:?} away from the gap: {}",
                f.h_prox[i]
            );
            assert_eq!(f.h0[i], 0.5);
        }
    }
}

#[test]
fn touching_bodies_share_the_smaller_size_on_their_interface() {
    // A thin plate (0.1 thick: proximity size 0.1/3) lying on a big block whose
    // top would otherwise take hmax; their vertices do not coincide.
    let mut s = Soup::default();
    s.boxed([0.0, 0.0, -2.0], [10.0, 10.0, 0.0], 20, false, false);
    s.boxed([3.1, 3.1, 0.0], [6.9, 6.9, 0.1], 8, false, false);
    let mut g = s.grid();
    assert_eq!(g.report().bodies, 2);
    let f = sizing::compute(&g, &proximity_only()).unwrap();
    let plate = 0.1 / 3.0;
    let inside = |x: f64| x > 3.1 + 1e-9 && x < 6.9 - 1e-9;
    let mut shared = 0;
    for (i, v) in g.vertices().iter().enumerate() {
        let on_block_top =
            v[2] == 0.0 && (v[0] <= 3.1 || v[0] >= 6.9 || v[1] <= 3.1 || v[1] >= 6.9);
        if v[2] == 0.0 && inside(v[0]) && inside(v[1]) {
            // Block top under the plate (the plate's own bottom vertices are
            // all on its rim, outside this open square).
            assert!(
                (f.h0[i] / plate - 1.0).abs() < 0.1,
                "vertex {i} {v:?}: {}",
                f.h0[i]
            );
            shared += 1;
        } else if on_block_top && (v[0] < 3.0 || v[0] > 7.0 || v[1] < 3.0 || v[1] > 7.0) {
            assert_eq!(f.h0[i], 0.5, "vertex {i} {v:?} away from the plate");
        }
    }
    assert!(shared >= 49, "{shared} block vertices under the plate");
    assert!(f.report.contact_vertices >= shared);
    // A query on the interface answers the plate's size whichever body it
    // lands on (a block cell away from the plate's rim, where the block's
    // triangles straddle it).
    g.set_sizes(f.h.clone()).unwrap();
    for k in 0..50 {
        let x = 3.6 + 2.8 * (k as f64 * 0.618_033_988_75).fract();
        let y = 3.6 + 2.8 * (k as f64 * 0.414_213_562_37).fract();
        let h = g.closest([x, y, 0.0], None).unwrap().size;
        assert!((h / plate - 1.0).abs() < 0.1, "({x}, {y}): {h}");
    }
}

#[test]
fn thin_walled_cup_is_one_body_with_wall_sizes() {
    let (l, w) = (10.0, 0.3);
    let mut s = Soup::default();
    s.boxed([0.0, 0.0, 0.0], [l, l, l], 20, false, true);
    s.boxed([w, w, w], [l - w, l - w, l], 20, true, true);
    // Rim: four strips joining the outer and inner top edges.
    let n = 20;
    let corners_o = [[0.0, 0.0], [l, 0.0], [l, l], [0.0, l]];
    let corners_i = [[w, w], [l - w, w], [l - w, l - w], [w, l - w]];
    for k in 0..4 {
        let (o0, o1) = (corners_o[k], corners_o[(k + 1) % 4]);
        let (i0, i1) = (corners_i[k], corners_i[(k + 1) % 4]);
        for j in 0..n {
            let (a, b) = (j as f64 / n as f64, (j + 1) as f64 / n as f64);
            let lerp = |p: [f64; 2], q: [f64; 2], t: f64| {
                [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]), l]
            };
            s.tri(lerp(o0, o1, a), lerp(o0, o1, b), lerp(i0, i1, b));
            s.tri(lerp(o0, o1, a), lerp(i0, i1, b), lerp(i0, i1, a));
        }
    }
    let g = s.grid();
    assert_eq!(g.report().bodies, 1);
    assert_eq!(g.report().boundary_edges, 0);
    let p = SizeParams {
        gradation: None,
        curvature: false,
        hmax: Some(1.0),
        ..Default::default()
    };
    let f = sizing::compute(&g, &p).unwrap();
    let features = abgs::mesh::Features::detect(&g, 30.0);
    let expect = w / 3.0;
    let mut on_faces = 0;
    for (i, v) in g.vertices().iter().enumerate() {
        if features.on_feature(i) {
            // Along edges and at corners the wall is up to √3·w thick diagonally.
            assert!(
                f.h_prox[i] >= 0.9 * expect && f.h_prox[i] <= 1.1 * 3f64.sqrt() * expect,
                "feature vertex {i} {v:?}: {}",
                f.h_prox[i]
            );
        } else {
            assert!(
                (f.h_prox[i] / expect - 1.0).abs() < 0.1,
                "vertex {i} {v:?}: {}",
                f.h_prox[i]
            );
            on_faces += 1;
        }
    }
    assert!(on_faces > 1000);
}

#[test]
fn pipeline_grades_and_respects_bounds() {
    let mut g = cylinder(1.0, 4.0, 32, 16, 3);
    let p = SizeParams {
        gradation: Some(Gradation::Beta(1.3)),
        ..Default::default()
    };
    let fields = sizing::compute(&g, &p).unwrap();
    let s = 1.3f64.ln();
    let (max, over) = sizing::gradation::max_face_slope(g.vertices(), g.triangles(), &fields.h, s);
    assert_eq!(over, 0, "max slope {max}");
    for i in 0..fields.h.len() {
        assert!(fields.h[i] <= fields.h0[i]);
        assert!(fields.h0[i] >= fields.report.hmin && fields.h0[i] <= fields.report.hmax);
    }
    let r = g.compute_sizes(&p).unwrap();
    assert_eq!(g.sizes().unwrap(), fields.h.as_slice());
    assert!(r.seconds_curvature >= 0.0);
    let l = g.lbo().unwrap();
    assert_eq!(l.edge.len(), g.topology().edges.len());
    // Bad parameters are errors, not panics.
    for bad in [
        SizeParams {
            n_circle: 0.0,
            ..Default::default()
        },
        SizeParams {
            hmin: Some(2.0),
            hmax: Some(1.0),
            ..Default::default()
        },
        SizeParams {
            gradation: Some(Gradation::Beta(1.0)),
            ..Default::default()
        },
        SizeParams {
            gradation: Some(Gradation::Slope(f64::NAN)),
            ..Default::default()
        },
    ] {
        assert!(sizing::compute(&g, &bad).is_err());
    }
}

#[test]
fn same_bits_with_one_and_two_threads() {
    let dir = common::shared_meshes();
    let g = abgs::Grid::load(&dir.join("occt_crankarm.stl")).unwrap();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| sizing::compute(&g, &SizeParams::default()).unwrap())
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.h, b.h);
    assert_eq!(a.h0, b.h0);
    assert_eq!(a.h_prox, b.h_prox);
    assert_eq!(a.h_curv, b.h_curv);
}
