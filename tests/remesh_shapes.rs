//! The isotropic remesher on synthetic shapes: a box, a cylinder, two touching
//! boxes, an open box, a sliver soup, and the size-driven mode on a plate and a
//! sphere. Acceptance: min-angle p1 ≥ 25°, max-angle p99 ≤ 110°, symmetric
//! Hausdorff ≤ 0.1 % of the diagonal (50k samples each way), features kept
//! both ways within 0.1 %, same bodies, no new boundary or non-manifold edges.

mod common;

use abgs::remesh::{quality, remesh, remesh_sized, RemeshParams, Remeshed, TargetLength};
use abgs::{BuildOptions, Grid};
use common::shapes::{cylinder, icosphere, Soup};

fn params(relative: f64) -> RemeshParams {
    RemeshParams {
        target: TargetLength::Relative(relative),
        ..Default::default()
    }
}

/// Asserts the acceptance numbers; `detected` also checks the output's own
/// sharp edges (not only the kept feature lines) against the input's.
fn accept(name: &str, input: &Grid, out: &Remeshed, detected: bool) -> quality::Acceptance {
    let a = quality::evaluate(input, &out.grid, Some(&out.feature_edges), 30.0, 50_000);
    let f = a.failures();
    assert!(f.is_empty(), "{name}: {f:?}\n{a:?}\n{:?}", out.report);
    if detected {
        let d = quality::evaluate(input, &out.grid, None, 30.0, 20_000);
        assert!(
            d.feature_hausdorff <= 1e-3 && d.new_creases == 0,
            "{name} (detected features): {d:?}"
        );
    }
    // Nothing was lost: the output is a valid grid with the same bodies.
    assert_eq!(out.grid.report().dropped_zero_area, 0, "{name}");
    assert_eq!(out.report.faces_out, out.grid.triangles().len());
    a
}

#[test]
fn box_is_remeshed_with_sharp_edges_and_corners_kept() {
    let mut s = Soup::default();
    s.boxed([0.0; 3], [1.0, 2.0, 0.5], 2, false, false);
    let g = s.grid();
    let out = remesh(&g, &params(0.03)).unwrap();
    let a = accept("box", &g, &out, true);
    assert!(a.faces_out > 1000, "{a:?}");
    // Corners never move: all 8 box corners are output vertices.
    for i in 0..8 {
        let c = [
            (i & 1) as f64,
            2.0 * ((i >> 1) & 1) as f64,
            0.5 * ((i >> 2) & 1) as f64,
        ];
        assert!(out.grid.vertices().contains(&c), "corner {c:?} lost");
    }
    // Iterations converge: the last one changes little.
    let last = out.report.iterations.last().unwrap();
    assert!(last.splits + last.collapses < a.faces_out / 20, "{last:?}");
}

#[test]
fn cylinder_keeps_its_rims() {
    let g = cylinder(1.0, 2.0, 64, 8, 4);
    let out = remesh(&g, &params(0.02)).unwrap();
    accept("cylinder", &g, &out, true);
    // The two rims are the only feature lines (loops without corners).
    assert_eq!(out.report.feature_lines, 2);
}

