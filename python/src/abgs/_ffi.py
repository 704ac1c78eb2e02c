"""The C ABI of libabgs (``include/abgs.h``) as ctypes declarations.

One ctypes ``Structure`` per header struct, field for field in the header's
order, and one prototype per function. ``tests/test_abi.py`` compiles a C
program against the header and checks every size and offset here against it.

The library is the ``libabgs.so`` shipped inside this package (built by cargo
when the wheel was built); the environment variable ``ABGS_LIBRARY`` may name
another build of it (a path to the shared library), e.g. for development.
"""

from __future__ import annotations

import ctypes
import os
import sys
from ctypes import (
    CFUNCTYPE,
    POINTER,
    c_char,
    c_char_p,
    c_double,
    c_int,
    c_int32,
    c_size_t,
    c_uint8,
    c_uint32,
    c_uint64,
    c_void_p,
)
from pathlib import Path
from typing import Any

# --- constants (the header's #defines) -------------------------------------

#: Value of a hint that names no triangle.
NO_HINT = 0xFFFFFFFF
#: ``method``: LBO-ABGS, the procedural simplifier.
METHOD_LBO = 0
#: ``method``: GCN-ABGS, the learned simplifier.
METHOD_GCN = 1
#: ``selection``: the whole pool estimated, then the lowest scores (the paper's).
SELECTION_GLOBAL = 0
#: ``selection``: the pool in batches, estimating only edges still free (default).
SELECTION_BATCHED = 1
#: ``stop``: nothing could be selected any more.
STOP_CONVERGED = 0
#: ``stop``: ``max_iterations`` reached.
STOP_MAX_ITERATIONS = 1
#: ``stop``: the progress callback asked to stop.
STOP_CANCELLED = 2
#: Source kind: a point.
SOURCE_POINT = 0
#: Source kind: a segment.
SOURCE_SEGMENT = 1
#: Source kind: a triangle.
SOURCE_TRIANGLE = 2


class _Struct(ctypes.Structure):
    """Base of the ABI's structs: ``struct_size`` first, set to ``sizeof`` on creation."""

    def __init__(self, **fields: Any) -> None:
        """Zero-fills the struct, sets ``struct_size`` (the header's growth rule), then ``fields``."""
        super().__init__()
        if self._fields_ and self._fields_[0][0] == "struct_size":
            self.struct_size = ctypes.sizeof(self)
        for k, v in fields.items():
            setattr(self, k, v)

    def as_dict(self) -> dict[str, Any]:
        """The fields as plain Python values (nested structs as dicts, arrays as
        lists), ``struct_size`` and pointers left out; only fields the library
        filled (below ``struct_size``) are read."""
        out: dict[str, Any] = {}
        limit = getattr(self, "struct_size", ctypes.sizeof(self))
        for name, ctype in self._fields_:
            if name == "struct_size" or name.startswith("_"):
                continue
            if getattr(type(self), name).offset + ctypes.sizeof(ctype) > limit:
                continue
            v = getattr(self, name)
            if isinstance(v, _PlainStruct):
                v = v.as_dict()
            elif isinstance(v, ctypes.Array):
                v = list(v)
            elif isinstance(v, (ctypes._Pointer, ctypes._CFuncPtr)) or ctype is c_void_p:
                continue
            out[name] = v
        return out

    def __repr__(self) -> str:
        """``Name(field=value, ...)`` over ``as_dict``."""
        inner = ", ".join(f"{k}={v!r}" for k, v in self.as_dict().items())
        return f"{type(self).__name__}({inner})"


class _PlainStruct(ctypes.Structure):
    """Base of the ABI's structs that have no ``struct_size`` (nested values)."""

    def as_dict(self) -> dict[str, Any]:
        """The fields as plain Python values."""
        return {name: getattr(self, name) for name, _ in self._fields_}

    def __repr__(self) -> str:
        """``Name(field=value, ...)``."""
        inner = ", ".join(f"{k}={v!r}" for k, v in self.as_dict().items())
        return f"{type(self).__name__}({inner})"


