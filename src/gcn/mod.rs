//! GCN-ABGS, the learned simplifier (DESIGN §3.6–3.7): a small graph network
//! that predicts, for every edge of a grid being simplified, the two
//! unit-free errors the accurate estimate of LBO-ABGS would compute
//! (`Δs − 1` and `Δd / h_loc`), in one forward pass.
//!
//! - [`features`]: the model's inputs, one function for training and inference;
//! - [`dataset`]: training graphs along LBO-ABGS runs (`abgs dataset`);
//! - [`runtime`]: the ONNX model through the `ort` API (pure-Rust tract
//!   backend by default; ONNX Runtime with the `onnxruntime` feature);
//! - [`scorer`]: the model as the simplification loop's edge scorer.
//!
//! The model ships inside the library ([`EMBEDDED_MODEL`], trained by
//! `training/build_model.sh`; its card is `models/MODEL_CARD.md`).

pub mod dataset;
pub mod features;
pub mod runtime;
pub mod scorer;

pub use runtime::Model;
pub use scorer::Learned;

use crate::error::Result;
use std::sync::OnceLock;

/// The embedded ONNX model's bytes (`models/gcn_abgs.onnx`).
pub const EMBEDDED_MODEL: &[u8] = include_bytes!("../../models/gcn_abgs.onnx");

/// The embedded model, loaded once per process. Errors when it cannot be
/// loaded (the error is returned again on every call).
pub fn embedded_model() -> Result<&'static Model> {
    static MODEL: OnceLock<std::result::Result<Model, String>> = OnceLock::new();
    MODEL
        .get_or_init(|| Model::from_bytes(EMBEDDED_MODEL).map_err(|e| e.to_string()))
        .as_ref()
        .map_err(|m| crate::error::Error::InvalidArgument(format!("embedded model: {m}")))
}
