use super::*;
use crate::remesh::quality::hausdorff;

/// A grid without welding or reorientation (the shapes below are built
/// indexed and consistently oriented).
fn build(v: Vec<[f64; 3]>, t: Vec<[u32; 3]>, h: Option<Vec<f64>>) -> Grid {
    let opts = BuildOptions {
        weld_relative_tolerance: None,
        orient: false,
    };
    Grid::from_arrays(v, t, h, &opts).unwrap()
}

/// The unit square in z = 0, n × n quads split into triangles.
fn square(n: usize) -> Grid {
    let (v, t) = crate::test_shapes::unit_square(n, |_, _| 0.0);
    build(v, t, None)
}

/// The unit cube, each face n × n quads, outward.
fn cube(n: usize) -> Grid {
    cubes(n, &[[0.0; 3]])
}

/// Unit cubes at the given offsets, each face n × n quads, outward, welded
/// where they touch.
fn cubes(n: usize, offsets: &[[f64; 3]]) -> Grid {
    let mut v: Vec<[f64; 3]> = Vec::new();
    let mut t = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut id = |p: [f64; 3], v: &mut Vec<[f64; 3]>| {
        let k = p.map(|x| (x * n as f64).round() as i64);
        *index.entry(k).or_insert_with(|| {
            v.push(p);
            (v.len() - 1) as u32
        })
    };
    // (origin, u, v) with u × v outward.
    let faces = [
        ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
    ];
    for off in offsets {
        for (o, du, dv) in faces {
            let p = |i: usize, j: usize| {
                let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
                [0, 1, 2].map(|k| off[k] + o[k] + a * du[k] + b * dv[k])
            };
            for j in 0..n {
                for i in 0..n {
                    let q =
                        [p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)].map(|x| id(x, &mut v));
                    t.push([q[0], q[1], q[2]]);
                    t.push([q[0], q[2], q[3]]);
                }
            }
        }
    }
    build(v, t, None)
}

/// Icosphere of radius `r` centred at `c`, `level` subdivisions.
fn sphere_arrays(r: f64, c: [f64; 3], level: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<[f64; 3]> = vec![
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ];
    let mut t: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let unit = |p: [f64; 3]| scale(p, 1.0 / norm(p));
    for p in v.iter_mut() {
        *p = unit(*p);
    }
    for _ in 0..level {
        let mut mid = std::collections::HashMap::new();
        let mut nt = Vec::new();
        for tri in &t {
            let mut m = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (tri[k].min(tri[(k + 1) % 3]), tri[k].max(tri[(k + 1) % 3]));
                m[k] = *mid.entry((a, b)).or_insert_with(|| {
                    v.push(unit(crate::geometry::add(v[a as usize], v[b as usize])));
                    (v.len() - 1) as u32
                });
            }
            nt.extend([
                [tri[0], m[0], m[2]],
                [tri[1], m[1], m[0]],
                [tri[2], m[2], m[1]],
                m,
            ]);
        }
        t = nt;
    }
    let v = v
        .into_iter()
        .map(|p| crate::geometry::add(scale(p, r), c))
        .collect();
    (v, t)
}

fn sphere(level: usize) -> Grid {
    let (v, t) = sphere_arrays(1.0, [0.0; 3], level);
    build(v, t, None)
}

fn params(target_faces: usize) -> QemParams {
    QemParams {
        target_faces,
        ..Default::default()
    }
}

fn unit_normal(g: &Grid, t: [u32; 3]) -> [f64; 3] {
    let [a, b, c] = t.map(|i| g.vertices()[i as usize]);
    let n = cross(sub(b, a), sub(c, a));
    scale(n, 1.0 / norm(n))
}

fn euler(g: &Grid) -> i64 {
    g.vertices().len() as i64 - g.topology().edges.len() as i64 + g.triangles().len() as i64
}

