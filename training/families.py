"""Part families of the training-data generator (see parts.py): each
`family_*` builds one CAD-like part with Gmsh's OpenCASCADE kernel in the
current gmsh model, from its own random generator and characteristic size L,
and returns its parameters; `BUILDERS` maps family names to them."""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import Any, Callable

import gmsh

DimTag = tuple[int, int]
Params = dict[str, Any]

FAMILIES = (
    "plate_holes",
    "block_fillets",
    "bosses",
    "ribbed",
    "thin_gaps",
    "assembly",
)

class PartError(RuntimeError):
    """An attempt failed; the part is retried with the next sub-seed."""


# --------------------------------------------------------------------------
# Small geometry helpers (act on the current gmsh model)
# --------------------------------------------------------------------------


def occ() -> Any:
    return gmsh.model.occ


def box(x: float, y: float, z: float, dx: float, dy: float, dz: float) -> DimTag:
    return (3, occ().addBox(x, y, z, dx, dy, dz))


def cyl(
    x: float, y: float, z: float, dx: float, dy: float, dz: float, r: float
) -> DimTag:
    return (3, occ().addCylinder(x, y, z, dx, dy, dz, r))


def vols(dimtags: list[DimTag]) -> list[DimTag]:
    return [d for d in dimtags if d[0] == 3]


def cut(obj: list[DimTag], tools: list[DimTag]) -> list[DimTag]:
    if not tools:
        return obj
    out, _ = occ().cut(obj, tools)
    out = vols(out)
    if not out:
        raise PartError("cut left nothing")
    return out


def fuse(obj: list[DimTag], tools: list[DimTag]) -> list[DimTag]:
    if not tools:
        return obj
    out, _ = occ().fuse(obj, tools)
    out = vols(out)
    if not out:
        raise PartError("fuse left nothing")
    return out


def mass(dimtags: list[DimTag]) -> float:
    return sum(occ().getMass(3, t) for _, t in dimtags)


def curves_of(body: list[DimTag]) -> list[int]:
    """Curve tags on the boundary of the volumes, sorted (deterministic)."""
    occ().synchronize()
    surfs = gmsh.model.getBoundary(body, combined=False, oriented=False)
    curves = gmsh.model.getBoundary(surfs, combined=False, oriented=False)
    return sorted({abs(t) for d, t in curves if d == 1})


def cbox(c: int) -> tuple[float, float, float, float, float, float]:
    return occ().getBoundingBox(1, c)


def ctype(c: int) -> str:
    return gmsh.model.getType(1, c)


def at_z(c: int, z: float, tol: float) -> bool:
    b = cbox(c)
    return abs(b[2] - z) < tol and abs(b[5] - z) < tol


def vertical(c: int, tol: float) -> bool:
    b = cbox(c)
    return (b[3] - b[0]) < tol and (b[4] - b[1]) < tol and (b[5] - b[2]) > tol


@dataclass
class Circle:
    x: float
    y: float
    r: float


def place_circles(
    rng: random.Random,
    rect: tuple[float, float, float, float],
    radii: list[float],
    margin: float,
    taken: list[Circle] | None = None,
    tries: int = 200,
) -> list[Circle]:
    """Rejection-sample non-overlapping discs inside rect (x0, y0, x1, y1).

    Discs keep `margin` to the rectangle's sides and to each other (and to the
    `taken` discs); a radius that does not fit is skipped.
    """
    x0, y0, x1, y1 = rect
    placed: list[Circle] = []
    others = list(taken or [])
    for r in radii:
        lo_x, hi_x = x0 + r + margin, x1 - r - margin
        lo_y, hi_y = y0 + r + margin, y1 - r - margin
        if lo_x >= hi_x or lo_y >= hi_y:
            continue
        for _ in range(tries):
            c = Circle(rng.uniform(lo_x, hi_x), rng.uniform(lo_y, hi_y), r)
            if all(
                math.hypot(c.x - o.x, c.y - o.y) > c.r + o.r + margin for o in others
            ):
                placed.append(c)
                others.append(c)
                break
    return placed


