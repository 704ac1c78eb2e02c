"""The FreeCAD macro, headless: a STEP through MeshPart, abgs and Gmsh into a
.FCStd; the reopened document holds the mesh, and the mesh follows the stored
field (edge length / h(midpoint) in [0.5, 2] for at least 95 % of edges).

Needs ``freecadcmd`` (FreeCAD 0.20, Debian) and the abgs and gmsh packages for
its Python in ``$ABGS_SITE`` (python/ci.sh sets both up). Skipped without
FreeCAD, unless ``ABGS_REQUIRE_FREECAD=1`` (CI), where that is a failure.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from conftest import MESHES, REPO

STEP = MESHES / "gmsh_t20_component8.step"
MACRO = REPO / "python" / "freecad" / "run_abgs.py"

CHECK = r'''
import json, sys, traceback
try:
    sys.path.insert(0, sys.argv[-1])
    import abgs_freecad
    abgs_freecad.add_site()
    import FreeCAD, abgs, numpy as np
    doc = FreeCAD.openDocument(sys.argv[-2])
    mesh = doc.getObject("Mesh")
    grid = doc.getObject("SizingGrid")
    field = doc.getObject("SizingField")
    pts, tris = mesh.Mesh.Topology
    gp, gt = grid.Mesh.Topology
    g = abgs.Grid.load(grid.GridFile)  # the exact grid, carried inside the .FCStd
    r = abgs_freecad.edge_ratios([(p.x, p.y, p.z) for p in pts], tris, g)
    gv = np.array([(p.x, p.y, p.z) for p in gp])
    out = {
        "types": {o.Name: o.TypeId for o in doc.Objects},
        "mesh_points": len(pts), "mesh_facets": len(tris),
        "mesh_is_solid": mesh.Mesh.isSolid(),
        "grid_points": len(gp), "grid_sizes": len(grid.Size),
        "field_points": len(field.Points.Points), "field_sizes": len(field.Size), "field_colors": len(field.Color),
        "same_sizes": list(field.Size) == list(grid.Size) == g.sizes.tolist(),
        "same_points": bool(np.allclose(gv, g.vertices, rtol=0, atol=1e-5 * g.stats.diagonal)),
        "same_triangles": bool(np.array_equal(np.array(gt), g.triangles)),
        "shape_faces": len(doc.getObject("Shape").Shape.Faces),
        "edges": int(len(r)), "inside": float(((r >= 0.5) & (r <= 2.0)).mean()),
        "median": float(np.median(r)), "p5": float(np.percentile(r, 5)), "p95": float(np.percentile(r, 95)),
    }
    print("ABGS_CHECK " + json.dumps(out))
except BaseException:
    traceback.print_exc()
    raise SystemExit(1)
raise SystemExit(0)
'''


def freecadcmd() -> str:
    """Path of freecadcmd, or skip (fail under ABGS_REQUIRE_FREECAD=1)."""
    exe = shutil.which("freecadcmd")
    if exe is None:
        if os.environ.get("ABGS_REQUIRE_FREECAD") == "1":
            pytest.fail("freecadcmd not found but ABGS_REQUIRE_FREECAD=1")
        pytest.skip("FreeCAD not installed (apt-get install freecad; python/ci.sh does)")
    return exe


def run(cmd: list[str], args: str = "") -> str:
    """Runs a freecadcmd command (``args``: the macro's options, ``$ABGS_ARGS``);
    fails the test with its output on a non-zero exit."""
    env = {**os.environ, "ABGS_ARGS": args}
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=900, env=env)
    out = r.stdout + r.stderr
    assert r.returncode == 0, f"{' '.join(cmd)} exited {r.returncode}:\n{out[-6000:]}"
    return out


def test_macro_on_step(tmp_path: Path) -> None:
    """STEP -> .FCStd; reopened: shape, mesh and field present, mesh follows the field."""
    exe = freecadcmd()
    assert STEP.is_file(), f"missing shared model {STEP}"
    doc = tmp_path / "component8.FCStd"
    # A dense grid of diagonal/50 keeps the test quick (the default is /100).
    out = run([exe, str(MACRO), str(STEP), str(doc)], "--relative-length 0.02")
    assert "wrote" in out and doc.is_file(), out[-3000:]
    check = tmp_path / "check.py"
    check.write_text(CHECK)
    out = run([exe, str(check), str(doc), str(MACRO.parent)])
    line = next((x for x in out.splitlines() if x.startswith("ABGS_CHECK ")), None)
    assert line is not None, out[-3000:]
    c = json.loads(line[len("ABGS_CHECK "):])
    assert c["types"] == {
        "Shape": "Part::Feature",
        "Mesh": "Mesh::Feature",
        "SizingGrid": "Mesh::FeatureCustom",
        "SizingField": "Points::FeatureCustom",
    }
    assert c["shape_faces"] > 0
    assert c["mesh_facets"] > 1000 and c["mesh_is_solid"]
    assert c["grid_points"] == c["grid_sizes"] == c["field_points"] == c["field_sizes"] == c["field_colors"]
    assert c["same_sizes"] and c["same_points"] and c["same_triangles"]
    assert c["inside"] >= 0.95, c
    assert 0.7 < c["median"] < 1.4, c
