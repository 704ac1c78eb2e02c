//! GCN-ABGS: training graphs along an LBO-ABGS run (their targets are the
//! accurate estimate's own numbers), the embedded model through the `ort`
//! API (deterministic, bad models refused), and the learned loop (same bits
//! for any thread count, topology kept, sizes faithful).
#![cfg(feature = "gcn")]

mod common;

use abgs::gcn::dataset::{trajectory, write, DatasetParams, FORMAT};
use abgs::simplify::{edge_scores, simplify, Method, SimplifyParams};
use abgs::Grid;
use common::shapes::icosphere;
use common::{euler, with_sizes};

/// A sphere of radius 1 with a size field that varies over it.
fn sized_sphere(level: usize) -> Grid {
    with_sizes(&icosphere(1.0, level), |p| {
        0.08 + 0.06 * (1.0 + p[0]) + 0.02 * p[2] * p[2]
    })
}

fn sorted_bits(mut v: Vec<[f32; 2]>) -> Vec<[u32; 2]> {
    v.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    v.iter().map(|x| x.map(f32::to_bits)).collect()
}

#[test]
fn dataset_targets_are_the_accurate_estimates_along_the_run() {
    let g = sized_sphere(4);
    let params = SimplifyParams::default();
    let dp = DatasetParams::default();
    let (snaps, report) = trajectory(&g, &params, &dp).unwrap();
    assert!(
        snaps.len() >= 3 && snaps.len() <= dp.snapshots,
        "{}",
        snaps.len()
    );
    // The dense grid first, the result last, faces falling in between.
    assert_eq!(snaps[0].faces, report.faces_in);
    assert_eq!(snaps.last().unwrap().faces, report.faces_out);
    assert!(snaps.windows(2).all(|w| w[1].faces < w[0].faces));
    for s in &snaps {
        s.graph.check().unwrap();
        let e = s.graph.n_edges;
        assert_eq!((s.target.len(), s.valid.len(), s.y.len()), (e, e, e));
        for i in 0..e {
            let t = s.target[i];
            if s.valid[i] == 1 {
                assert!(t[0] >= 0.0 && t[1] >= 0.0, "{t:?}");
                assert!(s.allow_rel[i] > 0.0);
            } else {
                assert!(t[0].is_nan() && t[1].is_nan() && s.y[i] == 1.0);
            }
        }
    }
    // The first snapshot's targets are exactly the dense grid's edge scores.
    let scores = edge_scores(&g, &params).unwrap();
    let expect: Vec<[f32; 2]> = scores
        .iter()
        .filter(|s| s.valid)
        .map(|s| [(s.ds - 1.0) as f32, s.dd_rel as f32])
        .collect();
    let got: Vec<[f32; 2]> = (0..snaps[0].graph.n_edges)
        .filter(|&i| snaps[0].valid[i] == 1)
        .map(|i| snaps[0].target[i])
        .collect();
    assert_eq!(sorted_bits(got), sorted_bits(expect));
    // Collapsible share falls along the run; none is left at convergence
    // (the loop stops only when every edge was a candidate or is known not to
    // be collapsible).
    let last = snaps.last().unwrap();
    let coll = |s: &abgs::gcn::dataset::Snapshot| {
        (0..s.graph.n_edges)
            .filter(|&i| s.valid[i] == 1 && s.y[i] < 0.5)
            .count()
    };
    assert!(coll(&snaps[0]) > 0);
    assert!(
        coll(last) * 10 < coll(&snaps[0]),
        "{} {}",
        coll(last),
        coll(&snaps[0])
    );
}

