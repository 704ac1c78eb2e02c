"""abgs: adaptive background grids for mesh sizing fields, from Python.

A thin layer over the C ABI of libabgs (``include/abgs.h``) through ctypes,
with numpy arrays in and out::

    import abgs
    surface = abgs.Grid.load("part.stl")            # or Grid.from_arrays(V, T)
    dense = surface.remesh(relative_length=0.01)    # the dense background grid
    dense.compute_sizes(hmax=5.0)                   # curvature, proximity, gradation
    coarse = dense.simplify(progress=print)         # LBO-ABGS
    print(abgs.evaluate(dense, coarse).size_deviation_p95)
    h = coarse.sizes_at(points)                     # N×3 -> N sizes, parallel
    coarse.save("field.msh")                        # Gmsh background field

Every failure raises ``AbgsError`` (or a subclass such as
``InvalidArgumentError``) carrying the library's ``status``, its ``name`` and
the ``message`` of ``abgs_last_error_message``.
"""

from __future__ import annotations

from ctypes import byref, c_double
from typing import Any

from . import _convert as cv
from . import errors
from ._ffi import (
    METHOD_GCN,
    METHOD_LBO,
    NO_HINT,
    STOP_CANCELLED,
    STOP_CONVERGED,
    STOP_MAX_ITERATIONS,
    AngleStats,
    ContactAgreement,
    EvalParams,
    Evaluation,
    GridStats,
    Hit,
    IterationRecord,
    RemeshReport,
    SimplifyReport,
    SizeReport,
    SizeSource,
    lib,
    library_path,
)
from .errors import (
    AbgsError,
    BusyError,
    EmptyError,
    InternalError,
    InvalidArgumentError,
    InvalidSizeError,
    IoError,
    NoSizesError,
    NonFiniteError,
    NotAvailableError,
    NullError,
    OutOfRangeError,
    ParseError,
    UnsupportedFormatError,
    check,
    status_description,
    status_name,
)
from .grid import Grid, Hint, point_source, segment_source, triangle_source

__version__ = "0.1.0"


def version() -> str:
    """The loaded library's version, ``"MAJOR.MINOR.PATCH"``."""
    return lib.abgs_version().decode()


def evaluate(
    reference: Grid,
    candidate: Grid,
    *,
    samples: int | None = None,
    hausdorff_samples: int | None = None,
    seed: int | None = None,
) -> Evaluation:
    """Measures ``candidate`` (e.g. a simplified grid) against ``reference``
    (the dense grid it came from): reduction, size deviation
    ``max(h_c/h_r, h_r/h_c)`` (mean, p95, p99, max), wrong-sheet share,
    symmetric Hausdorff distance, estimated element counts and angles — the
    numbers of ``abgs eval``. Both grids need sizes. ``None`` keeps the
    library's defaults (100 000 samples each, seed 1). Parallel,
    deterministic.

    Raises ``InvalidArgumentError`` (a sample count of 0), ``NoSizesError``,
    ``InvalidSizeError``, ``BusyError``.
    """
    p = EvalParams()
    check(lib.abgs_eval_params_default(byref(p)))
    cv.set_fields(p, {"samples": samples, "hausdorff_samples": hausdorff_samples, "seed": seed})
    out = Evaluation()
    _with_both(reference, candidate, lambda r, c: lib.abgs_evaluate(r, c, byref(p), byref(out)))
    return out


def hausdorff(a: Grid, b: Grid, *, samples: int = 100_000, seed: int = 1, directed: bool = False) -> float:
    """Sampled Hausdorff distance between the surfaces of ``a`` and ``b``:
    symmetric, or one-sided from ``a`` to ``b`` when ``directed`` (``samples``
    area-uniform points with ``seed``, plus every vertex, measured exactly).
    Sizes are not needed. Parallel, deterministic."""
    p = EvalParams()
    cv.set_fields(p, {"samples": samples, "seed": seed})
    fn = lib.abgs_hausdorff_directed if directed else lib.abgs_hausdorff
    out = c_double()
    _with_both(a, b, lambda x, y: fn(x, y, p.samples, p.seed, byref(out)))
    return out.value


def _with_both(a: Grid, b: Grid, call: Any) -> None:
    """Runs ``call(handle_a, handle_b)`` with both grids held open, raising on failure."""
    ha = a._acquire()
    try:
        hb = b._acquire()
        try:
            check(call(ha, hb))
        finally:
            b._release()
    finally:
        a._release()


__all__ = [
    "AbgsError",
    "AngleStats",
    "ContactAgreement",
    "BusyError",
    "EmptyError",
    "EvalParams",
    "Evaluation",
    "Grid",
    "GridStats",
    "Hint",
    "Hit",
    "InternalError",
    "InvalidArgumentError",
    "InvalidSizeError",
    "IoError",
    "IterationRecord",
    "METHOD_GCN",
    "METHOD_LBO",
    "NO_HINT",
    "NoSizesError",
    "NonFiniteError",
    "NotAvailableError",
    "NullError",
    "OutOfRangeError",
    "ParseError",
    "RemeshReport",
    "STOP_CANCELLED",
    "STOP_CONVERGED",
    "STOP_MAX_ITERATIONS",
    "SimplifyReport",
    "SizeReport",
    "SizeSource",
    "UnsupportedFormatError",
    "errors",
    "evaluate",
    "hausdorff",
    "library_path",
    "point_source",
    "segment_source",
    "status_description",
    "status_name",
    "triangle_source",
    "version",
]
