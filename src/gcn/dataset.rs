//! Training data for the learned simplifier (DESIGN §3.7): graphs taken
//! along a whole LBO-ABGS run, each with the model's inputs
//! ([`super::features::graph`], the very function inference uses) and the
//! accurate estimate's own unit-free numbers as targets.
//!
//! Targets are `Δs − 1` and `Δd / h_loc` from the exact estimate of every
//! live edge (no early exit), `NaN` where the collapse is invalid, `+∞`
//! where a sample could not be projected. They bake in no threshold: the
//! score `y` (kept for analysis) is made from them with the run's `T_size`
//! and the distance envelope `a_e` ([`super::scorer::edge_allowance`],
//! stored relative to `h_loc` as `allow_rel`), so GCN-ABGS keeps `T_size`,
//! `β`, `κ` and `max_distance` as run-time parameters as LBO-ABGS does.
//!
//! Snapshots: the dense grid, then the grid each time the face count has
//! fallen below `F₀·r^k` (`r` = [`DatasetParams::face_ratio`], k = 1, 2, …,
//! at most `snapshots − 1` in all), and the final grid: the model scores
//! coarsened grids at every iteration, not only dense ones.
//!
//! Format: one safetensors file; tensor names are prefixed with the
//! snapshot index (`"0/node_x"`, …), little-endian, row-major:
//! `node_x` f32 \[N,2\], `edge_x` f32 \[E,8\], `edge_ends` i64 \[E,2\],
//! `nbr_node` i64 \[N,K\], `nbr_edge` i64 \[N,K\], `nbr_mask` f32 \[N,K\],
//! `target` f32 \[E,2\], `valid` u8 \[E\], `allow_rel` f32 \[E\], `y` f32 \[E\].
//! Metadata: `format` = `abgs-dataset-1`, `snapshots`, `source`, `t_size`,
//! `beta`, `clearance`, and per snapshot `"{s}/iteration"`, `"{s}/faces"`.
//! Python reads it with `safetensors.numpy.load_file`.
//!
//! Cost: the LBO-ABGS run plus, per snapshot, the exact estimate of every
//! edge, O(E·S log F) (parallel; the same bits for any thread count).

use super::features::graph;
use super::runtime::GraphInputs;
use super::scorer::edge_allowance;
use crate::error::{Error, Result};
use crate::mesh::halfedge::E_LOCKED;
use crate::mesh::Grid;
use crate::simplify::estimate::{self, Estimate};
use crate::simplify::{run_loop, Accurate, SimplifyParams, SimplifyReport, View};
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::Path;

/// Metadata format tag.
pub const FORMAT: &str = "abgs-dataset-1";

/// How to take snapshots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DatasetParams {
    /// Most snapshots per run, the dense and the final grid included
    /// (default 6, at least 2).
    pub snapshots: usize,
    /// A snapshot is taken each time the face count falls below the dense
    /// count times this ratio to the power of the snapshots taken (default
    /// 0.6).
    pub face_ratio: f64,
}

impl Default for DatasetParams {
    fn default() -> Self {
        DatasetParams {
            snapshots: 6,
            face_ratio: 0.6,
        }
    }
}

/// One graph with its targets.
#[derive(Debug, Clone)]
pub struct Snapshot {
    /// The loop iteration it was taken before (1 = the dense grid).
    pub iteration: usize,
    /// Faces of the grid.
    pub faces: usize,
    /// The model's inputs.
    pub graph: GraphInputs,
    /// `(Δs − 1, Δd / h_loc)` per edge (NaN when invalid).
    pub target: Vec<[f32; 2]>,
    /// 1 when the collapse is allowed.
    pub valid: Vec<u8>,
    /// The distance envelope at the edge divided by `h_loc`.
    pub allow_rel: Vec<f32>,
    /// The accurate score at the run's parameters.
    pub y: Vec<f32>,
}

/// Labels every live edge of `view.mesh`. Parallel; O(E·S log F).
fn snapshot(view: &View) -> Result<Snapshot> {
    let mesh = view.mesh;
    let g = graph(mesh)?;
    let rows: Vec<([f32; 2], u8, f32, f32)> = g
        .edges
        .par_iter()
        .map(|&e| {
            let est = if mesh.edge_flags[e as usize] & E_LOCKED != 0 {
                Estimate::invalid(0.0, estimate::Binding::Topology)
            } else {
                estimate::estimate(mesh, view.target, e, view.lim, f64::INFINITY)
            };
            let [a, b] = mesh.edge_vertices(e);
            let h_loc = mesh.vertex_size[a as usize].min(mesh.vertex_size[b as usize]);
            let allow = edge_allowance(mesh, view.target, e, view.lim) / h_loc;
            let t = if est.valid {
                [(est.ds - 1.0) as f32, (est.dd / h_loc) as f32]
            } else {
                [f32::NAN; 2]
            };
            (t, est.valid as u8, allow as f32, est.y as f32)
        })
        .collect();
    Ok(Snapshot {
        iteration: view.iteration as usize,
        faces: mesh.face_count(),
        graph: g.inputs,
        target: rows.iter().map(|r| r.0).collect(),
        valid: rows.iter().map(|r| r.1).collect(),
        allow_rel: rows.iter().map(|r| r.2).collect(),
        y: rows.iter().map(|r| r.3).collect(),
    })
}

