//! The ONNX model runtime of GCN-ABGS: a [`Model`] loaded once, then
//! [`Model::predict`] on a [`GraphInputs`] gives the two per-edge predictions.
//!
//! # The model's interface (fixed; `training/` exports exactly this)
//! Inputs, all dimensions dynamic (N nodes, E edges, K neighbour slots):
//! `node_x` f32 \[N,2\], `edge_x` f32 \[E,8\], `edge_ends` i64 \[E,2\],
//! `nbr_node` i64 \[N,K\] (padding: the node itself), `nbr_edge` i64 \[N,K\]
//! (padding: 0), `nbr_mask` f32 \[N,K\] (1 real slot, 0 padding). Output: `pred` f32
//! \[E,2\], non-negative. A model that does not have this interface is an
//! [`Error::Model`] when it is loaded, and so is one that fails a trial run.
//!
//! # Backends
//! Everything goes through the `ort` crate's API; `ort` sends its calls to one table
//! of C functions, set once per process by `ort::set_api` (a second call is ignored).
//! So the backend is a process-wide choice, made at the first model load (or by
//! [`select_backend`] before it), not a per-model one:
//! - [`Backend::Tract`] (the default): the pure-Rust tract engine via `ort-tract`,
//!   built in: no download, no system library.
//! - `Backend::OnnxRuntime` (cargo feature `onnxruntime`, then the default):
//!   ONNX Runtime proper, loaded at run time from the shared library named by the
//!   environment variable `ORT_DYLIB_PATH` (`ort`'s convention), e.g. the
//!   `onnxruntime==1.31.1` wheel's `onnxruntime/capi/libonnxruntime.so.1.31.1`;
//!   unset, `libonnxruntime.so` is searched by the system loader. Needs 1.24 or newer.
//!
//! On tract, a graph of at least [`FIXED_MIN_EDGES`] edges runs on a session opened
//! for its sizes alone (N, E and K fixed in the ONNX file's declared shapes; module
//! `fixed`): tract's vectorised element-wise kernels need sizes it can prove at
//! optimisation time, and without them the model ran 2.4× slower.
//!
//! A test binary thus runs one backend through `ort`; both are checked against the
//! same stored ONNX Runtime outputs (`testdata/fixture_expected.json`, 1e-4), and with
//! the feature on, ONNX Runtime's outputs are also compared in-process to tract run
//! directly (not through `ort`).
//!
//! # Determinism
//! Same input, same bits, whatever the calling thread or rayon pool: tract runs on
//! the calling thread (its multithreaded kernels are not compiled in), ONNX Runtime
//! with one intra-op and one inter-op thread, sequential execution and deterministic
//! compute. Across machines, the SIMD kernels chosen may differ in the last bits.
//!
//! # Safety against bad input
//! ort-tract runs tract inside `extern "C"` callbacks, where a panic (e.g. an
//! out-of-range Gather index) aborts the process instead of unwinding, so
//! `catch_unwind` cannot help there. Hence: inputs are checked
//! ([`GraphInputs::check`]: lengths, index ranges, finite features) before any backend
//! sees them; on tract, a model is first parsed, optimised and run on a two-node trial
//! graph by tract directly, under `catch_unwind`, before `ort` gets it (a corrupt
//! constant index is an error there, not an abort); every `ort` call is under
//! `catch_unwind` as well. What remains: a model that is sound on the trial graph
//! but panics in tract on a larger one would still abort — not a risk for the
//! embedded, tested model, but one to keep in mind for model files from elsewhere.
//! ONNX Runtime checks indices itself and returns errors.
//!
//! ONNX Runtime logs its own errors to stderr as well (level from `ORT_LOG`:
//! `fatal`, `error` (default), `warning`, `info`, `verbose`).

use crate::error::{Error, Result};
use ort::session::builder::GraphOptimizationLevel;
use ort::session::Session;
use ort::value::TensorRef;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::sync::{Mutex, OnceLock};

