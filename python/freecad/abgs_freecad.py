"""abgs in FreeCAD: a sizing field for a CAD shape, and a Gmsh mesh that follows it.

Pipeline (every step in this FreeCAD process):

1. the shape (a STEP file, or any Part shape of a document) is tessellated by
   FreeCAD's own ``MeshPart.meshFromShape``;
2. the abgs Python package builds the background grid and its sizing field:
   ``remesh`` (dense grid) → ``compute_sizes`` → ``simplify`` (LBO-ABGS);
3. Gmsh (the ``gmsh`` Python API) meshes the same shape, handed over as a BREP
   file, with abgs as its size callback (``gmsh.model.mesh.setSizeCallback``:
   hinted surface queries of the simplified grid);
4. a ``.FCStd`` document stores the shape, the mesh and the field:

   - ``Shape`` (``Part::Feature``): the CAD shape;
   - ``Mesh`` (``Mesh::Feature``): Gmsh's surface triangles;
   - ``SizingGrid`` (``Mesh::FeatureCustom``): the simplified background grid,
     with ``Size`` (``App::PropertyFloatList``, one size per mesh point, in the
     mesh's point order), ``GridFile`` (``App::PropertyFileIncluded``: the grid
     as abgs wrote it, a legacy .vtk with full-precision points and the
     ``size`` array, carried inside the .FCStd; FreeCAD's own meshes keep
     single-precision points) and the run's parameters and counts;
   - ``SizingField`` (``Points::FeatureCustom``): the grid's vertices with
     ``Size`` (the same values) and ``Color`` (``App::PropertyColorList``, blue
     = large, red = small): in the GUI, set its *Display Mode* to ``Color`` to
     see the field.

Requires the ``abgs`` and ``gmsh`` packages on ``sys.path`` (see ``add_site``):
e.g. ``pip install --target DIR --no-deps ./python gmsh==4.15.2`` with any
Python 3 pip, then ``ABGS_SITE=DIR``.

Headless use (``freecadcmd`` takes every ``-option`` for itself: options go
in ``$ABGS_ARGS``)::

    ABGS_ARGS="--relative-length 0.02" freecadcmd -P DIR python/freecad/run_abgs.py part.step part.FCStd
"""

from __future__ import annotations

import argparse
import os
import shlex
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Optional, Sequence

#: Environment variable naming folders (os.pathsep-separated) that hold the
#: abgs and gmsh packages for FreeCAD's Python.
SITE_ENV = "ABGS_SITE"


def add_site(extra: Sequence[str] = ()) -> None:
    """Puts the folders of ``$ABGS_SITE`` and ``extra`` at the front of
    ``sys.path`` (FreeCAD's Python does not see a virtual environment)."""
    dirs = [d for d in os.environ.get(SITE_ENV, "").split(os.pathsep) if d] + list(extra)
    for d in reversed(dirs):
        d = str(Path(d).resolve())
        if d not in sys.path:
            sys.path.insert(0, d)


@dataclass
class Options:
    """Every setting of a run (defaults: the library's)."""

    #: MeshPart's linear deflection, relative to the shape's bounding-box
    #: diagonal (absolute = this × diagonal).
    deflection: float = 0.001
    #: MeshPart's angular deflection, radians.
    angular_deflection: float = 0.25
    #: Dense grid edge length / diagonal.
    relative_length: float = 0.01
    #: Elements per full circle (curvature sizes and remeshing).
    n_circle: float = 24.0
    #: Elements across a gap or wall.
    n_gap: float = 3.0
    #: Gradation ratio β.
    beta: float = 1.2
    #: Smallest / largest size, model units; 0 = diagonal/2000, diagonal/10.
    hmin: float = 0.0
    hmax: float = 0.0
    #: LBO-ABGS's largest size ratio per collapse.
    t_size: float = 1.2
    #: ``lbo`` or ``gcn``.
    method: str = "lbo"
    #: Gmsh's 2-D algorithm (6 = Frontal-Delaunay).
    algorithm: int = 6
    #: Gmsh's ``Geometry.Tolerance`` (some STEP files need 1e-6).
    tolerance: float = 1e-6
    #: Print progress.
    verbose: bool = True
    #: Extra Gmsh options (name -> number).
    gmsh_options: dict[str, float] = field(default_factory=dict)


@dataclass
class Result:
    """What ``run`` made: arrays, grids and timings."""

    mesh_vertices: Any  # N×3 float64
    mesh_triangles: Any  # M×3 int64
    grid: Any  # abgs.Grid (simplified, with sizes)
    dense_faces: int
    tessellation_faces: int
    seconds: dict[str, float]
    callback_calls: int
    info: dict[str, Any]