class GridStats(_Struct):
    """Counts, validation findings and extent of a grid (``abgs_grid_stats``).

    Fields: ``vertices``, ``triangles``, ``edges``, ``bodies``,
    ``boundary_edges``, ``non_manifold_edges``, ``non_manifold_vertices``,
    ``input_triangles``, ``dropped_triangles`` (repeated corner or zero area),
    ``welded_vertices``, ``flipped_triangles``, ``has_sizes`` (1 or 0),
    ``size_min`` / ``size_max`` (0 without sizes), ``bbox_min`` / ``bbox_max``
    (3 doubles each), ``diagonal``, ``memory_bytes``.
    """

    _fields_ = [
        ("struct_size", c_uint32),
        ("vertices", c_uint64),
        ("triangles", c_uint64),
        ("edges", c_uint64),
        ("bodies", c_uint64),
        ("boundary_edges", c_uint64),
        ("non_manifold_edges", c_uint64),
        ("non_manifold_vertices", c_uint64),
        ("input_triangles", c_uint64),
        ("dropped_triangles", c_uint64),
        ("welded_vertices", c_uint64),
        ("flipped_triangles", c_uint64),
        ("has_sizes", c_int32),
        ("size_min", c_double),
        ("size_max", c_double),
        ("bbox_min", c_double * 3),
        ("bbox_max", c_double * 3),
        ("diagonal", c_double),
        ("memory_bytes", c_uint64),
    ]


class EvalParams(_Struct):
    """Parameters of ``abgs_evaluate``: ``samples`` (size-deviation points),
    ``hausdorff_samples`` (per surface), ``seed``."""

    _fields_ = [
        ("struct_size", c_uint32),
        ("samples", c_uint64),
        ("hausdorff_samples", c_uint64),
        ("seed", c_uint64),
    ]


class AngleStats(_PlainStruct):
    """Smallest and largest angle per face, in degrees (``abgs_angle_stats``):
    ``min``, ``min_p1``, ``min_p5``, ``max_p99``, ``max``, ``mean_min``."""

    _fields_ = [
        ("min", c_double),
        ("min_p1", c_double),
        ("min_p5", c_double),
        ("max_p99", c_double),
        ("max", c_double),
        ("mean_min", c_double),
    ]


class ContactAgreement(_PlainStruct):
    """Where bodies touch, how far their sizes differ (``abgs_contact_agreement``):
    ``share`` (of the reference surface lying on two bodies), ``samples``,
    ``p50``, ``p95``, ``max`` (of ``max h / min h − 1``) and ``over_10`` (share
    of the contact samples above 10 %)."""

    _fields_ = [
        ("share", c_double),
        ("samples", c_uint64),
        ("p50", c_double),
        ("p95", c_double),
        ("max", c_double),
        ("over_10", c_double),
    ]


class Evaluation(_Struct):
    """A candidate grid measured against its reference (``abgs_evaluation``).

    Fields: ``faces_reference``, ``faces_candidate``, ``vertices_reference``,
    ``vertices_candidate``, ``reduction`` (1 − faces ratio), the size ratio
    ``max(h_c/h_r, h_r/h_c)`` at uniform samples on the reference
    (``size_deviation_mean``, ``_p95``, ``_p99``, ``_max``, ``_samples``),
    ``hausdorff`` (symmetric, model units), ``hausdorff_relative`` (over the
    ``diagonal``), estimated element counts ``(4/√3)∫h⁻²dA``
    (``element_count_reference``, ``element_count_candidate``,
    ``element_count_change``), ``angles_reference`` / ``angles_candidate``
    (``AngleStats``), ``seconds``, ``wrong_sheet`` (share of samples answered
    from another body or a face turned away), ``elements_per_cell``,
    ``elements_per_cell_reference``, and ``contact_reference`` /
    ``contact_candidate`` (``ContactAgreement``: where bodies touch).
    """

    _fields_ = [
        ("struct_size", c_uint32),
        ("faces_reference", c_uint64),
        ("faces_candidate", c_uint64),
        ("vertices_reference", c_uint64),
        ("vertices_candidate", c_uint64),
        ("reduction", c_double),
        ("size_deviation_mean", c_double),
        ("size_deviation_p95", c_double),
        ("size_deviation_max", c_double),
        ("size_deviation_samples", c_uint64),
        ("hausdorff", c_double),
        ("hausdorff_relative", c_double),
        ("diagonal", c_double),
        ("element_count_reference", c_double),
        ("element_count_candidate", c_double),
        ("element_count_change", c_double),
        ("angles_reference", AngleStats),
        ("angles_candidate", AngleStats),
        ("seconds", c_double),
        ("size_deviation_p99", c_double),
        ("wrong_sheet", c_double),
        ("elements_per_cell", c_double),
        ("elements_per_cell_reference", c_double),
        ("contact_reference", ContactAgreement),
        ("contact_candidate", ContactAgreement),
    ]