/// Node features per node (`node_x`'s second dimension).
pub const NODE_FEATURES: usize = 2;
/// Edge features per edge (`edge_x`'s second dimension).
pub const EDGE_FEATURES: usize = 8;
/// Predicted targets per edge (`pred`'s second dimension).
pub const TARGETS: usize = 2;
/// The environment variable naming ONNX Runtime's shared library (feature `onnxruntime`).
pub const ORT_DYLIB_PATH_VAR: &str = "ORT_DYLIB_PATH";
/// The output's name.
pub const OUTPUT_NAME: &str = "pred";

/// ONNX element types (`TensorProto.DataType`).
const ONNX_F32: i32 = 1;
const ONNX_I64: i32 = 7;

/// One declared dimension of the interface: a fixed size, or one of the graph's sizes
/// N, E, K (index into [`SIZE_NAMES`]), which must be dynamic.
#[derive(Clone, Copy)]
enum Dim {
    Fixed(i64),
    Size(usize),
}
/// The graph's sizes, as the module doc calls them.
const SIZE_NAMES: [&str; 3] = ["N", "E", "K"];
const N: Dim = Dim::Size(0);
const E: Dim = Dim::Size(1);
const K: Dim = Dim::Size(2);

/// Each input: name, element type, dimensions.
const INPUTS: [(&str, i32, [Dim; 2]); 6] = [
    ("node_x", ONNX_F32, [N, Dim::Fixed(NODE_FEATURES as i64)]),
    ("edge_x", ONNX_F32, [E, Dim::Fixed(EDGE_FEATURES as i64)]),
    ("edge_ends", ONNX_I64, [E, Dim::Fixed(2)]),
    ("nbr_node", ONNX_I64, [N, K]),
    ("nbr_edge", ONNX_I64, [N, K]),
    ("nbr_mask", ONNX_F32, [N, K]),
];

/// The inputs of one forward pass over a graph, row-major (see the module doc for the
/// meaning of each array).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GraphInputs {
    /// N, the number of nodes.
    pub n_nodes: usize,
    /// E, the number of edges.
    pub n_edges: usize,
    /// K, the number of neighbour slots per node.
    pub k: usize,
    /// \[N, 2\] node features.
    pub node_x: Vec<f32>,
    /// \[E, 8\] edge features.
    pub edge_x: Vec<f32>,
    /// \[E, 2\] the node indices of each edge's two ends.
    pub edge_ends: Vec<i64>,
    /// \[N, K\] the neighbour node of each slot (padding: the node itself).
    pub nbr_node: Vec<i64>,
    /// \[N, K\] the edge to that neighbour (padding: 0).
    pub nbr_edge: Vec<i64>,
    /// \[N, K\] 1 for a real slot, 0 for padding.
    pub nbr_mask: Vec<f32>,
}

impl GraphInputs {
    /// Checks the array lengths against N, E and K, that every feature is finite, every
    /// index in range (nodes in `[0, N)`, edges in `[0, E)`) and every mask value 0 or 1.
    /// With E = 0 there is no edge to point at: `nbr_edge` must be all 0 and `nbr_mask`
    /// all 0.
    pub fn check(&self) -> Result<()> {
        let (n, e, k) = (self.n_nodes, self.n_edges, self.k);
        let len = |what: &str, got: usize, rows: usize, cols: usize| -> Result<()> {
            match rows.checked_mul(cols) {
                Some(want) if want == got => Ok(()),
                _ => Err(Error::InvalidArgument(format!(
                    "{what} has {got} values, expected {rows} x {cols}"
                ))),
            }
        };
        len("node_x", self.node_x.len(), n, NODE_FEATURES)?;
        len("edge_x", self.edge_x.len(), e, EDGE_FEATURES)?;
        len("edge_ends", self.edge_ends.len(), e, 2)?;
        len("nbr_node", self.nbr_node.len(), n, k)?;
        len("nbr_edge", self.nbr_edge.len(), n, k)?;
        len("nbr_mask", self.nbr_mask.len(), n, k)?;
        for (what, v) in [("node_x", &self.node_x), ("edge_x", &self.edge_x)] {
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(Error::NonFinite(format!("{what}[{i}] = {}", v[i])));
            }
        }
        let in_range = |what: &str, v: &[i64], bound: usize| -> Result<()> {
            match v.iter().position(|&x| x < 0 || x as u64 >= bound as u64) {
                None => Ok(()),
                Some(i) => Err(Error::OutOfRange(format!(
                    "{what}[{i}] = {} is not in [0, {bound})",
                    v[i]
                ))),
            }
        };
        in_range("edge_ends", &self.edge_ends, n)?;
        in_range("nbr_node", &self.nbr_node, n)?;
        if e == 0 {
            if let Some(i) = self.nbr_edge.iter().position(|&x| x != 0) {
                return Err(Error::OutOfRange(format!(
                    "nbr_edge[{i}] = {} with no edges (padding is 0)",
                    self.nbr_edge[i]
                )));
            }
            if self.nbr_mask.iter().any(|&m| m != 0.0) {
                return Err(Error::InvalidArgument(
                    "nbr_mask has a real slot but there are no edges".into(),
                ));
            }
        } else {
            in_range("nbr_edge", &self.nbr_edge, e)?;
        }
        if let Some(i) = self.nbr_mask.iter().position(|&m| m != 0.0 && m != 1.0) {
            return Err(Error::InvalidArgument(format!(
                "nbr_mask[{i}] = {} is neither 0 nor 1",
                self.nbr_mask[i]
            )));
        }
        Ok(())
    }

    /// The same graph with one padding slot per node (K = 1) when K = 0, which the
    /// model gives the same result for (a padding slot is masked out), and which every
    /// backend runs (some reject zero-size dimensions).
    fn with_a_slot(&self) -> GraphInputs {
        let n = self.n_nodes;
        GraphInputs {
            k: 1,
            nbr_node: (0..n as i64).collect(),
            nbr_edge: vec![0; n],
            nbr_mask: vec![0.0; n],
            ..self.clone()
        }
    }
}

