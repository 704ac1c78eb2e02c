"""Bad input raises an AbgsError with the library's status (number and name)
and message, and never crashes the process."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest

import abgs
from abgs import errors as E

TETRA_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
TETRA_T = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.uint32)


def raises(status: int, fn: Callable[[], Any], cls: type = abgs.AbgsError) -> abgs.AbgsError:
    """Runs fn, checks it raised ``cls`` with ``status``, its name and a message."""
    with pytest.raises(cls) as info:
        fn()
    e = info.value
    assert e.status == status, (e.status, e.message)
    assert e.name == abgs.status_name(status) and e.name.startswith("ABGS_ERR_")
    assert e.message, "empty message"
    assert e.name in str(e) and e.message in str(e)
    return e


def tetra(**kw: Any) -> abgs.Grid:
    """A unit tetrahedron, with sizes 0.5 unless given."""
    return abgs.Grid.from_arrays(TETRA_V, TETRA_T, kw.get("sizes", np.full(4, 0.5)))


def test_status_names_and_descriptions() -> None:
    """Names and descriptions come from the library, numbers are the header's."""
    assert abgs.status_name(E.ERR_BUSY) == "ABGS_ERR_BUSY"
    assert abgs.status_name(0) == "ABGS_OK"
    assert abgs.status_name(12345) == "ABGS_UNKNOWN_STATUS"
    assert abgs.status_description(E.ERR_NULL) == "A required pointer is NULL."


def test_load_errors(tmp_path: Path) -> None:
    """Missing file: IO; unknown extension: UNSUPPORTED_FORMAT; garbage: PARSE."""
    e = raises(E.ERR_IO, lambda: abgs.Grid.load(tmp_path / "missing.stl"), abgs.IoError)
    assert "missing.stl" in e.message and isinstance(e, OSError)
    (tmp_path / "a.xyz").write_text("1 2 3\n")
    raises(E.ERR_UNSUPPORTED_FORMAT, lambda: abgs.Grid.load(tmp_path / "a.xyz"))
    (tmp_path / "bad.off").write_text("OFF\n3 1 0\n0 0 0\n1 0 zero\n0 1 0\n3 0 1 2\n")
    raises(E.ERR_PARSE, lambda: abgs.Grid.load(tmp_path / "bad.off"), abgs.ParseError)


def test_from_arrays_errors() -> None:
    """Each fault of the arrays gets its own status."""
    v = TETRA_V.copy()
    v[2, 1] = math.nan
    raises(E.ERR_NON_FINITE, lambda: abgs.Grid.from_arrays(v, TETRA_T), abgs.NonFiniteError)
    bad = TETRA_T.copy()
    bad[1, 2] = 4
    e = raises(E.ERR_OUT_OF_RANGE, lambda: abgs.Grid.from_arrays(TETRA_V, bad), abgs.OutOfRangeError)
    assert isinstance(e, IndexError)
    # Negative and too large indices would wrap in uint32: refused before C.
    raises(E.ERR_OUT_OF_RANGE, lambda: abgs.Grid.from_arrays(TETRA_V, TETRA_T.astype(np.int64) - 1))
    raises(E.ERR_OUT_OF_RANGE, lambda: abgs.Grid.from_arrays(TETRA_V, TETRA_T.astype(np.int64) + 2**32))
    raises(E.ERR_INVALID_ARGUMENT, lambda: abgs.Grid.from_arrays(TETRA_V, TETRA_T.astype(float)), ValueError)
    raises(E.ERR_INVALID_ARGUMENT, lambda: abgs.Grid.from_arrays(TETRA_V[:, :2], TETRA_T))
    raises(E.ERR_INVALID_ARGUMENT, lambda: abgs.Grid.from_arrays([["a", "b", "c"]], TETRA_T))
    raises(E.ERR_INVALID_SIZE, lambda: tetra(sizes=[0.5, 0.5, -1.0, 0.5]), abgs.InvalidSizeError)
    raises(E.ERR_INVALID_ARGUMENT, lambda: tetra(sizes=[0.5, 0.5]))
    raises(E.ERR_EMPTY, lambda: abgs.Grid.from_arrays(TETRA_V, np.zeros((0, 3), np.uint32)))
    raises(E.ERR_EMPTY, lambda: abgs.Grid.from_arrays(TETRA_V, [[0, 1, 1]]))  # degenerate only


