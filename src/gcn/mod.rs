//! GCN-ABGS, the learned simplifier (DESIGN §3.6–3.7): a small graph neural network,
//! exported to ONNX, scores every edge of the grid in one forward pass.
//!
//! - [`runtime`]: loading the ONNX model and running it through the `ort` API, on the
//!   built-in pure-Rust tract backend or (feature `onnxruntime`) ONNX Runtime proper.
pub mod runtime;