/// The engine that runs the model (one per process: see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Backend {
    /// tract, in pure Rust, built in (no download, no system library).
    Tract,
    /// ONNX Runtime, loaded from the shared library named by `ORT_DYLIB_PATH`.
    #[cfg(feature = "onnxruntime")]
    OnnxRuntime,
}

impl Backend {
    /// The backend used when none was selected: ONNX Runtime when built with the
    /// `onnxruntime` feature, else tract.
    pub const fn build_default() -> Backend {
        #[cfg(feature = "onnxruntime")]
        return Backend::OnnxRuntime;
        #[cfg(not(feature = "onnxruntime"))]
        return Backend::Tract;
    }

    /// A short name: `"tract"` or `"onnxruntime"`.
    pub const fn name(self) -> &'static str {
        match self {
            Backend::Tract => "tract",
            #[cfg(feature = "onnxruntime")]
            Backend::OnnxRuntime => "onnxruntime",
        }
    }
}

/// The process's `ort` setup: its backend, its one environment, and a description.
struct Runtime {
    backend: Backend,
    env: ort::environment::Environment,
    about: String,
}

static RUNTIME: OnceLock<std::result::Result<Runtime, String>> = OnceLock::new();

/// Sets up `ort` for `backend` (once per process: `ort::set_api` and the environment).
fn setup(backend: Backend) -> std::result::Result<Runtime, String> {
    let (api, about) = match backend {
        Backend::Tract => (ort_tract::api(), "tract (ort-tract 0.5.0)".to_string()),
        #[cfg(feature = "onnxruntime")]
        Backend::OnnxRuntime => {
            let path = match std::env::var_os(ORT_DYLIB_PATH_VAR) {
                Some(p) if !p.is_empty() => std::path::PathBuf::from(p),
                _ => format!(
                    "{}onnxruntime{}",
                    std::env::consts::DLL_PREFIX,
                    std::env::consts::DLL_SUFFIX
                )
                .into(),
            };
            let (api, version) =
                crate::ffi::onnxruntime::load_onnxruntime_api(&path).map_err(|e| {
                    match std::env::var_os(ORT_DYLIB_PATH_VAR) {
                        Some(_) => e,
                        None => format!(
                            "{e} (set {ORT_DYLIB_PATH_VAR} to ONNX Runtime's shared library, e.g. \
                             the onnxruntime wheel's onnxruntime/capi/libonnxruntime.so.1.31.1)"
                        ),
                    }
                })?;
            (api, format!("ONNX Runtime {version} ({})", path.display()))
        }
    };
    if !ort::set_api(api) {
        return Err("ort's backend was already set by other code in this process".into());
    }
    let env = guarded("environment", || {
        ort::init()
            .with_name("abgs")
            .with_telemetry(false)
            .build()
            .map_err(|e| e.to_string())
    })?;
    Ok(Runtime {
        backend,
        env,
        about,
    })
}