/// Runs LBO-ABGS on `grid` (with sizes) and takes snapshots along the way
/// (see the module doc). Returns them with the run's report.
pub fn trajectory(
    grid: &Grid,
    params: &SimplifyParams,
    dp: &DatasetParams,
) -> Result<(Vec<Snapshot>, SimplifyReport)> {
    if dp.snapshots < 2 || !(dp.face_ratio > 0.0 && dp.face_ratio < 1.0) {
        return Err(Error::InvalidArgument(
            "snapshots must be at least 2 and face_ratio in (0, 1)".into(),
        ));
    }
    let f0 = grid.triangles().len() as f64;
    let mut snaps: Vec<Snapshot> = Vec::new();
    let mut next = f0;
    let mut last_faces = usize::MAX;
    let mut observe = |view: &View| -> Result<()> {
        let faces = view.mesh.face_count();
        let due = faces as f64 <= next && snaps.len() + 1 < dp.snapshots;
        if (due || view.last) && faces != last_faces {
            snaps.push(snapshot(view)?);
            last_faces = faces;
            while faces as f64 <= next {
                next *= dp.face_ratio;
            }
        }
        Ok(())
    };
    let mut scorer = Accurate::default();
    let out = run_loop(grid, params, &mut scorer, None, Some(&mut observe))?;
    Ok((snaps, out.report))
}

fn bytes_f32(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

fn bytes_i64(v: &[i64]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// Writes `snaps` to `path` in the format of the module doc, with `meta`
/// added to the metadata.
pub fn write(path: &Path, snaps: &[Snapshot], meta: &[(&str, String)]) -> Result<()> {
    use safetensors::tensor::{Dtype, TensorView};
    let mut owned: Vec<(String, Dtype, Vec<usize>, Vec<u8>)> = Vec::new();
    let mut info: HashMap<String, String> = HashMap::new();
    info.insert("format".into(), FORMAT.into());
    info.insert("snapshots".into(), snaps.len().to_string());
    for (k, v) in meta {
        info.insert(k.to_string(), v.clone());
    }
    for (s, snap) in snaps.iter().enumerate() {
        let g = &snap.graph;
        let (n, e, k) = (g.n_nodes, g.n_edges, g.k);
        info.insert(format!("{s}/iteration"), snap.iteration.to_string());
        info.insert(format!("{s}/faces"), snap.faces.to_string());
        let t: Vec<f32> = snap.target.iter().flatten().copied().collect();
        let mut add = |name: &str, dt: Dtype, shape: Vec<usize>, data: Vec<u8>| {
            owned.push((format!("{s}/{name}"), dt, shape, data));
        };
        add("node_x", Dtype::F32, vec![n, 2], bytes_f32(&g.node_x));
        add("edge_x", Dtype::F32, vec![e, 8], bytes_f32(&g.edge_x));
        add("edge_ends", Dtype::I64, vec![e, 2], bytes_i64(&g.edge_ends));
        add("nbr_node", Dtype::I64, vec![n, k], bytes_i64(&g.nbr_node));
        add("nbr_edge", Dtype::I64, vec![n, k], bytes_i64(&g.nbr_edge));
        add("nbr_mask", Dtype::F32, vec![n, k], bytes_f32(&g.nbr_mask));
        add("target", Dtype::F32, vec![e, 2], bytes_f32(&t));
        add("valid", Dtype::U8, vec![e], snap.valid.clone());
        add("allow_rel", Dtype::F32, vec![e], bytes_f32(&snap.allow_rel));
        add("y", Dtype::F32, vec![e], bytes_f32(&snap.y));
    }
    let mut views = Vec::with_capacity(owned.len());
    for (name, dt, shape, data) in &owned {
        let v = TensorView::new(*dt, shape.clone(), data)
            .map_err(|e| Error::InvalidArgument(format!("dataset tensor {name}: {e}")))?;
        views.push((name.clone(), v));
    }
    safetensors::tensor::serialize_to_file(views, Some(info), path).map_err(|e| match e {
        safetensors::SafeTensorError::IoError(io) => Error::io(path, io),
        other => Error::InvalidArgument(format!("dataset: {other}")),
    })
}
