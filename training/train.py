#!/usr/bin/env python3
"""Train GCN-ABGS on ``abgs dataset`` files and export it to ONNX.

Usage::

    python training/train.py --data DIR --out models/ --seed 0 \
        [--epochs N] [--time-budget-min M] [--hidden 32] [--threads 2]

``DIR`` holds ``*.safetensors`` files written by ``abgs dataset`` (format
``abgs-dataset-1``, one file per part, several snapshots each). If ``DIR`` has
sub-folders ``train/``, ``val/`` and ``test/`` they are the split; otherwise the
files (parts) are split 80/10/10 by a seeded permutation of their sorted names.
Edges are never split: every snapshot of a part lands in the part's split.

Writes ``OUT/gcn_abgs.onnx`` (inputs node_x, edge_x, edge_ends, nbr_node,
nbr_edge, nbr_mask; output pred = (Δs − 1, Δd / h_loc) per edge, >= 0),
``OUT/gcn_abgs.json`` (everything: data, split, normalisation, architecture,
training log, held-out metrics, export check) and ``OUT/MODEL_CARD.md``.

The run is deterministic for a given seed, thread count, torch version and
machine (torch.use_deterministic_algorithms, fixed threads, seeded shuffles);
``--time-budget-min`` is only a safety stop, recorded when it fires.
"""

from __future__ import annotations

import argparse
import glob
import hashlib
import json
import math
import os
import platform
import sys
import time

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F
from safetensors import safe_open

FORMAT = "abgs-dataset-1"
INPUTS = ["node_x", "edge_x", "edge_ends", "nbr_node", "nbr_edge", "nbr_mask"]
OUTPUT = "pred"
OPSET = 17
# the ONNX operators the Rust runtime (tract and ONNX Runtime) is promised
ALLOWED_OPS = {
    "Gather", "MatMul", "Gemm", "Add", "Sub", "Mul", "Div", "Relu", "Abs",
    "Max", "ReduceSum", "ReduceMean", "Concat", "Unsqueeze", "Squeeze",
    "Softplus", "Exp", "Log", "Constant",
}
NODE_FEATURES = ["log(h/h_ref)", "LBO_v*h"]
EDGE_FEATURES = ["LBO_e*h_e", "dihedral", "opp_angle_min", "opp_angle_max",
                 "height_ratio_min", "height_ratio_max", "length/mean_length",
                 "normal_angle"]
TARGETS = ["ds_minus_1", "dd_over_hloc"]
# features that are non-negative and heavy-tailed: log1p before standardising
NODE_LOG = [0, 1]
EDGE_LOG = [1, 0, 0, 0, 1, 1, 1, 0]


# --------------------------------------------------------------------------
# data


class Graph:
    """One snapshot: torch tensors of the model inputs plus labels."""

    __slots__ = ("file", "snapshot", "iteration", "t_size", "x", "target",
                 "valid", "allow_rel", "y", "n_nodes", "n_edges", "K", "csr")

    def __init__(self, file, snapshot, meta, t):
        self.file = file
        self.snapshot = snapshot
        self.iteration = int(meta.get(f"{snapshot}/iteration", snapshot))
        self.t_size = float(meta.get("t_size", 1.2))
        self.x = {
            "node_x": torch.from_numpy(t["node_x"].astype(np.float32)),
            "edge_x": torch.from_numpy(t["edge_x"].astype(np.float32)),
            "edge_ends": torch.from_numpy(t["edge_ends"].astype(np.int64)),
            "nbr_node": torch.from_numpy(t["nbr_node"].astype(np.int64)),
            "nbr_edge": torch.from_numpy(t["nbr_edge"].astype(np.int64)),
            "nbr_mask": torch.from_numpy(t["nbr_mask"].astype(np.float32)),
        }
        self.target = t["target"].astype(np.float32)
        self.valid = t["valid"].astype(bool)
        self.allow_rel = t["allow_rel"].astype(np.float32)
        self.y = t["y"].astype(np.float32)
        self.n_nodes = t["node_x"].shape[0]
        self.n_edges = t["edge_x"].shape[0]
        self.K = t["nbr_node"].shape[1]
        # the real neighbour slots as a flat list (training only: the same masked
        # mean without the padding, see GcnAbgs.log_out)
        m = t["nbr_mask"] > 0
        dst = np.nonzero(m)[0]
        self.csr = (torch.from_numpy(dst.astype(np.int64)),
                    torch.from_numpy(t["nbr_node"][m].astype(np.int64)),
                    torch.from_numpy(t["nbr_edge"][m].astype(np.int64)))

    def inputs(self):
        return tuple(self.x[k] for k in INPUTS)


def check_graph(t, where):
    N = t["node_x"].shape[0]
    E = t["edge_x"].shape[0]
    K = t["nbr_node"].shape[1]
    shapes = {
        "node_x": (N, 2), "edge_x": (E, 8), "edge_ends": (E, 2),
        "nbr_node": (N, K), "nbr_edge": (N, K), "nbr_mask": (N, K),
        "target": (E, 2), "valid": (E,), "allow_rel": (E,), "y": (E,),
    }
    for k, s in shapes.items():
        if k not in t:
            raise ValueError(f"{where}: missing tensor {k}")
        if tuple(t[k].shape) != s:
            raise ValueError(f"{where}: {k} has shape {t[k].shape}, want {s}")
    for k, n in (("edge_ends", N), ("nbr_node", N), ("nbr_edge", E)):
        a = t[k]
        if a.size and (a.min() < 0 or a.max() >= n):
            raise ValueError(f"{where}: {k} out of range [0,{n})")
    for k in ("node_x", "edge_x"):
        if not np.isfinite(t[k]).all():
            raise ValueError(f"{where}: {k} has non-finite values "
                             "(the model's inputs must be finite)")


