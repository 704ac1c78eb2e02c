"""``Grid``: a background grid (triangle surface with one size per vertex).

Wraps the opaque ``abgs_grid`` handle: building it (file, arrays, remeshing,
simplification), computing or setting sizes, size queries (single, hinted,
batch, volume), copies of its arrays as numpy arrays, and saving.

Threads: every call into the library releases the GIL (ctypes), so queries
from several Python threads run in parallel, and the batch queries are
parallel inside the library as well. A mutating call (``set_sizes``,
``compute_sizes``, ``apply_gradation``, ``close``) on a grid in use by another
call raises ``BusyError`` and changes nothing.
"""

from __future__ import annotations

import ctypes
import os
import threading
from collections.abc import Callable, Sequence
from ctypes import byref, c_char, c_double, c_size_t, c_uint8, c_uint32, c_uint64, c_void_p
from typing import Any, Optional, Union

import numpy as np
import numpy.typing as npt

from . import _convert as cv
from ._ffi import (
    METHOD_GCN,
    METHOD_LBO,
    NO_HINT,
    PROGRESS_FN,
    SELECTION_BATCHED,
    SELECTION_GLOBAL,
    SOURCE_POINT,
    SOURCE_SEGMENT,
    SOURCE_TRIANGLE,
    GridStats,
    Hit,
    IterationRecord,
    RemeshParams,
    RemeshReport,
    SimplifyParams,
    SimplifyReport,
    SizeParams,
    SizeReport,
    SizeSource,
    lib,
)
from .errors import ERR_BUSY, ERR_INVALID_ARGUMENT, check, error

#: A path as ``open`` takes it.
PathLike = Union[str, "os.PathLike[str]"]
#: A progress callback: gets each iteration's record; a truthy return stops.
Progress = Callable[[IterationRecord], Optional[bool]]

_METHODS = {"lbo": METHOD_LBO, "gcn": METHOD_GCN}


class Hint:
    """The triangle of the last hinted query, to seed the next one.

    Keep one per coherent stream of points (an advancing front, one per
    thread): the answers equal the unhinted ones bit for bit, only faster.
    """

    __slots__ = ("_value",)

    def __init__(self) -> None:
        """A hint that names no triangle yet."""
        self._value = c_uint32(NO_HINT)

    @property
    def triangle(self) -> int | None:
        """The triangle the last query answered from (``None`` before the first)."""
        v = self._value.value
        return None if v == NO_HINT else v

    def reset(self) -> None:
        """Forgets the triangle (e.g. when the stream of points jumps)."""
        self._value.value = NO_HINT


def point_source(point: npt.ArrayLike, size: float, radius: float) -> SizeSource:
    """A user size source: every vertex within ``radius`` of ``point`` gets at most ``size``."""
    return _source(SOURCE_POINT, [point], size, radius)


def segment_source(a: npt.ArrayLike, b: npt.ArrayLike, size: float, radius: float) -> SizeSource:
    """A user size source along the segment ``a``–``b`` (see ``point_source``)."""
    return _source(SOURCE_SEGMENT, [a, b], size, radius)


def triangle_source(
    a: npt.ArrayLike, b: npt.ArrayLike, c: npt.ArrayLike, size: float, radius: float
) -> SizeSource:
    """A user size source over the triangle ``a b c`` (see ``point_source``)."""
    return _source(SOURCE_TRIANGLE, [a, b, c], size, radius)


def _source(kind: int, points: list[npt.ArrayLike], size: float, radius: float) -> SizeSource:
    """A ``SizeSource`` of ``kind`` through ``points`` (size and radius checked by the library)."""
    s = SizeSource(kind=kind)
    for i, p in enumerate(points):
        s.points[3 * i : 3 * i + 3] = cv.float_array(p, f"source point {i}", (3,)).tolist()
    cv.set_fields(s, {"size": size, "radius": radius})
    return s