class Hit(_Struct):
    """Answer of a closest-point query (``abgs_hit``): ``triangle``, ``bary``
    (3 barycentric coordinates), ``point`` (the closest point), ``distance``,
    ``size`` (NaN when the grid has no sizes)."""

    _fields_ = [
        ("struct_size", c_uint32),
        ("triangle", c_uint32),
        ("bary", c_double * 3),
        ("point", c_double * 3),
        ("distance", c_double),
        ("size", c_double),
    ]


class RemeshParams(_Struct):
    """Parameters of ``abgs_grid_remesh`` (see ``Grid.remesh``)."""

    _fields_ = [
        ("struct_size", c_uint32),
        ("edge_length", c_double),
        ("relative_length", c_double),
        ("feature_angle_deg", c_double),
        ("iterations", c_uint32),
        ("curvature_limit", c_int32),
        ("n_circle", c_double),
        ("piece_faces", c_double),
    ]


class RemeshReport(_Struct):
    """What ``abgs_grid_remesh`` did: ``vertices_in``, ``faces_in``,
    ``vertices_out``, ``faces_out``, ``target_length`` (NaN when size-driven),
    ``target_min``, ``target_max``, ``feature_edges_in``, ``feature_edges_out``,
    ``feature_lines``, ``corners``, ``iterations``, ``seconds``, ``n_issues``,
    ``pieces`` (large bodies cut into pieces; 0 when none was)."""

    _fields_ = [
        ("struct_size", c_uint32),
        ("vertices_in", c_uint64),
        ("faces_in", c_uint64),
        ("vertices_out", c_uint64),
        ("faces_out", c_uint64),
        ("target_length", c_double),
        ("target_min", c_double),
        ("target_max", c_double),
        ("feature_edges_in", c_uint64),
        ("feature_edges_out", c_uint64),
        ("feature_lines", c_uint64),
        ("corners", c_uint64),
        ("iterations", c_uint64),
        ("seconds", c_double),
        ("n_issues", c_uint64),
        ("pieces", c_uint64),
    ]


class IterationRecord(_Struct):
    """What one simplification iteration did (``abgs_iteration_record``):
    ``iteration`` (from 1), ``faces``, ``vertices``, ``candidates``,
    ``estimated``, ``collapsible``, ``accepted``, ``moved``, ``flips``,
    ``element_count`` (of the grid's own field), ``seconds``."""

    _fields_ = [
        ("struct_size", c_uint32),
        ("iteration", c_uint64),
        ("faces", c_uint64),
        ("vertices", c_uint64),
        ("candidates", c_uint64),
        ("estimated", c_uint64),
        ("collapsible", c_uint64),
        ("accepted", c_uint64),
        ("moved", c_uint64),
        ("flips", c_uint64),
        ("element_count", c_double),
        ("seconds", c_double),
    ]


#: ``abgs_progress_fn``: ``int32_t (*)(const abgs_iteration_record *, void *)``.
PROGRESS_FN = CFUNCTYPE(c_int32, POINTER(IterationRecord), c_void_p)


class SimplifyParams(_Struct):
    """Parameters of ``abgs_simplify`` (see ``Grid.simplify``)."""

    _fields_ = [
        ("struct_size", c_uint32),
        ("method", c_uint32),
        ("fraction", c_double),
        ("pool_factor", c_double),
        ("t_size", c_double),
        ("tau_d", c_double),
        ("max_distance", c_double),
        ("max_iterations", c_uint32),
        ("feature_angle_deg", c_double),
        ("corner_angle_deg", c_double),
        ("max_normal_turn_deg", c_double),
        ("max_angle_deg", c_double),
        ("repair", c_int32),
        ("progress", PROGRESS_FN),
        ("user_data", c_void_p),
        ("beta", c_double),
        ("clearance_fraction", c_double),
        ("t_score", c_double),
        ("verify", c_uint32),
        ("t_contact", c_double),
        ("selection", c_uint32),
        ("fit_sizes", c_uint32),
    ]


class SimplifyReport(_Struct):
    """What ``abgs_simplify`` did: ``faces_in``, ``vertices_in``,
    ``faces_out``, ``vertices_out``, ``iterations``, ``stop``
    (``STOP_CONVERGED``, ``STOP_MAX_ITERATIONS`` or ``STOP_CANCELLED``),
    ``feature_lines``, ``corners``, ``element_count_in``,
    ``element_count_out``, ``seconds``."""

    _fields_ = [
        ("struct_size", c_uint32),
        ("faces_in", c_uint64),
        ("vertices_in", c_uint64),
        ("faces_out", c_uint64),
        ("vertices_out", c_uint64),
        ("iterations", c_uint64),
        ("stop", c_uint32),
        ("feature_lines", c_uint64),
        ("corners", c_uint64),
        ("element_count_in", c_double),
        ("element_count_out", c_double),
        ("seconds", c_double),
    ]