def load_file(path):
    graphs = []
    with safe_open(path, "np") as f:
        meta = f.metadata() or {}
        if meta.get("format") != FORMAT:
            raise ValueError(f"{path}: format {meta.get('format')!r}, want {FORMAT}")
        S = int(meta["snapshots"])
        keys = set(f.keys())
        for s in range(S):
            t = {}
            for k in ("node_x", "edge_x", "edge_ends", "nbr_node", "nbr_edge",
                      "nbr_mask", "target", "valid", "allow_rel", "y"):
                name = f"{s}/{k}"
                if name in keys:
                    t[k] = f.get_tensor(name)
            check_graph(t, f"{path} snapshot {s}")
            if t["edge_x"].shape[0] == 0:
                continue
            graphs.append(Graph(os.path.basename(path), s, meta, t))
    return graphs, meta


def find_split(data_dir, seed):
    subs = {k: os.path.join(data_dir, k) for k in ("train", "val", "test")}
    if all(os.path.isdir(p) for p in subs.values()):
        split = {k: sorted(glob.glob(os.path.join(p, "*.safetensors")))
                 for k, p in subs.items()}
        how = "folders train/ val/ test/"
    else:
        files = sorted(glob.glob(os.path.join(data_dir, "*.safetensors")))
        if len(files) < 3:
            raise SystemExit(f"{data_dir}: need at least 3 dataset files, found {len(files)}")
        perm = np.random.default_rng(seed).permutation(len(files))
        n_val = max(1, int(round(0.1 * len(files))))
        n_test = max(1, int(round(0.1 * len(files))))
        test = sorted(files[i] for i in perm[:n_test])
        val = sorted(files[i] for i in perm[n_test:n_test + n_val])
        train = sorted(files[i] for i in perm[n_test + n_val:])
        split = {"train": train, "val": val, "test": test}
        how = f"seeded permutation of the sorted file names (seed {seed}), 80/10/10 by part"
    for k, v in split.items():
        if not v:
            raise SystemExit(f"empty {k} split")
    return split, how


def load_split(files):
    graphs, metas = [], {}
    for p in files:
        g, m = load_file(p)
        graphs += g
        metas[os.path.basename(p)] = m
    return graphs, metas


# --------------------------------------------------------------------------
# target transform and loss


def transform_targets(target, cap, scale=(1.0, 1.0)):
    """log1p(min(t, cap) / scale); +inf -> cap; also returns the 'censored' mask."""
    t = np.where(np.isposinf(target), cap, target)
    t = np.clip(t, 0.0, cap)
    censored = t >= cap
    return np.log1p(t / np.asarray(scale, np.float32)).astype(np.float32), censored


def graph_labels(g, cap, alpha, scale):
    """Per-edge label tensors of the valid edges of g (cached)."""
    m = g.valid & ~np.isnan(g.target).any(1)
    idx = np.nonzero(m)[0]
    tl, cens = transform_targets(g.target[idx], cap, scale)
    thr = np.stack([np.full(len(idx), math.log1p((g.t_size - 1.0) / scale[0])),
                    np.log1p(g.allow_rel[idx] / scale[1])], 1).astype(np.float32)
    # extra weight near the decision thresholds (in log space)
    with np.errstate(invalid="ignore", over="ignore"):
        w = 1.0 + alpha * np.exp(-((tl - thr) / 0.15) ** 2)
    w = np.where(np.isfinite(w), w, 1.0)
    return (torch.from_numpy(idx), torch.from_numpy(tl),
            torch.from_numpy(cens), torch.from_numpy(w.astype(np.float32)))


def loss_fn(o, tl, cens, w, delta=0.1):
    # censored targets (at the cap or +inf) only punish under-prediction
    d = torch.where(cens, torch.relu(tl - o), o - tl)
    ad = d.abs()
    hub = torch.where(ad < delta, 0.5 * d * d / delta, ad - 0.5 * delta)
    return (hub * w).sum() / w.sum()


# --------------------------------------------------------------------------
# model


class Normalise(nn.Module):
    """x -> standardise(clip(log1p-selected(x))) with constants from training."""

    def __init__(self, logmask, lo, hi, mean, std):
        super().__init__()
        f = lambda a: torch.tensor(np.asarray(a, np.float32))  # noqa: E731
        self.register_buffer("logmask", f(logmask))
        self.register_buffer("linmask", 1.0 - f(logmask))
        self.register_buffer("lo", f(lo))
        self.register_buffer("hi", f(hi))
        self.register_buffer("mean", f(mean))
        self.register_buffer("inv_std", 1.0 / f(std))

    def forward(self, x):
        x = x * self.linmask + torch.log(torch.relu(x) + 1.0) * self.logmask
        x = self.lo + torch.relu(x - self.lo)  # max(x, lo)
        x = self.hi - torch.relu(self.hi - x)  # min(x, hi)
        return (x - self.mean) * self.inv_std