/// The process's runtime, set up on first use with `want` (or the build's default);
/// an error if it is set up with another backend or its set-up failed.
fn runtime(want: Option<Backend>) -> Result<&'static Runtime> {
    let rt = RUNTIME.get_or_init(|| setup(want.unwrap_or(Backend::build_default())));
    match rt {
        Err(msg) => Err(Error::Model(format!("cannot set up the runtime: {msg}"))),
        Ok(rt) => match want {
            Some(b) if b != rt.backend => Err(Error::Model(format!(
                "backend {} requested, but this process already runs {}",
                b.name(),
                rt.backend.name()
            ))),
            _ => Ok(rt),
        },
    }
}

/// Chooses the backend for the whole process; call it before the first model is loaded.
/// Selecting the backend already in use is fine; another one is an [`Error::Model`], as
/// is a failed set-up (e.g. ONNX Runtime's library not found).
pub fn select_backend(backend: Backend) -> Result<()> {
    runtime(Some(backend)).map(|_| ())
}

/// The backend this process runs models on, once one was set up.
pub fn active_backend() -> Option<Backend> {
    RUNTIME.get()?.as_ref().ok().map(|rt| rt.backend)
}

/// Runs `f` under `catch_unwind`, turning a panic into a message naming `what`.
fn guarded<T>(
    what: &str,
    f: impl FnOnce() -> std::result::Result<T, String>,
) -> std::result::Result<T, String> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(p) => {
            let msg = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            Err(format!("{what}: the backend panicked: {msg}"))
        }
    }
}

