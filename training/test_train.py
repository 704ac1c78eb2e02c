"""Developer test of the GCN-ABGS training pipeline (needs torch; not run in CI).

    /path/to/venv/bin/python -m pytest training/test_train.py -q

Trains on a tiny synthetic dataset, exports to ONNX, checks the operator set and
ONNX Runtime against torch, the files written, determinism, and the model's
invariances (node / neighbour order, the two ends of an edge). CPU, < 30 s.
"""

from __future__ import annotations

import json
import os
import sys

import numpy as np
import pytest

torch = pytest.importorskip("torch")
pytest.importorskip("onnx")
ort = pytest.importorskip("onnxruntime")

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import synth_dataset  # noqa: E402
import train  # noqa: E402


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    d = tmp_path_factory.mktemp("synth")
    for k in range(6):
        synth_dataset.write_part(str(d / f"part_{k:04d}.safetensors"), 1000 + k, 2, 500)
    return d


@pytest.fixture(scope="module")
def trained(data, tmp_path_factory):
    out = tmp_path_factory.mktemp("model")
    rec = train.main(["--data", str(data), "--out", str(out), "--seed", "0",
                      "--epochs", "2", "--hidden", "16", "--quiet"])
    return out, rec


def test_files_and_metrics(trained):
    out, rec = trained
    for f in ("gcn_abgs.onnx", "gcn_abgs.json", "MODEL_CARD.md"):
        assert (out / f).exists(), f
    with open(out / "gcn_abgs.json") as f:
        j = json.load(f)
    assert j["export"]["check"]["ok"]
    assert set(j["export"]["onnx"]["ops"]) <= train.ALLOWED_OPS
    for split in ("val", "test"):
        m = j["metrics"][split]
        assert 0 <= m["collapsible"]["precision"] <= 1
        assert m["ds_minus_1"]["mae_log"] >= 0
    # split by part: no file in two splits
    files = [set(j["data"][k]["files"]) for k in ("train", "val", "test")]
    assert not (files[0] & files[1] or files[0] & files[2] or files[1] & files[2])
    assert (out / "gcn_abgs.onnx").stat().st_size < 200_000
    card = (out / "MODEL_CARD.md").read_text()
    assert "Held-out metrics" in card and "nan" not in card.split("## Held-out")[0]


def test_onnx_interface(trained, data):
    out, _ = trained
    import onnx
    m = onnx.load(str(out / "gcn_abgs.onnx"))
    assert [i.name for i in m.graph.input] == train.INPUTS
    assert [o.name for o in m.graph.output] == [train.OUTPUT]
    so = ort.SessionOptions()
    so.intra_op_num_threads = 1
    sess = ort.InferenceSession(str(out / "gcn_abgs.onnx"), so,
                                providers=["CPUExecutionProvider"])
    # a graph of another size and K than the export example
    g, _ = train.load_file(str(data / "part_0003.safetensors"))
    for gr in g:
        (p,) = sess.run(None, {k: gr.x[k].numpy() for k in train.INPUTS})
        assert p.shape == (gr.n_edges, 2) and p.dtype == np.float32
        assert np.isfinite(p).all() and (p >= 0).all()


def _permute(g, rng):
    """The same graph with nodes, edges, edge ends and neighbour slots shuffled."""
    x = {k: v.numpy().copy() for k, v in g.x.items()}
    N, E = g.n_nodes, g.n_edges
    pn = rng.permutation(N)  # new -> old
    inv_n = np.argsort(pn)  # old -> new
    pe = rng.permutation(E)
    inv_e = np.argsort(pe)
    node_x = x["node_x"][pn]
    edge_x = x["edge_x"][pe]
    ends = inv_n[x["edge_ends"][pe]]
    flip = rng.uniform(size=E) < 0.5
    ends[flip] = ends[flip][:, ::-1]
    nn_, ne, nm = x["nbr_node"][pn], x["nbr_edge"][pn], x["nbr_mask"][pn]
    nn_ = inv_n[nn_]
    ne = inv_e[ne]
    for i in range(N):  # shuffle slots; padding stays (self, edge 0 of the new order)
        s = rng.permutation(nn_.shape[1])
        nn_[i], ne[i], nm[i] = nn_[i][s], ne[i][s], nm[i][s]
        pad = nm[i] == 0
        nn_[i][pad] = i
        ne[i][pad] = 0
    t = lambda a: torch.from_numpy(np.ascontiguousarray(a))  # noqa: E731
    return (t(node_x), t(edge_x), t(ends), t(nn_), t(ne), t(nm)), pe


def test_order_invariance(trained, data):
    _, rec = trained
    g, _ = train.load_file(str(data / "part_0001.safetensors"))
    gr = g[0]
    rng = np.random.default_rng(5)
    import onnxruntime
    out = trained[0]
    sess = onnxruntime.InferenceSession(str(out / "gcn_abgs.onnx"),
                                        providers=["CPUExecutionProvider"])
    (p0,) = sess.run(None, {k: gr.x[k].numpy() for k in train.INPUTS})
    inputs, pe = _permute(gr, rng)
    (p1,) = sess.run(None, dict(zip(train.INPUTS, (a.numpy() for a in inputs))))
    np.testing.assert_allclose(p1, p0[pe], rtol=1e-4, atol=1e-5)


def test_deterministic(data, tmp_path):
    a = train.main(["--data", str(data), "--out", str(tmp_path / "a"), "--seed", "3",
                    "--epochs", "1", "--hidden", "8", "--quiet"])
    b = train.main(["--data", str(data), "--out", str(tmp_path / "b"), "--seed", "3",
                    "--epochs", "1", "--hidden", "8", "--quiet"])
    assert a["export"]["sha256"] == b["export"]["sha256"]


def test_rejects_bad_files(tmp_path):
    from safetensors.numpy import save_file
    save_file({"0/node_x": np.zeros((3, 2), np.float32)}, str(tmp_path / "x.safetensors"),
              metadata={"format": "something-else", "snapshots": "1"})
    with pytest.raises(ValueError):
        train.load_file(str(tmp_path / "x.safetensors"))


def test_training_aggregation_matches_export(data):
    """The flat (CSR) aggregation used in training equals the padded one exported."""
    g, _ = train.load_file(str(data / "part_0002.safetensors"))
    rng = np.random.default_rng(0)
    norm = {"node": train.feature_stats(g, "node_x", train.NODE_LOG, rng),
            "edge": train.feature_stats(g, "edge_x", train.EDGE_LOG, rng)}
    torch.manual_seed(0)
    model = train.GcnAbgs(norm, 16, 2, [0.1, 0.25])
    with torch.no_grad():
        for gr in g:
            a = model.log_out(*gr.inputs())
            b = model.log_out(*gr.inputs(), csr=gr.csr)
            assert float((a - b).abs().max()) < 1e-5