class GcnAbgs(nn.Module):
    def __init__(self, norm, hidden=32, layers=2, scale=(1.0, 1.0)):
        super().__init__()
        self.register_buffer("scale", torch.tensor(np.asarray(scale, np.float32)))
        D = hidden
        self.norm_node = Normalise(*norm["node"])
        self.norm_edge = Normalise(*norm["edge"])
        self.node1, self.node2 = nn.Linear(2, D), nn.Linear(D, D)
        self.edge1, self.edge2 = nn.Linear(8, D), nn.Linear(D, D)
        self.msg_edge = nn.ModuleList(nn.Linear(8, D) for _ in range(layers))
        self.upd1 = nn.ModuleList(nn.Linear(2 * D, D) for _ in range(layers))
        self.upd2 = nn.ModuleList(nn.Linear(D, D) for _ in range(layers))
        self.glob1, self.glob2 = nn.Linear(D, D), nn.Linear(D, D)
        self.head1 = nn.Linear(3 * D, D)
        self.head_g = nn.Linear(D, D, bias=False)
        self.head2 = nn.Linear(D, D)
        self.head3 = nn.Linear(D, 2)
        self.register_buffer("one", torch.ones(()))

    def log_out(self, node_x, edge_x, edge_ends, nbr_node, nbr_edge, nbr_mask,
                edge_idx=None, csr=None):
        """The raw predictions in the training space, log1p(pred / scale);
        may be negative (the exported output clamps at 0). With edge_idx, only
        for those edges (training: the head runs on the labelled edges only).
        With csr = (node, neighbour, edge) of the real slots, the aggregation
        runs over those instead of the padded [N,K] lists: the same masked mean
        (up to summation order) at 2E instead of N*K messages; training only,
        the export uses the padded form (Gather + masked ReduceSum)."""
        xn = self.norm_node(node_x)
        xe = self.norm_edge(edge_x)
        h = self.node2(torch.relu(self.node1(xn)))
        mask = nbr_mask.unsqueeze(2)  # [N,K,1]
        inv_cnt = self.one / torch.maximum(nbr_mask.sum(1, keepdim=True), self.one)
        for lin_e, u1, u2 in zip(self.msg_edge, self.upd1, self.upd2):
            ee = lin_e(xe)  # [E,D]
            if csr is None:
                msg = torch.relu(F.embedding(nbr_node, h) + F.embedding(nbr_edge, ee))
                agg = (msg * mask).sum(1) * inv_cnt  # [N,D]
            else:
                msg = torch.relu(h[csr[1]] + ee[csr[2]])  # [M,D]
                agg = torch.zeros_like(h).index_add_(0, csr[0], msg) * inv_cnt
            h = h + u2(torch.relu(u1(torch.cat([h, agg], 1))))
        g = h.mean(0, keepdim=True)  # [1,D]
        g = self.glob2(torch.relu(self.glob1(g)))
        if edge_idx is not None:
            xe = xe[edge_idx]
            edge_ends = edge_ends[edge_idx]
        e = self.edge2(torch.relu(self.edge1(xe)))
        ha = F.embedding(edge_ends[:, 0], h)
        hb = F.embedding(edge_ends[:, 1], h)
        z = torch.relu(self.head1(torch.cat([e, ha + hb, torch.abs(ha - hb)], 1))
                       + self.head_g(g))
        z = torch.relu(self.head2(z))
        return self.head3(z)

    def forward(self, node_x, edge_x, edge_ends, nbr_node, nbr_edge, nbr_mask):
        o = self.log_out(node_x, edge_x, edge_ends, nbr_node, nbr_edge, nbr_mask)
        return (torch.exp(torch.relu(o)) - self.one) * self.scale


def n_params(model):
    return sum(p.numel() for p in model.parameters())


def feature_stats(graphs, key, logcols, rng, max_rows=2_000_000):
    rows = sum(g.x[key].shape[0] for g in graphs)
    keep = min(1.0, max_rows / max(rows, 1))
    parts = []
    for g in graphs:
        a = g.x[key].numpy()
        if keep < 1.0:
            a = a[rng.uniform(size=len(a)) < keep]
        parts.append(a)
    a = np.concatenate(parts).astype(np.float64)
    lm = np.asarray(logcols, bool)
    a[:, lm] = np.log1p(np.maximum(a[:, lm], 0.0))
    lo = np.percentile(a, 0.1, axis=0)
    hi = np.percentile(a, 99.9, axis=0)
    a = np.clip(a, lo, hi)
    mean = a.mean(0)
    std = np.maximum(a.std(0), 1e-3)
    return [list(map(float, v)) for v in (np.asarray(logcols, float), lo, hi, mean, std)]


# --------------------------------------------------------------------------
# metrics


def rankdata(a):
    order = np.argsort(a, kind="mergesort")
    s = a[order]
    r = np.empty(len(a), np.float64)
    # average ranks over ties
    edges = np.nonzero(np.r_[True, s[1:] != s[:-1], True])[0]
    for i in range(len(edges) - 1):
        lo, hi = edges[i], edges[i + 1]
        r[order[lo:hi]] = 0.5 * (lo + hi - 1)
    return r


def _corr(a, b):
    if len(a) < 2 or a.std() == 0 or b.std() == 0:
        return float("nan")
    return float(np.corrcoef(a, b)[0, 1])


def _near_thr(p, t, thr):
    """Median |p/t - 1| over edges whose truth lies within a factor 2 of the threshold."""
    m = (t > 0.5 * thr) & (t < 2.0 * thr) & np.isfinite(t)
    return float(np.median(np.abs(p[m] / t[m] - 1.0))) if m.any() else float("nan")


def spearman(a, b):
    return _corr(rankdata(a), rankdata(b))


@torch.no_grad()
def predict(model, g):
    return model(*g.inputs()).numpy()