#[test]
fn needle_tessellated_cylinder_is_refined_along_its_whole_length() {
    // A CAD export tessellates a long fillet by needles spanning its length
    // (here 16 facets around, one along 40 radii): the curvature cap must
    // reach the middle of the needles, not only their ends.
    let g = cylinder(1.0, 40.0, 16, 1, 1);
    let p = params(0.01);
    let l0 = 0.01 * g.bbox().diagonal();
    let out = remesh(&g, &p).unwrap();
    accept("needle cylinder", &g, &out, true);
    let v = out.grid.vertices();
    let topo = out.grid.topology();
    let (mut sum, mut n) = (0.0, 0usize);
    for e in &topo.edges {
        let [a, b] = e.map(|i| v[i as usize]);
        if (15.0..25.0).contains(&(0.5 * (a[2] + b[2]))) {
            sum += (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
            n += 1;
        }
    }
    // Half the curvature size is π/24 ≈ 0.13 < L0 ≈ 0.40.
    let mean = sum / n as f64;
    let cap = 0.5 * 2.0 * std::f64::consts::PI / 24.0;
    assert!(
        mean < 1.3 * cap && mean < 0.5 * l0,
        "mean {mean}, cap {cap}, L0 {l0}"
    );
}

#[test]
fn boxes_sharing_an_edge_stay_apart_and_the_edge_is_kept() {
    // Two unit boxes touching along the line x = 1, y = 1: four faces meet
    // at each of its edges (non-manifold), one body each side.
    let mut s = Soup::default();
    s.boxed([0.0; 3], [1.0, 1.0, 1.0], 3, false, false);
    s.boxed([1.0, 1.0, 0.0], [2.0, 2.0, 1.0], 3, false, false);
    let g = s.grid();
    assert_eq!(g.topology().body_count, 2);
    assert!(g.report().non_manifold_edges > 0, "{:?}", g.report());
    let out = remesh(&g, &params(0.03)).unwrap();
    accept("boxes sharing an edge", &g, &out, true);
    // The contact line may be refined (both sides alike) but stays whole:
    // its non-manifold edges add up to its length, 1.
    let nm_length = |g: &Grid| {
        let topo = g.topology();
        let v = g.vertices();
        (0..topo.edges.len())
            .filter(|&e| topo.faces_of_edge(e).len() > 2)
            .map(|e| {
                let [a, b] = topo.edges[e].map(|i| v[i as usize]);
                (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
            })
            .sum::<f64>()
    };
    assert!((nm_length(&g) - 1.0).abs() < 1e-12);
    assert!(
        (nm_length(&out.grid) - 1.0).abs() < 1e-9,
        "{}",
        nm_length(&out.grid)
    );
    assert_eq!(out.grid.topology().body_count, 2);
}

#[test]
fn box_standing_on_a_box_stays_two_bodies() {
    // An assembly: a small box on a large one, the contact faces tessellated
    // independently (no shared vertices), as CAD exports them.
    let mut s = Soup::default();
    s.boxed([0.0; 3], [2.0, 2.0, 1.0], 4, false, false);
    s.boxed([0.3, 0.35, 1.0], [1.3, 1.35, 1.7], 3, false, false);
    let g = s.grid();
    assert_eq!(g.topology().body_count, 2);
    let out = remesh(&g, &params(0.02)).unwrap();
    accept("stacked boxes", &g, &out, true);
    // Nothing of one body moved onto the other: the small box's bottom is
    // still at z = 1 and inside its own footprint.
    let v = out.grid.vertices();
    let topo = out.grid.topology();
    for (f, t) in out.grid.triangles().iter().enumerate() {
        let c = t.map(|i| v[i as usize]);
        if topo.face_body[f] != topo.face_body[0] {
            assert!(c
                .iter()
                .all(|p| p[2] >= 1.0 - 1e-12 && p[0] >= 0.3 - 1e-12 && p[0] <= 1.3 + 1e-12));
        }
    }
}

#[test]
fn coincident_contact_faces_do_not_break_the_remesher() {
    // Two boxes whose contact faces are the same triangles (a conforming
    // export): every contact triangle is on non-manifold edges only. The
    // remesher must leave them as they are, say so, and keep the rest sound.
    let mut s = Soup::default();
    s.boxed([0.0; 3], [1.0, 1.0, 1.0], 4, false, false);
    s.boxed([1.0, 0.25, 0.25], [2.0, 0.75, 0.75], 2, false, false);
    let g = s.grid();
    assert!(g.report().non_manifold_edges > 0, "{:?}", g.report());
    let out = remesh(&g, &params(0.03)).unwrap();
    assert!(
        out.report.issues.iter().any(|s| s.contains("locked")),
        "{:?}",
        out.report.issues
    );
    let a = quality::evaluate(&g, &out.grid, Some(&out.feature_edges), 30.0, 20_000);
    assert!(a.hausdorff <= 1e-3 && a.min_angle_p1 >= 25.0, "{a:?}");
    assert_eq!(a.new_boundary_edges, 0, "{a:?}");
}

#[test]
fn open_box_keeps_its_boundary() {
    let mut s = Soup::default();
    s.boxed([0.0; 3], [1.0, 1.0, 0.6], 3, false, true);
    let g = s.grid();
    assert!(g.report().boundary_edges > 0);
    let out = remesh(&g, &params(0.03)).unwrap();
    accept("open box", &g, &out, true);
    assert!(out.grid.report().boundary_edges > 0);
}

#[test]
fn sliver_fans_are_cleaned_up() {
    // Each face of a box as a fan of needles from one corner: min angle ≈ 0.3°.
    let mut s = Soup::default();
    let quad_fan = |s: &mut Soup, o: [f64; 3], u: [f64; 3], v: [f64; 3], n: usize| {
        let p = |a: f64, b: f64| [0, 1, 2].map(|k| o[k] + a * u[k] + b * v[k]);
        for i in 0..n {
            let (a0, a1) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
            s.tri(p(0.0, 0.0), p(1.0, a0), p(1.0, a1));
            s.tri(p(0.0, 0.0), p(a1, 1.0), p(a0, 1.0));
        }
    };
    quad_fan(&mut s, [0.0; 3], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], 200);
    quad_fan(
        &mut s,
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        200,
    );
    quad_fan(&mut s, [0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 200);
    quad_fan(
        &mut s,
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        200,
    );
    quad_fan(&mut s, [0.0; 3], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], 200);
    quad_fan(
        &mut s,
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        200,
    );
    let g = s.grid();
    assert!(g.angle_stats().min_angle < 0.5);
    let out = remesh(&g, &params(0.03)).unwrap();
    accept("sliver fans", &g, &out, true);
}

#[test]
fn deterministic_with_any_thread_count() {
    let g = cylinder(1.0, 1.0, 48, 6, 3);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| remesh(&g, &params(0.04)).unwrap())
    };
    let (a, b) = (run(1), run(3));
    assert_eq!(a.grid.vertices(), b.grid.vertices());
    assert_eq!(a.grid.triangles(), b.grid.triangles());
    assert_eq!(a.feature_edges, b.feature_edges);
}