def _defaults(struct_cls: type, default_fn: Any, values: dict[str, Any]) -> Any:
    """A ``struct_cls`` filled with the library's defaults (``default_fn``),
    then the non-``None`` entries of ``values`` that name its fields."""
    p = struct_cls()
    check(default_fn(byref(p)))
    names = {n for n, _ in struct_cls._fields_}
    cv.set_fields(p, {k: v for k, v in values.items() if k in names})
    return p


class Grid:
    """A background grid: triangles over a surface, with one size per vertex.

    Make one with ``Grid.load``, ``Grid.from_arrays``, ``Grid.remesh`` or
    ``Grid.simplify``; release it with ``close`` (or a ``with`` block; the
    garbage collector frees it too).
    """

    def __init__(self, handle: int, *, _token: object = None) -> None:
        """Takes ownership of ``handle`` (an ``abgs_grid *``); not for direct use."""
        if _token is not _PRIVATE:
            raise TypeError("use Grid.load, Grid.from_arrays, Grid.remesh or Grid.simplify")
        self._ptr: int | None = handle
        self._lock = threading.Lock()
        self._uses = 0
        #: What ``remesh`` did (on grids it made), else ``None``.
        self.remesh_report: RemeshReport | None = None
        #: What ``simplify`` did (on grids it made), else ``None``.
        self.simplify_report: SimplifyReport | None = None

    # --- lifetime -----------------------------------------------------------

    def _acquire(self) -> int:
        """The handle, counted as in use until ``_release`` (``close`` waits for none)."""
        with self._lock:
            if self._ptr is None:
                raise error(ERR_INVALID_ARGUMENT, "the grid was closed")
            self._uses += 1
            return self._ptr

    def _release(self) -> None:
        """Ends one use begun by ``_acquire``."""
        with self._lock:
            self._uses -= 1

    def _call(self, fn: Any, *args: Any) -> None:
        """Calls ``fn(handle, *args)`` and raises on a non-OK status."""
        h = self._acquire()
        try:
            check(fn(h, *args))
        finally:
            self._release()

    def close(self) -> None:
        """Frees the grid (idempotent). Raises ``BusyError`` while another
        thread is using it (nothing is freed then)."""
        with self._lock:
            if self._ptr is None:
                return
            if self._uses:
                raise error(ERR_BUSY, "the grid is in use by another call (close refused)")
            check(lib.abgs_grid_free(self._ptr))
            self._ptr = None

    @property
    def closed(self) -> bool:
        """True once ``close`` freed the grid."""
        return self._ptr is None

    def __enter__(self) -> Grid:
        """Returns the grid itself."""
        return self

    def __exit__(self, *exc: object) -> None:
        """Closes the grid."""
        self.close()

    def __del__(self) -> None:
        """Frees the grid if it is still open (errors are ignored here)."""
        ptr = getattr(self, "_ptr", None)
        if ptr is not None and lib is not None:
            lib.abgs_grid_free(ptr)
            self._ptr = None

    def __repr__(self) -> str:
        """``Grid(V vertices, F triangles, sizes|no sizes)``."""
        if self._ptr is None:
            return "Grid(closed)"
        s = self.stats
        return f"Grid({s.vertices} vertices, {s.triangles} triangles, {'sizes' if s.has_sizes else 'no sizes'})"

    # --- construction -------------------------------------------------------

    @classmethod
    def load(cls, path: PathLike) -> Grid:
        """Loads a grid from a file, format by extension (stl, obj, off, ply,
        msh, vtk, vtu, mesh); a per-vertex array named ``size`` becomes the
        sizes. STL is welded (1e-7 of the diagonal).

        Raises ``IoError``, ``ParseError``, ``UnsupportedFormatError``,
        ``NonFiniteError``, ``OutOfRangeError``, ``InvalidSizeError`` or ``EmptyError``.
        """
        out = c_void_p()
        check(lib.abgs_grid_load(os.fsencode(path), byref(out)))
        return cls(out.value, _token=_PRIVATE)

    @classmethod
    def from_arrays(
        cls,
        vertices: npt.ArrayLike,
        triangles: npt.ArrayLike,
        sizes: npt.ArrayLike | None = None,
    ) -> Grid:
        """A grid from ``vertices`` (N×3 float64), ``triangles`` (M×3 vertex
        indices, 0-based) and optional ``sizes`` (N values, finite and > 0).
        The arrays are copied. Vertices are neither welded nor reordered;
        zero-area triangles are dropped (``stats.dropped_triangles``) and the
        orientation is made consistent per body. O(M log M).

        Raises ``NonFiniteError`` (a coordinate), ``OutOfRangeError`` (an
        index), ``InvalidSizeError``, ``EmptyError`` (no triangle left) and
        ``InvalidArgumentError`` (shapes, dtypes).
        """
        v = cv.float_array(vertices, "vertices", (None, 3))
        t = cv.index_array(triangles, "triangles", 3)
        s = None
        if sizes is not None:
            s = cv.float_array(sizes, "sizes", (v.shape[0],))
        out = c_void_p()
        check(
            lib.abgs_grid_from_arrays(
                cv.ptr(v, c_double),
                v.shape[0],
                cv.ptr(t, c_uint32),
                t.shape[0],
                None if s is None else cv.ptr(s, c_double),
                byref(out),
            )
        )
        return cls(out.value, _token=_PRIVATE)

    @classmethod
    def from_bytes(cls, data: bytes | bytearray | memoryview) -> Grid:
        """A grid from the bytes of ``to_bytes`` (or a ``.abgs`` file), checked
        before use (length, magic, version, byte order, CRC-32, counts, then
        the content as ``from_arrays`` checks it). The grid answers every
        query bit for bit as the one that was serialised. O(V + F).

        Raises ``ParseError``, ``UnsupportedFormatError``, ``NonFiniteError``,
        ``OutOfRangeError``, ``InvalidSizeError``, ``EmptyError`` or
        ``InvalidArgumentError``.
        """
        buf = bytes(data)
        out = c_void_p()
        check(lib.abgs_grid_deserialize(buf, len(buf), byref(out)))
        return cls(out.value, _token=_PRIVATE)

    def to_bytes(self) -> bytes:
        """The grid, sizes and search tree in the versioned binary form
        (``.abgs``), for sending to other processes (MPI, a cache) and
        ``from_bytes``. The bytes depend only on the grid. O(V + F)."""
        n = c_size_t()
        self._call(lib.abgs_grid_serialize, None, 0, byref(n))
        buf = ctypes.create_string_buffer(n.value)
        self._call(lib.abgs_grid_serialize, buf, n.value, byref(n))
        return buf.raw[: n.value]

    def save(self, path: PathLike) -> None:
        """Writes the grid (sizes as point data ``size``), format by extension:
        vtk (ParaView), msh (Gmsh background field), mesh (+ .sol for MMG),
        vtu, ply, obj, off, stl."""
        self._call(lib.abgs_grid_save, os.fsencode(path))

    # --- contents -----------------------------------------------------------

    @property
    def stats(self) -> GridStats:
        """Counts, validation findings, size range and extent. O(V)."""
        s = GridStats()
        self._call(lib.abgs_grid_get_stats, byref(s))
        return s

    def _count(self, fn: Any) -> int:
        """A count from ``fn(grid, size_t *)``."""
        n = c_size_t()
        self._call(fn, byref(n))
        return n.value

    @property
    def n_vertices(self) -> int:
        """Number of vertices. O(1)."""
        return self._count(lib.abgs_grid_vertex_count)

    @property
    def n_triangles(self) -> int:
        """Number of triangles. O(1)."""
        return self._count(lib.abgs_grid_triangle_count)

    @property
    def has_sizes(self) -> bool:
        """True when the grid carries sizes."""
        return bool(self.stats.has_sizes)

    @property
    def vertices(self) -> np.ndarray:
        """A copy of the vertex coordinates, N×3 float64."""
        out = np.empty((self.n_vertices, 3), dtype=np.float64)
        self._call(lib.abgs_grid_copy_vertices, cv.ptr(out, c_double), out.size)
        return out

    @property
    def triangles(self) -> np.ndarray:
        """A copy of the triangles, M×3 uint32 vertex indices."""
        out = np.empty((self.n_triangles, 3), dtype=np.uint32)
        self._call(lib.abgs_grid_copy_triangles, cv.ptr(out, c_uint32), out.size)
        return out

    @property
    def sizes(self) -> np.ndarray:
        """A copy of the sizes, one per vertex (float64). Raises ``NoSizesError`` without sizes."""
        out = np.empty(self.n_vertices, dtype=np.float64)
        self._call(lib.abgs_grid_copy_sizes, cv.ptr(out, c_double), out.size)
        return out

    def set_sizes(self, sizes: npt.ArrayLike) -> None:
        """Replaces the sizes: one per vertex, each finite and > 0 (else
        ``InvalidSizeError``; a wrong count is ``InvalidArgumentError``). O(V + F)."""
        s = cv.float_array(sizes, "sizes", (None,))
        self._call(lib.abgs_grid_set_sizes, cv.ptr(s, c_double), s.shape[0])

    @property
    def edges(self) -> np.ndarray:
        """The unique edges, E×2 uint32 (smaller index first, sorted): the
        order of the per-edge values of ``lbo``."""
        n = self._count(lib.abgs_grid_edge_count)
        out = np.empty((n, 2), dtype=np.uint32)
        self._call(lib.abgs_grid_copy_edges, cv.ptr(out, c_uint32), out.size)
        return out

    def lbo(self) -> tuple[np.ndarray, np.ndarray]:
        """Laplace–Beltrami operator of the sizes: (per vertex, per edge in
        ``edges`` order). Raises ``NoSizesError`` without sizes. O(F)."""
        v = np.empty(self.n_vertices, dtype=np.float64)
        e = np.empty(self._count(lib.abgs_grid_edge_count), dtype=np.float64)
        self._call(lib.abgs_lbo, cv.ptr(v, c_double), v.size, cv.ptr(e, c_double), e.size)
        return v, e

    # --- sizes --------------------------------------------------------------

    def compute_sizes(
        self,
        *,
        n_circle: float | None = None,
        n_gap: float | None = None,
        hmin: float | None = None,
        hmax: float | None = None,
        feature_angle_deg: float | None = None,
        feature_size: float | None = None,
        beta: float | None = None,
        slope: float | None = None,
        curvature: bool | None = None,
        proximity: bool | None = None,
        gradation: bool | None = None,
        contact_gap: float | None = None,
        sources: Sequence[SizeSource] = (),
    ) -> SizeReport:
        """Computes sizes on the vertices from the geometry and installs them.

        H0 = min(curvature size ``2π/(κ·n_circle)``, proximity size
        ``gap/n_gap``, ``feature_size`` on feature edges, ``sources``),
        clamped to [``hmin``, ``hmax``], then graded so that neighbouring
        sizes differ by at most ``beta`` (or the slope bound ``slope``).
        ``None`` keeps the library's default: n_circle 24, n_gap 3,
        hmin = diagonal/2000, hmax = diagonal/10, feature angle 30°,
        feature_size off, beta 1.2, curvature/proximity/gradation on,
        contact_gap = hmin. Sources come from ``point_source``,
        ``segment_source``, ``triangle_source``.

        Raises ``InvalidArgumentError``, ``NonFiniteError``,
        ``InvalidSizeError`` (parameters), ``BusyError``.
        """
        values = dict(locals())
        values.pop("sources")  # a pointer and a count in C, set below
        p = _defaults(SizeParams, lib.abgs_size_params_default, values)
        arr = (SizeSource * len(sources))(*sources) if sources else None
        if arr is not None:
            p.sources = ctypes.cast(arr, ctypes.POINTER(SizeSource))
            p.n_sources = len(sources)
        rep = SizeReport()
        self._call(lib.abgs_compute_size, byref(p), byref(rep))
        return rep

    def apply_gradation(self, beta: float = 1.2, slope: float = 0.0) -> int:
        """Grades the current sizes in place: the largest field below them with
        ``|∇h| <= slope`` (if > 0, else ``ln beta``) on every triangle.
        Returns the number of faces the verify pass fixed. O(V log V)."""
        fixed = c_uint64()
        self._call(lib.abgs_apply_gradation, float(beta), float(slope), byref(fixed))
        return fixed.value

    # --- queries ------------------------------------------------------------

    def size_at(self, point: npt.ArrayLike, hint: Hint | None = None) -> float:
        """Size at ``point`` (3 numbers): exact closest point on the grid,
        barycentric interpolation there. With ``hint`` the search starts from
        the triangle of the previous answer and updates it (same bits, faster
        for coherent points). Expected O(log F).

        Raises ``NonFiniteError``, ``NoSizesError``, ``InvalidArgumentError`` (shape).
        """
        p = cv.float_array(point, "point", (3,))
        out = c_double()
        if hint is None:
            self._call(lib.abgs_query_size, cv.ptr(p, c_double), byref(out))
        else:
            self._call(lib.abgs_query_size_hinted, cv.ptr(p, c_double), byref(hint._value), byref(out))
        return out.value

    def sizes_at(self, points: npt.ArrayLike) -> np.ndarray:
        """Sizes at N points (N×3), in parallel inside the library, without a
        Python loop and without the GIL. Equal to ``size_at`` bit for bit.
        All points are checked first (``NonFiniteError``: nothing computed)."""
        p = cv.float_array(points, "points", (None, 3))
        out = np.empty(p.shape[0], dtype=np.float64)
        self._call(lib.abgs_query_sizes, cv.ptr(p, c_double), p.shape[0], cv.ptr(out, c_double))
        return out

    def size_at_volume(self, point: npt.ArrayLike, beta: float = 1.2) -> float:
        """Volume-mode size at ``point``: ``min over surface points y of
        h(y) + ln(beta)·|point − y|``, the size a volume mesher should use
        inside the domain with gradation ratio ``beta`` (> 1). Exact."""
        p = cv.float_array(point, "point", (3,))
        out = c_double()
        self._call(lib.abgs_query_size_volume, cv.ptr(p, c_double), float(beta), byref(out))
        return out.value

    def sizes_at_volume(self, points: npt.ArrayLike, beta: float = 1.2) -> np.ndarray:
        """Volume-mode sizes at N points (N×3), in parallel (see ``size_at_volume``)."""
        p = cv.float_array(points, "points", (None, 3))
        out = np.empty(p.shape[0], dtype=np.float64)
        self._call(
            lib.abgs_query_sizes_volume, cv.ptr(p, c_double), p.shape[0], float(beta), cv.ptr(out, c_double)
        )
        return out

    def closest(self, point: npt.ArrayLike, hint: Hint | None = None) -> Hit:
        """Closest point on the grid: ``triangle``, ``bary``, ``point``,
        ``distance`` and ``size`` (NaN without sizes). ``hint`` seeds the
        search (it is not updated)."""
        p = cv.float_array(point, "point", (3,))
        h = Hit()
        seed = NO_HINT if hint is None else hint._value.value
        self._call(lib.abgs_query_closest, cv.ptr(p, c_double), seed, byref(h))
        return h

    # --- remeshing and simplification ---------------------------------------

    def remesh(
        self,
        *,
        edge_length: float | None = None,
        relative_length: float | None = None,
        feature_angle_deg: float | None = None,
        iterations: int | None = None,
        curvature_limit: bool | None = None,
        n_circle: float | None = None,
        piece_faces: float | None = None,
        sizing: Grid | None = None,
    ) -> Grid:
        """The dense grid: this surface isotropically remeshed (split, collapse,
        flip, tangential relaxation with projection), feature lines and
        corners kept, bodies apart. The new grid has no sizes; its
        ``remesh_report`` says what was done.

        Uniform mode (``sizing`` None): target length ``edge_length``, or, when
        that is 0 / None, ``relative_length`` × diagonal (default 0.01).
        Size-driven mode: the target length is ``sizing``'s size there
        (``sizing`` must carry sizes; it may be this grid). ``curvature_limit``
        (default on) caps the target at half the curvature size with
        ``n_circle`` (24) elements per circle; ``feature_angle_deg`` (30),
        ``iterations`` (10). A body expected to make more than twice
        ``piece_faces`` (50000; at least 1, or 0: never) triangles is cut along its creases
        into pieces remeshed side by side. O(F log F) per iteration,
        parallel, deterministic.
        """
        p = _defaults(RemeshParams, lib.abgs_remesh_params_default, locals())
        rep = RemeshReport()
        out = c_void_p()
        s = sizing._acquire() if sizing is not None else None
        try:
            self._call(lib.abgs_grid_remesh, s, byref(p), byref(out), byref(rep))
        finally:
            if sizing is not None:
                sizing._release()
        g = Grid(out.value, _token=_PRIVATE)
        g.remesh_report = rep
        return g

    @property
    def feature_edges(self) -> np.ndarray:
        """The feature edges the remesher kept (K×2 uint32 vertex indices).
        Raises ``InvalidArgumentError`` on a grid ``remesh`` did not make."""
        n = self._count(lib.abgs_grid_remesh_feature_edge_count)
        out = np.empty((n, 2), dtype=np.uint32)
        self._call(lib.abgs_grid_remesh_copy_feature_edges, cv.ptr(out, c_uint32), out.size)
        return out

    def remesh_issues(self) -> list[str]:
        """The texts of what the remesher left as it was (``remesh_report.n_issues`` of them)."""
        n = 0 if self.remesh_report is None else self.remesh_report.n_issues
        texts = []
        for i in range(n):
            need = c_size_t()
            self._call(lib.abgs_grid_remesh_issue, i, None, 0, byref(need))
            buf = (c_char * need.value)()
            self._call(lib.abgs_grid_remesh_issue, i, buf, need.value, None)
            texts.append(buf.value.decode(errors="replace"))
        return texts

    def simplify(
        self,
        *,
        method: str | int = "lbo",
        fraction: float | None = None,
        pool_factor: float | None = None,
        selection: str | int | None = None,
        t_size: float | None = None,
        t_contact: float | None = None,
        tau_d: float | None = None,
        max_distance: float | None = None,
        max_iterations: int | None = None,
        feature_angle_deg: float | None = None,
        corner_angle_deg: float | None = None,
        max_normal_turn_deg: float | None = None,
        max_angle_deg: float | None = None,
        repair: bool | None = None,
        beta: float | None = None,
        clearance_fraction: float | None = None,
        t_score: float | None = None,
        verify: bool | None = None,
        fit_sizes: bool | None = None,
        progress: Progress | None = None,
    ) -> Grid:
        """The simplified grid: edge collapses keeping the interpolated size
        within ``t_size`` (1.2) of this (dense, sized) grid's and the surface
        within the distance envelope; features, corners and bodies kept. Its
        ``simplify_report`` says what was done, ``iterations()`` lists the
        per-iteration records. This grid is only read.

        ``method``: ``"lbo"`` (LBO-ABGS, default) or ``"gcn"`` (GCN-ABGS, the
        embedded model; ``t_score`` 0.5 and ``verify`` apply). Defaults:
        fraction 0.10, pool_factor 2, selection ``"batched"`` (``"global"``:
        the whole pool estimated, then the lowest scores, the paper's
        selection; about 3x slower), t_contact 1.2 (where bodies touch; lower makes touching bodies' own fields agree, at a cost in faces),
        tau_d 0 (derived envelope),
        max_distance 0 (none), max_iterations 1000, feature and corner angle
        30°, normal turn 60°, max angle 170°, repair on, beta 1.2,
        clearance_fraction 0.25, fit_sizes on (the vertex sizes fitted to
        this grid's field at the end, by element-weighted least squares;
        off: each vertex keeps this grid's size at its position, the
        paper's rule, whose sizes lie above the field where it is small).

        ``progress(record)`` is called after each iteration that collapsed
        something, on this thread, with an ``IterationRecord``; a truthy return
        stops (the grid made so far is returned, ``stop == STOP_CANCELLED``).
        An exception raised inside it stops the simplification too and is
        re-raised here (the partial grid is freed).

        Raises ``NoSizesError``, ``InvalidArgumentError`` / ``NonFiniteError``
        (parameters, an unknown method), ``BusyError``.
        """
        method = _method(method)
        if selection is not None:
            selection = _selection(selection)
        values = dict(locals())
        values.pop("progress")
        p = _defaults(SimplifyParams, lib.abgs_simplify_params_default, values)
        raised: list[BaseException] = []
        if progress is not None:
            p.progress = PROGRESS_FN(_trampoline(progress, raised))
        rep = SimplifyReport()
        out = c_void_p()
        self._call(lib.abgs_simplify, byref(p), byref(out), byref(rep))
        g = Grid(out.value, _token=_PRIVATE)
        if raised:
            g.close()
            raise raised[0]
        g.simplify_report = rep
        return g

    def iterations(self) -> list[IterationRecord]:
        """The per-iteration records of a grid ``simplify`` made (else ``[]``)."""
        n = 0 if self.simplify_report is None else self.simplify_report.iterations
        recs = []
        for i in range(n):
            r = IterationRecord()
            self._call(lib.abgs_grid_simplify_iteration, i, byref(r))
            recs.append(r)
        return recs

    def edge_scores(self, **params: Any) -> dict[str, np.ndarray]:
        """Every edge's collapse estimate on this grid as it is (in ``edges``
        order): ``ds`` (Δs), ``dd`` (Δd / h_loc), ``valid`` (bool) and ``y``
        (score; < 0.5 = collapsible). ``params``: thresholds and angles as in
        ``simplify``. Parallel, deterministic."""
        unknown = set(params) - {n for n, _ in SimplifyParams._fields_} - {"method"}
        if unknown:
            raise error(ERR_INVALID_ARGUMENT, f"unknown parameters {sorted(unknown)}")
        if "method" in params:
            params["method"] = _method(params["method"])
        p = _defaults(SimplifyParams, lib.abgs_simplify_params_default, params)
        n = self._count(lib.abgs_grid_edge_count)
        ds, dd, y = (np.empty(n, dtype=np.float64) for _ in range(3))
        valid = np.empty(n, dtype=np.uint8)
        self._call(
            lib.abgs_edge_scores,
            byref(p),
            cv.ptr(ds, c_double),
            cv.ptr(dd, c_double),
            cv.ptr(valid, c_uint8),
            cv.ptr(y, c_double),
            n,
        )
        return {"ds": ds, "dd": dd, "valid": valid.astype(bool), "y": y}