def full_circles_at(
    body: list[DimTag], z: float, centres: list[Circle], tol: float
) -> list[int]:
    """Closed circles of `body` in the plane z whose centre is one of
    `centres` (the hole or boss axes): partial arcs (rounded corners, slot
    ends) are left out, since blending them alone breaks tangent chains."""
    out = []
    for c in curves_of(body):
        if ctype(c) != "Circle" or not at_z(c, z, tol):
            continue
        b = cbox(c)
        cx, cy = (b[0] + b[3]) / 2.0, (b[1] + b[4]) / 2.0
        if abs((b[3] - b[0]) - (b[4] - b[1])) < tol and any(
            abs(cx - k.x) < tol and abs(cy - k.y) < tol for k in centres
        ):
            out.append(c)
    return out


def try_fillet(
    body: list[DimTag], curves: list[int], radius: float, log: Params, key: str
) -> list[DimTag]:
    """Fillet `curves` of `body`; on any OCC failure keep the unfilleted body.

    The fillet is built with removeVolume=False (gmsh drops the input volume
    when OCC fails otherwise) and checked (non-empty, volume change under
    50 %) before the original is removed.
    """
    return _try_blend(body, curves, radius, log, key, chamfer=False)


def try_chamfer(
    body: list[DimTag], curves: list[int], dist: float, log: Params, key: str
) -> list[DimTag]:
    """Chamfer `curves` of `body` (symmetric distance); fallback as try_fillet."""
    return _try_blend(body, curves, dist, log, key, chamfer=True)


def _try_blend(
    body: list[DimTag],
    curves: list[int],
    size: float,
    log: Params,
    key: str,
    chamfer: bool,
) -> list[DimTag]:
    log[f"{key}_size"] = size
    log[f"{key}_edges"] = len(curves)
    if not curves or size <= 0.0:
        log[key] = "skipped"
        return body
    o = occ()
    o.synchronize()
    before = mass(body)
    tags = [t for _, t in body]
    new: list[DimTag] = []
    try:
        if chamfer:
            surfs = []
            for c in curves:
                up, _ = gmsh.model.getAdjacencies(1, c)
                if len(up) == 0:
                    raise PartError("curve without surface")
                surfs.append(int(up[0]))
            out = o.chamfer(tags, curves, surfs, [size], removeVolume=False)
        else:
            out = o.fillet(tags, curves, [size], removeVolume=False)
        new = vols(out)
        o.synchronize()
        if not new:
            raise PartError("empty result")
        after = mass(new)
        if not (0.5 * before < after < 1.5 * before):
            raise PartError(f"volume {before:.3g} -> {after:.3g}")
    except Exception as exc:  # OCC fails on some inputs: fall back
        if new:
            o.remove(new, recursive=True)
            o.synchronize()
        log[key] = "failed"
        log[f"{key}_error"] = str(exc)[:120]
        return body
    o.remove(body, recursive=True)
    o.synchronize()
    log[key] = "ok"
    return new


def slot_tool(
    cx: float, cy: float, z0: float, length: float, width: float, h: float, ang: float
) -> DimTag:
    """A rounded slot (capsule prism) centred at (cx, cy), rotated by ang."""
    r = width / 2.0
    core = box(-length / 2.0, -r, z0, length, width, h)
    ends = [cyl(-length / 2.0, 0.0, z0, 0, 0, h, r), cyl(length / 2.0, 0.0, z0, 0, 0, h, r)]
    tool = fuse([core], ends)
    o = occ()
    o.rotate(tool, 0, 0, 0, 0, 0, 1, ang)
    o.translate(tool, cx, cy, 0)
    return tool[0]


def plate_corner_fillet(
    rng: random.Random, body: list[DimTag], b: float, L: float, log: Params
) -> list[DimTag]:
    """Round the vertical edges of a plate with probability 1/2."""
    if rng.random() < 0.5:
        tol = 1e-3 * L
        edges = [c for c in curves_of(body) if vertical(c, tol)]
        body = try_fillet(body, edges, rng.uniform(0.03, 0.15) * b, log, "corner_fillet")
    return body