#[test]
fn dataset_file_reads_back() {
    let g = sized_sphere(3);
    let dp = DatasetParams {
        snapshots: 3,
        face_ratio: 0.5,
    };
    let (snaps, _) = trajectory(&g, &SimplifyParams::default(), &dp).unwrap();
    let dir = std::env::temp_dir().join(format!("abgs_gcn_ds_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("d.safetensors");
    write(&path, &snaps, &[("source", "sphere".into())]).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let (_, meta) = safetensors::SafeTensors::read_metadata(&bytes).unwrap();
    let info = meta.metadata().as_ref().unwrap();
    assert_eq!(info["format"], FORMAT);
    assert_eq!(info["snapshots"], snaps.len().to_string());
    assert_eq!(info["source"], "sphere");
    let st = safetensors::SafeTensors::deserialize(&bytes).unwrap();
    for (s, snap) in snaps.iter().enumerate() {
        let t = st.tensor(&format!("{s}/edge_x")).unwrap();
        assert_eq!(t.shape(), &[snap.graph.n_edges, 8]);
        let back: Vec<f32> = t
            .data()
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(back, snap.graph.edge_x);
        let k = st.tensor(&format!("{s}/nbr_node")).unwrap();
        assert_eq!(k.shape(), &[snap.graph.n_nodes, snap.graph.k]);
    }
    // A bad schedule is refused.
    let bad = DatasetParams {
        snapshots: 1,
        face_ratio: 0.5,
    };
    assert!(trajectory(&g, &SimplifyParams::default(), &bad).is_err());
    std::fs::remove_dir_all(&dir).ok();
}

/// The vertices, triangles and sizes of a grid as bits.
fn bits(g: &Grid) -> (Vec<[u64; 3]>, Vec<[u32; 3]>, Vec<u64>) {
    (
        g.vertices().iter().map(|p| p.map(f64::to_bits)).collect(),
        g.triangles().to_vec(),
        g.sizes().unwrap().iter().map(|h| h.to_bits()).collect(),
    )
}

/// The evaluation of a simplified sphere against its dense grid.
fn eval_params() -> abgs::metrics::EvalParams {
    abgs::metrics::EvalParams {
        samples: 20_000,
        hausdorff_samples: 20_000,
        ..Default::default()
    }
}

/// GCN-ABGS (defaults, no verify) on `g` with the embedded model, its scorer
/// set up by `configure`; the result and what `count` reads off the scorer
/// afterwards.
fn run_learned(
    g: &Grid,
    configure: impl FnOnce(&mut abgs::gcn::Learned),
    count: impl FnOnce(&abgs::gcn::Learned) -> usize,
) -> (abgs::simplify::Simplified, usize) {
    let mut scorer = abgs::gcn::Learned::new(abgs::gcn::embedded_model().unwrap());
    configure(&mut scorer);
    let s = abgs::simplify::simplify_with(g, &gcn_params(false), &mut scorer, None).unwrap();
    (s, count(&scorer))
}

/// `out`, simplified from the sized sphere `g`, keeps its field (size
/// deviation p95 < 1.2) and stays a closed sphere (Euler characteristic 2).
fn keeps_the_field(g: &Grid, out: &Grid) {
    let e = abgs::metrics::evaluate(g, out, &eval_params()).unwrap();
    assert!(e.size_deviation.p95 < 1.2, "{}", e.size_deviation.p95);
    assert_eq!(euler(out), 2);
}

fn gcn_params(verify: bool) -> SimplifyParams {
    SimplifyParams {
        method: Method::Gcn,
        verify,
        ..Default::default()
    }
}

#[test]
fn embedded_model_predictions_are_deterministic_and_non_negative() {
    let g = sized_sphere(3);
    let (mesh, _) = abgs::mesh::halfedge::HalfedgeMesh::from_grid(&g, None);
    let mut mesh = mesh;
    for v in 0..mesh.n_vertices() {
        mesh.vertex_size[v] = g.sizes().unwrap()[mesh.vertex_origin[v] as usize];
    }
    let graph = abgs::gcn::features::graph(&mesh).unwrap();
    let model = abgs::gcn::embedded_model().unwrap();
    let a = model.predict(&graph.inputs).unwrap();
    let b = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(|| model.predict(&graph.inputs).unwrap());
    assert_eq!(a.len(), graph.inputs.n_edges);
    assert_eq!(
        a.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>(),
        b.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>()
    );
    assert!(a.iter().flatten().all(|x| x.is_finite() && *x >= 0.0));
}

#[test]
fn gcn_abgs_same_bits_on_one_and_two_threads() {
    let g = sized_sphere(4);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| simplify(&g, &gcn_params(false), None).unwrap())
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(bits(&one.grid), bits(&two.grid));
    assert_eq!(one.report.faces_out, two.report.faces_out);
}

#[test]
fn gcn_abgs_simplifies_and_keeps_the_field() {
    let g = sized_sphere(4);
    let ep = eval_params();
    let lbo = simplify(&g, &SimplifyParams::default(), None).unwrap();
    for verify in [false, true] {
        let s = simplify(&g, &gcn_params(verify), None).unwrap();
        let r = &s.report;
        assert!(
            r.faces_out < r.faces_in / 4,
            "verify {verify}: {} faces",
            r.faces_out
        );
        // A closed sphere stays a closed sphere (Euler characteristic 2).
        let out = &s.grid;
        assert_eq!(euler(out), 2);
        let e = abgs::metrics::evaluate(&g, out, &ep).unwrap();
        assert!(
            e.size_deviation.p95 < 1.25,
            "verify {verify}: size deviation p95 {}",
            e.size_deviation.p95
        );
        // Within a factor of two of LBO-ABGS's face count.
        let ratio = r.faces_out as f64 / lbo.report.faces_out as f64;
        assert!(
            (0.5..2.0).contains(&ratio),
            "verify {verify}: faces ratio {ratio}"
        );
    }
}

#[test]
fn a_model_that_cannot_run_is_an_error() {
    use abgs::gcn::{Learned, Model};
    assert!(Model::from_bytes(b"not an onnx model").is_err());
    let missing = std::env::temp_dir().join("abgs_no_such_model.onnx");
    let e = Model::from_file(&missing).err().unwrap();
    assert!(e.to_string().contains("abgs_no_such_model"), "{e}");
    // A truncated copy of the embedded model.
    let cut = &abgs::gcn::EMBEDDED_MODEL[..abgs::gcn::EMBEDDED_MODEL.len() / 2];
    assert!(Model::from_bytes(cut).is_err());
    // A good model still works through the seam.
    let m = Model::from_bytes(abgs::gcn::EMBEDDED_MODEL).unwrap();
    let s = abgs::simplify::simplify_with(
        &sized_sphere(3),
        &gcn_params(false),
        &mut Learned::new(&m),
        None,
    )
    .unwrap();
    assert!(s.report.faces_out < s.report.faces_in);
}

#[test]
fn the_tail_goes_on_where_the_model_stops_and_keeps_the_field() {
    let g = sized_sphere(4);
    let run = |tail: bool| run_learned(&g, |s| s.tail = tail, |s| s.tail_checks());
    let (without, no_checks) = run(false);
    let (with, checks) = run(true);
    assert_eq!(no_checks, 0);
    assert!(checks > 0, "the tail made no accurate estimate");
    // Both runs are the same until the model's choices run out, where the
    // run without the tail stops; the tail then removes more.
    assert!(
        with.report.faces_out < without.report.faces_out,
        "tail {} faces, without {}",
        with.report.faces_out,
        without.report.faces_out
    );
    keeps_the_field(&g, &with.grid);
}

#[test]
fn reused_predictions_save_forward_passes_and_keep_the_field() {
    let g = sized_sphere(4);
    let run = |share: f64| run_learned(&g, |s| s.stale_share = share, |s| s.passes());
    // Share 0: a pass whenever an edge changed, i.e. every iteration.
    let (every, every_passes) = run(0.0);
    let (reused, reused_passes) = run(abgs::gcn::scorer::STALE_SHARE);
    assert!(every_passes >= every.report.iterations.len());
    assert!(
        reused_passes < every_passes,
        "reuse {reused_passes} passes, every iteration {every_passes}"
    );
    for s in [&every, &reused] {
        keeps_the_field(&g, &s.grid);
    }
    // Reuse is a cheaper ranking, not a coarser result.
    let (a, b) = (
        every.report.faces_out as f64,
        reused.report.faces_out as f64,
    );
    assert!((a - b).abs() <= 0.2 * a, "{a} vs {b} faces");
}