def _log(opts: Options, msg: str) -> None:
    """Prints ``msg`` when ``opts.verbose`` (FreeCAD's console if present)."""
    if not opts.verbose:
        return
    try:
        import FreeCAD

        FreeCAD.Console.PrintMessage(msg + "\n")
    except ImportError:
        print(msg, flush=True)


def read_step(path: str | os.PathLike[str]) -> Any:
    """The shape of a STEP (or IGES, BREP) file, read by FreeCAD's Part module."""
    import Part

    shape = Part.Shape()
    shape.read(str(path))
    if shape.isNull():
        raise ValueError(f"{path}: no shape")
    return shape


def tessellate(shape: Any, opts: Options) -> tuple[Any, Any]:
    """``MeshPart.meshFromShape`` with deflections relative to the diagonal:
    (vertices N×3 float64, triangles M×3 int64). Points are shared between the
    faces of the shape (FreeCAD's mesh kernel merges equal points)."""
    import MeshPart
    import numpy as np

    diag = shape.BoundBox.DiagonalLength
    mesh = MeshPart.meshFromShape(
        Shape=shape,
        LinearDeflection=opts.deflection * diag,
        AngularDeflection=opts.angular_deflection,
        Relative=False,
    )
    points, facets = mesh.Topology
    v = np.array([(p.x, p.y, p.z) for p in points], dtype=np.float64)
    t = np.array(facets, dtype=np.int64).reshape(-1, 3)
    return v, t


def sizing_field(vertices: Any, triangles: Any, opts: Options) -> tuple[Any, dict[str, Any]]:
    """The simplified background grid with its sizes, from a tessellation:
    remesh (dense grid) → compute_sizes → simplify. Returns (grid, info)."""
    import abgs

    info: dict[str, Any] = {}
    t0 = time.perf_counter()
    with abgs.Grid.from_arrays(vertices, triangles) as surface:
        st = surface.stats
        info["bodies"] = st.bodies
        info["boundary_edges"] = st.boundary_edges
        dense = surface.remesh(relative_length=opts.relative_length, n_circle=opts.n_circle)
    with dense:
        info["seconds_remesh"] = time.perf_counter() - t0
        info["dense_faces"] = dense.n_triangles
        t0 = time.perf_counter()
        rep = dense.compute_sizes(
            n_circle=opts.n_circle, n_gap=opts.n_gap, beta=opts.beta, hmin=opts.hmin, hmax=opts.hmax
        )
        info["hmin"], info["hmax"] = rep.hmin, rep.hmax
        info["seconds_sizes"] = time.perf_counter() - t0
        t0 = time.perf_counter()

        def progress(rec: abgs.IterationRecord) -> None:
            if rec.iteration % 10 == 0:
                _log(opts, f"  simplify: iteration {rec.iteration}: {rec.faces} faces")

        grid = dense.simplify(method=opts.method, t_size=opts.t_size, beta=opts.beta, progress=progress)
        info["seconds_simplify"] = time.perf_counter() - t0
        info["grid_faces"] = grid.n_triangles
    return grid, info


