//! Tests of the model runtime on the fixture of `training/make_fixture.py`. They run on
//! the process's backend: tract in the default build, ONNX Runtime with the
//! `onnxruntime` feature (and `ORT_DYLIB_PATH` set).

use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const FIXTURE: &[u8] = include_bytes!("../testdata/fixture.onnx");
const EXPECTED: &str = include_str!("../testdata/fixture_expected.json");
const BAD_NODE_FEATURES: &[u8] = include_bytes!("../testdata/bad_node_features.onnx");
const BAD_MASK_RANK: &[u8] = include_bytes!("../testdata/bad_mask_rank.onnx");
const BAD_OUTPUT: &[u8] = include_bytes!("../testdata/bad_output.onnx");
const BAD_DIM_NAMES: &[u8] = include_bytes!("../testdata/bad_dim_names.onnx");

/// The fixture model, loaded once per test binary.
fn fixture() -> &'static Model {
    static M: OnceLock<Model> = OnceLock::new();
    M.get_or_init(|| Model::from_bytes(FIXTURE).expect("fixture loads"))
}

/// The stored graph and ONNX Runtime's output on it.
fn expected() -> (GraphInputs, Vec<f32>) {
    let v: serde_json::Value = serde_json::from_str(EXPECTED).unwrap();
    let f32s = |k: &str| -> Vec<f32> {
        let a = v[k].as_array().unwrap();
        a.iter().map(|x| x.as_f64().unwrap() as f32).collect()
    };
    let i64s = |k: &str| -> Vec<i64> {
        let a = v[k].as_array().unwrap();
        a.iter().map(|x| x.as_i64().unwrap()).collect()
    };
    let n = |k: &str| v[k].as_u64().unwrap() as usize;
    let g = GraphInputs {
        n_nodes: n("n_nodes"),
        n_edges: n("n_edges"),
        k: n("k"),
        node_x: f32s("node_x"),
        edge_x: f32s("edge_x"),
        edge_ends: i64s("edge_ends"),
        nbr_node: i64s("nbr_node"),
        nbr_edge: i64s("nbr_edge"),
        nbr_mask: f32s("nbr_mask"),
    };
    (g, f32s("pred"))
}

/// A triangulated `nx` x `ny` grid of nodes with seeded random features and `k`
/// neighbour slots (at least the maximum degree, 6).
pub(super) fn grid_graph(nx: usize, ny: usize, k: usize, seed: u64) -> GraphInputs {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let id = |i: usize, j: usize| (j * nx + i) as i64;
    let mut ends = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            if i + 1 < nx {
                ends.extend([id(i, j), id(i + 1, j)]);
            }
            if j + 1 < ny {
                ends.extend([id(i, j), id(i, j + 1)]);
            }
            if i + 1 < nx && j + 1 < ny {
                ends.extend([id(i, j), id(i + 1, j + 1)]);
            }
        }
    }
    let (n, e) = (nx * ny, ends.len() / 2);
    let mut nbr_node: Vec<i64> = (0..n)
        .flat_map(|v| std::iter::repeat_n(v as i64, k))
        .collect();
    let mut nbr_edge = vec![0i64; n * k];
    let mut nbr_mask = vec![0f32; n * k];
    let mut deg = vec![0usize; n];
    for (ei, c) in ends.chunks_exact(2).enumerate() {
        for (a, b) in [(c[0], c[1]), (c[1], c[0])] {
            let s = a as usize * k + deg[a as usize];
            deg[a as usize] += 1;
            (nbr_node[s], nbr_edge[s], nbr_mask[s]) = (b, ei as i64, 1.0);
        }
    }
    let mut normal =
        |len: usize| -> Vec<f32> { (0..len).map(|_| rng.gen_range(-2.0f32..2.0)).collect() };
    GraphInputs {
        n_nodes: n,
        n_edges: e,
        k,
        node_x: normal(n * NODE_FEATURES),
        edge_x: normal(e * EDGE_FEATURES),
        edge_ends: ends,
        nbr_node,
        nbr_edge,
        nbr_mask,
    }
}

fn bits(p: &[[f32; 2]]) -> Vec<u32> {
    p.iter().flat_map(|r| r.map(f32::to_bits)).collect()
}

fn max_abs_diff(p: &[[f32; 2]], want: &[f32]) -> f32 {
    assert_eq!(p.len() * 2, want.len());
    p.iter()
        .flatten()
        .zip(want)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f32::max)
}