@torch.no_grad()
def select_precision(p, g, fraction=0.1):
    """GCN-ABGS's choice on one graph: the valid edges with the lowest predicted
    score, predicted collapsible, at most fraction * E of them (before the 1-ring
    filter). Returns (selected, truly collapsible among them)."""
    ts = g.t_size
    with np.errstate(divide="ignore", invalid="ignore"):
        yp = np.minimum(1.0, 0.5 * np.maximum(p[:, 0] / (ts - 1.0), p[:, 1] / g.allow_rel))
    ok = g.valid & ~np.isnan(g.target).any(1) & (yp < 0.5)
    idx = np.nonzero(ok)[0]
    k = min(len(idx), int(fraction * g.n_edges))
    if k == 0:
        return 0, 0
    chosen = idx[np.argsort(yp[idx], kind="stable")[:k]]
    return k, int((g.y[chosen] < 0.5).sum())


def evaluate(model, graphs, cap, scale, max_rank=2_000_000, seed=0):
    P, T, A, Y, TS, V, SN = [], [], [], [], [], [], []
    sel = {}
    for g in graphs:
        p = predict(model, g)
        k, good = select_precision(p, g)
        a, b = sel.get(g.snapshot, (0, 0))
        sel[g.snapshot] = (a + k, b + good)
        P.append(p), T.append(g.target), A.append(g.allow_rel), Y.append(g.y)
        TS.append(np.full(g.n_edges, g.t_size, np.float32)), V.append(g.valid)
        SN.append(np.full(g.n_edges, g.snapshot, np.int64))
    P, T, A, Y, TS, V, SN = map(np.concatenate, (P, T, A, Y, TS, V, SN))
    m = V & ~np.isnan(T).any(1)
    P, T, A, Y, TS, SN = P[m], T[m], A[m], Y[m], TS[m], SN[m]
    tl, _ = transform_targets(T, cap)
    pl, _ = transform_targets(P, cap)
    ts, _ = transform_targets(T, cap, scale)
    ps, _ = transform_targets(P, cap, scale)
    out = {"edges_valid": int(m.sum()), "edges_total": int(len(m)),
           "graphs": len(graphs)}
    sub = np.arange(len(tl))
    if len(sub) > max_rank:  # Spearman on a fixed subsample for speed
        sub = np.sort(np.random.default_rng(seed).choice(len(tl), max_rank, replace=False))
    for k, name in enumerate(TARGETS):
        out[name] = {
            "mae_log": float(np.abs(pl[:, k] - tl[:, k]).mean()),
            "mae_train_space": float(np.abs(ps[:, k] - ts[:, k]).mean()),
            "median_rel_err_near_threshold": _near_thr(P[:, k], T[:, k],
                                                      (TS - 1.0) if k == 0 else A),
            "pearson_log": _corr(pl[:, k], tl[:, k]),
            "spearman": spearman(pl[sub, k], tl[sub, k]),
            "capped_or_inf_share": float((tl[:, k] >= math.log1p(cap) - 1e-6).mean()),
        }
    truth = Y < 0.5
    pred_c = (P[:, 0] < TS - 1.0) & (P[:, 1] / A < 1.0)
    tp = int((truth & pred_c).sum())
    prec = tp / max(int(pred_c.sum()), 1)
    rec = tp / max(int(truth.sum()), 1)
    y_pred = np.minimum(1.0, 0.5 * np.maximum(P[:, 0] / (TS - 1.0), P[:, 1] / A))
    truth_from_t = (T[:, 0] < TS - 1.0) & (T[:, 1] / A < 1.0)
    out["collapsible"] = {
        "truth_share": float(truth.mean()),
        "predicted_share": float(pred_c.mean()),
        "precision": float(prec),
        "recall": float(rec),
        "f1": float(2 * prec * rec / max(prec + rec, 1e-12)),
        "accuracy": float((truth == pred_c).mean()),
        "score_spearman": spearman(y_pred[sub], Y[sub]),
        "truth_y_vs_targets_agreement": float((truth == truth_from_t).mean()),
        "selected_10pct_precision": (sum(b for _, b in sel.values())
                                     / max(sum(a for a, _ in sel.values()), 1)),
    }
    # by snapshot index (0 = dense grid; the last ones are the coarsest)
    by = {}
    for s in sorted(set(SN.tolist())):
        k = SN == s
        t, p = truth[k], pred_c[k]
        tp = int((t & p).sum())
        pr, rc = tp / max(int(p.sum()), 1), tp / max(int(t.sum()), 1)
        by[str(s)] = {"edges_valid": int(k.sum()), "truth_share": float(t.mean()),
                      "precision": pr, "recall": rc,
                      "f1": 2 * pr * rc / max(pr + rc, 1e-12),
                      "selected_10pct": sel.get(s, (0, 0))[0],
                      "selected_10pct_precision": sel.get(s, (0, 0))[1] / max(sel.get(s, (0, 0))[0], 1),
                      "mae_log": [float(np.abs(pl[k, j] - tl[k, j]).mean()) for j in range(2)]}
    out["by_snapshot"] = by
    return out


# --------------------------------------------------------------------------
# export


