"""The Python package gives the CLI's answers on a shared model, bit for bit:
dense grid, sizes, simplified grid, evaluation and queries (surface, volume)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import abgs

from conftest import MODEL, RELATIVE, run_cli


@pytest.fixture(scope="module")
def cli_run(cli: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The CLI's pipeline on MODEL: dense grid, sizes, simplification, files in a temp dir."""
    d = tmp_path_factory.mktemp("cli")
    f = {k: d / f"{k}.vtk" for k in ("dense", "sized", "simplified")}
    f["report"] = d / "report.json"
    run_cli(cli, "grid", MODEL, "-o", f["dense"], "--relative", RELATIVE)
    run_cli(cli, "size", f["dense"], "-o", f["sized"])
    run_cli(cli, "simplify", f["sized"], "-o", f["simplified"], "--report", f["report"])
    return f


def assert_same_grid(a: abgs.Grid, b: abgs.Grid) -> None:
    """Same vertices, triangles and sizes, bit for bit."""
    np.testing.assert_array_equal(a.vertices, b.vertices)
    np.testing.assert_array_equal(a.triangles, b.triangles)
    np.testing.assert_array_equal(a.sizes, b.sizes)


def test_dense_grid_and_sizes_equal_cli(cli_run: dict[str, Path], dense: abgs.Grid) -> None:
    """remesh + compute_sizes from Python == `abgs grid` + `abgs size`."""
    cli_dense = abgs.Grid.load(cli_run["dense"])
    np.testing.assert_array_equal(dense.vertices, cli_dense.vertices)
    np.testing.assert_array_equal(dense.triangles, cli_dense.triangles)
    assert_same_grid(dense, abgs.Grid.load(cli_run["sized"]))


def test_simplify_equals_cli(cli_run: dict[str, Path], coarse: abgs.Grid) -> None:
    """simplify from Python (on the in-memory grid) == `abgs simplify` (on its file),
    with the same per-iteration table."""
    assert_same_grid(coarse, abgs.Grid.load(cli_run["simplified"]))
    rep = json.loads(cli_run["report"].read_text())["report"]
    assert coarse.simplify_report is not None
    assert coarse.simplify_report.faces_out == rep["faces_out"]
    assert coarse.simplify_report.element_count_in == rep["element_count_in"]
    assert rep["stop"] == "converged" and coarse.simplify_report.stop == abgs.STOP_CONVERGED
    mine = [r.as_dict() for r in coarse.iterations()]
    assert len(mine) == len(rep["iterations"]) > 1
    for a, b in zip(mine, rep["iterations"]):
        for k in ("iteration", "faces", "vertices", "candidates", "estimated", "collapsible", "accepted"):
            assert a[k] == b[k], k
        assert a["element_count"] == b["element_count"]


def test_evaluate_equals_cli(cli: Path, cli_run: dict[str, Path], dense: abgs.Grid, coarse: abgs.Grid) -> None:
    """abgs.evaluate == `abgs eval --json` on the same pair of grids."""
    out = run_cli(
        cli, "eval", "--reference", cli_run["sized"], "--candidate", cli_run["simplified"],
        "--json", "--samples", 20000, "--hausdorff-samples", 20000, "--seed", 3,
    )
    want = json.loads(out)
    e = abgs.evaluate(dense, coarse, samples=20000, hausdorff_samples=20000, seed=3)
    for k in ("faces_reference", "faces_candidate", "reduction", "hausdorff", "hausdorff_relative",
              "element_count_reference", "element_count_candidate", "wrong_sheet", "elements_per_cell"):
        assert getattr(e, k) == want[k], k
    sd = want["size_deviation"]
    assert (e.size_deviation_mean, e.size_deviation_p95, e.size_deviation_p99, e.size_deviation_max) == (
        sd["mean"], sd["p95"], sd["p99"], sd["max"])
    assert e.size_deviation_samples == sd["samples"] == 20000
    assert e.angles_candidate.min == want["angles_candidate"]["min"]
    assert 1.0 <= e.size_deviation_p95 < 1.3 and e.reduction > 0.5


@pytest.mark.parametrize("mode", ["surface", "volume"])
def test_queries_equal_cli(cli: Path, cli_run: dict[str, Path], coarse: abgs.Grid, points: np.ndarray,
                           tmp_path: Path, mode: str) -> None:
    """sizes_at / sizes_at_volume == `abgs query` on the same grid and points."""
    pts = tmp_path / "points.txt"
    np.savetxt(pts, points, fmt="%.17g")
    out = run_cli(cli, "query", cli_run["simplified"], "--points", pts, "--mode", mode, "--beta", 1.3)
    want = np.array([float(x) for x in out.split()])
    got = coarse.sizes_at(points) if mode == "surface" else coarse.sizes_at_volume(points, 1.3)
    np.testing.assert_array_equal(got, want)
