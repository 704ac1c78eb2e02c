//! Sessions specialised to one graph's sizes: the embedded model with its
//! dynamic dimensions N, E and K fixed to the sizes of the graph at hand.
//!
//! Why: tract picks its vectorised element-wise kernels (by-scalar and
//! same-shape binary operations) only when it can prove at optimisation time
//! that a tensor holds at least a few dozen elements. With N, E and K
//! symbolic it cannot (a symbol may be 0), so every Add, Max (the ReLUs), Sub
//! and Mul of the model over \[N, K, D\] and \[E, D\] tensors ran element by
//! element through a generic broadcasting loop: 47 % of GCN-ABGS's time on
//! occt_crankarm. With the sizes fixed, the same graph runs 2.4× faster
//! (occt_crankarm's dense grid, 86,979 edges, tract run directly: 455 ms →
//! 185 ms per pass, same output bits; the whole GCN-ABGS run 6.1 → 4.5 s),
//! for about 10–20 ms of parsing and optimising per session.
//!
//! So [`super::Model::predict`] on the tract backend opens a session
//! specialised to the graph when it has at least [`FIXED_MIN_EDGES`] edges,
//! runs it once and drops it; smaller graphs use the pooled dynamic
//! sessions. ONNX Runtime keeps the dynamic sessions (whether fixed sizes
//! would speed it up was not measured). Which session runs depends on E alone, so the
//! predictions stay the same bits run to run and for any thread count.
//!
//! Cost: O(model size) to decode, edit and encode the ONNX protobuf, plus
//! the backend's own parse and optimisation.

use prost::Message;
use tract_onnx::pb::{tensor_shape_proto::dimension::Value as DimValue, type_proto, ModelProto};

/// Fewest edges for which a specialised session is opened: at about 3 µs
/// saved per edge against 10–20 ms to open one, it pays from a few thousand
/// edges. Measured (GCN-ABGS's model time over a whole run, same output
/// bits): occt_crankarm 3.57 / 3.45 / 4.00 s and gmsh_bracket_assembly
/// 9.86 / 9.06 / 10.40 s from 1,024 / 4,096 / 16,384 edges.
pub const FIXED_MIN_EDGES: usize = 4_096;

/// The ONNX model `bytes` with its dimensions named as input `node_x`'s
/// axis 0 (N), `edge_x`'s axis 0 (E) and `nbr_node`'s axis 1 (K) fixed to
/// `n`, `e` and `k` in every declared input, output and intermediate value.
/// Errors when the bytes are not ONNX or those names are missing (the model
/// was checked on load, so neither is expected).
pub fn fixed_sizes(
    bytes: &[u8],
    n: usize,
    e: usize,
    k: usize,
) -> std::result::Result<Vec<u8>, String> {
    let mut model = ModelProto::decode(bytes).map_err(|err| format!("not an ONNX model: {err}"))?;
    let graph = model.graph.as_mut().ok_or("the ONNX file has no graph")?;
    let name_of = |input: &str, axis: usize| -> Option<String> {
        let v = graph.input.iter().find(|v| v.name == input)?;
        let Some(type_proto::Value::TensorType(t)) = v.r#type.as_ref()?.value.as_ref() else {
            return None;
        };
        match &t.shape.as_ref()?.dim.get(axis)?.value {
            Some(DimValue::DimParam(p)) => Some(p.clone()),
            _ => None,
        }
    };
    let sizes: Vec<(String, i64)> = [("node_x", 0, n), ("edge_x", 0, e), ("nbr_node", 1, k)]
        .into_iter()
        .map(|(input, axis, size)| {
            name_of(input, axis)
                .map(|name| (name, size as i64))
                .ok_or_else(|| format!("input '{input}' has no named axis {axis}"))
        })
        .collect::<std::result::Result<_, _>>()?;
    let values = graph
        .input
        .iter_mut()
        .chain(graph.output.iter_mut())
        .chain(graph.value_info.iter_mut());
    for v in values {
        let Some(type_proto::Value::TensorType(t)) =
            v.r#type.as_mut().and_then(|t| t.value.as_mut())
        else {
            continue;
        };
        for d in t.shape.iter_mut().flat_map(|s| s.dim.iter_mut()) {
            if let Some(DimValue::DimParam(p)) = &d.value {
                if let Some((_, size)) = sizes.iter().find(|(name, _)| name == p) {
                    d.value = Some(DimValue::DimValue(*size));
                }
            }
        }
    }
    Ok(model.encode_to_vec())
}