def export_onnx(model, example, path):
    model.eval()
    dyn = {
        "node_x": {0: "N"}, "edge_x": {0: "E"}, "edge_ends": {0: "E"},
        "nbr_node": {0: "N", 1: "K"}, "nbr_edge": {0: "N", 1: "K"},
        "nbr_mask": {0: "N", 1: "K"}, OUTPUT: {0: "E"},
    }
    kw = dict(input_names=INPUTS, output_names=[OUTPUT], dynamic_axes=dyn,
              opset_version=OPSET, do_constant_folding=True)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            torch.onnx.export(model, example, path, dynamo=False, **kw)
        except TypeError:  # older torch without the dynamo argument
            torch.onnx.export(model, example, path, **kw)
    import onnx
    m = onnx.load(path)
    onnx.checker.check_model(m, full_check=True)
    ops = sorted({n.op_type for n in m.graph.node})
    bad = sorted(set(ops) - ALLOWED_OPS)
    if bad:
        raise SystemExit(f"exported ONNX uses operators outside the allowed set: {bad}")
    if m.graph.sparse_initializer:
        raise SystemExit("exported ONNX has sparse initializers")
    names_in = [i.name for i in m.graph.input]
    names_out = [o.name for o in m.graph.output]
    if names_in != INPUTS or names_out != [OUTPUT]:
        raise SystemExit(f"exported ONNX has inputs {names_in}, outputs {names_out}")
    counts = {}
    for n in m.graph.node:
        counts[n.op_type] = counts.get(n.op_type, 0) + 1
    return {"ops": ops, "op_counts": dict(sorted(counts.items())),
            "nodes": len(m.graph.node), "opset": OPSET,
            "ir_version": int(m.ir_version)}


def check_onnx(model, path, graphs, tol=1e-4):
    import onnxruntime as ort
    so = ort.SessionOptions()
    so.intra_op_num_threads = 1
    so.inter_op_num_threads = 1
    sess = ort.InferenceSession(path, so, providers=["CPUExecutionProvider"])
    worst_abs = worst_rel = 0.0
    for g in graphs:
        feed = {k: g.x[k].numpy() for k in INPUTS}
        (a,) = sess.run([OUTPUT], feed)
        b = predict(model, g)
        if a.shape != b.shape:
            raise SystemExit(f"ONNX output shape {a.shape} != torch {b.shape}")
        d = np.abs(a.astype(np.float64) - b)
        worst_abs = max(worst_abs, float(d.max()))
        worst_rel = max(worst_rel, float((d / np.maximum(np.abs(b), 1.0)).max()))
        if (a < 0).any() or not np.isfinite(a).all():
            raise SystemExit("ONNX predictions negative or non-finite")
    ok = worst_rel <= tol
    return {"graphs": len(graphs), "max_abs_diff": worst_abs,
            "max_rel_diff": worst_rel, "tolerance_rel": tol, "ok": ok,
            "onnxruntime": ort.__version__, "threads": 1}


# --------------------------------------------------------------------------
# main


def split_summary(graphs, files):
    return {
        "parts": len(files),
        "graphs": len(graphs),
        "nodes": int(sum(g.n_nodes for g in graphs)),
        "edges": int(sum(g.n_edges for g in graphs)),
        "valid_edges": int(sum(g.valid.sum() for g in graphs)),
        "max_K": int(max(g.K for g in graphs)),
        "files": [os.path.basename(f) for f in files],
    }


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        h.update(f.read())
    return h.hexdigest()


def fmt(x, d=3):
    return "nan" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{d}f}"