def _method(method: str | int) -> int:
    """The ABI's number of a simplification method: ``"lbo"``, ``"gcn"`` or an
    int (passed on for the library to check)."""
    if isinstance(method, str):
        if method.lower() not in _METHODS:
            raise error(ERR_INVALID_ARGUMENT, f"method: expected 'lbo' or 'gcn', got {method!r}")
        return _METHODS[method.lower()]
    return method


def _selection(selection: str | int) -> int:
    """The ABI's number of a selection: ``"batched"``, ``"global"`` or an
    int (passed on for the library to check)."""
    if isinstance(selection, str):
        names = {"batched": SELECTION_BATCHED, "global": SELECTION_GLOBAL}
        if selection.lower() not in names:
            raise error(ERR_INVALID_ARGUMENT, f"selection: expected 'batched' or 'global', got {selection!r}")
        return names[selection.lower()]
    return selection


def _trampoline(progress: Progress, raised: list[BaseException]) -> Callable[[Any, Any], int]:
    """The C callback around ``progress``: copies the record (the bytes the
    library filled), calls ``progress``, returns 1 to stop on a truthy answer
    or on any exception (kept in ``raised``; nothing escapes into C)."""

    def call(rec_ptr: Any, _user_data: Any) -> int:
        try:
            rec = IterationRecord()
            n = min(ctypes.sizeof(rec), rec_ptr.contents.struct_size)
            ctypes.memmove(byref(rec), rec_ptr, n)
            rec.struct_size = n
            return 1 if progress(rec) else 0
        except BaseException as e:  # noqa: BLE001 - re-raised by Grid.simplify
            raised.append(e)
            return 1

    return call


_PRIVATE = object()