/// Checks the ONNX file's declared interface on its protobuf, before a backend parses
/// the graph: the six inputs and nothing else, their element types, ranks and fixed
/// sizes, and the output. N, E and K must be dynamic and named (`dim_param`), each with
/// one name used by every input that has it, the three names distinct: tract matches
/// dimensions by name and cannot unify two names (a model with per-input names, as
/// some exporters write by default, runs on ONNX Runtime but not on tract).
fn check_interface(bytes: &[u8]) -> std::result::Result<(), String> {
    use tract_onnx::pb::{tensor_shape_proto::dimension, type_proto, ValueInfoProto};
    use tract_onnx::prelude::Framework;
    let proto = guarded("reading the model", || {
        tract_onnx::onnx()
            .proto_model_for_read(&mut &bytes[..])
            .map_err(|e| format!("not an ONNX model: {e:#}"))
    })?;
    let graph = proto.graph.as_ref().ok_or("the ONNX file has no graph")?;
    // element type and dimensions (Ok(size) | Err(name, "" if none)) of a declared value
    type Dims = Vec<std::result::Result<i64, String>>;
    let typed = |v: &ValueInfoProto| -> Option<(i32, Dims)> {
        let Some(type_proto::Value::TensorType(t)) = v.r#type.as_ref()?.value.as_ref() else {
            return None;
        };
        let dims = t.shape.as_ref()?.dim.iter().map(|d| match &d.value {
            Some(dimension::Value::DimValue(x)) => Ok(*x),
            Some(dimension::Value::DimParam(p)) => Err(p.clone()),
            None => Err(String::new()),
        });
        Some((t.elem_type, dims.collect()))
    };
    let type_name = |t: i32| match t {
        ONNX_F32 => "f32".to_string(),
        ONNX_I64 => "i64".to_string(),
        t => format!("ONNX type {t}"),
    };
    for v in &graph.input {
        if !INPUTS.iter().any(|(name, ..)| *name == v.name) {
            let hint = if graph.initializer.iter().any(|i| i.name == v.name) {
                " (an initializer listed as an input: export without keep_initializers_as_inputs)"
            } else {
                ""
            };
            return Err(format!("unexpected input '{}'{hint}", v.name));
        }
    }
    // the name each of N, E, K has in the file, and where it was first seen
    let mut names: [Option<(String, &str)>; 3] = Default::default();
    for (name, ty, want) in INPUTS {
        let v = graph
            .input
            .iter()
            .find(|v| v.name == name)
            .ok_or_else(|| format!("no input '{name}'"))?;
        let (t, dims) = typed(v).ok_or_else(|| format!("input '{name}' is not a tensor"))?;
        if t != ty || dims.len() != want.len() {
            return Err(format!(
                "input '{name}' is {} of rank {}, expected {} of rank {}",
                type_name(t),
                dims.len(),
                type_name(ty),
                want.len()
            ));
        }
        for (axis, (got, want)) in dims.iter().zip(want).enumerate() {
            match (want, got) {
                (Dim::Fixed(w), Ok(g)) if w == *g => {}
                (Dim::Fixed(w), _) => {
                    let got = match got {
                        Ok(g) => g.to_string(),
                        Err(p) if p.is_empty() => "dynamic".to_string(),
                        Err(p) => format!("dynamic '{p}'"),
                    };
                    return Err(format!(
                        "input '{name}' axis {axis} is {got}, expected the fixed size {w}"
                    ));
                }
                (Dim::Size(s), Ok(g)) => {
                    return Err(format!(
                        "input '{name}' axis {axis} ({}) is fixed to {g}; it must be dynamic",
                        SIZE_NAMES[s]
                    ))
                }
                (Dim::Size(s), Err(p)) if p.is_empty() => {
                    return Err(format!(
                        "input '{name}' axis {axis} ({}) has no name: name the dynamic \
                         axes, one name each for N, E and K",
                        SIZE_NAMES[s]
                    ))
                }
                (Dim::Size(s), Err(p)) => match &names[s] {
                    None => names[s] = Some((p.clone(), name)),
                    Some((q, first)) if q != p => {
                        return Err(format!(
                            "{} is named '{q}' in input '{first}' but '{p}' in input \
                             '{name}': tract needs one name per size",
                            SIZE_NAMES[s]
                        ))
                    }
                    Some(_) => {}
                },
            }
        }
    }
    let named: Vec<&String> = names.iter().flatten().map(|(p, _)| p).collect();
    if (1..named.len()).any(|i| named[..i].contains(&named[i])) {
        return Err(format!("N, E and K need distinct names, not {named:?}"));
    }
    let out = graph
        .output
        .iter()
        .find(|v| v.name == OUTPUT_NAME)
        .ok_or_else(|| format!("no output '{OUTPUT_NAME}'"))?;
    let e_name = names[1].as_ref().map(|(p, _)| p.as_str());
    match typed(out) {
        Some((ONNX_F32, dims))
            if dims.len() == 2
                && matches!(&dims[0], Err(p) if p.is_empty() || Some(p.as_str()) == e_name)
                && matches!(&dims[1], Ok(2) | Err(_)) =>
        {
            Ok(())
        }
        _ => Err(format!(
            "output '{OUTPUT_NAME}' is not f32 [E, {TARGETS}] (with E named as in the inputs)"
        )),
    }
}

/// Runs the model with tract directly (its own API, not through `ort`), under
/// `catch_unwind`: the `pred` values, row-major, or a message. The tract backend's
/// load runs this on the trial graph first, so that a model on which tract fails or
/// panics (e.g. a constant Gather index out of range) is an error here and not an
/// abort inside ort-tract's callbacks.
pub(crate) fn run_tract_direct(
    bytes: &[u8],
    g: &GraphInputs,
) -> std::result::Result<Vec<f32>, String> {
    use tract_onnx::prelude::*;
    guarded("tract", || {
        let (n, e, k) = (g.n_nodes, g.n_edges, g.k);
        let f = |shape: &[usize], v: &[f32]| Tensor::from_shape(shape, v).map(|t| t.into_tvalue());
        let i = |shape: &[usize], v: &[i64]| Tensor::from_shape(shape, v).map(|t| t.into_tvalue());
        let run = || -> TractResult<Vec<f32>> {
            let plan = tract_onnx::onnx()
                .model_for_read(&mut &bytes[..])?
                .with_input_names(INPUTS.iter().map(|(name, ..)| *name))?
                .into_optimized()?
                .into_runnable()?;
            let out = plan.run(tvec![
                f(&[n, NODE_FEATURES], &g.node_x)?,
                f(&[e, EDGE_FEATURES], &g.edge_x)?,
                i(&[e, 2], &g.edge_ends)?,
                i(&[n, k], &g.nbr_node)?,
                i(&[n, k], &g.nbr_edge)?,
                f(&[n, k], &g.nbr_mask)?,
            ])?;
            let pred = out.first().ok_or_else(|| TractError::msg("no output"))?;
            if pred.shape() != [e, TARGETS] {
                return Err(TractError::msg(format!(
                    "output shape {:?}, expected [{e}, {TARGETS}]",
                    pred.shape()
                )));
            }
            Ok(pred.try_as_plain_ram()?.as_slice::<f32>()?.to_vec())
        };
        run().map_err(|e| format!("tract cannot run the model: {e:#}"))
    })
}