class SizeSource(_Struct):
    """A user size source (``abgs_size_source``): ``kind`` (``SOURCE_*``),
    ``points`` (up to 3 points, 9 doubles), ``size``, ``radius``."""

    _fields_ = [
        ("struct_size", c_uint32),
        ("kind", c_uint32),
        ("points", c_double * 9),
        ("size", c_double),
        ("radius", c_double),
    ]


class SizeParams(_Struct):
    """Parameters of ``abgs_compute_size`` (see ``Grid.compute_sizes``)."""

    _fields_ = [
        ("struct_size", c_uint32),
        ("n_circle", c_double),
        ("n_gap", c_double),
        ("hmin", c_double),
        ("hmax", c_double),
        ("feature_angle_deg", c_double),
        ("feature_size", c_double),
        ("beta", c_double),
        ("slope", c_double),
        ("curvature", c_int32),
        ("proximity", c_int32),
        ("gradation", c_int32),
        ("contact_gap", c_double),
        ("sources", POINTER(SizeSource)),
        ("n_sources", c_size_t),
    ]


class SizeReport(_Struct):
    """What ``abgs_compute_size`` did: ``hmin``, ``hmax``, ``slope`` used,
    ``feature_edges``, ``patches``, vertex counts ``limited_by_curvature``,
    ``limited_by_proximity``, ``limited_by_feature``, ``limited_by_source``,
    ``clamped_to_hmin``, ``at_hmax``, ``faces_fixed``, ``max_slope_ratio``,
    seconds per stage (``seconds_features``, ``seconds_curvature``,
    ``seconds_proximity``, ``seconds_gradation``, ``seconds_contacts``) and
    ``contact_vertices``."""

    _fields_ = [
        ("struct_size", c_uint32),
        ("hmin", c_double),
        ("hmax", c_double),
        ("slope", c_double),
        ("feature_edges", c_uint64),
        ("patches", c_uint64),
        ("limited_by_curvature", c_uint64),
        ("limited_by_proximity", c_uint64),
        ("limited_by_feature", c_uint64),
        ("limited_by_source", c_uint64),
        ("clamped_to_hmin", c_uint64),
        ("at_hmax", c_uint64),
        ("faces_fixed", c_uint64),
        ("max_slope_ratio", c_double),
        ("seconds_features", c_double),
        ("seconds_curvature", c_double),
        ("seconds_proximity", c_double),
        ("seconds_gradation", c_double),
        ("contact_vertices", c_uint64),
        ("seconds_contacts", c_double),
    ]


#: Every struct of the header, by its C name (used by the ABI test).
STRUCTS: dict[str, type[ctypes.Structure]] = {
    "abgs_grid_stats": GridStats,
    "abgs_eval_params": EvalParams,
    "abgs_angle_stats": AngleStats,
    "abgs_contact_agreement": ContactAgreement,
    "abgs_evaluation": Evaluation,
    "abgs_hit": Hit,
    "abgs_remesh_params": RemeshParams,
    "abgs_remesh_report": RemeshReport,
    "abgs_iteration_record": IterationRecord,
    "abgs_simplify_params": SimplifyParams,
    "abgs_simplify_report": SimplifyReport,
    "abgs_size_source": SizeSource,
    "abgs_size_params": SizeParams,
    "abgs_size_report": SizeReport,
}

# --- the library -------------------------------------------------------------

_GRID = c_void_p  # abgs_grid * (opaque)
_PD = POINTER(c_double)
_PU32 = POINTER(c_uint32)
_PSZ = POINTER(c_size_t)

