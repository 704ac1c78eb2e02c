use super::*;
use crate::mesh::BuildOptions;

/// The unit square `n × n` (two triangles per cell), lifted to `z(x, y)`, with
/// sizes `h(x, y, z)` (none when `h` is `None`).
fn plate(n: usize, z: impl Fn(f64, f64) -> f64, h: Option<&dyn Fn([f64; 3]) -> f64>) -> Grid {
    let (v, t) = crate::test_shapes::unit_square(n, z);
    let s = h.map(|h| v.iter().map(|&p| h(p)).collect());
    Grid::from_arrays(v, t, s, &BuildOptions::default()).unwrap()
}

fn flat(_: f64, _: f64) -> f64 {
    0.0
}

fn bumpy(x: f64, y: f64) -> f64 {
    0.08 * (6.0 * x).sin() * (5.0 * y).cos()
}

fn field(p: [f64; 3]) -> f64 {
    0.02 + 0.05 * p[0] + 0.03 * p[1] * p[1] + 0.1 * p[2].abs()
}

fn params(samples: usize) -> EvalParams {
    EvalParams {
        samples,
        hausdorff_samples: samples,
        seed: 3,
    }
}

#[test]
fn identical_grids_agree_exactly() {
    let g = plate(40, bumpy, Some(&field));
    let e = evaluate(&g, &g, &params(20_000)).unwrap();
    assert_eq!(e.reduction, 0.0);
    assert_eq!((e.faces_reference, e.faces_candidate), (3200, 3200));
    assert_eq!((e.vertices_reference, e.vertices_candidate), (1681, 1681));
    let d = e.size_deviation;
    assert_eq!((d.mean, d.p95, d.max, d.samples), (1.0, 1.0, 1.0, 20_000));
    assert!(
        e.hausdorff <= 1e-15 && e.hausdorff_relative <= 1e-15,
        "{e:?}"
    );
    assert!(e.element_count_change.abs() < 1e-12, "{e:?}");
    assert_eq!(e.angles_reference, e.angles_candidate);
    assert!(e.diagonal > 2f64.sqrt() && e.seconds >= 0.0);
}

#[test]
fn constant_size_counts_area_over_h_squared() {
    let h = 0.05;
    let g = plate(7, flat, Some(&|_| h));
    let want = 4.0 / 3f64.sqrt() / (h * h);
    let own = estimated_element_count(&g, None).unwrap();
    assert!((own / want - 1.0).abs() < 1e-12, "{own} vs {want}");
    // The same through a (coarser) sizing grid, and on a surface without sizes.
    let sizing = plate(2, flat, Some(&|_| h));
    let bare = plate(5, flat, None);
    for c in [
        estimated_element_count(&g, Some(&sizing)).unwrap(),
        estimated_element_count(&bare, Some(&sizing)).unwrap(),
    ] {
        assert!((c / want - 1.0).abs() < 1e-12, "{c} vs {want}");
    }
}

#[test]
fn linear_field_seven_point_rule_converges() {
    // h = 1 + x + 2y on the unit square: ∫ h⁻² dA = ln(3/2) / 2.
    let lin = |p: [f64; 3]| 1.0 + p[0] + 2.0 * p[1];
    let exact = 4.0 / 3f64.sqrt() * 0.5 * 1.5f64.ln();
    let coarse = plate(1, flat, Some(&lin));
    let fine = plate(64, flat, Some(&lin));
    let c = estimated_element_count(&coarse, None).unwrap();
    let f = estimated_element_count(&fine, None).unwrap();
    let (ec, ef) = ((c / exact - 1.0).abs(), (f / exact - 1.0).abs());
    assert!(
        ec < 1e-2 && ef < 1e-10 && ef < ec,
        "coarse {ec:e}, fine {ef:e}"
    );
    // The coarse grid represents the linear field exactly: as a sizing grid of
    // the fine surface it gives the fine count.
    let through = estimated_element_count(&fine, Some(&coarse)).unwrap();
    assert!((through / f - 1.0).abs() < 1e-12, "{through} vs {f}");
    // Reference fine, candidate coarse: no size deviation, change 0, and the
    // reduction of 128 faces to 2.
    let e = evaluate(&fine, &coarse, &params(10_000)).unwrap();
    assert!(e.size_deviation.max < 1.0 + 1e-12, "{e:?}");
    assert!(e.element_count_change.abs() < 1e-12);
    assert_eq!(e.reduction, 1.0 - 2.0 / 8192.0);
    assert!(e.hausdorff < 1e-15);
}

