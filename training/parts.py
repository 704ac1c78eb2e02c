#!/usr/bin/env python3
"""Synthetic CAD parts for training GCN-ABGS (the learned simplifier).

These parts are the *training data* of the learned model. The models in
``../shared/meshes`` are test data only and must never be used for training,
validation or tuning; this script is the only source of training geometry.

Usage::

    python training/parts.py --out DIR --count N --seed S [--jobs J]

writes ``DIR/part_0000.stl`` (binary, surface triangulation), ``DIR/part_0000.step``
(the solids as modelled), ... and ``DIR/parts.json`` (one record per part: name,
family, variant, parameters, bounding box and its diagonal, triangle count,
number of bodies, retries, mesh settings, SHA-256 of both files).

Families (drawn with equal probability by each part's own RNG), all built with
Gmsh's OpenCASCADE kernel (boxes, cylinders, wedges, cut / fuse, fillets,
chamfers):

1. ``plate_holes``   plates with through / blind / counterbored holes, slots
                     (rounded, any angle), edge notches, rounded corners and
                     chamfered hole edges.
2. ``block_fillets`` blocks with steps, pockets and cross holes, then fillets
                     and chamfers on chosen edge sets (vertical, top, bottom,
                     all, random subsets).
3. ``bosses``        cylindrical bosses fused on a plate (top and bottom), some
                     with through holes, root fillets and top chamfers.
4. ``ribbed``        thin ribs fused to a base: parallel, grid, frame, or an
                     L-bracket with triangular gussets; optional root fillets.
5. ``thin_gaps``     thin walls and narrow gaps: an open tray (box minus a
                     slightly smaller box, walls 1-5 % of the size), a thin
                     tube, two parallel plates separated by a gap of 0.5-3 % of
                     the size (two bodies), or a block with a slit of that width.
6. ``assembly``      2-5 touching bodies kept as separate solids (not fused,
                     not fragmented: every body is a closed surface of its own
                     and touching faces are coincident but triangulated
                     independently, as CAD exporters do): a shaft in a bore of
                     the same radius with collars, plates stacked face to face
                     (optionally pinned through a common hole), blocks and
                     cylinders sitting on a plate.

Scale law: each part draws a characteristic size L log-uniformly in
[0.005, 5] model units (millimetre-sized to metre-sized parts) and every
dimension of the part is a fraction of L, so the dataset covers four decades
of absolute size with the same shapes. The surface mesh follows L too:
``Mesh.MeshSizeMax`` = L/15, ``Mesh.MeshSizeMin`` = L/2000 and 12-20 elements
per 2*pi from curvature; if the triangle count falls outside [2000, 60000] the
part is re-meshed with the sizes scaled (recorded in ``mesh``).

Determinism: part k is built from ``random.Random(seed + k)`` only, so it does
not depend on the other parts, on ``--count`` or on ``--jobs``. (Hence seed S
part k+1 is seed S+1 part k: give disjoint sets, e.g. training and validation,
seeds further apart than their counts.) If an attempt
fails (an OCC boolean, gmsh meshing, or STL validation: empty, triangle count
out of range, open surface, degenerate triangles) the part is retried with the
next sub-seed, ``random.Random(f"{seed + k}.{attempt}")``; the failures are
recorded in the part's ``retries``. Fillets and chamfers that OCC cannot
compute fall back to the unfilleted shape (recorded in the parameters, e.g.
``"fillet": "failed"``) and are not failures. The same seed and count give the
same STL bytes, the same parts.json and the same STEP bytes (the timestamp in
the STEP header is fixed). Each attempt runs in its own process with its own
gmsh session (initialize / finalize), at most ``--jobs`` at a time (a small
process pool: a hung attempt can be killed, which a multiprocessing.Pool
cannot do), and is killed after ``--timeout`` seconds, so a hanging OCC or
meshing call cannot stall the run; only such a timeout depends on the machine,
and the default is far above the usual seconds per part.

Meshing: ``Mesh.MeshSizeExtendFromBoundary`` is 1 (sizes grade smoothly into
the faces) unless the 1-D mesh predicts an explosion (small fillets bounding
large flat faces would fill them with fillet-sized triangles); then it is 0 and
the faces are meshed at MeshSizeMax, graded only near their fine boundaries.
Each record gives the settings used (``mesh``), the STL's welded vertex count
and its connected components counted as abgs does (faces joined across edges
with exactly two faces). Every STL is closed body by body: each edge has an
even number of faces.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import multiprocessing as mp
import multiprocessing.connection as mpc
import os
import random
import re
import shutil
import struct
import sys
import time
from collections import deque
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gmsh

from families import BUILDERS, FAMILIES, Params, PartError, mass, occ

L_MIN = 0.005
L_MAX = 5.0
TRI_MIN = 2000
TRI_MAX = 60000
TRI_LOW_TARGET = 5000  # re-mesh target when a part comes out too coarse
TRI_HIGH_TARGET = 30000  # re-mesh target when a part comes out too fine
EXTEND_LIMIT = 2 * TRI_MAX  # predicted count above which sizes do not extend
MESH_PASSES = 5
HMAX_FACTOR = 1.0 / 15.0
HMIN_FACTOR = 1.0 / 2000.0
CURV_POINTS = (12, 20)
DEFAULT_TIMEOUT_S = 300.0
DEFAULT_MAX_ATTEMPTS = 25
STEP_TIMESTAMP = "2000-01-01T00:00:00"





# --------------------------------------------------------------------------
# Meshing, STL validation
# --------------------------------------------------------------------------


def estimate_triangles() -> float:
    """Triangles the 2-D mesh will have when sizes extend from the boundary,
    estimated from the 1-D mesh: per surface, area / (0.433 h^2) with h the
    mean boundary element length."""
    total = 0.0
    for _, s in gmsh.model.getEntities(2):
        length, count = 0.0, 0
        for _, c in gmsh.model.getBoundary([(2, s)], combined=False, oriented=False):
            length += occ().getMass(1, abs(c))
            _, tags, _ = gmsh.model.mesh.getElements(1, abs(c))
            count += sum(len(t) for t in tags)
        if count and length > 0.0:
            h = length / count
            total += occ().getMass(2, s) / (0.433 * h * h)
    return total


def mesh_surfaces(L: float, curv_points: int) -> Params:
    """Generate the 2-D mesh, re-meshing with scaled sizes until the triangle
    count is in [TRI_MIN, TRI_MAX]. Returns the settings used.

    Sizes extend from the boundary into the faces (smooth gradation) unless
    that is predicted to explode the count (small fillets bounding large flat
    faces); then the faces are meshed at MeshSizeMax with sizes graded from
    their finer boundaries (``extend_from_boundary`` 0 in the record).
    """
    hmax, hmin, ncurv = HMAX_FACTOR * L, HMIN_FACTOR * L, float(curv_points)
    extend = 1
    history = []
    for _ in range(MESH_PASSES):
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", round(ncurv))
        gmsh.option.setNumber("Mesh.MeshSizeMax", hmax)
        gmsh.option.setNumber("Mesh.MeshSizeMin", hmin)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", extend)
        gmsh.model.mesh.clear()
        gmsh.model.mesh.generate(1)
        if extend and estimate_triangles() > EXTEND_LIMIT:
            extend = 0
            gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", extend)
        gmsh.model.mesh.generate(2)
        n = len(gmsh.model.mesh.getElementsByType(2)[0])
        history.append(n)
        if n < TRI_MIN:
            hmax *= max(0.4, math.sqrt(max(n, 1) / TRI_LOW_TARGET))
        elif n > TRI_MAX:
            f = math.sqrt(n / TRI_HIGH_TARGET)
            hmax *= f
            hmin *= f
            ncurv = max(6.0, ncurv / f)
        else:
            return {
                "size_max": hmax,
                "size_min": hmin,
                "curvature_points": round(ncurv),
                "extend_from_boundary": extend,
                "passes": len(history),
                "triangles_per_pass": history,
            }
    raise PartError(f"triangle count out of range after {MESH_PASSES} passes: {history}")


def read_stl_stats(path: Path) -> Params:
    """Parse a binary STL; check it is non-empty, closed and non-degenerate.

    Vertices are welded on exact float32 coordinates. Closed: every edge is
    used an even number of times (each body is closed; coincident faces of
    touching bodies may add a second pair). Components are counted as abgs
    does: faces joined across edges with exactly two faces.
    """
    data = path.read_bytes()
    if len(data) < 84:
        raise PartError("STL too short")
    (n,) = struct.unpack_from("<I", data, 80)
    if n == 0 or len(data) != 84 + 50 * n:
        raise PartError(f"STL malformed: {n} triangles, {len(data)} bytes")
    index: dict[tuple[float, float, float], int] = {}
    tris = []
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    degenerate = 0
    for i in range(n):
        v = struct.unpack_from("<9f", data, 84 + 50 * i + 12)
        ids = []
        for k in range(3):
            p = v[3 * k : 3 * k + 3]
            if p not in index:
                index[p] = len(index)
                for d in range(3):
                    lo[d], hi[d] = min(lo[d], p[d]), max(hi[d], p[d])
            ids.append(index[p])
        if len(set(ids)) < 3:
            degenerate += 1
        tris.append(ids)
    if degenerate:
        raise PartError(f"{degenerate} degenerate triangles")
    edges: dict[tuple[int, int], list[int]] = {}
    for f, (i, j, k) in enumerate(tris):
        for u, w in ((i, j), (j, k), (k, i)):
            edges.setdefault((u, w) if u < w else (w, u), []).append(f)
    odd = sum(1 for fs in edges.values() if len(fs) % 2)
    if odd:
        raise PartError(f"open surface: {odd} edges with an odd number of faces")
    parent = list(range(n))

    def find(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for fs in edges.values():
        if len(fs) == 2:
            ra, rb = find(fs[0]), find(fs[1])
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    components = len({find(f) for f in range(n)})
    diag = math.dist(lo, hi)
    return {
        "triangles": n,
        "vertices": len(index),
        "components": components,
        "bbox_min": lo,
        "bbox_max": hi,
        "bbox_diagonal": diag,
    }


def fix_step_timestamp(path: Path) -> None:
    text = path.read_text(encoding="latin-1")
    text = re.sub(
        r"(FILE_NAME\('[^']*',\s*')[^']*(')", rf"\g<1>{STEP_TIMESTAMP}\g<2>", text, count=1
    )
    path.write_text(text, encoding="latin-1")


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def round_floats(x: Any) -> Any:
    """Round floats to 6 significant digits for the JSON record."""
    if isinstance(x, float):
        return float(f"{x:.6g}")
    if isinstance(x, dict):
        return {k: round_floats(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [round_floats(v) for v in x]
    return x


# --------------------------------------------------------------------------
# One attempt (runs in its own process)
# --------------------------------------------------------------------------


def attempt_rng(seed: int, index: int, attempt: int) -> tuple[random.Random, str]:
    if attempt == 0:
        return random.Random(seed + index), str(seed + index)
    sub = f"{seed + index}.{attempt}"
    return random.Random(sub), sub


def build_part(seed: int, index: int, attempt: int, work: Path) -> Params:
    """Build, export and validate one part; raise PartError on failure.

    Writes work/part_NNNN.aA.step and .stl; returns the part's record."""
    rng, sub_seed = attempt_rng(seed, index, attempt)
    family = rng.choice(FAMILIES)
    L = math.exp(rng.uniform(math.log(L_MIN), math.log(L_MAX)))
    curv_points = rng.randint(*CURV_POINTS)
    stem = f"part_{index:04d}.a{attempt}"
    step_path, stl_path = work / f"{stem}.step", work / f"{stem}.stl"
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.option.setNumber("Geometry.OCCParallel", 0)
        gmsh.model.add(f"part_{index:04d}")
        params = BUILDERS[family](rng, L)
        occ().synchronize()
        bodies = gmsh.model.getEntities(3)
        expected = params.pop("expected_bodies", 1)
        if family == "assembly":
            if len(bodies) < 2:
                raise PartError(f"assembly with {len(bodies)} bodies")
        elif len(bodies) != expected:
            raise PartError(f"{len(bodies)} bodies, expected {expected}")
        if any(occ().getMass(3, t) <= 0.0 for _, t in bodies):
            raise PartError("volume with non-positive mass")
        gmsh.write(str(step_path))
        mesh = mesh_surfaces(L, curv_points)
        gmsh.option.setNumber("Mesh.Binary", 1)
        gmsh.write(str(stl_path))
    except PartError:
        raise
    except Exception as exc:  # gmsh raises plain Exception
        raise PartError(f"{type(exc).__name__}: {exc}") from exc
    finally:
        gmsh.finalize()
    stats = read_stl_stats(stl_path)
    if not TRI_MIN <= stats["triangles"] <= TRI_MAX:
        raise PartError(f"triangle count {stats['triangles']} out of range")
    if stats["components"] < len(bodies):
        raise PartError(f"{stats['components']} STL components < {len(bodies)} bodies")
    fix_step_timestamp(step_path)
    return round_floats(
        {
            "name": f"part_{index:04d}",
            "index": index,
            "family": family,
            "variant": params.get("variant", family),
            "sub_seed": sub_seed,
            "L": L,
            "parameters": params,
            "bodies": len(bodies),
            "mesh": mesh,
            **stats,
        }
    )