def write_card(path, rec):
    a, d, t, e = rec["architecture"], rec["data"], rec["training"], rec["export"]
    lines = [
        "# GCN-ABGS model card",
        "",
        "`gcn_abgs.onnx`: the learned edge scorer of GCN-ABGS (DESIGN.md §3.6-3.7). For every "
        "edge of a sized triangle grid it predicts the two unit-free numbers that LBO-ABGS's "
        "accurate estimate computes, `Δs − 1` and `Δd / h_loc` (non-negative); the caller turns "
        "them into the score `y = min(1, ½·max((Δs−1)/(T_size−1), (Δd/h_loc)/allow_rel))` with its "
        "own thresholds and checks validity itself (the model does not predict validity).",
        "",
        "Generated by `training/train.py`; do not edit by hand.",
        "",
        "## Interface",
        "",
        f"ONNX opset {e['onnx']['opset']}, {e['bytes']} bytes, sha256 `{e['sha256']}`.",
        "",
        "| name | type | shape | meaning |",
        "|---|---|---|---|",
        "| node_x | f32 | [N,2] | log(h/h_ref) (h_ref = median size), LBO_v·h |",
        "| edge_x | f32 | [E,8] | LBO_e·h_e, dihedral, opposite angles (min,max), height/length ratios (min,max), length/mean length, vertex-normal angle |",
        "| edge_ends | i64 | [E,2] | node indices of the ends |",
        "| nbr_node, nbr_edge | i64 | [N,K] | padded neighbour lists (padding: the node itself, edge 0) |",
        "| nbr_mask | f32 | [N,K] | 1 for a neighbour, 0 for padding |",
        "| pred (output) | f32 | [E,2] | (Δs − 1, Δd/h_loc), ≥ 0 |",
        "",
        "Raw features go in: normalisation (log1p of the heavy-tailed non-negative features, "
        "clipping to the training set's 0.1-99.9 % range, standardisation) is inside the graph. "
        "Inputs must be finite.",
        "",
        f"Operators: {', '.join(e['onnx']['ops'])}.",
        "",
        "## Architecture",
        "",
        f"Hidden width {a['hidden']}, {a['layers']} message-passing layers, {a['parameters']} parameters. "
        "Node MLP (2→D→D); per layer GINE-style messages relu(h[nbr_node] + W_l·x_e[nbr_edge]), "
        "masked mean over the K neighbours, update h += MLP([h, agg]); global mean pool → MLP; "
        "edge MLP (8→D→D); head on [edge embedding, h_a+h_b, |h_a−h_b|] + linear(global) → D → D → 2, "
        "2 outputs o in the training space, pred = s·(exp(relu(o)) − 1) with the target scales "
        f"s = {a['target_scale']} (so pred ≥ 0). Symmetric in the two ends of an "
        "edge and invariant to node, edge and neighbour order; only Gather and masked reductions "
        "(no scatter), so it is deterministic on any backend.",
        "",
        "## Data",
        "",
        d["description"],
        "",
        f"Split: {d['split_method']}.",
        "",
        "| split | parts | graphs | edges | valid edges |",
        "|---|---|---|---|---|",
    ]
    for k in ("train", "val", "test"):
        s = d[k]
        lines.append(f"| {k} | {s['parts']} | {s['graphs']} | {s['edges']} | {s['valid_edges']} |")
    lines += [
        "",
        "## Training",
        "",
        f"Targets t (per edge, valid edges only) are trained as log1p(min(t, {t['cap']}) / s) with s = {t['target_scale']} "
        "(half the typical decision thresholds, so the log space resolves the region around them; +inf → the cap; "
        "a capped target only punishes under-prediction), Huber loss (δ = 0.1) in that log space, "
        f"weighted ×(1 + {t['threshold_weight']}·exp(−(Δ/0.15)²)) by the distance Δ to the decision threshold "
        "(log1p(T_size−1) for Δs−1, log1p(allow_rel) for Δd/h_loc). "
        f"Adam, lr {t['lr']} with cosine decay, one graph per step, {t['epochs_run']} of {t['epochs']} epochs "
        f"(best validation loss at epoch {t['best_epoch']}), seed {t['seed']}, {t['threads']} threads, "
        f"torch {t['torch']}; {fmt(t['seconds_per_epoch'], 1)} s per epoch, {fmt(t['train_seconds'], 0)} s in all"
        + (" (stopped by the time budget)." if t["stopped_by_budget"] else "."),
        "",
        "## Held-out metrics (test parts)",
        "",
        "Over valid edges of the test parts; decisions at each dataset's T_size (default 1.2: "
        "Δs−1 < 0.2) and Δe = pred₁/allow_rel < 1; truth is `valid & y < 0.5` from the exact estimate.",
        "",
        "| split | target | MAE log1p(t) | MAE log1p(t/s) | Pearson log1p(t) | Spearman | median rel. err. near threshold |",
        "|---|---|---|---|---|---|---|",
    ]
    for split in ("val", "test"):
        m = rec["metrics"][split]
        for k in TARGETS:
            lines.append(f"| {split} | {k} | {fmt(m[k]['mae_log'], 4)} | {fmt(m[k]['mae_train_space'], 4)} | "
                         f"{fmt(m[k]['pearson_log'])} | {fmt(m[k]['spearman'])} | {fmt(m[k]['median_rel_err_near_threshold'])} |")
    lines += ["", "| split | truly collapsible | predicted | precision | recall | F1 | accuracy | score Spearman | precision of the 10 % choice |",
              "|---|---|---|---|---|---|---|---|---|"]
    for split in ("val", "test"):
        c = rec["metrics"][split]["collapsible"]
        lines.append(f"| {split} | {fmt(c['truth_share'])} | {fmt(c['predicted_share'])} | {fmt(c['precision'])} | "
                     f"{fmt(c['recall'])} | {fmt(c['f1'])} | {fmt(c['accuracy'])} | {fmt(c['score_spearman'])} | "
                     f"{fmt(c['selected_10pct_precision'])} |")
    lines += ["", "Precision of the 10 % choice: per graph, the valid edges predicted collapsible "
              "with the lowest predicted scores, at most 10 % of the edges (GCN-ABGS's candidates "
              "before the 1-ring filter, n = 0.1); the share of them truly collapsible."]
    lines += ["", "By snapshot (test; 0 = dense grid, then coarser grids along the LBO-ABGS run):", "",
              "| snapshot | valid edges | truly collapsible | precision | recall | F1 | 10 % choice: edges, precision | MAE log1p (Δs−1, Δd/h_loc) |",
              "|---|---|---|---|---|---|---|---|"]
    for s, c in rec["metrics"]["test"]["by_snapshot"].items():
        lines.append(f"| {s} | {c['edges_valid']} | {fmt(c['truth_share'])} | {fmt(c['precision'])} | "
                     f"{fmt(c['recall'])} | {fmt(c['f1'])} | {c['selected_10pct']}, {fmt(c['selected_10pct_precision'])} | "
                     f"{fmt(c['mae_log'][0], 4)}, {fmt(c['mae_log'][1], 4)} |")
    oc = e["check"]
    lines += [
        "",
        "## Export check",
        "",
        f"ONNX Runtime {oc['onnxruntime']} (1 thread) against torch on {oc['graphs']} held-out graphs: "
        f"max abs diff {oc['max_abs_diff']:.3g}, max rel diff {oc['max_rel_diff']:.3g} "
        f"(tolerance {oc['tolerance_rel']:g}): {'pass' if oc['ok'] else 'FAIL'}.",
        "",
        "## Rebuild",
        "",
        "```",
        *([f"{rec['build'].get('command', 'training/build_model.sh')}   # everything, from nothing; it runs:"]
          if rec.get("build") else []),
        rec["command"],
        "```",
        "",
    ]
    if rec.get("build"):
        b = rec["build"]
        st = b.get("stages_seconds", {})
        total = b.get("seconds_before_training", 0) + rec["total_seconds"]
        lines += [
            f"abgs CLI: {b.get('abgs', '?')}.",
            "",
            f"Whole build (`{b.get('command', 'training/build_model.sh')}`, {b.get('cpu', '?')}, "
            f"{b.get('jobs', '?')} jobs): "
            + ", ".join(f"{k} {v} s" for k, v in st.items())
            + f", training + export {rec['total_seconds']:.0f} s; total {total:.0f} s "
            f"({total / 60:.1f} min).",
            "",
        ]
    lines += [
        f"This training run: {fmt(t['train_seconds'], 0)} s of training + export on "
        f"{platform.machine()} ({t['threads']} threads). Same seed, thread count, torch version and "
        "machine type give the same bytes; otherwise the model agrees within tolerance, not bit for bit.",
        "",
    ]
    with open(path, "w") as f:
        f.write("\n".join(lines))