#[test]
fn doubled_sizes_deviate_by_two_and_quarter_the_count() {
    let g = plate(30, bumpy, Some(&field));
    let doubled = plate(30, bumpy, Some(&|p| 2.0 * field(p)));
    let e = evaluate(&g, &doubled, &params(20_000)).unwrap();
    let d = e.size_deviation;
    for x in [d.mean, d.p95, d.max] {
        assert!((x - 2.0).abs() < 1e-12, "{d:?}");
    }
    assert!((e.element_count_change + 0.75).abs() < 1e-12, "{e:?}");
    assert!((e.element_count_reference / e.element_count_candidate - 4.0).abs() < 1e-12);
    // Symmetric ratio: halved sizes deviate by 2 as well.
    let back = size_deviation(&doubled, &g, 5_000, 1).unwrap();
    assert!((back.mean - 2.0).abs() < 1e-12 && back.samples == 5_000);
}

#[test]
fn deviation_of_a_constant_candidate() {
    // Reference h = 1 + x, candidate h = 1: ratio 1 + x, mean 1.5, p95 1.95, max 2.
    let r = plate(20, flat, Some(&|p| 1.0 + p[0]));
    let c = plate(3, flat, Some(&|_| 1.0));
    let d = size_deviation(&r, &c, 40_000, 9).unwrap();
    assert!((d.mean - 1.5).abs() < 5e-3, "{d:?}");
    assert!((d.p95 - 1.95).abs() < 5e-3, "{d:?}");
    assert!(d.max <= 2.0 && d.max > 1.99, "{d:?}");
}

#[test]
fn hausdorff_is_the_exact_maximum_over_its_samples() {
    // The sweep skips points proven within the running maximum; the result must
    // still be the largest exact distance over every sample and vertex.
    let a = plate(40, bumpy, None);
    let b = plate(9, |x, y| 0.8 * bumpy(x, y), None);
    for (from, to) in [(&a, &b), (&b, &a)] {
        let mut pts: Vec<[f64; 3]> = surface_points(from, 5000, 11)
            .into_iter()
            .map(|s| s.1)
            .collect();
        pts.extend_from_slice(from.vertices());
        let brute = pts
            .iter()
            .map(|&p| to.bvh().closest(p, None).unwrap().closest.dist2)
            .fold(0.0, f64::max)
            .sqrt();
        assert!(brute > 0.0);
        assert_eq!(
            hausdorff_directed(from, to, 5000, 11).to_bits(),
            brute.to_bits()
        );
    }
}

#[test]
fn same_bits_whatever_the_thread_count() {
    let reference = plate(60, bumpy, Some(&field));
    let candidate = plate(13, |x, y| 0.9 * bumpy(x, y), Some(&|p| 1.3 * field(p)));
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| evaluate(&reference, &candidate, &params(30_000)).unwrap())
    };
    let bits = |e: &Evaluation| {
        let d = e.size_deviation;
        let mut b = vec![
            e.reduction,
            d.mean,
            d.p95,
            d.max,
            e.hausdorff,
            e.hausdorff_relative,
            e.element_count_reference,
            e.element_count_candidate,
            e.element_count_change,
        ];
        for a in [e.angles_reference, e.angles_candidate] {
            b.extend([a.min, a.min_p1, a.min_p5, a.max_p99, a.max, a.mean_min]);
        }
        b.into_iter().map(f64::to_bits).collect::<Vec<u64>>()
    };
    let one = run(1);
    assert!(one.size_deviation.max > 1.3 && one.hausdorff > 0.0);
    for threads in [2, 3] {
        assert_eq!(bits(&one), bits(&run(threads)), "{threads} threads");
    }
}

#[test]
fn angle_stats_of_right_triangles() {
    let a = angle_stats(&plate(4, flat, None));
    for x in [a.min, a.min_p1, a.min_p5, a.mean_min] {
        assert!((x - 45.0).abs() < 1e-9, "{a:?}");
    }
    assert!((a.max - 90.0).abs() < 1e-9 && (a.max_p99 - 90.0).abs() < 1e-9);
}