#[test]
fn model_is_send_and_sync() {
    fn check<T: Send + Sync>() {}
    check::<Model>();
}

#[test]
fn fixture_matches_stored_onnxruntime_outputs() {
    let (g, want) = expected();
    let m = fixture();
    assert_eq!(m.backend(), Backend::build_default());
    assert_eq!(active_backend(), Some(Backend::build_default()));
    let got = m.predict(&g).unwrap();
    assert_eq!(got.len(), g.n_edges);
    let d = max_abs_diff(&got, &want);
    assert!(d <= 1e-4, "{}: max |diff| = {d:e}", m.backend().name());
    assert!(got.iter().flatten().all(|&x| x >= 0.0));
}

#[test]
fn scores_are_bit_identical_across_runs_and_pools() {
    let m = fixture();
    let g = grid_graph(30, 20, 8, 7);
    let first = bits(&m.predict(&g).unwrap());
    for _ in 0..3 {
        assert_eq!(bits(&m.predict(&g).unwrap()), first);
    }
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        assert_eq!(bits(&pool.install(|| m.predict(&g)).unwrap()), first);
        // concurrent calls from the pool's threads take turns on the session
        let all: Vec<Vec<u32>> = pool.install(|| {
            use rayon::prelude::*;
            (0..4)
                .into_par_iter()
                .map(|_| bits(&m.predict(&g).unwrap()))
                .collect()
        });
        assert!(all.iter().all(|b| *b == first), "{threads} threads");
    }
}

#[test]
fn padding_slots_do_not_change_scores() {
    let m = fixture();
    let (g, _) = expected();
    let base = m.predict(&g).unwrap();
    // three more padding slots per node
    let k2 = g.k + 3;
    let mut wide = GraphInputs {
        k: k2,
        nbr_node: Vec::new(),
        nbr_edge: Vec::new(),
        nbr_mask: Vec::new(),
        ..g.clone()
    };
    for v in 0..g.n_nodes {
        let row = v * g.k..(v + 1) * g.k;
        wide.nbr_node.extend(&g.nbr_node[row.clone()]);
        wide.nbr_node.extend([v as i64; 3]);
        wide.nbr_edge.extend(&g.nbr_edge[row.clone()]);
        wide.nbr_edge.extend([0; 3]);
        wide.nbr_mask.extend(&g.nbr_mask[row]);
        wide.nbr_mask.extend([0.0; 3]);
    }
    let flat: Vec<f32> = base.iter().flatten().copied().collect();
    assert!(max_abs_diff(&m.predict(&wide).unwrap(), &flat) <= 1e-6);
}

#[test]
fn zero_edges_zero_nodes_and_zero_slots() {
    let m = fixture();
    let none = GraphInputs::default();
    assert_eq!(m.predict(&none).unwrap(), Vec::<[f32; 2]>::new());
    let isolated = GraphInputs {
        n_nodes: 3,
        k: 2,
        node_x: vec![0.5; 6],
        nbr_node: vec![0, 0, 1, 1, 2, 2],
        nbr_edge: vec![0; 6],
        nbr_mask: vec![0.0; 6],
        ..GraphInputs::default()
    };
    assert!(m.predict(&isolated).unwrap().is_empty());
    let no_slots = GraphInputs {
        k: 0,
        nbr_node: Vec::new(),
        nbr_edge: Vec::new(),
        nbr_mask: Vec::new(),
        ..isolated.clone()
    };
    assert!(m.predict(&no_slots).unwrap().is_empty());
    // edges but no neighbour slots: run with one padding slot per node
    let mut g = grid_graph(3, 2, 6, 1);
    g.k = 0;
    g.nbr_node.clear();
    g.nbr_edge.clear();
    g.nbr_mask.clear();
    let p = m.predict(&g).unwrap();
    assert_eq!(p.len(), g.n_edges);
    let with_slot = m.predict(&g.with_a_slot()).unwrap();
    assert_eq!(bits(&p), bits(&with_slot));
}