def shown_path(x):
    """A path as the card shows it: relative to the repository when inside it
    (no machine's own absolute paths in the committed card), else unchanged."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if os.sep in x and os.path.abspath(x).startswith(root + os.sep):
        return os.path.relpath(os.path.abspath(x), root)
    return x


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--epochs", type=int, default=30)
    ap.add_argument("--time-budget-min", type=float, default=None,
                    help="stop training after this many minutes (safety stop)")
    ap.add_argument("--hidden", type=int, default=32)
    ap.add_argument("--layers", type=int, default=2)
    ap.add_argument("--lr", type=float, default=3e-3)
    ap.add_argument("--cap", type=float, default=10.0)
    ap.add_argument("--threshold-weight", type=float, default=1.0)
    ap.add_argument("--target-scale", default=None,
                    help="s0,s1: train on log1p(t/s); default half the typical thresholds")
    ap.add_argument("--clip", type=float, default=1.0, help="gradient norm clip")
    ap.add_argument("--threads", type=int, default=1,
                    help="torch threads (default 1; 2 spin-wait badly on a shared 2-core machine)")
    ap.add_argument("--description", default=None,
                    help="data description for the model card")
    ap.add_argument("--build-info", default=None,
                    help="JSON file with build facts (wall time, command) for the card")
    ap.add_argument("--quiet", action="store_true")
    a = ap.parse_args(argv)
    t_start = time.time()

    torch.manual_seed(a.seed)
    np.random.seed(a.seed)
    torch.use_deterministic_algorithms(True)
    # deterministic mode fills every new tensor with NaN by default: slow, and not
    # needed (nothing reads uninitialised memory)
    torch.utils.deterministic.fill_uninitialized_memory = False
    torch.set_num_threads(a.threads)
    try:
        torch.set_num_interop_threads(1)
    except RuntimeError:  # already set in this process
        pass
    log = (lambda *x: None) if a.quiet else (lambda *x: print(*x, flush=True))

    split, how = find_split(a.data, a.seed)
    data = {k: load_split(v) for k, v in split.items()}
    train, val, test = (data[k][0] for k in ("train", "val", "test"))
    log(f"data: {len(train)} / {len(val)} / {len(test)} graphs "
        f"({len(split['train'])} / {len(split['val'])} / {len(split['test'])} parts)")

    rng = np.random.default_rng(a.seed)
    norm = {"node": feature_stats(train, "node_x", NODE_LOG, rng),
            "edge": feature_stats(train, "edge_x", EDGE_LOG, rng)}
    if a.target_scale:
        scale = [float(v) for v in a.target_scale.split(",")]
    else:  # half the decision thresholds, typical over the training set
        ts = np.median([g.t_size for g in train])
        ar = np.concatenate([g.allow_rel[g.valid] for g in train])
        ar = ar[np.isfinite(ar) & (ar > 0)]
        scale = [0.5 * (float(ts) - 1.0), 0.5 * float(np.median(ar)) if len(ar) else 0.5]
        scale = [float(f"{v:.6g}") for v in scale]
    model = GcnAbgs(norm, a.hidden, a.layers, scale)
    log(f"model: hidden {a.hidden}, {n_params(model)} parameters, target scale {scale}")
    labels = [graph_labels(g, a.cap, a.threshold_weight, scale) for g in train]
    vlabels = [graph_labels(g, a.cap, a.threshold_weight, scale) for g in val]
    opt = torch.optim.Adam(model.parameters(), lr=a.lr)
    steps_total = a.epochs * len(train)
    sched = torch.optim.lr_scheduler.LambdaLR(
        opt, lambda s: 0.02 + 0.98 * 0.5 * (1 + math.cos(math.pi * min(s, steps_total) / steps_total)))

    def val_loss():
        model.eval()
        tot = wsum = 0.0
        with torch.no_grad():
            for g, (idx, tl, cens, w) in zip(val, vlabels):
                if len(idx) == 0:
                    continue
                o = model.log_out(*g.inputs(), edge_idx=idx)
                tot += float(loss_fn(o, tl, cens, w)) * float(w.sum())
                wsum += float(w.sum())
        return tot / max(wsum, 1e-12)

    history, best, best_state, best_epoch = [], float("inf"), None, 0
    epoch_times, epoch_cpu, stopped = [], [], False
    t_train = time.time()
    for ep in range(a.epochs):
        t0, c0 = time.time(), time.process_time()
        model.train()
        order = rng.permutation(len(train))
        tot = 0.0
        n = 0
        for i in order:
            idx, tl, cens, w = labels[i]
            if len(idx) == 0:
                continue
            o = model.log_out(*train[i].inputs(), edge_idx=idx, csr=train[i].csr)
            loss = loss_fn(o, tl, cens, w)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(model.parameters(), a.clip)
            opt.step()
            sched.step()
            tot += loss.item()
            n += 1
        vl = val_loss()
        dt, dc = time.time() - t0, time.process_time() - c0
        epoch_times.append(dt)
        epoch_cpu.append(dc)
        history.append({"epoch": ep + 1, "train_loss": tot / max(n, 1), "val_loss": vl,
                        "seconds": round(dt, 2), "cpu_seconds": round(dc, 2)})
        if vl < best:
            best, best_epoch = vl, ep + 1
            best_state = {k: v.clone() for k, v in model.state_dict().items()}
        log(f"epoch {ep + 1}/{a.epochs}: train {tot / max(n, 1):.5f} val {vl:.5f} "
            f"({dt:.1f} s, cpu {dc:.1f} s)")
        if a.time_budget_min is not None and (time.time() - t_start) / 60 + dt / 60 > a.time_budget_min:
            stopped = ep + 1 < a.epochs
            if stopped:
                log(f"time budget reached after epoch {ep + 1}")
            break
    train_seconds = time.time() - t_train
    model.load_state_dict(best_state)
    model.eval()

    metrics = {"val": evaluate(model, val, a.cap, scale, seed=a.seed),
               "test": evaluate(model, test, a.cap, scale, seed=a.seed)}
    log(json.dumps(metrics["test"], indent=1))

    os.makedirs(a.out, exist_ok=True)
    onnx_path = os.path.join(a.out, "gcn_abgs.onnx")
    ex = test[0]
    info = export_onnx(model, ex.inputs(), onnx_path)
    check = check_onnx(model, onnx_path, test + val[:3])
    log(f"onnx: {os.path.getsize(onnx_path)} bytes, ops {info['ops']}, check {check}")
    if not check["ok"]:
        raise SystemExit(f"ONNX Runtime disagrees with torch: {check}")

    desc = a.description or (
        "Files `*.safetensors` written by `abgs dataset` (format abgs-dataset-1): snapshots "
        "(graphs) of LBO-ABGS runs on sized dense grids, labelled with the exact estimates.")
    args_shown, skip = [], False
    for x in (argv if argv is not None else sys.argv[1:]):
        if skip:
            skip = False
            continue
        if x in ("--description", "--build-info", "--quiet"):
            skip = x != "--quiet"
            continue
        args_shown.append(shown_path(x) if " " not in x else f"'{x}'")
    cmd = " ".join(["python", "training/train.py"] + args_shown)
    rec = {
        "format": "gcn-abgs-model-1",
        "onnx": "gcn_abgs.onnx",
        "inputs": {"node_x": ["N", 2], "edge_x": ["E", 8], "edge_ends": ["E", 2],
                   "nbr_node": ["N", "K"], "nbr_edge": ["N", "K"], "nbr_mask": ["N", "K"]},
        "input_types": {"node_x": "f32", "edge_x": "f32", "edge_ends": "i64",
                        "nbr_node": "i64", "nbr_edge": "i64", "nbr_mask": "f32"},
        "output": {"pred": ["E", 2]},
        "node_features": NODE_FEATURES,
        "edge_features": EDGE_FEATURES,
        "targets": TARGETS,
        "architecture": {"hidden": a.hidden, "layers": a.layers, "target_scale": scale,
                         "parameters": n_params(model),
                         "normalisation": {"node": dict(zip(
                             ["log1p", "lo", "hi", "mean", "std"], norm["node"])),
                             "edge": dict(zip(["log1p", "lo", "hi", "mean", "std"], norm["edge"]))}},
        "data": {"dir": shown_path(os.path.abspath(a.data)), "split_method": how, "description": desc,
                 **{k: split_summary(data[k][0], split[k]) for k in ("train", "val", "test")}},
        "training": {"seed": a.seed, "epochs": a.epochs, "epochs_run": len(history),
                     "best_epoch": best_epoch, "lr": a.lr, "cap": a.cap,
                     "threshold_weight": a.threshold_weight, "target_scale": scale,
                     "grad_clip": a.clip,
                     "loss": "huber(0.1) on log1p(min(t,cap)/scale), censored at cap",
                     "threads": a.threads, "torch": torch.__version__,
                     "numpy": np.__version__, "python": platform.python_version(),
                     "seconds_per_epoch": float(np.mean(epoch_times)) if epoch_times else None,
                     "cpu_seconds_per_epoch": float(np.mean(epoch_cpu)) if epoch_cpu else None,
                     "train_seconds": train_seconds, "stopped_by_budget": bool(stopped),
                     "history": history},
        "metrics": metrics,
        "export": {"onnx": info, "check": check, "bytes": os.path.getsize(onnx_path),
                   "sha256": sha256(onnx_path)},
        "command": cmd,
        "total_seconds": time.time() - t_start,
    }
    if a.build_info and os.path.exists(a.build_info):
        with open(a.build_info) as f:
            rec["build"] = json.load(f)
    with open(os.path.join(a.out, "gcn_abgs.json"), "w") as f:
        json.dump(rec, f, indent=1, allow_nan=True)
        f.write("\n")
    write_card(os.path.join(a.out, "MODEL_CARD.md"), rec)
    log(f"wrote {onnx_path} ({time.time() - t_start:.0f} s)")
    return rec


if __name__ == "__main__":
    main()