# --------------------------------------------------------------------------
# Families: each builds one part into the current model and returns its
# parameters (all lengths are in model units, proportional to L).
# --------------------------------------------------------------------------


def family_plate_holes(rng: random.Random, L: float) -> Params:
    a, b, t = L, rng.uniform(0.35, 1.0) * L, rng.uniform(0.02, 0.12) * L
    p: Params = {"a": a, "b": b, "t": t}
    body = [box(0, 0, 0, a, b, t)]
    body = plate_corner_fillet(rng, body, b, L, p)
    taken: list[Circle] = []
    tools: list[DimTag] = []
    if rng.random() < 0.3:  # rectangular notch in the edge y = 0
        w, d = rng.uniform(0.1, 0.3) * a, rng.uniform(0.1, 0.3) * b
        x = rng.uniform(0.2, 0.8) * a
        tools.append(box(x - w / 2.0, -t, -t, w, d + t, 3 * t))
        taken.append(Circle(x, 0.0, math.hypot(w / 2.0, d)))
        p["notch"] = {"x": x, "w": w, "d": d}
    n_holes, n_slots = rng.randint(1, 8), rng.randint(0, 3)
    margin = 0.02 * L
    holes = place_circles(
        rng,
        (0, 0, a, b),
        [rng.uniform(0.015, 0.07) * L for _ in range(n_holes)],
        margin,
        taken,
    )
    taken += holes
    kinds: dict[str, int] = {"through": 0, "blind": 0, "counterbore": 0}
    for h in holes:
        u = rng.random()
        if u < 0.7:
            kinds["through"] += 1
            tools.append(cyl(h.x, h.y, -t, 0, 0, 3 * t, h.r))
        elif u < 0.85:
            kinds["blind"] += 1
            depth = rng.uniform(0.3, 0.8) * t
            tools.append(cyl(h.x, h.y, t - depth, 0, 0, depth + t, h.r))
        else:
            kinds["counterbore"] += 1
            depth = rng.uniform(0.25, 0.5) * t
            tools.append(cyl(h.x, h.y, -t, 0, 0, 3 * t, 0.6 * h.r))
            tools.append(cyl(h.x, h.y, t - depth, 0, 0, depth + t, h.r))
    slots = []
    for _ in range(n_slots):
        length, width = rng.uniform(0.08, 0.3) * L, rng.uniform(0.02, 0.07) * L
        ang = rng.choice([0.0, math.pi / 2, rng.uniform(0.0, math.pi)])
        spot = place_circles(rng, (0, 0, a, b), [length / 2 + width / 2], margin, taken)
        if spot:
            c = spot[0]
            taken.append(c)
            tools.append(slot_tool(c.x, c.y, -t, length, width, 3 * t, ang))
            slots.append({"length": length, "width": width, "angle": ang})
    p.update(holes=len(holes), hole_kinds=kinds, slots=slots)
    body = cut(body, tools)
    if rng.random() < 0.3:  # chamfer the top edges of the holes
        tol = 1e-3 * L
        edges = full_circles_at(body, t, holes, tol)
        r_min = min([h.r for h in holes] or [t])
        body = try_chamfer(body, edges, rng.uniform(0.1, 0.3) * min(t, r_min), p, "hole_chamfer")
    return p