def _child(conn: mpc.Connection, seed: int, index: int, attempt: int, work: str) -> None:
    # OCC's STEP writer prints to stdout: keep the parent's output clean.
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    try:
        rec = build_part(seed, index, attempt, Path(work))
        conn.send(("ok", rec))
    except BaseException as exc:  # report everything; the parent retries
        conn.send(("fail", f"{type(exc).__name__}: {str(exc)[:300]}"))
    finally:
        conn.close()


# --------------------------------------------------------------------------
# Scheduler
# --------------------------------------------------------------------------


@dataclass
class Running:
    proc: Any
    conn: mpc.Connection
    index: int
    attempt: int
    start: float


def generate(
    out: Path,
    count: int,
    seed: int,
    jobs: int,
    timeout_s: float,
    max_attempts: int,
    verbose: bool = True,
) -> list[Params]:
    """Generate `count` parts into `out`; each attempt in its own process."""
    out.mkdir(parents=True, exist_ok=True)
    work = out / ".work"
    work.mkdir(exist_ok=True)
    methods = mp.get_all_start_methods()
    ctx = mp.get_context("fork" if "fork" in methods else "spawn")
    pending: deque[tuple[int, int]] = deque((i, 0) for i in range(count))
    running: list[Running] = []
    records: dict[int, Params] = {}
    retries: dict[int, list[Params]] = {i: [] for i in range(count)}
    t0 = time.monotonic()

    def finish(r: Running, status: str, payload: Any) -> None:
        stem = f"part_{r.index:04d}.a{r.attempt}"
        tmp = [work / f"{stem}.step", work / f"{stem}.stl"]
        if status == "ok":
            name = f"part_{r.index:04d}"
            os.replace(tmp[0], out / f"{name}.step")
            os.replace(tmp[1], out / f"{name}.stl")
            payload["retries"] = retries[r.index]
            payload["stl_sha256"] = sha256(out / f"{name}.stl")
            payload["step_sha256"] = sha256(out / f"{name}.step")
            records[r.index] = payload
            if verbose:
                print(
                    f"[{len(records):4d}/{count}] {name} {payload['family']:13s} "
                    f"{payload['variant']:15s} L={payload['L']:<8.4g} "
                    f"{payload['triangles']:6d} tris {payload['bodies']} bodies "
                    f"{len(retries[r.index])} retries {time.monotonic() - r.start:5.1f} s",
                    file=sys.stderr,
                    flush=True,
                )
            return
        for p in tmp:
            p.unlink(missing_ok=True)
        retries[r.index].append({"attempt": r.attempt, "error": payload})
        if verbose:
            print(f"  part_{r.index:04d} attempt {r.attempt} failed: {payload}", file=sys.stderr)
        if r.attempt + 1 >= max_attempts:
            raise RuntimeError(f"part_{r.index:04d}: {max_attempts} attempts failed")
        pending.appendleft((r.index, r.attempt + 1))

    try:
        while pending or running:
            while pending and len(running) < jobs:
                i, a = pending.popleft()
                recv, send = ctx.Pipe(duplex=False)
                proc = ctx.Process(target=_child, args=(send, seed, i, a, str(work)))
                proc.start()
                send.close()
                running.append(Running(proc, recv, i, a, time.monotonic()))
            waitables: list[Any] = [r.conn for r in running] + [r.proc.sentinel for r in running]
            mpc.wait(waitables, timeout=1.0)
            still: list[Running] = []
            for r in running:
                msg = None
                if r.conn.poll():
                    try:
                        msg = r.conn.recv()
                    except EOFError:
                        msg = ("fail", f"worker died (exit code {r.proc.exitcode})")
                elif not r.proc.is_alive():
                    r.proc.join()
                    msg = ("fail", f"worker died (exit code {r.proc.exitcode})")
                elif time.monotonic() - r.start > timeout_s:
                    r.proc.kill()
                    msg = ("fail", f"timeout after {timeout_s:.0f} s")
                if msg is None:
                    still.append(r)
                    continue
                r.proc.join()
                r.conn.close()
                finish(r, *msg)
            running = still
    finally:
        for r in running:
            r.proc.kill()
            r.proc.join()
    shutil.rmtree(work, ignore_errors=True)
    if verbose:
        print(f"{count} parts in {time.monotonic() - t0:.1f} s", file=sys.stderr)
    return [records[i] for i in range(count)]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, required=True, help="output directory")
    ap.add_argument("--count", type=int, required=True, help="number of parts")
    ap.add_argument("--seed", type=int, required=True, help="base seed")
    ap.add_argument("--jobs", type=int, default=1, help="parallel processes (default 1)")
    ap.add_argument(
        "--timeout", type=float, default=DEFAULT_TIMEOUT_S,
        help="seconds per attempt before it is killed and retried "
        f"(default {DEFAULT_TIMEOUT_S:.0f})",
    )
    ap.add_argument(
        "--max-attempts", type=int, default=DEFAULT_MAX_ATTEMPTS,
        help=f"attempts per part before giving up (default {DEFAULT_MAX_ATTEMPTS})",
    )
    ap.add_argument("--quiet", action="store_true", help="no progress output")
    args = ap.parse_args(argv)
    if args.count < 1 or args.jobs < 1:
        ap.error("--count and --jobs must be positive")
    parts = generate(
        args.out, args.count, args.seed, args.jobs, args.timeout, args.max_attempts,
        verbose=not args.quiet,
    )
    doc = {
        "generator": "training/parts.py",
        "gmsh": gmsh.__version__,
        "seed": args.seed,
        "count": args.count,
        "note": "training data only; ../shared/meshes is test data and never used here",
        "parts": parts,
    }
    (args.out / "parts.json").write_text(json.dumps(doc, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