def test_query_and_size_errors() -> None:
    """No sizes, NaN points, wrong counts, bad shapes."""
    g = abgs.Grid.from_arrays(TETRA_V, TETRA_T)
    raises(E.ERR_NO_SIZES, lambda: g.size_at([0, 0, 0]), abgs.NoSizesError)
    raises(E.ERR_NO_SIZES, lambda: g.sizes)
    assert math.isnan(g.closest([2, 2, 2]).size)  # closest works without sizes
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.set_sizes([1.0, 2.0, 3.0]))
    raises(E.ERR_INVALID_SIZE, lambda: g.set_sizes([1.0, 2.0, math.inf, 1.0]))
    g.set_sizes([1.0, 2.0, 3.0, 4.0])
    raises(E.ERR_NON_FINITE, lambda: g.size_at([0, math.nan, 0]))
    raises(E.ERR_NON_FINITE, lambda: g.sizes_at([[0, 0, 0], [0, 0, math.inf]]))
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.sizes_at([0, 0, 0]))
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.size_at([0, 0]))
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.size_at_volume([0, 0, 0], beta=0.5))
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.feature_edges)  # not a remeshed grid
    raises(E.ERR_IO, lambda: g.save("/nonexistent-dir/x.vtk"))
    raises(E.ERR_UNSUPPORTED_FORMAT, lambda: g.save("x.unknown"))


def test_parameter_errors() -> None:
    """Parameters checked by the library (and integers checked before C)."""
    g = tetra()
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.simplify(fraction=0.0))
    raises(E.ERR_NON_FINITE, lambda: g.simplify(t_size=math.nan))
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.simplify(method="qem"))
    e = raises(E.ERR_INVALID_ARGUMENT, lambda: g.simplify(method=7))
    assert "method" in e.message
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.simplify(selection="lazy"))
    e = raises(E.ERR_INVALID_ARGUMENT, lambda: g.simplify(selection=2))
    assert "selection" in e.message
    e = raises(E.ERR_INVALID_ARGUMENT, lambda: g.simplify(fit_sizes=2))
    assert "fit_sizes" in e.message
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.simplify(max_iterations=-1))
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.simplify(max_iterations=2.5))
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.remesh(iterations=0))
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.remesh(feature_angle_deg=200.0))
    raises(E.ERR_NON_FINITE, lambda: g.remesh(edge_length=math.inf))
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.remesh(piece_faces=-1.0))
    raises(E.ERR_NON_FINITE, lambda: g.remesh(piece_faces=math.inf))
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.compute_sizes(beta=0.9))
    raises(E.ERR_INVALID_SIZE, lambda: g.compute_sizes(sources=[abgs.point_source([0, 0, 0], -1.0, 1.0)]))
    raises(E.ERR_INVALID_ARGUMENT, lambda: abgs.evaluate(g, g, samples=0))
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.edge_scores(nonsense=1))
    nosizes = abgs.Grid.from_arrays(TETRA_V, TETRA_T)
    raises(E.ERR_NO_SIZES, lambda: nosizes.simplify())
    raises(E.ERR_NO_SIZES, lambda: g.remesh(sizing=nosizes))


def test_closed_grid() -> None:
    """A closed grid refuses every call (no use after free); close is idempotent."""
    g = tetra()
    g.close()
    g.close()
    assert g.closed and repr(g) == "Grid(closed)"
    raises(E.ERR_INVALID_ARGUMENT, lambda: g.size_at([0, 0, 0]))
    with tetra() as h:
        assert h.size_at([0.1, 0.1, 0.1]) == 0.5
    assert h.closed


def test_constructor_is_private() -> None:
    """Grid(...) with a raw pointer is refused."""
    with pytest.raises(TypeError):
        abgs.Grid(12345)