def family_block_fillets(rng: random.Random, L: float) -> Params:
    a, b, c = L, rng.uniform(0.4, 1.0) * L, rng.uniform(0.2, 0.8) * L
    p: Params = {"a": a, "b": b, "c": c}
    body = [box(0, 0, 0, a, b, c)]
    small = min(b, c)
    tools: list[DimTag] = []
    if rng.random() < 0.5:  # step: an L-shaped profile
        sx, sz = rng.uniform(0.3, 0.6) * a, rng.uniform(0.3, 0.6) * c
        tools.append(box(a - sx, -b, c - sz, 2 * sx, 3 * b, 2 * sz))
        p["step"] = {"dx": sx, "dz": sz}
        small = min(small, sz, c - sz)
    if rng.random() < 0.4:  # pocket in the top face (left half)
        px, py = rng.uniform(0.15, 0.35) * a, rng.uniform(0.2, 0.6) * b
        pd = rng.uniform(0.2, 0.6) * c
        x0 = rng.uniform(0.05, 0.45 - px / a) * a
        y0 = rng.uniform(0.1 * b, 0.9 * b - py)
        tools.append(box(x0, y0, c - pd, px, py, 2 * pd))
        p["pocket"] = {"dx": px, "dy": py, "depth": pd}
        small = min(small, px, py, pd)
    if rng.random() < 0.3:  # cross hole along y
        r = rng.uniform(0.05, 0.15) * min(a, c)
        x, z = rng.uniform(0.2, 0.4) * a, rng.uniform(0.3, 0.45) * c
        tools.append(cyl(x, -b, z, 0, 3 * b, 0, r))
        p["cross_hole"] = {"r": r}
    body = cut(body, tools)
    tol = 1e-3 * L
    mode = rng.choice(["vertical", "top", "all", "random"])
    edges = curves_of(body)
    if mode == "vertical":
        sel = [e for e in edges if vertical(e, tol)]
    elif mode == "top":
        sel = [e for e in edges if at_z(e, c, tol)]
    elif mode == "all":
        sel = edges
    else:
        sel = sorted(rng.sample(edges, max(1, int(len(edges) * rng.uniform(0.2, 0.6)))))
    p["fillet_mode"] = mode
    body = try_fillet(body, sel, rng.uniform(0.03, 0.25) * small, p, "fillet")
    if rng.random() < 0.6:
        edges = [e for e in curves_of(body) if ctype(e) == "Line"]
        sel = [e for e in edges if at_z(e, 0.0, tol)]
        if not sel or rng.random() < 0.5:
            sel = sorted(rng.sample(edges, min(len(edges), rng.randint(1, 6))))
        body = try_chamfer(body, sel, rng.uniform(0.02, 0.12) * small, p, "chamfer")
    return p


def family_bosses(rng: random.Random, L: float) -> Params:
    a, b, t = L, rng.uniform(0.4, 1.0) * L, rng.uniform(0.04, 0.12) * L
    p: Params = {"a": a, "b": b, "t": t}
    body = [box(0, 0, 0, a, b, t)]
    body = plate_corner_fillet(rng, body, b, L, p)
    spots = place_circles(
        rng, (0, 0, a, b), [rng.uniform(0.04, 0.13) * L for _ in range(rng.randint(1, 6))],
        0.03 * L,
    )
    if not spots:
        raise PartError("no boss fits")
    bosses, holes = [], []
    tops: list[float] = []
    for s in spots:
        h = rng.uniform(0.05, 0.4) * L
        down = rng.random() < 0.2
        if down:
            bosses.append(cyl(s.x, s.y, t / 2, 0, 0, -(h + t / 2), s.r))
        else:
            bosses.append(cyl(s.x, s.y, t / 2, 0, 0, h + t / 2, s.r))
            tops.append(t + h)
        rec: Params = {"r": s.r, "h": h, "down": down}
        if rng.random() < 0.5:
            rh = rng.uniform(0.3, 0.65) * s.r
            holes.append(cyl(s.x, s.y, -h - 2 * t, 0, 0, 2 * h + 4 * t, rh))
            rec["hole_r"] = rh
        p.setdefault("bosses", []).append(rec)
    body = fuse(body, bosses)
    body = cut(body, holes)
    tol = 1e-3 * L
    r_min = min(s.r for s in spots)
    h_min = min(x["h"] for x in p["bosses"])
    if rng.random() < 0.5:
        edges = full_circles_at(body, t, spots, tol)
        size = rng.uniform(0.1, 0.35) * min(r_min, h_min, t)
        body = try_fillet(body, edges, size, p, "root_fillet")
    if rng.random() < 0.4 and tops:
        edges = sorted({e for z in set(tops) for e in full_circles_at(body, z, spots, tol)})
        size = rng.uniform(0.05, 0.2) * min(0.35 * r_min, h_min)
        body = try_chamfer(body, edges, size, p, "top_chamfer")
    return p