#[test]
fn bad_inputs_are_errors() {
    let m = fixture();
    let (g, _) = expected();
    let bad = |f: &dyn Fn(&mut GraphInputs)| {
        let mut b = g.clone();
        f(&mut b);
        m.predict(&b).unwrap_err()
    };
    assert!(matches!(
        bad(&|b| {
            b.node_x.pop();
        }),
        Error::InvalidArgument(_)
    ));
    assert!(matches!(
        bad(&|b| b.n_edges += 1),
        Error::InvalidArgument(_)
    ));
    assert!(matches!(
        bad(&|b| b.k = usize::MAX),
        Error::InvalidArgument(_)
    ));
    assert!(matches!(
        bad(&|b| b.edge_ends[3] = 12),
        Error::OutOfRange(_)
    ));
    assert!(matches!(
        bad(&|b| b.edge_ends[0] = -1),
        Error::OutOfRange(_)
    ));
    assert!(matches!(bad(&|b| b.nbr_node[5] = 99), Error::OutOfRange(_)));
    assert!(matches!(bad(&|b| b.nbr_edge[5] = 23), Error::OutOfRange(_)));
    assert!(matches!(
        bad(&|b| b.nbr_mask[2] = 0.5),
        Error::InvalidArgument(_)
    ));
    assert!(matches!(
        bad(&|b| b.edge_x[9] = f32::NAN),
        Error::NonFinite(_)
    ));
    assert!(matches!(
        bad(&|b| b.node_x[1] = f32::INFINITY),
        Error::NonFinite(_)
    ));
    // no edges: nothing for a slot to point at
    let e0 = GraphInputs {
        n_nodes: 1,
        k: 1,
        node_x: vec![0.0; 2],
        nbr_node: vec![0],
        nbr_edge: vec![0],
        nbr_mask: vec![1.0],
        ..GraphInputs::default()
    };
    assert!(matches!(
        m.predict(&e0).unwrap_err(),
        Error::InvalidArgument(_)
    ));
}

fn model_err(bytes: &[u8]) -> String {
    match Model::from_bytes(bytes) {
        Err(Error::Model(msg)) => msg,
        Err(e) => panic!("expected Error::Model, got {e}"),
        Ok(_) => panic!("expected an error"),
    }
}

/// `bytes` with every occurrence of `from` replaced by `to` (same length).
fn replace(bytes: &[u8], from: &[u8], to: &[u8]) -> Vec<u8> {
    let mut out = bytes.to_vec();
    let mut n = 0;
    for i in 0..=out.len() - from.len() {
        if &out[i..i + from.len()] == from {
            out[i..i + from.len()].copy_from_slice(to);
            n += 1;
        }
    }
    assert!(n > 0);
    out
}

#[test]
fn corrupt_models_are_errors() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let random: Vec<u8> = (0..4096).map(|_| rng.gen()).collect();
    for (what, bytes) in [
        ("empty", &[][..]),
        ("half", &FIXTURE[..FIXTURE.len() / 2]),
        ("all but the last byte", &FIXTURE[..FIXTURE.len() - 1]),
        ("random", &random[..]),
        ("zeros", &[0u8; 64][..]),
    ] {
        let msg = model_err(bytes);
        assert!(!msg.is_empty(), "{what}");
    }
    // the fixture with bytes changed at random: an error or a model that runs, never a
    // panic or an abort
    let (g, _) = expected();
    let (mut loaded, mut failed) = (0, 0);
    for _ in 0..300 {
        let mut b = FIXTURE.to_vec();
        for _ in 0..rng.gen_range(1..4) {
            let i = rng.gen_range(0..b.len());
            b[i] = rng.gen();
        }
        match Model::from_bytes(&b) {
            Ok(m) => {
                loaded += 1;
                let _ = m.predict(&g);
            }
            Err(Error::Model(_)) => failed += 1,
            Err(e) => panic!("{e}"),
        }
    }
    assert!(loaded > 0 && failed > 0, "{loaded} loaded, {failed} failed");
}

#[test]
fn wrong_interface_is_an_error() {
    let msg = model_err(&replace(FIXTURE, b"node_x", b"node_y"));
    assert!(msg.contains("node_y"), "{msg}");
    let msg = model_err(&replace(FIXTURE, b"nbr_mask", b"nbr_masq"));
    assert!(msg.contains("nbr_masq"), "{msg}");
    let msg = model_err(&replace(FIXTURE, b"pred", b"prex"));
    assert!(msg.contains("no output 'pred'"), "{msg}");
    let msg = model_err(BAD_NODE_FEATURES);
    assert!(
        msg.contains("'node_x' axis 1 is 3, expected the fixed size 2"),
        "{msg}"
    );
    let msg = model_err(BAD_MASK_RANK);
    assert!(msg.contains("'nbr_mask' is f32 of rank 3"), "{msg}");
    // declares pred [E, T]: only the trial run shows [E, 3]
    let msg = model_err(BAD_OUTPUT);
    assert!(msg.contains("trial run"), "{msg}");
    // each input with its own names for N, E, K (runs on ONNX Runtime, not on tract)
    let msg = model_err(BAD_DIM_NAMES);
    assert!(msg.contains("tract needs one name per size"), "{msg}");
}

