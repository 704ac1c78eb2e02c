use super::*;
use crate::geometry::scale;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

type Mesh = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// A `side × side` plate of `nx × nx` cells, z = `bump(x, y)`. With `jitter = 0`
/// every cell is split by the same diagonal (structured right triangles);
/// otherwise interior vertices move by up to `jitter` cells per axis and each cell
/// takes the diagonal with the larger smallest angle.
fn plate(nx: usize, side: f64, jitter: f64, seed: u64, bump: impl Fn(f64, f64) -> f64) -> Mesh {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let l = side / nx as f64;
    let mut v = Vec::with_capacity((nx + 1) * (nx + 1));
    for j in 0..=nx {
        for i in 0..=nx {
            let (mut x, mut y) = (i as f64 * l, j as f64 * l);
            if jitter > 0.0 && i > 0 && j > 0 && i < nx && j < nx {
                x += rng.gen_range(-jitter..jitter) * l;
                y += rng.gen_range(-jitter..jitter) * l;
            }
            v.push([x, y, bump(x, y)]);
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let ccw = |t: [u32; 3]| {
        let [a, b, c] = t.map(|k| v[k as usize]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0.0
    };
    let mut t = Vec::with_capacity(2 * nx * nx);
    for j in 0..nx {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            let first = [[a, b, c], [a, c, d]];
            let second = [[a, b, d], [b, c, d]];
            // The diagonal with the larger smallest angle (Delaunay-like), when
            // both keep the triangles positively oriented.
            let use_second = jitter > 0.0 && {
                let ok1 = first.iter().all(|&x| ccw(x));
                let ok2 = second.iter().all(|&x| ccw(x));
                let min_angle = |q: [[u32; 3]; 2]| {
                    q.iter()
                        .flat_map(|t| {
                            let [a, b, c] = t.map(|k| v[k as usize]);
                            crate::geometry::triangle_angles_deg(a, b, c)
                        })
                        .fold(180.0, f64::min)
                };
                ok2 && (!ok1 || min_angle(second) > min_angle(first))
            };
            t.extend(if use_second { second } else { first });
        }
    }
    (v, t)
}

fn flat(_: f64, _: f64) -> f64 {
    0.0
}

fn bumpy(x: f64, y: f64) -> f64 {
    0.15 * (3.0 * x).sin() * (2.0 * y).cos()
}

fn random_h0(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| rng.gen_range(0.05..1.0)).collect()
}

fn run(mesh: &Mesh, h0: &[f64], s: f64) -> (Vec<f64>, GradationReport) {
    let topo = Topology::build(mesh.0.len(), &mesh.1);
    grade(&mesh.0, &mesh.1, &topo, h0, s)
}

/// The guarantees of `grade`: feasible, below h0 bit for bit, report consistent.
fn assert_valid(mesh: &Mesh, h0: &[f64], h: &[f64], rep: &GradationReport, s: f64) {
    let (max, bad) = max_face_slope(&mesh.0, &mesh.1, h, s);
    assert_eq!(bad, 0, "max slope ratio {}", max / s);
    assert!(max <= s * (1.0 + SLOPE_TOLERANCE));
    assert!(rep.max_slope_ratio <= 1.0 + SLOPE_TOLERANCE);
    assert!((rep.max_slope_ratio - max / s).abs() <= 1e-12);
    assert!(h.iter().zip(h0).all(|(a, b)| a <= b));
}

fn l2(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// One small source near the centre of `mesh`: h0 = `hmax` everywhere else.
/// Returns (h0, source vertex).
fn single_source(mesh: &Mesh, centre: [f64; 3], hmax: f64, hsrc: f64) -> (Vec<f64>, usize) {
    let src = (0..mesh.0.len())
        .min_by(|&a, &b| dist2(mesh.0[a], centre).total_cmp(&dist2(mesh.0[b], centre)))
        .unwrap();
    let mut h0 = vec![hmax; mesh.0.len()];
    h0[src] = hsrc;
    (h0, src)
}

/// Largest relative difference to the cone `min(hmax, h_src + s·|x − x_src|)`.
fn cone_error(mesh: &Mesh, h: &[f64], src: usize, hmax: f64, hsrc: f64, s: f64) -> f64 {
    let xs = mesh.0[src];
    mesh.0
        .iter()
        .zip(h)
        .map(|(p, &hv)| {
            let exact = hmax.min(hsrc + s * dist2(*p, xs).sqrt());
            (hv - exact).abs() / exact
        })
        .fold(0.0, f64::max)
}

#[test]
fn face_slope_of_linear_fields() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for _ in 0..100 {
        let p: [[f64; 3]; 3] =
            std::array::from_fn(|_| std::array::from_fn(|_| rng.gen_range(-1.0..1.0)));
        let g: [f64; 3] = std::array::from_fn(|_| rng.gen_range(-1.0..1.0));
        let h = p.map(|x| 0.3 + dot(g, x));
        // Expected: the component of g in the triangle's plane.
        let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
        let gp = sub(g, scale(n, dot(g, n) / norm2(n)));
        let sl = face_slope(p[0], p[1], p[2], h[0], h[1], h[2]);
        assert!(
            (sl - norm(gp)).abs() <= 1e-9 * (1.0 + norm(gp)),
            "{sl} vs {}",
            norm(gp)
        );
    }
    let z = [0.0; 3];
    assert_eq!(
        face_slope(z, [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], 0.0, 1.0, 5.0),
        0.0
    );
    assert_eq!(face_slope(z, z, z, 0.0, 1.0, 5.0), 0.0);
    // Right triangle with legs 1: gradient (1, 2).
    let sl = face_slope(z, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0, 2.0, 3.0);
    assert!((sl - 5f64.sqrt()).abs() < 1e-15);
    assert!(face_slope(z, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0, f64::NAN, 3.0).is_nan());
}

#[test]
fn project_ellipse_lands_on_the_boundary() {
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    for _ in 0..1000 {
        let (p, q, r): (f64, f64, f64) = (
            rng.gen_range(0.01..100.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(0.01..100.0),
        );
        let a = [p, q * (p * r).sqrt(), r];
        let y = [rng.gen_range(-10.0..10.0), rng.gen_range(-10.0..10.0)];
        let z = project_ellipse(a, y, 0.5);
        let f = |z: [f64; 2]| a[0] * z[0] * z[0] + 2.0 * a[1] * z[0] * z[1] + a[2] * z[1] * z[1];
        assert!(f(z) <= 0.25 * (1.0 + 1e-12));
        if f(y) > 0.25 {
            assert!(f(z) >= 0.25 * (1.0 - 1e-9));
            // Optimality: y − z is along the normal A z.
            let n = [a[0] * z[0] + a[1] * z[1], a[1] * z[0] + a[2] * z[1]];
            let d = [y[0] - z[0], y[1] - z[1]];
            let c = (d[0] * n[1] - d[1] * n[0]).abs();
            assert!(c <= 1e-7 * d[0].hypot(d[1]) * n[0].hypot(n[1]) + 1e-300);
        }
    }
}

#[test]
fn feasible_h0_is_unchanged() {
    let s = 1.2f64.ln();
    let meshes = [
        plate(20, 1.0, 0.0, 1, flat),
        plate(20, 1.0, 0.3, 2, flat),
        plate(20, 1.0, 0.3, 3, bumpy),
    ];
    for mesh in &meshes {
        let constant = vec![0.7; mesh.0.len()];
        let linear = |k: f64| -> Vec<f64> {
            mesh.0
                .iter()
                .map(|p| 0.2 + k * s * (0.6 * p[0] + 0.8 * p[1]))
                .collect()
        };
        for h0 in [constant, linear(0.5), linear(0.99)] {
            let (h, rep) = run(mesh, &h0, s);
            assert_eq!(h, h0);
            assert_eq!((rep.faces_fixed, rep.vertices_lowered), (0, 0));
            assert!(rep.max_slope_ratio <= 1.0);
        }
    }
}

#[test]
fn random_h0_gives_a_feasible_field_below_h0() {
    let meshes = [
        plate(60, 1.0, 0.0, 1, flat),
        plate(60, 1.0, 0.3, 2, flat),
        plate(60, 1.0, 0.3, 3, bumpy),
    ];
    for (k, mesh) in meshes.iter().enumerate() {
        for beta in [1.05, 1.2, 1.5] {
            let s = f64::ln(beta);
            let h0 = random_h0(mesh.0.len(), 10 + k as u64);
            let (h, rep) = run(mesh, &h0, s);
            assert_valid(mesh, &h0, &h, &rep, s);
            assert!(rep.faces_fixed > 0 && rep.max_slope_ratio_before_fix > 1.0);
            println!("mesh {k} beta {beta}: {rep:?}");
        }
    }
}

#[test]
fn unreferenced_and_non_finite_values_are_kept() {
    let s = 1.2f64.ln();
    let (mut v, t) = plate(10, 1.0, 0.2, 4, flat);
    v.push([5.0, 5.0, 0.0]); // on no triangle
    let n = v.len();
    let mut h0 = random_h0(n, 3);
    h0[n - 1] = 0.001;
    h0[7] = f64::INFINITY;
    h0[30] = f64::NAN;
    h0[50] = f64::NEG_INFINITY;
    let topo = Topology::build(n, &t);
    let (h, _) = grade(&v, &t, &topo, &h0, s);
    assert_eq!(h[n - 1], 0.001);
    assert!(h[30].is_nan());
    assert_eq!(h[50], f64::NEG_INFINITY);
    assert!(h[7].is_finite()); // +inf is lowered by its neighbours
    assert!(h.iter().zip(&h0).all(|(a, b)| a.is_nan() || a <= b));
}

/// The reference on one right triangle, where the projection is known: the
/// corner at the right angle stays, the other two share the slope budget.
#[test]
fn reference_on_one_triangle() {
    let s = 0.5;
    let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let t = vec![[0, 1, 2]];
    let r = reference_solution(&v, &t, &[1.0, 1.5, 1.5], s, 1e-13, 500);
    let expected = [1.0, 1.0 + s / 2f64.sqrt(), 1.0 + s / 2f64.sqrt()];
    for k in 0..3 {
        assert!((r[k] - expected[k]).abs() < 1e-6, "{r:?}");
    }
}

/// Small meshes against the exact L2 projection. The projection is the closest
/// feasible field, so ours can only be farther; we ask for at most 1 % farther.
#[test]
fn close_to_the_l2_reference() {
    let meshes = [
        ("structured", plate(12, 1.0, 0.0, 0, flat)),
        ("jittered", plate(12, 1.0, 0.3, 1, flat)),
        ("bumpy", plate(12, 1.0, 0.3, 2, bumpy)),
        ("fine-plate", plate(12, 0.25, 0.3, 3, flat)),
    ];
    let mut worst = 0.0f64;
    for (name, mesh) in &meshes {
        for beta in [1.2, 1.5] {
            let s = f64::ln(beta);
            let mut line = format!(
                "{name} ({} faces) beta {beta}: |h − H0| / |ref − H0| =",
                mesh.1.len()
            );
            for seed in 0..4 {
                let h0 = random_h0(mesh.0.len(), seed);
                let (h, rep) = run(mesh, &h0, s);
                assert_valid(mesh, &h0, &h, &rep, s);
                let r = reference_solution(&mesh.0, &mesh.1, &h0, s, 1e-12, 2000);
                let (rmax, _) = max_face_slope(&mesh.0, &mesh.1, &r, s);
                assert!(
                    rmax <= s * (1.0 + 1e-6),
                    "reference slope ratio {}",
                    rmax / s
                );
                assert!(r.iter().zip(&h0).all(|(a, b)| a <= b));
                let ratio = l2(&h, &h0) / l2(&r, &h0);
                line += &format!(" {ratio:.5}");
                worst = worst.max(ratio);
                assert!(
                    ratio <= 1.01,
                    "{name} beta {beta} seed {seed}: ratio {ratio}"
                );
            }
            println!("{line}");
        }
    }
    println!("worst L2 ratio {worst:.5}");
}

// Single source on a plate: h = min(hmax, h_src + s·|x − x_src|) within 3 %.
// The plates are 0.1 wide with 100 × 100 cells (20 000 faces), so cells are a
// tenth of the source size. With cells as large as the source, no feasible
// piecewise-linear field is within 3 % next to it: on a face with a right angle
// at the source, (hb − ha)² + (hc − ha)² ≤ (s·L)² puts one of the two neighbours
// at least 0.29·s·L below the cone, 4.5 % of its value. The exact L2 projection
// itself stays 0.3–0.9 s·L below the cone on such meshes.

const PLATE_SOURCE: (f64, f64, [f64; 3]) = (0.02, 0.01, [0.05, 0.05, 0.0]);

fn plate_source_error(mesh: &Mesh) -> f64 {
    let s = 1.2f64.ln();
    let (hmax, hsrc, centre) = PLATE_SOURCE;
    let (h0, src) = single_source(mesh, centre, hmax, hsrc);
    let (h, rep) = run(mesh, &h0, s);
    assert_valid(mesh, &h0, &h, &rep, s);
    cone_error(mesh, &h, src, hmax, hsrc, s)
}

#[test]
fn single_source_on_a_structured_plate() {
    let e = plate_source_error(&plate(100, 0.1, 0.0, 0, flat));
    println!("structured plate, single source: max relative error {e:.4}");
    assert!(e <= 0.03);
}

#[test]
fn single_source_on_a_jittered_plate() {
    for seed in [7, 8] {
        let e = plate_source_error(&plate(100, 0.1, 0.3, seed, flat));
        println!("jittered plate (seed {seed}), single source: max relative error {e:.4}");
        assert!(e <= 0.03);
    }
}

/// Why the brief's two steps are not enough, on the structured plate: edge-only
/// marching measures distances along edges (21 % too long here), and marching
/// with triangle updates followed by the face-by-face fix drifts away from the
/// cone along the axes (11 % too low).
#[test]
fn edge_marching_and_fix_alone_are_not_enough() {
    let mesh = plate(100, 0.1, 0.0, 0, flat);
    let s = 1.2f64.ln();
    let (hmax, hsrc, centre) = PLATE_SOURCE;
    let (h0, src) = single_source(&mesh, centre, hmax, hsrc);
    let topo = Topology::build(mesh.0.len(), &mesh.1);
    let m = Surface {
        v: &mesh.0,
        t: &mesh.1,
        topo: &topo,
    };
    let (mut edge, mut eik) = (h0.clone(), h0.clone());
    m.march(&mut edge, s, Update::Edge, None);
    m.march(&mut eik, s, Update::Eikonal, None);
    let e_edge = cone_error(&mesh, &edge, src, hmax, hsrc, s);
    let e_eik = cone_error(&mesh, &eik, src, hmax, hsrc, s);
    m.fix_faces(&mut eik, s);
    let e_fix = cone_error(&mesh, &eik, src, hmax, hsrc, s);
    println!("edge-only marching {e_edge:.4}, triangle updates {e_eik:.4}, then fixed face by face {e_fix:.4}");
    assert!(e_edge > 0.1 && e_eik < 0.03 && e_fix > 0.05);
}

#[test]
fn deterministic() {
    let mesh = plate(80, 1.0, 0.3, 8, bumpy);
    let h0 = random_h0(mesh.0.len(), 8);
    let s = 1.2f64.ln();
    let (a, ra) = run(&mesh, &h0, s);
    let (b, rb) = run(&mesh, &h0, s);
    assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
    assert_eq!(ra, rb);
}

#[test]
fn timing_65k_faces() {
    let mesh = plate(180, 1.0, 0.3, 9, bumpy);
    let h0 = random_h0(mesh.0.len(), 9);
    let s = 1.2f64.ln();
    let topo = Topology::build(mesh.0.len(), &mesh.1);
    let (hmax, hsrc, _) = PLATE_SOURCE;
    let (h1, _) = single_source(&mesh, [0.5, 0.5, 0.0], hmax * 10.0, hsrc * 10.0);
    for (name, h0) in [("random H0", &h0), ("single source", &h1)] {
        let mut best = f64::INFINITY;
        let mut out = None;
        for _ in 0..5 {
            let t0 = Instant::now();
            let r = grade(&mesh.0, &mesh.1, &topo, h0, s);
            best = best.min(t0.elapsed().as_secs_f64());
            out = Some(r);
        }
        let (h, rep) = out.unwrap();
        assert_valid(&mesh, h0, &h, &rep, s);
        println!(
            "grade, {name}, {} faces: {:.2} ms (best of 5); {rep:?}",
            mesh.1.len(),
            best * 1e3
        );
    }
}

#[test]
fn lowering_a_sliver_never_goes_below_its_smallest_corner() {
    // Slivers of every shape and orientation with corners far apart in value:
    // the L2 projection alone can send a corner far below the smallest one
    // (even below zero); the fix must keep every corner in [min, old].
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let t = 0.18;
    let mut below = 0;
    for _ in 0..20_000 {
        let height = 10f64.powf(rng.gen_range(-6.5..-1.0));
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [rng.gen_range(-0.5..1.5), height, 0.0],
        ];
        let h = [0, 1, 2].map(|_| 10f64.powf(rng.gen_range(-2.0..4.0)));
        if face_slope(p[0], p[1], p[2], h[0], h[1], h[2]) <= t {
            continue;
        }
        let lo = h[0].min(h[1]).min(h[2]);
        let new = lower_face(p, h, t * (1.0 - FIX_MARGIN));
        for k in 0..3 {
            assert!(new[k] <= h[k], "raised: {h:?} -> {new:?}");
            below += usize::from(new[k] < lo);
        }
        // (Its slope may miss the bound by rounding on a sliver: fix_faces
        // then flattens the face.)
    }
    assert_eq!(below, 0, "corners lowered below the smallest one");
}

/// Grading the pieces of a grid side by side gives the whole grid's field
/// and report bit for bit: three bodies (two of them sharing a vertex, so
/// one piece) with point-like minima that need every step, a body whose
/// field is already graded, and a vertex on no triangle.
#[test]
fn pieces_grade_as_the_whole() {
    use crate::test_shapes::unit_square;
    let mut v: Vec<[f64; 3]> = Vec::new();
    let mut t: Vec<[u32; 3]> = Vec::new();
    let mut add = |(sv, st): (Vec<[f64; 3]>, Vec<[u32; 3]>), shift: [f64; 3]| {
        let o = v.len() as u32;
        v.extend(
            sv.into_iter()
                .map(|p| [p[0] + shift[0], p[1] + shift[1], p[2] + shift[2]]),
        );
        t.extend(st.into_iter().map(|x| x.map(|i| i + o)));
    };
    add(unit_square(12, |x, y| 0.2 * x * y), [0.0; 3]);
    add(unit_square(9, |_, _| 0.0), [3.0, 0.0, 0.0]);
    add(unit_square(7, |x, _| 0.3 * x), [6.0, 0.0, 0.0]);
    // A body touching the first at its corner (1, 1, 0.2): one piece with it.
    let corner = v.iter().position(|p| *p == [1.0, 1.0, 0.2]).unwrap() as u32;
    let o = v.len() as u32;
    v.extend([[2.0, 1.0, 0.2], [1.0, 2.0, 0.2]]);
    t.push([corner, o, o + 1]);
    v.push([9.0, 9.0, 9.0]); // on no triangle
    let topo = crate::mesh::Topology::build(v.len(), &t);
    let s = 0.3;
    let mut seed = 11;
    let mut h0: Vec<f64> = v
        .iter()
        .map(|p| {
            if p[0] >= 6.0 {
                0.5
            } else {
                0.05 + crate::test_shapes::rng(&mut seed)
            }
        })
        .collect();
    h0[5] = 0.001;
    h0[200] = 0.002;
    let pieces = super::parts::Pieces::new(&v, &t).expect("several pieces");
    assert_eq!(pieces.len(), 3);
    for h0 in [h0.clone(), vec![0.4; v.len()]] {
        let whole = super::grade(&v, &t, &topo, &h0, s);
        let parts = pieces.grade(&v, &t, &h0, s);
        let bits = |h: &[f64]| h.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&whole.0), bits(&parts.0));
        assert_eq!(whole.1, parts.1);
    }
    let whole = super::grade(&v, &t, &topo, &h0, s);
    assert!(whole.1.faces_fixed > 0 && whole.1.vertices_lowered > 0);
}