#[test]
fn bad_parameters_are_errors() {
    let g = cylinder(1.0, 1.0, 16, 2, 1);
    for p in [
        params(0.0),
        params(f64::NAN),
        RemeshParams {
            feature_angle_deg: -1.0,
            ..Default::default()
        },
        RemeshParams {
            fidelity: f64::INFINITY,
            ..Default::default()
        },
    ] {
        assert!(remesh(&g, &p).is_err());
    }
    assert!(remesh_sized(&g, &g, &RemeshParams::default()).is_err());
}

/// Mean of length / h(midpoint) over the output edges, and the share within [0.6, 1.5].
fn size_ratios(out: &Grid, sizing: &Grid) -> (f64, f64) {
    quality::length_ratios(out, |p, hint| sizing.query_size_hinted(p, hint)).unwrap()
}

fn sized(g: &Grid, h: impl Fn([f64; 3]) -> f64) -> Grid {
    let sizes = g.vertices().iter().map(|&p| h(p)).collect();
    Grid::from_arrays(
        g.vertices().to_vec(),
        g.triangles().to_vec(),
        Some(sizes),
        &BuildOptions::default(),
    )
    .unwrap()
}

#[test]
fn size_driven_plate_follows_the_field() {
    let mut s = Soup::default();
    s.quad([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 20, 20);
    let plate = s.grid();
    let sizing = sized(&plate, |p| 0.02 + 0.1 * p[0]);
    let out = remesh_sized(&plate, &sizing, &RemeshParams::default()).unwrap();
    let (mean, within) = size_ratios(&out.grid, &sizing);
    assert!((0.85..=1.2).contains(&mean), "mean {mean}");
    assert!(within >= 0.9, "within {within}");
    accept("sized plate", &plate, &out, true);
}

#[test]
fn size_driven_sphere_follows_the_field() {
    let sphere = icosphere(1.0, 4);
    let sizing = sized(&sphere, |p| 0.02 + 0.1 * (p[0] + 1.0));
    let p = RemeshParams {
        curvature_limit: false,
        ..Default::default()
    };
    let out = remesh_sized(&sphere, &sizing, &p).unwrap();
    let (mean, within) = size_ratios(&out.grid, &sizing);
    assert!((0.85..=1.2).contains(&mean), "mean {mean}");
    assert!(within >= 0.9, "within {within}");
    let a = quality::evaluate(&sphere, &out.grid, Some(&out.feature_edges), 30.0, 50_000);
    assert!(a.min_angle_p1 >= 25.0 && a.max_angle_p99 <= 110.0, "{a:?}");
    assert_eq!(a.bodies_out, 1);
}
