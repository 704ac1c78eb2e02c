#!/usr/bin/env python3
"""Synthetic GCN-ABGS datasets for development and tests (not training data).

Writes files in exactly the format of ``abgs dataset`` (``abgs-dataset-1``, see
``training/README.md``): one safetensors file per "part", S snapshots each,
every snapshot a jittered triangulated height field carrying a smooth size
field, with features computed from its geometry and made-up targets that are
a learnable (noisy, heavy-tailed) function of the features and of the
neighbourhood. Used by ``test_train.py`` and to time the training code before
real data exist; the real data come from the Rust CLI.

Usage::

    python training/synth_dataset.py --out DIR --parts P [--snapshots S]
        [--edges E] [--seed 0]
"""

from __future__ import annotations

import argparse
import json
import os

import numpy as np
from safetensors.numpy import save_file

FORMAT = "abgs-dataset-1"


def _angle(u, v):
    nu = np.linalg.norm(u, axis=-1)
    nv = np.linalg.norm(v, axis=-1)
    c = (u * v).sum(-1)
    return np.arccos(np.clip(c / np.maximum(nu * nv, 1e-30), -1.0, 1.0))


def make_graph(rng: np.random.Generator, n: int, t_size: float):
    """One snapshot on an n x n jittered grid; returns the tensors of one graph."""
    xs = np.linspace(0.0, 1.0, n)
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    jit = 0.3 / (n - 1)
    X = X + rng.uniform(-jit, jit, X.shape)
    Y = Y + rng.uniform(-jit, jit, Y.shape)
    # a smooth random height field with a ridge (sharp-ish features)
    a = rng.uniform(0.02, 0.2, 3)
    f = rng.uniform(1.0, 4.0, 3)
    Z = (a[0] * np.sin(f[0] * np.pi * X) * np.cos(f[1] * np.pi * Y)
         + a[1] * np.abs(X - 0.5) * (rng.uniform() < 0.5)
         + a[2] * np.exp(-((X - 0.3) ** 2 + (Y - 0.6) ** 2) * 20 * f[2]))
    P = np.stack([X.ravel(), Y.ravel(), Z.ravel()], 1)
    # size field: smooth, spanning ~1.5 decades
    b = rng.uniform(0.5, 2.0, 2)
    logh = (np.log(rng.uniform(0.005, 0.05)) + b[0] * np.sin(2 * X * b[1] + Y)
            + 0.6 * np.exp(-((X - 0.7) ** 2 + (Y - 0.2) ** 2) * 30)).ravel()
    h = np.exp(logh)

    idx = np.arange(n * n).reshape(n, n)
    a0 = idx[:-1, :-1].ravel()
    a1 = idx[1:, :-1].ravel()
    a2 = idx[:-1, 1:].ravel()
    a3 = idx[1:, 1:].ravel()
    F = np.concatenate([np.stack([a0, a1, a3], 1), np.stack([a0, a3, a2], 1)])
    # edges with their faces and opposite vertices
    he = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    opp = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    fid = np.tile(np.arange(len(F)), 3)
    key = np.sort(he, 1)
    uniq, inv = np.unique(key[:, 0] * (n * n) + key[:, 1], return_inverse=True)
    E = len(uniq)
    ends = np.stack([uniq // (n * n), uniq % (n * n)], 1)
    order = np.argsort(inv, kind="stable")
    cnt = np.bincount(inv, minlength=E)
    first = np.zeros(E, np.int64)
    first[1:] = np.cumsum(cnt)[:-1]
    o1 = opp[order[first]]
    f1 = fid[order[first]]
    has2 = cnt == 2
    o2 = np.where(has2, opp[order[np.minimum(first + 1, len(order) - 1)]], o1)
    f2 = np.where(has2, fid[order[np.minimum(first + 1, len(order) - 1)]], f1)

    fn = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    fn /= np.linalg.norm(fn, axis=1, keepdims=True)
    vn = np.zeros_like(P)
    for k in range(3):
        np.add.at(vn, F[:, k], fn)
    vn /= np.linalg.norm(vn, axis=1, keepdims=True)

    pa, pb = P[ends[:, 0]], P[ends[:, 1]]
    L = np.linalg.norm(pb - pa, axis=1)
    dihedral = _angle(fn[f1], fn[f2])

    def opp_angle(o):
        return _angle(pa - P[o], pb - P[o])

    def height_ratio(o):
        area2 = np.linalg.norm(np.cross(pb - pa, P[o] - pa), axis=1)
        return (area2 / np.maximum(L, 1e-30)) / np.maximum(L, 1e-30)

    oa = np.sort(np.stack([opp_angle(o1), opp_angle(o2)], 1), 1)
    hr = np.sort(np.stack([height_ratio(o1), height_ratio(o2)], 1), 1)
    nang = _angle(vn[ends[:, 0]], vn[ends[:, 1]])

    # umbrella "LBO" of the sizes, made unit-free
    N = n * n
    deg = np.bincount(ends.ravel(), minlength=N)
    s = np.zeros(N)
    np.add.at(s, ends[:, 0], h[ends[:, 1]])
    np.add.at(s, ends[:, 1], h[ends[:, 0]])
    lmean2 = np.zeros(N)
    np.add.at(lmean2, ends[:, 0], L**2)
    np.add.at(lmean2, ends[:, 1], L**2)
    lmean2 /= deg
    lbo = np.abs(s / deg - h) / lmean2
    lbo_v = lbo * h
    he_ = 0.5 * (h[ends[:, 0]] + h[ends[:, 1]])
    lbo_e = 0.5 * (lbo[ends[:, 0]] + lbo[ends[:, 1]]) * he_

    node_x = np.stack([np.log(h / np.median(h)), lbo_v], 1).astype(np.float32)
    edge_x = np.stack([lbo_e, dihedral, oa[:, 0], oa[:, 1], hr[:, 0], hr[:, 1],
                       L / L.mean(), nang], 1).astype(np.float32)

    # padded neighbour lists (padding: the node itself, edge 0, mask 0)
    K = int(deg.max())
    nbr_node = np.repeat(np.arange(N)[:, None], K, 1)
    nbr_edge = np.zeros((N, K), np.int64)
    nbr_mask = np.zeros((N, K), np.float32)
    src = np.concatenate([ends[:, 0], ends[:, 1]])
    dst = np.concatenate([ends[:, 1], ends[:, 0]])
    eid = np.concatenate([np.arange(E), np.arange(E)])
    o = np.lexsort((dst, src))
    src, dst, eid = src[o], dst[o], eid[o]
    start = np.zeros(N, np.int64)
    start[1:] = np.cumsum(deg)[:-1]
    slot = np.arange(len(src)) - start[src]
    nbr_node[src, slot] = dst
    nbr_edge[src, slot] = eid
    nbr_mask[src, slot] = 1.0

    # made-up targets: size mismatch and chord deviation, smoothed over the
    # neighbourhood of the ends, heavy tailed
    hloc = np.minimum(h[ends[:, 0]], h[ends[:, 1]])
    dl = np.abs(np.log(h[ends[:, 0]] / h[ends[:, 1]]))
    v0 = dl + 0.15 * lbo_e + 0.05 * (L / hloc)
    v1 = 0.4 * (dihedral + nang) * (L / hloc) + 0.1 * oa[:, 1] ** 2
    nb0 = np.zeros(N)
    np.add.at(nb0, ends[:, 0], v0)
    np.add.at(nb0, ends[:, 1], v0)
    nb0 /= deg
    t0 = (0.6 * v0 + 0.4 * 0.5 * (nb0[ends[:, 0]] + nb0[ends[:, 1]])) * np.exp(
        rng.normal(0, 0.15, E))
    t1 = v1 * np.exp(rng.normal(0, 0.15, E))
    t0 = 0.5 * np.expm1(2.5 * t0)
    t1 = 0.15 * np.expm1(2.0 * t1)
    valid = has2 & (rng.uniform(size=E) > 0.05) & (oa[:, 1] < 2.6)
    target = np.stack([t0, t1], 1).astype(np.float32)
    target[~valid] = np.nan
    bad = valid & (rng.uniform(size=E) < 0.003)
    target[bad, 1] = np.inf
    allow_rel = np.full(E, 0.25, np.float32)
    thin = rng.uniform(size=E) < 0.1
    allow_rel[thin] = 0.08
    with np.errstate(invalid="ignore"):
        y = np.minimum(1.0, 0.5 * np.maximum(target[:, 0] / (t_size - 1.0),
                                             target[:, 1] / allow_rel))
    y = np.where(valid, y, 1.0).astype(np.float32)
    return {
        "node_x": node_x,
        "edge_x": edge_x,
        "edge_ends": ends.astype(np.int64),
        "nbr_node": nbr_node.astype(np.int64),
        "nbr_edge": nbr_edge,
        "nbr_mask": nbr_mask,
        "target": target,
        "valid": valid.astype(np.uint8),
        "allow_rel": allow_rel,
        "y": y,
    }, len(F)


def write_part(path: str, seed: int, snapshots: int, edges: int, t_size=1.2):
    rng = np.random.default_rng(seed)
    tensors, meta = {}, {
        "format": FORMAT,
        "snapshots": str(snapshots),
        "source": f"synthetic_{seed}.stl",
        "t_size": str(t_size),
        "beta": "1.2",
        "clearance": "3",
    }
    n0 = max(6, int(round(np.sqrt(edges / 3.0))))
    for s in range(snapshots):
        n = max(5, int(round(n0 * 0.8**s)))
        g, faces = make_graph(rng, n, t_size)
        for k, v in g.items():
            tensors[f"{s}/{k}"] = np.ascontiguousarray(v)
        meta[f"{s}/iteration"] = str(s)
        meta[f"{s}/faces"] = str(faces)
    save_file(tensors, path, metadata=meta)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--parts", type=int, default=20)
    ap.add_argument("--snapshots", type=int, default=3)
    ap.add_argument("--edges", type=int, default=3000,
                    help="edges of the first (densest) snapshot, about")
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    for k in range(a.parts):
        write_part(os.path.join(a.out, f"part_{k:04d}.safetensors"),
                   a.seed * 100003 + k, a.snapshots, a.edges)
    print(json.dumps({"out": a.out, "parts": a.parts}))


if __name__ == "__main__":
    main()