def family_ribbed(rng: random.Random, L: float) -> Params:
    a, b, t = L, rng.uniform(0.4, 1.0) * L, rng.uniform(0.03, 0.1) * L
    tr, hr = rng.uniform(0.01, 0.04) * L, rng.uniform(0.08, 0.35) * L
    variant = rng.choice(["parallel", "grid", "frame", "l_bracket"])
    p: Params = {"variant": variant, "a": a, "b": b, "t": t, "rib_t": tr, "rib_h": hr}
    body = [box(0, 0, 0, a, b, t)]
    ribs: list[DimTag] = []
    z0, zh = t / 2, hr + t / 2  # ribs overlap the base by t/2

    def rib_x(y: float, x0: float = 0.0, x1: float = a) -> None:
        ribs.append(box(x0, y - tr / 2, z0, x1 - x0, tr, zh))

    def rib_y(x: float, y0: float = 0.0, y1: float = b) -> None:
        ribs.append(box(x - tr / 2, y0, z0, tr, y1 - y0, zh))

    if variant == "parallel":
        n = rng.randint(2, 8)
        inset = rng.uniform(0.0, 0.1) * a
        for i in range(n):
            rib_x((i + 1) * b / (n + 1), inset, a - inset)
        p["ribs"] = n
    elif variant == "grid":
        nx, ny = rng.randint(1, 4), rng.randint(1, 4)
        for i in range(nx):
            rib_x((i + 1) * b / (nx + 1))
        for j in range(ny):
            rib_y((j + 1) * a / (ny + 1))
        p["ribs"] = nx + ny
    elif variant == "frame":
        rib_x(tr / 2)
        rib_x(b - tr / 2)
        rib_y(tr / 2)
        rib_y(a - tr / 2)
        n = rng.randint(0, 3)
        for j in range(n):
            rib_y((j + 1) * a / (n + 1))
        p["ribs"] = 4 + n
    else:  # L-bracket: a wall at x in [0, t] and triangular gussets
        wall_h = rng.uniform(0.3, 0.8) * L
        ribs.append(box(0, 0, 0, t, b, wall_h))
        n = rng.randint(1, 4)
        leg_x = rng.uniform(0.3, 0.8) * (a - t)
        leg_z = rng.uniform(0.3, 0.8) * (wall_h - t)
        for i in range(n):
            y = (i + 1) * b / (n + 1) - tr / 2
            w = occ().addWedge(0, 0, 0, leg_x + t / 2, leg_z + t / 2, tr, ltx=0.0)
            g = [(3, w)]
            occ().rotate(g, 0, 0, 0, 1, 0, 0, math.pi / 2)
            occ().translate(g, t / 2, y + tr, t / 2)
            ribs += g
        p.update(wall_h=wall_h, gussets=n, leg_x=leg_x, leg_z=leg_z)
    body = fuse(body, ribs)
    tol = 1e-3 * L
    if rng.random() < 0.4:
        edges = [e for e in curves_of(body) if ctype(e) == "Line" and at_z(e, t, tol)]
        body = try_fillet(body, edges, rng.uniform(0.2, 0.6) * tr, p, "root_fillet")
    if rng.random() < 0.3 and variant != "l_bracket":
        edges = [e for e in curves_of(body) if at_z(e, t + hr, tol)]
        body = try_fillet(body, edges, rng.uniform(0.2, 0.45) * tr, p, "top_fillet")
    return p


