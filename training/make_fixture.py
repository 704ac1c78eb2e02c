#!/usr/bin/env python3
"""Builds the GCN-ABGS test fixture: a small ONNX model with the exact interface of
the real edge scorer (DESIGN.md 3.7) and the ops it will use, plus the outputs that
ONNX Runtime computes on a small deterministic graph.

Writes (next to the Rust runtime, src/gcn/testdata/):
  fixture.onnx           the model (opset 17, dynamic N, E, K; seeded weights, a few KB)
  fixture_expected.json  a small graph's inputs (flattened, row-major) and ONNX
                         Runtime's `pred` on it; src/gcn/runtime.rs's tests compare
                         every backend against it (tolerance 1e-4)
  bad_node_features.onnx valid ONNX, wrong interface: node_x is [N,3]
  bad_mask_rank.onnx     valid ONNX, wrong interface: nbr_mask is [N,K,1]
  bad_output.onnx        valid ONNX, declares pred [E,T] but gives [E,3]: only a
                         run shows it
  bad_dim_names.onnx     valid ONNX, runs on ONNX Runtime, but every input names its
                         dynamic axes on its own (tract cannot unify them)

Needs only onnx, numpy and (for the expected outputs) onnxruntime; the versions used:
    python3 -m venv /tmp/ortv
    /tmp/ortv/bin/pip install onnx==1.23.2 numpy==2.4.6 onnxruntime==1.31.1
    /tmp/ortv/bin/python training/make_fixture.py

Model interface (all dims dynamic and named, one name each for N, E, K, shared by the
inputs that have it: tract cannot unify two names for one size; with torch.onnx.export,
dynamic_axes={"node_x": {0: "N"}, "edge_x": {0: "E"}, "edge_ends": {0: "E"},
"nbr_node": {0: "N", 1: "K"}, "nbr_edge": {0: "N", 1: "K"}, "nbr_mask": {0: "N", 1: "K"},
"pred": {0: "E"}}):
  node_x f32 [N,2], edge_x f32 [E,8], edge_ends i64 [E,2], nbr_node i64 [N,K],
  nbr_edge i64 [N,K], nbr_mask f32 [N,K]  ->  pred f32 [E,2] (non-negative)

Architecture (hidden width D): node MLP, edge MLP, two masked-mean message-passing
layers (Gather of node and edge embeddings by the [N,K] index tensors -> [N,K,D],
Relu, times the mask, ReduceSum over the slots, Div by max(count, 1)), global mean
pool over the nodes (ReduceMean keepdims, broadcast-added to the edges), head on
[edge + global, node_a + node_b, |node_a - node_b|] -> Softplus.
"""

import json
import os
import sys

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "src", "gcn", "testdata")
D = 8  # hidden width: keeps the file a few KB
SEED = 20240611