#: name -> (argument types); every function returns abgs_status (int) unless
#: listed in _RESTYPES.
_PROTOTYPES: dict[str, list[Any]] = {
    "abgs_last_error_message": [],
    "abgs_status_name": [c_int],
    "abgs_status_description": [c_int],
    "abgs_version": [],
    "abgs_version_number": [],
    "abgs_grid_from_arrays": [_PD, c_size_t, _PU32, c_size_t, _PD, POINTER(_GRID)],
    "abgs_grid_load": [c_char_p, POINTER(_GRID)],
    "abgs_grid_save": [_GRID, c_char_p],
    "abgs_grid_set_sizes": [_GRID, _PD, c_size_t],
    "abgs_grid_get_stats": [_GRID, POINTER(GridStats)],
    "abgs_grid_vertex_count": [_GRID, _PSZ],
    "abgs_grid_triangle_count": [_GRID, _PSZ],
    "abgs_grid_copy_vertices": [_GRID, _PD, c_size_t],
    "abgs_grid_copy_triangles": [_GRID, _PU32, c_size_t],
    "abgs_grid_copy_sizes": [_GRID, _PD, c_size_t],
    "abgs_grid_free": [_GRID],
    "abgs_grid_serialize": [_GRID, c_void_p, c_size_t, _PSZ],
    "abgs_grid_deserialize": [c_void_p, c_size_t, POINTER(_GRID)],
    "abgs_eval_params_default": [POINTER(EvalParams)],
    "abgs_evaluate": [_GRID, _GRID, POINTER(EvalParams), POINTER(Evaluation)],
    "abgs_hausdorff": [_GRID, _GRID, c_uint64, c_uint64, _PD],
    "abgs_hausdorff_directed": [_GRID, _GRID, c_uint64, c_uint64, _PD],
    "abgs_query_size": [_GRID, _PD, _PD],
    "abgs_query_size_hinted": [_GRID, _PD, _PU32, _PD],
    "abgs_query_sizes": [_GRID, _PD, c_size_t, _PD],
    "abgs_query_size_volume": [_GRID, _PD, c_double, _PD],
    "abgs_query_sizes_volume": [_GRID, _PD, c_size_t, c_double, _PD],
    "abgs_query_closest": [_GRID, _PD, c_uint32, POINTER(Hit)],
    "abgs_remesh_params_default": [POINTER(RemeshParams)],
    "abgs_grid_remesh": [_GRID, _GRID, POINTER(RemeshParams), POINTER(_GRID), POINTER(RemeshReport)],
    "abgs_grid_remesh_feature_edge_count": [_GRID, _PSZ],
    "abgs_grid_remesh_copy_feature_edges": [_GRID, _PU32, c_size_t],
    "abgs_grid_remesh_issue": [_GRID, c_size_t, POINTER(c_char), c_size_t, _PSZ],
    "abgs_simplify_params_default": [POINTER(SimplifyParams)],
    "abgs_simplify": [_GRID, POINTER(SimplifyParams), POINTER(_GRID), POINTER(SimplifyReport)],
    "abgs_grid_simplify_iteration": [_GRID, c_size_t, POINTER(IterationRecord)],
    "abgs_edge_scores": [_GRID, POINTER(SimplifyParams), _PD, _PD, POINTER(c_uint8), _PD, c_size_t],
    "abgs_size_params_default": [POINTER(SizeParams)],
    "abgs_compute_size": [_GRID, POINTER(SizeParams), POINTER(SizeReport)],
    "abgs_apply_gradation": [_GRID, c_double, c_double, POINTER(c_uint64)],
    "abgs_grid_edge_count": [_GRID, _PSZ],
    "abgs_grid_copy_edges": [_GRID, _PU32, c_size_t],
    "abgs_lbo": [_GRID, _PD, c_size_t, _PD, c_size_t],
}

_RESTYPES: dict[str, Any] = {
    "abgs_last_error_message": c_char_p,
    "abgs_status_name": c_char_p,
    "abgs_status_description": c_char_p,
    "abgs_version": c_char_p,
    "abgs_version_number": c_uint32,
}


def library_path() -> Path:
    """Path of the shared library this package loads: ``$ABGS_LIBRARY`` if
    set, else the ``libabgs`` shipped beside this file."""
    env = os.environ.get("ABGS_LIBRARY")
    if env:
        return Path(env)
    name = {"darwin": "libabgs.dylib", "win32": "abgs.dll"}.get(sys.platform, "libabgs.so")
    return Path(__file__).with_name(name)


def _load() -> ctypes.CDLL:
    """Loads the library and declares every prototype (ctypes releases the GIL
    during each call: ``CDLL``, not ``PyDLL``)."""
    path = library_path()
    if not path.is_file():
        raise ImportError(
            f"abgs: shared library not found at {path} (set ABGS_LIBRARY, or "
            "reinstall the package: the wheel build runs cargo)"
        )
    lib = ctypes.CDLL(str(path))
    for name, argtypes in _PROTOTYPES.items():
        fn = getattr(lib, name)
        fn.argtypes = argtypes
        fn.restype = _RESTYPES.get(name, c_int)
    return lib


#: The loaded library.
lib = _load()