#[test]
fn flat_square_decimates_to_a_few_faces_and_keeps_its_boundary() {
    let input = square(30);
    let out = decimate(&input, &params(2)).unwrap();
    let g = &out.grid;
    assert_eq!(g.triangles().len(), 2);
    assert_eq!(out.collapses, input.vertices().len() - g.vertices().len());
    assert!(hausdorff(&input, g, 20_000, 1) < 1e-12);
    for corner in [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ] {
        assert!(g.vertices().contains(&corner), "corner {corner:?} lost");
    }
    // The boundary is one loop of length 4 on the square's sides.
    let topo = g.topology();
    let mut length = 0.0;
    for (e, &[a, b]) in topo.edges.iter().enumerate() {
        if topo.faces_of_edge(e).len() == 1 {
            let (pa, pb) = (g.vertices()[a as usize], g.vertices()[b as usize]);
            length += norm(sub(pa, pb));
        }
    }
    assert!((length - 4.0).abs() < 1e-12, "boundary length {length}");
    for &t in g.triangles() {
        assert!(unit_normal(g, t)[2] > 0.999_999);
    }
}

#[test]
fn cube_keeps_corners_and_sharp_edges() {
    let input = cube(8);
    let out = decimate(&input, &params(12)).unwrap();
    let g = &out.grid;
    // The coarsest cube: its 8 corners, 12 faces.
    assert_eq!(g.triangles().len(), 12);
    assert_eq!(g.vertices().len(), 8);
    for i in 0..8 {
        let c = [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64];
        assert!(g.vertices().contains(&c), "corner {c:?} lost");
    }
    // Every face lies in one side of the cube (no face cuts a sharp edge),
    // and the surface is the cube's.
    for &t in g.triangles() {
        let n = unit_normal(g, t);
        assert!(n.iter().any(|x| x.abs() > 1.0 - 1e-9), "normal {n:?}");
    }
    let diag = input.bbox().diagonal();
    assert!(hausdorff(&input, g, 20_000, 1) < 1e-9 * diag);
    let f = Features::detect(g, 30.0);
    let sharp: f64 = g
        .topology()
        .edges
        .iter()
        .enumerate()
        .filter(|&(e, _)| f.is_feature(e))
        .map(|(_, &[a, b])| norm(sub(g.vertices()[a as usize], g.vertices()[b as usize])))
        .sum();
    assert!((sharp - 12.0).abs() < 1e-9, "sharp edges of length {sharp}");
    assert_eq!(euler(g), 2);
}

#[test]
fn sphere_reaches_the_target_without_flips() {
    let input = sphere(4);
    assert_eq!(input.triangles().len(), 5120);
    for target in [500, 121] {
        let out = decimate(&input, &params(target)).unwrap();
        let g = &out.grid;
        let nf = g.triangles().len();
        assert!(nf <= target && nf + 2 >= target, "{nf} faces for {target}");
        assert_eq!(euler(g), 2);
        assert_eq!(g.topology().body_count, 1);
        assert_eq!(g.topology().boundary_edge_count(), 0);
        for &t in g.triangles() {
            let [a, b, c] = t.map(|i| g.vertices()[i as usize]);
            let centroid = scale(
                crate::geometry::add(crate::geometry::add(a, b), c),
                1.0 / 3.0,
            );
            assert!(dot(unit_normal(g, t), centroid) > 0.0);
        }
        let d = hausdorff(&input, g, 20_000, 1);
        assert!(d < 0.1, "Hausdorff {d} at {target} faces");
    }
}

#[test]
fn two_bodies_stay_apart() {
    let (mut v, mut t) = sphere_arrays(1.0, [0.0; 3], 3);
    let (v2, t2) = sphere_arrays(0.5, [1.6, 0.0, 0.0], 3);
    let o = v.len() as u32;
    v.extend(v2);
    t.extend(t2.into_iter().map(|x| x.map(|i| i + o)));
    let input = build(v, t, None);
    let out = decimate(&input, &params(200)).unwrap();
    let g = &out.grid;
    assert_eq!(g.triangles().len(), 200);
    assert_eq!(g.topology().body_count, 2);
    assert_eq!(euler(g), 4);
}