def family_thin_gaps(rng: random.Random, L: float) -> Params:
    variant = rng.choice(["tray", "tube", "two_plates", "slit_block"])
    p: Params = {"variant": variant}
    tol = 1e-3 * L
    if variant == "tray":  # box minus a slightly smaller box: thin walls, open top
        a, b, c = L, rng.uniform(0.4, 1.0) * L, rng.uniform(0.2, 0.7) * L
        w = rng.uniform(0.01, 0.05) * L
        p.update(a=a, b=b, c=c, wall=w)
        outer = [box(0, 0, 0, a, b, c)]
        inner = [box(w, w, w, a - 2 * w, b - 2 * w, c)]
        if rng.random() < 0.5:
            r = rng.uniform(0.05, 0.2) * b
            edges = [e for e in curves_of(outer) if vertical(e, tol)]
            outer = try_fillet(outer, edges, r, p, "outer_fillet")
            if p["outer_fillet"] == "ok" and r > 1.5 * w:
                edges = [e for e in curves_of(inner) if vertical(e, tol)]
                inner = try_fillet(inner, edges, r - w, p, "inner_fillet")
        cut(outer, inner)
    elif variant == "tube":
        r = rng.uniform(0.1, 0.4) * L
        w = rng.uniform(0.01, 0.05) * L
        p.update(length=L, r=r, wall=w)
        cut([cyl(0, 0, 0, 0, 0, L, r)], [cyl(0, 0, -L, 0, 0, 3 * L, r - w)])
    elif variant == "two_plates":  # two bodies with a narrow gap
        a, b = L, rng.uniform(0.4, 1.0) * L
        t1, t2 = rng.uniform(0.03, 0.1) * L, rng.uniform(0.03, 0.1) * L
        g = rng.uniform(0.005, 0.03) * L
        p.update(a=a, b=b, t1=t1, t2=t2, gap=g, expected_bodies=2)
        lower = [box(0, 0, 0, a, b, t1)]
        s = rng.uniform(0.6, 1.0)
        dx, dy = rng.uniform(0, 1 - s) * a, rng.uniform(0, 1 - s) * b
        upper = [box(dx, dy, t1 + g, s * a, s * b, t2)]
        p["upper_scale"] = s
        if rng.random() < 0.5:  # aligned holes through both plates
            holes = place_circles(
                rng, (dx, dy, dx + s * a, dy + s * b),
                [rng.uniform(0.02, 0.06) * L for _ in range(rng.randint(1, 4))], 0.02 * L,
            )
            top = t1 + g + t2
            cut(lower, [cyl(h.x, h.y, -top, 0, 0, 3 * top, h.r) for h in holes])
            cut(upper, [cyl(h.x, h.y, -top, 0, 0, 3 * top, h.r) for h in holes])
            p["holes"] = len(holes)
    else:  # slit_block: a saw cut of width g, open at x = a
        a, b, c = L, rng.uniform(0.3, 0.8) * L, rng.uniform(0.2, 0.6) * L
        g = rng.uniform(0.005, 0.03) * L
        depth = rng.uniform(0.4, 0.8) * a
        zc = rng.uniform(0.35, 0.65) * c
        p.update(a=a, b=b, c=c, gap=g, depth=depth)
        tools = [box(a - depth, -b, zc - g / 2, 2 * depth, 3 * b, g)]
        if rng.random() < 0.6:  # stress-relief hole at the end of the slit
            rr = rng.uniform(1.0, 3.0) * g
            tools.append(cyl(a - depth, -b, zc, 0, 3 * b, 0, rr))
            p["relief_r"] = rr
        if rng.random() < 0.5:  # clamp-bolt hole across the slit
            rb = rng.uniform(0.04, 0.1) * min(b, L)
            tools.append(cyl(a - depth / 2, b / 2, -c, 0, 0, 3 * c, rb))
            p["bolt_r"] = rb
        cut([box(0, 0, 0, a, b, c)], tools)
    return p