def gmsh_mesh(shape: Any, grid: Any, info: dict[str, Any], opts: Options) -> tuple[Any, Any, int]:
    """Gmsh's surface mesh of ``shape`` sized by ``grid`` (abgs as the size
    callback). Returns (vertices N×3, triangles M×3 0-based, callback calls)."""
    import abgs
    import gmsh
    import numpy as np

    calls = 0
    hint = abgs.Hint()

    def size(dim: int, tag: int, x: float, y: float, z: float, lc: float) -> float:
        nonlocal calls
        calls += 1
        return min(lc, grid.size_at((x, y, z), hint))

    with tempfile.TemporaryDirectory() as tmp:
        brep = os.path.join(tmp, "shape.brep")
        shape.exportBrep(brep)
        gmsh.initialize(interruptible=False)
        try:
            gmsh.option.setNumber("General.Terminal", 1 if opts.verbose else 0)
            gmsh.option.setNumber("General.Verbosity", 2)
            gmsh.option.setNumber("Geometry.Tolerance", opts.tolerance)
            gmsh.option.setNumber("Geometry.OCCFixDegenerated", 1)
            gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
            gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
            gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
            gmsh.option.setNumber("Mesh.MeshSizeMin", 0.5 * info["hmin"])
            gmsh.option.setNumber("Mesh.MeshSizeMax", info["hmax"])
            gmsh.option.setNumber("Mesh.Algorithm", opts.algorithm)
            for k, v in opts.gmsh_options.items():
                gmsh.option.setNumber(k, v)
            gmsh.model.add("abgs")
            gmsh.model.occ.importShapes(brep)
            gmsh.model.occ.synchronize()
            gmsh.model.mesh.setSizeCallback(size)
            gmsh.model.mesh.generate(2)
            tags, coords, _ = gmsh.model.mesh.getNodes()
            _, elem_nodes = gmsh.model.mesh.getElementsByType(2)
        finally:
            gmsh.finalize()
    tags = np.asarray(tags, dtype=np.int64)
    where = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    where[tags] = np.arange(len(tags))
    tri = where[np.asarray(elem_nodes, dtype=np.int64)].reshape(-1, 3)
    if (tri < 0).any():
        raise RuntimeError("gmsh: a triangle names a node without coordinates")
    used = np.unique(tri)
    remap = np.full(len(tags), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    xyz = np.asarray(coords, dtype=np.float64).reshape(-1, 3)[used]
    return xyz, remap[tri], calls


def size_colors(sizes: Any) -> list[tuple[float, float, float]]:
    """One RGB colour per size on a log scale: red = smallest, blue = largest."""
    import numpy as np

    s = np.log(np.asarray(sizes, dtype=np.float64))
    lo, hi = float(s.min()), float(s.max())
    t = (s - lo) / (hi - lo) if hi > lo else np.zeros_like(s)
    # A blue-white-red ramp.
    r = np.where(t < 0.5, 1.0, 2.0 * (1.0 - t))
    g = np.where(t < 0.5, 2.0 * t, 2.0 * (1.0 - t))
    b = np.where(t < 0.5, 2.0 * t, 1.0)
    return [(float(x), float(y), float(z)) for x, y, z in zip(r, g, b)]


def _fc_mesh(vertices: Any, triangles: Any) -> Any:
    """A FreeCAD ``Mesh.Mesh`` with these points (in this order; FreeCAD keeps
    them in single precision) and triangles."""
    import FreeCAD
    import Mesh

    m = Mesh.Mesh()
    m.addFacets(([FreeCAD.Vector(*p) for p in vertices.tolist()], [tuple(f) for f in triangles.tolist()]), True)
    if m.CountPoints != len(vertices) or m.CountFacets != len(triangles):
        raise RuntimeError(
            f"FreeCAD kept {m.CountPoints} points, {m.CountFacets} facets of {len(vertices)}, {len(triangles)}"
        )
    return m


def store(doc: Any, shape: Any, result: Result, add_shape: bool = True) -> None:
    """Adds the shape (when ``add_shape``), Gmsh's mesh and the field
    (``SizingGrid``, ``SizingField``) to the FreeCAD document ``doc`` (see
    the module doc)."""
    import FreeCAD
    import Points

    if add_shape:
        part = doc.addObject("Part::Feature", "Shape")
        part.Shape = shape

    m = doc.addObject("Mesh::Feature", "Mesh")
    m.Mesh = _fc_mesh(result.mesh_vertices, result.mesh_triangles)
    m.Label = "Mesh (Gmsh, sized by abgs)"

    g = result.grid
    gv, gt, gs = g.vertices, g.triangles, g.sizes
    grid = doc.addObject("Mesh::FeatureCustom", "SizingGrid")
    grid.Mesh = _fc_mesh(gv, gt)
    grid.addProperty("App::PropertyFloatList", "Size", "abgs", "Size at each mesh point (model units)")
    grid.Size = gs.tolist()
    grid.addProperty("App::PropertyFileIncluded", "GridFile", "abgs", "The grid as abgs wrote it (.vtk, sizes included)")
    with tempfile.TemporaryDirectory() as tmp:
        vtk = os.path.join(tmp, "sizing_grid.vtk")
        g.save(vtk)
        grid.GridFile = vtk  # copied into the document's own folder
    for k, val in result.info.items():
        if isinstance(val, (int, float)) and not isinstance(val, bool):
            name = "".join(p.capitalize() for p in k.split("_"))
            grid.addProperty("App::PropertyFloat", name, "abgs run", k)
            setattr(grid, name, float(val))
    grid.Label = "Sizing grid (abgs)"

    pts = doc.addObject("Points::FeatureCustom", "SizingField")
    pts.Points = Points.Points([FreeCAD.Vector(*p) for p in gv.tolist()])
    pts.addProperty("App::PropertyFloatList", "Size", "abgs", "Size at each point (model units)")
    pts.Size = gs.tolist()
    pts.addProperty("App::PropertyColorList", "Color", "abgs", "Size as colour (red = small, blue = large)")
    pts.Color = size_colors(gs)
    pts.Label = "Sizing field (abgs): Display Mode = Color"
    doc.recompute()


def run(shape: Any, opts: Options) -> Result:
    """Tessellation, sizing field and Gmsh mesh for ``shape`` (see the module doc)."""
    seconds: dict[str, float] = {}
    t0 = time.perf_counter()
    v, t = tessellate(shape, opts)
    seconds["tessellate"] = time.perf_counter() - t0
    _log(opts, f"MeshPart: {len(v)} points, {len(t)} facets")
    t0 = time.perf_counter()
    grid, info = sizing_field(v, t, opts)
    seconds["field"] = time.perf_counter() - t0
    _log(opts, f"abgs: dense {info['dense_faces']} faces -> grid {info['grid_faces']} faces "
               f"(h in [{info['hmin']:.4g}, {info['hmax']:.4g}])")
    t0 = time.perf_counter()
    mv, mt, calls = gmsh_mesh(shape, grid, info, opts)
    seconds["gmsh"] = time.perf_counter() - t0
    _log(opts, f"gmsh: {len(mt)} triangles, {len(mv)} nodes, {calls} size callbacks")
    info.update({f"seconds_{k}": s for k, s in seconds.items()})
    info["mesh_triangles"] = len(mt)
    info["callback_calls"] = calls
    return Result(mv, mt, grid, info["dense_faces"], len(t), seconds, calls, info)


def edge_ratios(vertices: Any, triangles: Any, grid: Any) -> Any:
    """Edge length / h(edge midpoint) over the unique edges of a triangle mesh,
    h from ``grid`` (one batch query, no Python loop)."""
    import numpy as np

    t = np.asarray(triangles, dtype=np.int64)
    e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    e = np.unique(np.sort(e, axis=1), axis=0)
    v = np.asarray(vertices, dtype=np.float64)
    a, b = v[e[:, 0]], v[e[:, 1]]
    h = grid.sizes_at(0.5 * (a + b))
    return np.linalg.norm(a - b, axis=1) / h


def main(argv: Optional[Sequence[str]] = None, log: Callable[[str], None] = print) -> int:
    """Command line: STEP in, .FCStd out (run under ``freecadcmd``)."""
    ap = argparse.ArgumentParser(prog="abgs_freecad", description=__doc__.split("\n\n")[0])
    ap.add_argument("step", help="STEP (or IGES, BREP) file")
    ap.add_argument("output", help="the .FCStd document to write")
    d = Options()
    for name in ("deflection", "relative_length", "n_circle", "n_gap", "beta", "hmin", "hmax", "t_size",
                 "tolerance"):
        ap.add_argument("--" + name.replace("_", "-"), type=float, default=getattr(d, name))
    ap.add_argument("--method", choices=["lbo", "gcn"], default=d.method)
    ap.add_argument("--algorithm", type=int, default=d.algorithm)
    ap.add_argument("--quiet", action="store_true")
    a = ap.parse_args(argv)
    opts = Options(
        deflection=a.deflection, relative_length=a.relative_length, n_circle=a.n_circle, n_gap=a.n_gap,
        beta=a.beta, hmin=a.hmin, hmax=a.hmax, t_size=a.t_size, tolerance=a.tolerance, method=a.method,
        algorithm=a.algorithm, verbose=not a.quiet,
    )
    import FreeCAD
    import numpy as np

    t0 = time.perf_counter()
    shape = read_step(a.step)
    result = run(shape, opts)
    doc = FreeCAD.newDocument("abgs")
    store(doc, shape, result)
    out = str(Path(a.output).resolve())
    doc.saveAs(out)
    FreeCAD.closeDocument(doc.Name)
    r = edge_ratios(result.mesh_vertices, result.mesh_triangles, result.grid)
    inside = 100.0 * float(((r >= 0.5) & (r <= 2.0)).mean())
    log(f"wrote {out}: {len(result.mesh_triangles)} triangles; edge/h median {float(np.median(r)):.3f}, "
        f"{inside:.1f} % in [0.5, 2]; {time.perf_counter() - t0:.1f} s")
    return 0


def main_from_freecadcmd(argv: Sequence[str]) -> int:
    """``main`` with the positional arguments ``argv`` (what ``freecadcmd``
    passes on to a script) followed by the options of ``$ABGS_ARGS``
    (shell-quoted): ``freecadcmd`` keeps every ``-option`` for itself."""
    return main(list(argv) + shlex.split(os.environ.get("ABGS_ARGS", "")))