#[test]
fn errors_instead_of_panics() {
    let sized = plate(4, flat, Some(&|_| 0.1));
    let bare = plate(4, flat, None);
    let p = EvalParams::default();
    assert_eq!((p.samples, p.hausdorff_samples), (100_000, 100_000));
    assert!(matches!(evaluate(&bare, &sized, &p), Err(Error::NoSizes)));
    assert!(matches!(evaluate(&sized, &bare, &p), Err(Error::NoSizes)));
    assert!(matches!(
        size_deviation(&sized, &bare, 10, 1),
        Err(Error::NoSizes)
    ));
    assert!(matches!(
        size_deviation(&sized, &sized, 0, 1),
        Err(Error::InvalidArgument(_))
    ));
    let zero = EvalParams {
        hausdorff_samples: 0,
        ..p
    };
    assert!(matches!(
        evaluate(&sized, &sized, &zero),
        Err(Error::InvalidArgument(_))
    ));
    assert!(matches!(
        estimated_element_count(&bare, None),
        Err(Error::NoSizes)
    ));
    assert!(matches!(
        estimated_element_count(&sized, Some(&bare)),
        Err(Error::NoSizes)
    ));
    assert!(estimated_element_count(&bare, Some(&sized)).is_ok());
    assert!(positive(0.0, "x", [0.0; 3]).is_err());
    assert!(positive(f64::NAN, "x", [0.0; 3]).is_err());
    assert!(positive(f64::INFINITY, "x", [0.0; 3]).is_err());
    assert!(percentile(&[], 0.5).is_nan());
}

#[test]
fn morton_order_is_a_coherent_permutation() {
    // A 16 × 16 lattice, shuffled: the Z-order visits it in 2 × 2 blocks.
    let pts: Vec<[f64; 3]> = (0..256u32)
        .map(|k| {
            let i = (k * 97) % 256;
            [(i % 16) as f64, (i / 16) as f64, 0.0]
        })
        .collect();
    let order = morton_order(&pts);
    let mut seen = order.clone();
    seen.sort_unstable();
    assert_eq!(seen, (0..256).collect::<Vec<u32>>());
    let steps: f64 = order
        .windows(2)
        .map(|w| crate::geometry::dist2(pts[w[0] as usize], pts[w[1] as usize]).sqrt())
        .sum();
    assert!(steps < 2.0 * 256.0, "path length {steps}");
    assert_eq!(
        order[0] as usize,
        pts.iter().position(|p| p == &[0.0; 3]).unwrap()
    );
    assert_eq!(morton_order(&[[1.0; 3]; 3]), vec![0, 1, 2]);
}

/// `g` with every triangle's orientation reversed.
fn flipped(g: &Grid) -> Grid {
    let t = g.triangles().iter().map(|t| [t[0], t[2], t[1]]).collect();
    let opts = BuildOptions {
        weld_relative_tolerance: None,
        orient: false,
    };
    Grid::from_arrays(
        g.vertices().to_vec(),
        t,
        g.sizes().map(|s| s.to_vec()),
        &opts,
    )
    .unwrap()
}

#[test]
fn wrong_sheet_counts_faces_turned_away_and_other_bodies() {
    let g = plate(20, bumpy, Some(&field));
    assert_eq!(size_deviation(&g, &g, 5_000, 1).unwrap().wrong_sheet, 0.0);
    // Every query lands on a face turned away.
    assert_eq!(
        size_deviation(&g, &flipped(&g), 5_000, 1)
            .unwrap()
            .wrong_sheet,
        1.0
    );
    // Two parallel plates 0.2 apart (two bodies); the candidate keeps only the
    // upper one twice over (its lower body lifted onto the upper): the lower
    // plate's samples land on the other body, the upper's do not.
    let (v, t) = crate::test_shapes::unit_square(10, flat);
    let two = |lift: f64| {
        let mut vv = v.clone();
        vv.extend(v.iter().map(|p| [p[0], p[1], p[2] + 0.2]));
        let n = v.len() as u32;
        let mut tt = t.clone();
        tt.extend(t.iter().map(|t| t.map(|i| i + n)));
        for p in vv.iter_mut().take(v.len()) {
            p[2] += lift;
        }
        let h = vec![0.1; vv.len()];
        Grid::from_arrays(vv, tt, Some(h), &BuildOptions::default()).unwrap()
    };
    let reference = two(0.0);
    assert_eq!(reference.topology().body_count, 2);
    let w = size_deviation(&reference, &two(0.3), 20_000, 1)
        .unwrap()
        .wrong_sheet;
    // The lower plate (half the area) moved to z = 0.3: its samples at z = 0
    // are now closer to the upper plate (0.2) than to their own (0.3).
    assert!((w - 0.5).abs() < 0.02, "{w}");
}