/// A loaded model: `ort` sessions of it, kept idle in a pool (a run needs
/// `&mut`). A [`Model::predict`] takes an idle session, or opens one more from
/// the model's bytes when all are busy (the parts of a mesh simplified side by
/// side predict at once), and puts it back; so there are at most as many
/// sessions as concurrent callers. Every session runs the same graph on its
/// caller's thread alone, so which one answers changes no bit.
pub struct Model {
    idle: Mutex<Vec<Session>>,
    bytes: Box<[u8]>,
    backend: Backend,
}

impl std::fmt::Debug for Model {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Model")
            .field("backend", &self.backend)
            .finish_non_exhaustive()
    }
}

impl Model {
    /// Loads a model from the bytes of an ONNX file on the process's backend (set up on
    /// first use: see [`select_backend`]), checks its interface and runs it once on a
    /// two-node graph. A corrupt model or one with another interface is an
    /// [`Error::Model`].
    pub fn from_bytes(bytes: &[u8]) -> Result<Model> {
        let rt = runtime(None)?;
        check_interface(bytes).map_err(Error::Model)?;
        if rt.backend == Backend::Tract {
            run_tract_direct(bytes, &trial_graph())
                .map_err(|e| Error::Model(format!("trial run: {e}")))?;
        }
        let session = open_session(rt, bytes)
            .map_err(|e| Error::Model(format!("{} cannot load the model: {e}", rt.about)))?;
        let model = Model {
            idle: Mutex::new(vec![session]),
            bytes: bytes.into(),
            backend: rt.backend,
        };
        model.predict(&trial_graph()).map_err(|e| match e {
            Error::Model(m) => Error::Model(format!("trial run: {m}")),
            e => e,
        })?;
        Ok(model)
    }

    /// Loads a model from an ONNX file ([`Error::Io`] if it cannot be read, else as
    /// [`Model::from_bytes`]).
    pub fn from_file(path: &Path) -> Result<Model> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        Model::from_bytes(&bytes).map_err(|e| match e {
            Error::Model(m) => Error::Model(format!("'{}': {m}", path.display())),
            e => e,
        })
    }

    /// The backend this model runs on.
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// The two predictions of every edge, in edge order, after checking `g`
    /// ([`GraphInputs::check`]). No edges: empty, without running the model. The output
    /// must be \[E, 2\] and finite, else [`Error::Model`].
    pub fn predict(&self, g: &GraphInputs) -> Result<Vec<[f32; 2]>> {
        g.check()?;
        if g.n_edges == 0 {
            return Ok(Vec::new());
        }
        let padded;
        let g = if g.k == 0 {
            padded = g.with_a_slot();
            &padded
        } else {
            g
        };
        let flat = self.run(g).map_err(Error::Model)?;
        if flat.len() != g.n_edges * TARGETS {
            return Err(Error::Model(format!(
                "output has {} values, expected {} x {TARGETS}",
                flat.len(),
                g.n_edges
            )));
        }
        if let Some(i) = flat.iter().position(|x| !x.is_finite()) {
            return Err(Error::Model(format!(
                "output value {} of edge {} is {}",
                i % TARGETS,
                i / TARGETS,
                flat[i]
            )));
        }
        Ok(flat.chunks_exact(TARGETS).map(|c| [c[0], c[1]]).collect())
    }

    /// One forward pass on an idle session (or a new one): the `pred` values,
    /// row-major, after checking their shape.
    fn run(&self, g: &GraphInputs) -> std::result::Result<Vec<f32>, String> {
        if self.backend == Backend::Tract && g.n_edges >= fixed::FIXED_MIN_EDGES {
            // One session for this graph's sizes (module `fixed`), then dropped.
            let bytes = fixed::fixed_sizes(&self.bytes, g.n_nodes, g.n_edges, g.k)?;
            let mut session = open_session(runtime(None).map_err(|e| e.to_string())?, &bytes)?;
            return run_session(&mut session, g);
        }
        let idle = || self.idle.lock().unwrap_or_else(|p| p.into_inner());
        let taken = idle().pop();
        let mut session = match taken {
            Some(s) => s,
            None => open_session(runtime(None).map_err(|e| e.to_string())?, &self.bytes)?,
        };
        let out = run_session(&mut session, g);
        // A session whose run failed is dropped, not reused.
        if out.is_ok() {
            idle().push(session);
        }
        out
    }
}