def family_assembly(rng: random.Random, L: float) -> Params:
    """2-5 touching bodies, left as separate closed solids."""
    n = rng.randint(2, 5)
    variant = rng.choice(["shaft_in_bore", "stacked_plates", "blocks_on_plate"])
    p: Params = {"variant": variant, "bodies_planned": n}
    if variant == "shaft_in_bore":
        ly = rng.uniform(0.3, 0.6) * L  # housing length along the shaft (y)
        wx, hz = rng.uniform(0.3, 0.6) * L, rng.uniform(0.3, 0.6) * L
        r = rng.uniform(0.1, 0.3) * min(wx, hz)
        stick = rng.uniform(0.1, 0.3) * L
        xc, zc = wx / 2, hz / 2
        cut([box(0, 0, 0, wx, ly, hz)], [cyl(xc, -ly, zc, 0, 3 * ly, 0, r)])
        cyl(xc, -stick, zc, 0, ly + 2 * stick, 0, r)  # the shaft, same radius
        extras = ["collar_front", "collar_back", "base"]
        rng.shuffle(extras)
        # collars stay above the base plate (z >= 0): ro <= 0.95 zc (> 1.5 r)
        ro = min(rng.uniform(1.4, 2.0) * r, 0.95 * min(xc, zc))
        tc = min(rng.uniform(0.02, 0.08) * L, 0.8 * stick)
        for e in extras[: n - 2]:
            if e == "collar_front":
                cut([cyl(xc, -tc, zc, 0, tc, 0, ro)], [cyl(xc, -2 * tc, zc, 0, 4 * tc, 0, r)])
            elif e == "collar_back":
                cut([cyl(xc, ly, zc, 0, tc, 0, ro)], [cyl(xc, ly - tc, zc, 0, 3 * tc, 0, r)])
            else:
                m = rng.uniform(0.1, 0.3) * L
                box(-m, -m, -0.08 * L, wx + 2 * m, ly + 2 * m, 0.08 * L)
        p.update(housing=[wx, ly, hz], r=r, shaft_out=stick)
        p["parts"] = ["housing", "shaft"] + extras[: n - 2]
    elif variant == "stacked_plates":
        pinned = n >= 3 and rng.random() < 0.5
        plates = n - 1 if pinned else n
        a, b = L, rng.uniform(0.4, 1.0) * L
        z = 0.0
        boxes = []
        x0, y0, sa, sb = 0.0, 0.0, a, b
        for i in range(plates):
            t = rng.uniform(0.02, 0.1) * L
            if i > 0:
                s = rng.uniform(0.6, 1.0)
                x0 += rng.uniform(0, 1 - s) * sa
                y0 += rng.uniform(0, 1 - s) * sb
                sa, sb = s * sa, s * sb
            boxes.append((x0, y0, z, sa, sb, t))
            z += t
        if pinned:
            xs, ys = x0 + sa / 2, y0 + sb / 2  # inside every plate's footprint
            r = rng.uniform(0.1, 0.3) * min(sa, sb) / 2
            for bx in boxes:
                cut([box(*bx)], [cyl(xs, ys, -z, 0, 0, 3 * z, r)])
            stick = rng.uniform(0.05, 0.2) * L
            cyl(xs, ys, -stick, 0, 0, z + 2 * stick, r)
            p["pin_r"] = r
        else:
            for bx in boxes:
                box(*bx)
        p.update(plates=plates, pinned=pinned, height=z)
    else:  # blocks (or cylinders) sitting on a plate
        a, b, t = L, rng.uniform(0.5, 1.0) * L, rng.uniform(0.03, 0.1) * L
        box(0, 0, 0, a, b, t)
        spots = place_circles(
            rng, (0, 0, a, b), [rng.uniform(0.08, 0.22) * L for _ in range(n - 1)], 0.02 * L
        )
        if not spots:
            raise PartError("no block fits")
        items = []
        for s in spots:
            h = rng.uniform(0.05, 0.3) * L
            if rng.random() < 0.3:
                cyl(s.x, s.y, t, 0, 0, h, s.r)
                items.append("cylinder")
                continue
            half = s.r / math.sqrt(2)
            blk = [box(s.x - half, s.y - half, t, 2 * half, 2 * half, h)]
            items.append("block")
            if rng.random() < 0.4:
                tol = 1e-3 * L
                edges = [e for e in curves_of(blk) if vertical(e, tol)]
                log: Params = {}
                try_fillet(blk, edges, rng.uniform(0.1, 0.4) * half, log, "fillet")
                items[-1] = f"block_fillet_{log['fillet']}"
        p.update(plate=[a, b, t], items=items)
    return p


BUILDERS: dict[str, Callable[[random.Random, float], Params]] = {
    "plate_holes": family_plate_holes,
    "block_fillets": family_block_fillets,
    "bosses": family_bosses,
    "ribbed": family_ribbed,
    "thin_gaps": family_thin_gaps,
    "assembly": family_assembly,
}