def build_model(d=D, node_feats=2, out_cols=2, mask_rank3=False, own_dim_names=False):
    """The fixture (defaults), or a variant with a wrong interface for the tests."""
    D = d  # noqa: N806
    rng = np.random.default_rng(SEED)
    inits = []

    def weight(name, shape, scale=None):
        scale = scale if scale is not None else 1.0 / np.sqrt(shape[0])
        w = (rng.standard_normal(shape) * scale).astype(np.float32)
        inits.append(numpy_helper.from_array(w, name))
        return name

    def const(name, arr):
        inits.append(numpy_helper.from_array(np.asarray(arr), name))
        return name

    nodes = []

    def op(kind, ins, out, **attrs):
        nodes.append(helper.make_node(kind, ins, [out], name=out, **attrs))
        return out

    def linear(x, w, b, out):
        return op("Add", [op("MatMul", [x, w], out + "_mm"), b], out)

    const("axes1", np.array([1], dtype=np.int64))
    const("axes2", np.array([2], dtype=np.int64))
    const("one", np.array(1.0, dtype=np.float32))
    const("idx0", np.array(0, dtype=np.int64))
    const("idx1", np.array(1, dtype=np.int64))

    # node and edge MLPs
    h = op("Relu", [linear("node_x", weight("Wn", [node_feats, D]), weight("bn", [D], 0.1), "hn0")], "h0")
    e = op("Relu", [linear("edge_x", weight("We", [8, D]), weight("be", [D], 0.1), "he0")], "e0")

    # mask [N,K,1] and the clamped neighbour count [N,1]
    if mask_rank3:
        mask3 = "nbr_mask"
        cnt = op("ReduceSum", ["nbr_mask", "axes1"], "cnt_raw", keepdims=0)
    else:
        mask3 = op("Unsqueeze", ["nbr_mask", "axes2"], "mask3")
        cnt = op("ReduceSum", ["nbr_mask", "axes1"], "cnt_raw", keepdims=1)
    cnt = op("Max", [cnt, "one"], "cnt")

    # two message-passing layers: h' = relu((h + mean_k relu(h[nbr] + e[nbr_edge])) W + b)
    for layer in (1, 2):
        p = f"l{layer}"
        hn = op("Gather", [h, "nbr_node"], p + "_hn", axis=0)  # [N,K,D]
        en = op("Gather", [e, "nbr_edge"], p + "_en", axis=0)  # [N,K,D]
        m = op("Relu", [op("Add", [hn, en], p + "_msum")], p + "_m")
        m = op("Mul", [m, mask3], p + "_mm3")
        s = op("ReduceSum", [m, "axes1"], p + "_s", keepdims=0)  # [N,D]
        agg = op("Div", [s, cnt], p + "_agg")
        z = op("Add", [h, agg], p + "_z")
        h = op("Relu", [linear(z, weight(p + "_W", [D, D]), weight(p + "_b", [D], 0.1), p + "_lin")], p + "_h")

    # global mean pool [1,D], broadcast-added to the edge embeddings [E,D]
    g = op("ReduceMean", [h], "g", axes=[0], keepdims=1)
    e2 = op("Relu", [linear(e, weight("We2", [D, D]), weight("be2", [D], 0.1), "he2")], "e2")
    eg = op("Add", [e2, g], "eg")

    # end embeddings: one Gather with the [E,2] index tensor (sum), one per end (difference)
    ends = op("Gather", [h, "edge_ends"], "ends", axis=0)  # [E,2,D]
    nsum = op("ReduceSum", [ends, "axes1"], "nsum", keepdims=0)
    a = op("Gather", [h, op("Gather", ["edge_ends", "idx0"], "end_a", axis=1)], "na", axis=0)
    b = op("Gather", [h, op("Gather", ["edge_ends", "idx1"], "end_b", axis=1)], "nb", axis=0)
    ndiff = op("Abs", [op("Sub", [a, b], "nsub")], "ndiff")

    cat = op("Concat", [eg, nsum, ndiff], "cat", axis=1)  # [E,3D]
    hid = op("Relu", [linear(cat, weight("Wh1", [3 * D, D]), weight("bh1", [D], 0.1), "hh1")], "hid")
    out = linear(hid, weight("Wh2", [D, out_cols]), weight("bh2", [out_cols], 0.1), "hh2")
    op("Softplus", [out], "pred")

    f32, i64 = TensorProto.FLOAT, TensorProto.INT64
    inputs = [
        helper.make_tensor_value_info("node_x", f32, ["N", node_feats]),
        helper.make_tensor_value_info("edge_x", f32, ["E", 8]),
        helper.make_tensor_value_info("edge_ends", i64, ["E", 2]),
        helper.make_tensor_value_info("nbr_node", i64, ["N", "K"]),
        helper.make_tensor_value_info("nbr_edge", i64, ["N", "K"]),
        helper.make_tensor_value_info("nbr_mask", f32, ["N", "K", 1] if mask_rank3 else ["N", "K"]),
    ]
    outputs = [helper.make_tensor_value_info("pred", f32, ["E", 2 if out_cols == 2 else "T"])]
    if own_dim_names:
        for i, vi in enumerate(inputs + outputs):
            for d in vi.type.tensor_type.shape.dim:
                if d.dim_param:
                    d.dim_param = f"{d.dim_param}_{i}"
    graph = helper.make_graph(nodes, "gcn_abgs_fixture", inputs, outputs, inits)
    model = helper.make_model(
        graph, opset_imports=[helper.make_opsetid("", 17)], producer_name="abgs make_fixture.py"
    )
    model.ir_version = 8
    onnx.checker.check_model(model, full_check=True)
    return model