/// The fixture with its declared interface edited by `f`.
fn edited(f: impl FnOnce(&mut tract_onnx::pb::GraphProto)) -> Vec<u8> {
    use prost::Message;
    let mut m = tract_onnx::pb::ModelProto::decode(FIXTURE).unwrap();
    f(m.graph.as_mut().unwrap());
    m.encode_to_vec()
}

/// The dimension `axis` of the declared value `name` (input or output).
fn dim<'g>(
    g: &'g mut tract_onnx::pb::GraphProto,
    name: &str,
    axis: usize,
) -> &'g mut Option<tract_onnx::pb::tensor_shape_proto::dimension::Value> {
    use tract_onnx::pb::type_proto::Value;
    let v = g.input.iter_mut().chain(g.output.iter_mut());
    let v = v.into_iter().find(|v| v.name == name).unwrap();
    let Some(Value::TensorType(t)) = v.r#type.as_mut().unwrap().value.as_mut() else {
        panic!()
    };
    &mut t.shape.as_mut().unwrap().dim[axis].value
}

#[test]
fn dynamic_sizes_must_be_named_once() {
    use tract_onnx::pb::tensor_shape_proto::dimension::Value::{DimParam, DimValue};
    // the unedited round trip loads
    Model::from_bytes(&edited(|_| {})).unwrap();
    let msg = model_err(&edited(|g| *dim(g, "node_x", 0) = Some(DimValue(12))));
    assert!(msg.contains("(N) is fixed to 12"), "{msg}");
    let msg = model_err(&edited(|g| *dim(g, "nbr_edge", 1) = None));
    assert!(msg.contains("(K) has no name"), "{msg}");
    let msg = model_err(&edited(|g| {
        *dim(g, "edge_ends", 0) = Some(DimParam("M".into()))
    }));
    assert!(
        msg.contains("E is named 'E' in input 'edge_x' but 'M'"),
        "{msg}"
    );
    let msg = model_err(&edited(|g| {
        for (name, axis) in [("nbr_node", 1), ("nbr_edge", 1), ("nbr_mask", 1)] {
            *dim(g, name, axis) = Some(DimParam("N".into()));
        }
    }));
    assert!(msg.contains("distinct names"), "{msg}");
    let msg = model_err(&edited(|g| *dim(g, "edge_x", 1) = Some(DimValue(7))));
    assert!(msg.contains("expected the fixed size 8"), "{msg}");
    let msg = model_err(&edited(|g| *dim(g, "pred", 0) = Some(DimParam("X".into()))));
    assert!(msg.contains("output 'pred' is not f32 [E, 2]"), "{msg}");
    // an initializer listed as an input (old exporters)
    let msg = model_err(&edited(|g| {
        let mut w = g.input[0].clone();
        w.name = g.initializer[0].name.clone();
        g.input.push(w);
    }));
    assert!(msg.contains("keep_initializers_as_inputs"), "{msg}");
}

#[test]
fn missing_model_file_is_an_io_error() {
    let e = Model::from_file(Path::new("/nonexistent/abgs/model.onnx")).unwrap_err();
    assert!(matches!(e, Error::Io { .. }), "{e}");
}

#[test]
fn from_file_reads_the_fixture() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/gcn/testdata/fixture.onnx");
    let m = Model::from_file(&p).unwrap();
    let (g, _) = expected();
    assert_eq!(
        bits(&m.predict(&g).unwrap()),
        bits(&fixture().predict(&g).unwrap())
    );
}

#[test]
fn backend_is_one_per_process() {
    fixture();
    select_backend(Backend::build_default()).unwrap();
    #[cfg(feature = "onnxruntime")]
    assert!(matches!(
        select_backend(Backend::Tract),
        Err(Error::Model(_))
    ));
}