/// Opens an `ort` session of the ONNX `bytes` on runtime `rt`: one intra-op and
/// one inter-op thread, sequential and deterministic (module doc).
fn open_session(rt: &Runtime, bytes: &[u8]) -> std::result::Result<Session, String> {
    guarded("creating the session", || {
        let err = |e: ort::Error<ort::session::builder::SessionBuilder>| e.to_string();
        let mut builder = Session::builder(&rt.env)
            .map_err(|e| e.to_string())?
            .with_optimization_level(GraphOptimizationLevel::All)
            .map_err(err)?
            .with_intra_threads(1)
            .map_err(err)?
            .with_inter_threads(1)
            .map_err(err)?
            .with_parallel_execution(false)
            .map_err(err)?
            .with_deterministic_compute(true)
            .map_err(err)?;
        builder.commit_from_memory(bytes).map_err(|e| e.to_string())
    })
}

/// One forward pass of `session` on `g`: the `pred` values, row-major, after
/// checking their shape.
fn run_session(session: &mut Session, g: &GraphInputs) -> std::result::Result<Vec<f32>, String> {
    let (n, e, k) = (g.n_nodes, g.n_edges, g.k);
    guarded("running the model", || {
        let err = |e: ort::Error| e.to_string();
        let inputs = ort::inputs![
            "node_x" => TensorRef::from_array_view(([n, NODE_FEATURES], &g.node_x[..])).map_err(err)?,
            "edge_x" => TensorRef::from_array_view(([e, EDGE_FEATURES], &g.edge_x[..])).map_err(err)?,
            "edge_ends" => TensorRef::from_array_view(([e, 2], &g.edge_ends[..])).map_err(err)?,
            "nbr_node" => TensorRef::from_array_view(([n, k], &g.nbr_node[..])).map_err(err)?,
            "nbr_edge" => TensorRef::from_array_view(([n, k], &g.nbr_edge[..])).map_err(err)?,
            "nbr_mask" => TensorRef::from_array_view(([n, k], &g.nbr_mask[..])).map_err(err)?,
        ];
        let outputs = session.run(inputs).map_err(err)?;
        let pred = outputs
            .get(OUTPUT_NAME)
            .ok_or_else(|| format!("no output '{OUTPUT_NAME}'"))?;
        let (shape, data) = pred.try_extract_tensor::<f32>().map_err(err)?;
        if **shape != [e as i64, TARGETS as i64] {
            return Err(format!(
                "output shape {:?}, expected [{e}, {TARGETS}]",
                &**shape
            ));
        }
        Ok(data.to_vec())
    })
}

/// Two nodes joined by one edge, all features 0: the trial run of [`Model::from_bytes`].
fn trial_graph() -> GraphInputs {
    GraphInputs {
        n_nodes: 2,
        n_edges: 1,
        k: 1,
        node_x: vec![0.0; 2 * NODE_FEATURES],
        edge_x: vec![0.0; EDGE_FEATURES],
        edge_ends: vec![0, 1],
        nbr_node: vec![1, 0],
        nbr_edge: vec![0, 0],
        nbr_mask: vec![1.0, 1.0],
    }
}

mod fixed;
#[cfg(test)]
mod tests;

pub use fixed::FIXED_MIN_EDGES;