def fixture_graph():
    """A 4 x 3 vertex grid of quads split into triangles, with seeded features.
    Returns the six inputs as numpy arrays; the neighbour lists are padded to
    K = max degree + 1 (so every node has at least one padding slot)."""
    rng = np.random.default_rng(SEED + 1)
    nx, ny = 4, 3
    vid = lambda i, j: j * nx + i  # noqa: E731
    tris = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            a, b, c, d = vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)
            tris += [(a, b, c), (a, c, d)]
    edges = sorted({tuple(sorted((t[k], t[(k + 1) % 3]))) for t in tris for k in range(3)})
    n, m = nx * ny, len(edges)
    adj = [[] for _ in range(n)]
    for ei, (u, v) in enumerate(edges):
        adj[u].append((v, ei))
        adj[v].append((u, ei))
    k = max(len(a) for a in adj) + 1
    nbr_node = np.tile(np.arange(n, dtype=np.int64)[:, None], (1, k))
    nbr_edge = np.zeros((n, k), dtype=np.int64)
    nbr_mask = np.zeros((n, k), dtype=np.float32)
    for v, lst in enumerate(adj):
        for s, (w, ei) in enumerate(lst):
            nbr_node[v, s], nbr_edge[v, s], nbr_mask[v, s] = w, ei, 1.0
    return {
        "node_x": rng.standard_normal((n, 2)).astype(np.float32),
        "edge_x": rng.standard_normal((m, 8)).astype(np.float32),
        "edge_ends": np.array(edges, dtype=np.int64),
        "nbr_node": nbr_node,
        "nbr_edge": nbr_edge,
        "nbr_mask": nbr_mask,
    }


def main():
    import onnxruntime as ort

    os.makedirs(OUT, exist_ok=True)
    model = build_model()
    path = os.path.join(OUT, "fixture.onnx")
    onnx.save(model, path)
    for name, kw in [
        ("bad_node_features", dict(node_feats=3)),
        ("bad_mask_rank", dict(mask_rank3=True)),
        ("bad_output", dict(out_cols=3)),
        ("bad_dim_names", dict(own_dim_names=True)),
    ]:
        onnx.save(build_model(d=2, **kw), os.path.join(OUT, name + ".onnx"))

    feeds = fixture_graph()
    so = ort.SessionOptions()
    so.intra_op_num_threads = 1
    so.inter_op_num_threads = 1
    sess = ort.InferenceSession(path, so, providers=["CPUExecutionProvider"])
    (pred,) = sess.run(["pred"], feeds)
    assert pred.shape == (feeds["edge_x"].shape[0], 2) and np.all(pred >= 0)

    n, k = feeds["nbr_node"].shape
    doc = {
        "about": "written by training/make_fixture.py: inputs row-major, pred from onnxruntime "
        + ort.__version__,
        "n_nodes": n,
        "n_edges": int(feeds["edge_x"].shape[0]),
        "k": k,
    }
    for name, arr in feeds.items():
        doc[name] = [float(x) if arr.dtype == np.float32 else int(x) for x in arr.ravel()]
    # float(np.float32) is exact in f64, and its repr parses back to the same f32
    doc["pred"] = [float(x) for x in pred.ravel()]
    with open(os.path.join(OUT, "fixture_expected.json"), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print(f"wrote {path} ({os.path.getsize(path)} bytes), N={n} E={doc['n_edges']} K={k}", file=sys.stderr)


if __name__ == "__main__":
    main()
