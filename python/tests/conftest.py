"""Shared fixtures: the repository, the shared models, the CLI, small grids.

Models are read from ``../shared/meshes`` beside the repository (never copied).
The CLI is ``target/release/abgs`` of the repository (``ABGS_CLI`` may name
another); the tests that compare with it are skipped, saying so, when it is
missing (``cargo build --release -p abgs-cli`` builds it; python/ci.sh does).
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import abgs

REPO = Path(__file__).resolve().parents[2]
MESHES = REPO.parent / "shared" / "meshes"
#: The small shared model every test uses (a STEP and its STL).
MODEL = MESHES / "gmsh_t20_component8.stl"
#: Coarse dense grid, so that the whole suite stays quick.
RELATIVE = 0.03


def cli_path() -> Path | None:
    """The abgs CLI to compare with, or None."""
    env = os.environ.get("ABGS_CLI")
    if env:
        return Path(env) if Path(env).is_file() else None
    p = REPO / "target" / "release" / "abgs"
    return p if p.is_file() else (Path(shutil.which("abgs")) if shutil.which("abgs") else None)


@pytest.fixture(scope="session")
def cli() -> Path:
    """Path of the CLI (the test is skipped without it)."""
    p = cli_path()
    if p is None:
        pytest.skip("abgs CLI not built (cargo build --release -p abgs-cli)")
    return p


def run_cli(cli: Path, *args: object) -> str:
    """Runs the CLI, fails the test with its stderr when it fails, returns stdout."""
    r = subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, f"abgs {' '.join(map(str, args))} failed:\n{r.stderr}"
    return r.stdout


@pytest.fixture(scope="session")
def surface() -> abgs.Grid:
    """The shared model's STL as loaded."""
    assert MODEL.is_file(), f"missing shared model {MODEL}"
    return abgs.Grid.load(MODEL)


@pytest.fixture(scope="session")
def dense(surface: abgs.Grid) -> abgs.Grid:
    """Its dense grid (relative length RELATIVE) with default sizes."""
    g = surface.remesh(relative_length=RELATIVE)
    g.compute_sizes()
    return g


@pytest.fixture(scope="session")
def coarse(dense: abgs.Grid) -> abgs.Grid:
    """The dense grid simplified by LBO-ABGS with the defaults."""
    return dense.simplify()


@pytest.fixture(scope="session")
def points(dense: abgs.Grid) -> np.ndarray:
    """2 000 query points: near the surface and all over the bounding box (fixed seed)."""
    rng = np.random.default_rng(7)
    s = dense.stats
    lo, hi = np.array(s.bbox_min), np.array(s.bbox_max)
    box = lo + (hi - lo) * rng.random((1000, 3))
    v = dense.vertices
    near = v[rng.integers(0, len(v), 1000)] + rng.normal(scale=0.01 * s.diagonal, size=(1000, 3))
    return np.vstack([near, box])
