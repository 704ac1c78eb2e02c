use super::field::{Source, SourceField};
use super::{run, RemeshParams};
use crate::geometry::closest_point_triangle;
use crate::test_shapes::{canonical_triangles, rng, touching_sheets};

#[test]
fn source_field_equals_brute_force() {
    let mut seed = 7;
    let p = |s: &mut u64| [rng(s) * 10.0, rng(s) * 10.0, rng(s) * 10.0];
    let mut sources: Vec<Source> = Vec::new();
    for i in 0..300 {
        let a = p(&mut seed);
        let b = p(&mut seed);
        let c = p(&mut seed);
        // Points, segments and triangles.
        let prim = match i % 3 {
            0 => [a; 3],
            1 => [a, b, b],
            _ => [a, b, c],
        };
        sources.push((prim, 0.1 + rng(&mut seed)));
    }
    sources.push(([[0.0; 3]; 3], f64::INFINITY)); // ignored
    let slope = 0.3;
    let field = SourceField::new(&sources, slope);
    for _ in 0..500 {
        let q = [
            rng(&mut seed) * 14.0 - 2.0,
            rng(&mut seed) * 14.0 - 2.0,
            rng(&mut seed) * 14.0 - 2.0,
        ];
        let brute = sources
            .iter()
            .filter(|s| s.1.is_finite())
            .map(|(t, h)| h + slope * closest_point_triangle(q, t[0], t[1], t[2]).dist2.sqrt())
            .fold(f64::INFINITY, f64::min);
        assert_eq!(field.eval(q), brute, "at {q:?}");
        // Seeded by this query's own winner, then by a far point's.
        assert_eq!(field.eval(q), brute, "at {q:?}, seeded");
        field.eval([1e3, -1e3, 1e3]);
        assert_eq!(field.eval(q), brute, "at {q:?}, seeded far away");
    }
    assert_eq!(SourceField::new(&[], slope).eval([0.0; 3]), f64::INFINITY);
}

/// Remeshing the parts (bodies) apart, in parallel, gives the triangles of
/// remeshing the whole mesh at once, and the same counts.
#[test]
fn parts_remeshed_apart_are_the_whole_remeshed() {
    let g = touching_sheets();
    let params = RemeshParams {
        iterations: 4,
        ..RemeshParams::default()
    };
    let l0 = 0.09;
    let whole = run(&g, None, Some(l0), &params, true).unwrap();
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let parts = pool.install(|| run(&g, None, Some(l0), &params, false).unwrap());
        let (a, b) = (&whole.grid, &parts.grid);
        assert!(a.triangles().len() > 4 * g.triangles().len());
        assert_eq!(a.vertices().len(), b.vertices().len());
        assert_eq!(
            canonical_triangles(a.vertices(), a.triangles()),
            canonical_triangles(b.vertices(), b.triangles())
        );
        let counts = |r: &super::RemeshReport| {
            r.iterations
                .iter()
                .map(|i| {
                    [
                        i.splits,
                        i.collapses,
                        i.flips,
                        i.cut_moves,
                        i.vertices,
                        i.faces,
                    ]
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(counts(&whole.report), counts(&parts.report));
        assert_eq!(whole.report.final_flips, parts.report.final_flips);
        let key = |g: &crate::mesh::Grid, e: &[[u32; 2]]| {
            let mut k: Vec<[[u64; 3]; 2]> = e
                .iter()
                .map(|x| {
                    let mut c = x.map(|i| g.vertices()[i as usize].map(f64::to_bits));
                    c.sort();
                    c
                })
                .collect();
            k.sort();
            k
        };
        assert_eq!(key(a, &whole.feature_edges), key(b, &parts.feature_edges));
    }
}

/// The parts' scheduling key predicts what remeshing makes: on a flat unit
/// square of two input triangles at L = 0.05, exactly the area over an
/// equilateral triangle's and within a fifth of the faces the remesher
/// writes; a part without a finite target counts nothing.
#[test]
fn expected_faces_predicts_the_output() {
    use crate::mesh::halfedge::HalfedgeMesh;
    let opts = crate::mesh::BuildOptions {
        weld_relative_tolerance: Some(1e-9),
        orient: false,
    };
    let (v, t) = crate::test_shapes::unit_square(1, |_, _| 0.0);
    let g = crate::mesh::Grid::from_arrays(v, t, None, &opts).unwrap();
    let l0 = 0.05;
    let (mut m, _) = HalfedgeMesh::from_grid(&g, None);
    m.vertex_size.iter_mut().for_each(|h| *h = l0);
    let expected = super::expected_faces(&m);
    let want = 4.0 / 3f64.sqrt() / (l0 * l0);
    assert!(
        (expected - want).abs() < 1e-9 * want,
        "{expected} vs {want}"
    );
    let made = run(&g, None, Some(l0), &RemeshParams::default(), false)
        .unwrap()
        .grid
        .triangles()
        .len() as f64;
    assert!(
        (made - expected).abs() < 0.2 * made,
        "expected {expected}, made {made}"
    );
    m.vertex_size.iter_mut().for_each(|h| *h = f64::INFINITY);
    assert_eq!(super::expected_faces(&m), 0.0);
}

/// A body expected to make many more triangles than `piece_faces` is cut
/// along its creases into pieces remeshed side by side: the output is one
/// closed body with no seam (every cut vertex merged), the same bits for
/// any thread count, and passes the dense grid's acceptance; with no cut it
/// reports no pieces.
#[test]
fn a_large_body_is_cut_into_pieces_with_no_seam() {
    let g = crate::test_shapes::box_grid(4);
    let l0 = 0.05;
    let params = RemeshParams {
        iterations: 6,
        piece_faces: 1_000.0,
        ..RemeshParams::default()
    };
    let mut outs = Vec::new();
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        outs.push(pool.install(|| run(&g, None, Some(l0), &params, false).unwrap()));
    }
    let out = &outs[0];
    let r = &out.report;
    assert!(r.pieces >= 2, "{r:?}");
    assert!(r.build.cut_edges > 0 && r.build.cut_vertices > 0, "{r:?}");
    assert_eq!(r.build.split_vertices + r.build.locked_edges, 0, "{r:?}");
    assert!(r.issues.is_empty(), "{:?}", r.issues);
    let (v, t) = (out.grid.vertices(), out.grid.triangles());
    let topo = out.grid.topology();
    assert_eq!(topo.body_count, 1);
    assert!((0..topo.edges.len()).all(|e| topo.faces_of_edge(e).len() == 2));
    // A closed sphere-like surface: V − E + F = 2.
    assert_eq!(v.len() + t.len(), topo.edges.len() + 2);
    let a = super::quality::evaluate(&g, &out.grid, Some(&out.feature_edges), 30.0, 20_000);
    assert!(a.failures().is_empty(), "{:?}\n{a:?}", a.failures());
    let b = &outs[1].grid;
    assert_eq!(
        canonical_triangles(v, t),
        canonical_triangles(b.vertices(), b.triangles())
    );
    let whole = RemeshParams {
        piece_faces: f64::INFINITY,
        ..params
    };
    let w = run(&g, None, Some(l0), &whole, false).unwrap();
    assert_eq!(w.report.pieces + w.report.build.cut_edges, 0);
    assert!(run(
        &g,
        None,
        Some(l0),
        &RemeshParams {
            piece_faces: 0.0,
            ..whole.clone()
        },
        false
    )
    .is_err());
    assert!(run(
        &g,
        None,
        Some(l0),
        &RemeshParams {
            piece_faces: 0.5,
            ..whole.clone()
        },
        false
    )
    .is_err());
}