#[cfg(feature = "onnxruntime")]
#[test]
fn onnxruntime_matches_stored_outputs_and_tract() {
    let m = fixture();
    assert_eq!(m.backend(), Backend::OnnxRuntime);
    let (g, want) = expected();
    let got = m.predict(&g).unwrap();
    assert!(max_abs_diff(&got, &want) <= 1e-4);
    assert!(max_abs_diff(&got, &run_tract_direct(FIXTURE, &g).unwrap()) <= 1e-4);
    let big = grid_graph(40, 25, 9, 11);
    let got = m.predict(&big).unwrap();
    let d = max_abs_diff(&got, &run_tract_direct(FIXTURE, &big).unwrap());
    assert!(d <= 1e-4, "max |onnxruntime - tract| = {d:e}");
}

/// Timing on ~100k edges (N = 35k, K = 10) of the fixture, or of the model file named
/// by `ABGS_GCN_MODEL`; run with
/// `cargo test --release --lib gcn::runtime::tests::predict_time -- --ignored --nocapture`.
#[test]
#[ignore]
fn predict_time_100k_edges() {
    let t0 = std::time::Instant::now();
    let m = match std::env::var_os("ABGS_GCN_MODEL") {
        Some(p) => Model::from_file(Path::new(&p)).unwrap(),
        None => Model::from_bytes(FIXTURE).unwrap(),
    };
    let load = t0.elapsed();
    let g = grid_graph(187, 187, 10, 5);
    let mut times = Vec::new();
    for _ in 0..5 {
        let t = std::time::Instant::now();
        let p = m.predict(&g).unwrap();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        assert_eq!(p.len(), g.n_edges);
    }
    eprintln!(
        "{}: load {:.1} ms; N = {}, E = {}, K = {}: predict {:?} ms",
        m.backend().name(),
        load.as_secs_f64() * 1e3,
        g.n_nodes,
        g.n_edges,
        g.k,
        times
            .iter()
            .map(|t| (t * 10.0).round() / 10.0)
            .collect::<Vec<_>>()
    );
}

#[cfg(feature = "onnxruntime")]
#[test]
fn onnxruntime_loader_rejects_bad_libraries() {
    use crate::ffi::onnxruntime::load_onnxruntime_api;
    let e = load_onnxruntime_api(Path::new("/nonexistent/libonnxruntime.so")).unwrap_err();
    assert!(e.contains("cannot load"), "{e}");
    let e = load_onnxruntime_api(Path::new("libm.so.6")).unwrap_err();
    assert!(e.contains("not ONNX Runtime"), "{e}");
}

#[test]
fn sessions_fixed_to_the_graph_sizes_agree_with_the_dynamic_one() {
    // Large enough for Model::predict to take the fixed-size session on tract.
    let g = grid_graph(48, 48, 8, 7);
    assert!(g.n_edges >= FIXED_MIN_EDGES);
    let rt = runtime(None).unwrap();
    let mut dynamic = open_session(rt, FIXTURE).unwrap();
    let want = run_session(&mut dynamic, &g).unwrap();
    let got = fixture().predict(&g).unwrap();
    for (w, p) in want.chunks_exact(TARGETS).zip(&got) {
        for (a, b) in w.iter().zip(p) {
            assert!((a - b).abs() <= 1e-5 * (1.0 + a.abs()), "{a} vs {b}");
        }
    }
    // The edit itself: every N, E, K of the interface becomes a number, and
    // bytes that are not ONNX are refused.
    use prost::Message;
    let bytes = fixed::fixed_sizes(FIXTURE, g.n_nodes, g.n_edges, g.k).unwrap();
    let m = tract_onnx::pb::ModelProto::decode(&bytes[..]).unwrap();
    let graph = m.graph.unwrap();
    for v in graph.input.iter().chain(&graph.output) {
        use tract_onnx::pb::tensor_shape_proto::dimension::Value;
        use tract_onnx::pb::type_proto::Value as Type;
        let Some(Type::TensorType(t)) = v.r#type.as_ref().unwrap().value.as_ref() else {
            panic!("{} is not a tensor", v.name)
        };
        for d in &t.shape.as_ref().unwrap().dim {
            assert!(
                matches!(d.value, Some(Value::DimValue(_))),
                "{}: {d:?}",
                v.name
            );
        }
    }
    assert!(fixed::fixed_sizes(b"not an onnx model", 2, 1, 1).is_err());
}