#[test]
fn non_manifold_edge_between_touching_cubes_is_kept() {
    // Two cubes sharing the edge x = y = 1: its vertices are locked.
    let n = 6;
    let input = cubes(n, &[[0.0; 3], [1.0, 1.0, 0.0]]);
    assert_eq!(input.topology().non_manifold_edge_count(), n);
    let out = decimate(&input, &params(24)).unwrap();
    let g = &out.grid;
    assert!(g.triangles().len() < input.triangles().len() / 4);
    assert_eq!(g.topology().non_manifold_edge_count(), n);
    for k in 0..=n {
        let p = [1.0, 1.0, k as f64 / n as f64];
        assert!(g.vertices().contains(&p), "locked vertex {p:?} lost");
    }
    let diag = input.bbox().diagonal();
    assert!(hausdorff(&input, g, 20_000, 1) < 1e-9 * diag);
}

fn sized_sphere() -> Grid {
    let (v, t) = sphere_arrays(1.0, [0.0; 3], 4);
    let h = v.iter().map(|p| 0.1 + 0.05 * p[2] + 0.02 * p[0]).collect();
    build(v, t, Some(h))
}

#[test]
fn sizes_are_reprojected_from_the_input() {
    let input = sized_sphere();
    let out = decimate(&input, &params(400)).unwrap();
    let g = &out.grid;
    let h = g.sizes().expect("output has sizes");
    for (p, &s) in g.vertices().iter().zip(h) {
        assert_eq!(s, input.query_size(*p).unwrap());
    }
    // No sizes in, none out.
    assert!(decimate(&sphere(3), &params(400))
        .unwrap()
        .grid
        .sizes()
        .is_none());
}

#[test]
fn result_is_deterministic() {
    let input = sized_sphere();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let g = pool.install(|| decimate(&input, &params(300)).unwrap().grid);
        (
            g.vertices().to_vec(),
            g.triangles().to_vec(),
            g.sizes().unwrap().to_vec(),
        )
    };
    let a = run(1);
    assert!(a == run(2), "1 and 2 threads differ");
    assert!(a == run(2), "two runs differ");
    let c1 = decimate(&cube(6), &params(40)).unwrap().grid;
    let c2 = decimate(&cube(6), &params(40)).unwrap().grid;
    assert_eq!(c1.vertices(), c2.vertices());
    assert_eq!(c1.triangles(), c2.triangles());
}

#[test]
fn target_above_the_input_changes_nothing() {
    let input = sized_sphere();
    let out = decimate(&input, &params(1_000_000)).unwrap();
    assert_eq!(out.collapses, 0);
    let g = &out.grid;
    assert_eq!(g.vertices().len(), input.vertices().len());
    assert_eq!(g.triangles().len(), input.triangles().len());
    assert!(hausdorff(&input, g, 10_000, 1) < 1e-12);
    // Re-projected sizes at unmoved vertices are the input's.
    for (p, &s) in g.vertices().iter().zip(g.sizes().unwrap()) {
        let i = input.vertices().iter().position(|q| q == p).unwrap();
        assert!((s - input.sizes().unwrap()[i]).abs() < 1e-12);
    }
}

#[test]
fn bad_parameters_are_errors() {
    let input = square(4);
    let bad = [
        QemParams {
            target_faces: 0,
            ..Default::default()
        },
        QemParams {
            feature_angle_deg: f64::NAN,
            ..Default::default()
        },
        QemParams {
            feature_angle_deg: 200.0,
            ..Default::default()
        },
        QemParams {
            max_normal_turn_deg: 0.0,
            ..Default::default()
        },
        QemParams {
            boundary_weight: -1.0,
            ..Default::default()
        },
        QemParams {
            boundary_weight: f64::INFINITY,
            ..Default::default()
        },
    ];
    for p in bad {
        assert!(
            matches!(decimate(&input, &p), Err(Error::InvalidArgument(_))),
            "{p:?}"
        );
    }
}

#[test]
fn quadric_optimum_and_fallback() {
    // Three orthogonal planes through (1, 2, 3): optimum there, cost 0.
    let p = [1.0, 2.0, 3.0];
    let mut q = Quadric::default();
    for n in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] {
        q = q.add(&Quadric::plane(n, -dot(n, p), 2.0));
    }
    let x = q.optimum().unwrap();
    assert!(norm(sub(x, p)) < 1e-12);
    assert_eq!(q.eval(x), 0.0);
    assert!((q.eval([0.0, 2.0, 3.0]) - 2.0).abs() < 1e-12);
    // One plane: singular, no optimum.
    let single = Quadric::plane([0.0, 0.0, 1.0], -1.0, 1.0);
    assert!(single.optimum().is_none());
}

/// The cofactor solve the optimum used before nalgebra.
fn cofactor_optimum(q: &Quadric) -> Option<[f64; 3]> {
    let [a00, a01, a02, a11, a12, a22] = q.a;
    let c00 = a11 * a22 - a12 * a12;
    let c01 = a02 * a12 - a01 * a22;
    let c02 = a01 * a12 - a02 * a11;
    let det = a00 * c00 + a01 * c01 + a02 * c02;
    let tr = (a00 + a11 + a22) / 3.0;
    if !(det.is_finite() && tr > 0.0 && det.abs() > 1e-10 * tr * tr * tr) {
        return None;
    }
    let c11 = a00 * a22 - a02 * a02;
    let c12 = a01 * a02 - a00 * a12;
    let c22 = a00 * a11 - a01 * a01;
    let r = [-q.b[0], -q.b[1], -q.b[2]];
    Some([
        (c00 * r[0] + c01 * r[1] + c02 * r[2]) / det,
        (c01 * r[0] + c11 * r[1] + c12 * r[2]) / det,
        (c02 * r[0] + c12 * r[1] + c22 * r[2]) / det,
    ])
}

#[test]
fn optimum_equals_the_cofactor_solve() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let mut solved = 0;
    for _ in 0..2000 {
        // A sum of a few random planes: positive semi-definite, as in decimation.
        let mut q = Quadric::default();
        for _ in 0..rng.gen_range(2..6) {
            let n = [0, 1, 2].map(|_| rng.gen_range(-1.0..1.0));
            let l = norm(n);
            let n = scale(n, 1.0 / l);
            q = q.add(&Quadric::plane(
                n,
                rng.gen_range(-2.0..2.0),
                rng.gen_range(0.1..3.0),
            ));
        }
        let (a, b) = (q.optimum(), cofactor_optimum(&q));
        assert_eq!(a.is_some(), b.is_some());
        if let (Some(a), Some(b)) = (a, b) {
            // Relative to the solution's size, scaled by the conditioning
            // the test admits (det above 1e-10 of (trace/3)³): within 1e-12
            // for the well-conditioned ones.
            let m = norm(b).max(1.0);
            let err = norm(sub(a, b)) / m;
            let tr = q.a[0] + q.a[3] + q.a[5];
            let cond = tr * tr * tr / 27.0 / cofactor_det(&q).abs();
            assert!(err <= 1e-12 * cond.max(1.0), "{a:?} vs {b:?} (cond {cond})");
            if cond < 1e3 {
                assert!(err <= 1e-12, "{a:?} vs {b:?}");
                solved += 1;
            }
        }
    }
    assert!(solved > 500, "{solved}");
}

fn cofactor_det(q: &Quadric) -> f64 {
    let [a00, a01, a02, a11, a12, a22] = q.a;
    a00 * (a11 * a22 - a12 * a12) + a01 * (a02 * a12 - a01 * a22) + a02 * (a01 * a12 - a02 * a11)
}
