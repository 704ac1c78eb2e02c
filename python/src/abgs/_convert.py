"""Checks and conversions of Python values before they cross into C.

Arrays become C-contiguous numpy arrays of the ABI's element types; shapes,
integer ranges and dtypes the C side cannot see are refused here with the
status the library gives for the same fault (``InvalidArgumentError``,
``OutOfRangeError``). Values the library checks itself (NaN, indices against
the vertex count, sizes <= 0) are passed through unchanged, so its own status
and message reach the caller.
"""

from __future__ import annotations

import ctypes
from typing import Any

import numpy as np
import numpy.typing as npt

from .errors import ERR_INVALID_ARGUMENT, ERR_OUT_OF_RANGE, error

_U32_MAX = 0xFFFFFFFF


def float_array(value: npt.ArrayLike, name: str, shape: tuple[int | None, ...]) -> np.ndarray:
    """``value`` as a C-contiguous float64 array of ``shape`` (``None`` = any length).

    Raises ``InvalidArgumentError`` for a non-numeric value or a wrong shape.
    O(n) (a copy only when the dtype or layout differs).
    """
    try:
        a = np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise error(ERR_INVALID_ARGUMENT, f"{name}: not an array of numbers ({e})") from None
    if a.ndim != len(shape) or any(s is not None and s != n for s, n in zip(shape, a.shape)):
        want = "x".join("N" if s is None else str(s) for s in shape)
        raise error(ERR_INVALID_ARGUMENT, f"{name}: expected shape {want}, got {a.shape}")
    return a


def index_array(value: npt.ArrayLike, name: str, width: int) -> np.ndarray:
    """``value`` as a C-contiguous ``(M, width)`` uint32 array.

    Only integer input is taken (a float array is ``InvalidArgumentError``); a negative index or one above ``2**32 - 1`` is
    ``OutOfRangeError`` (it would wrap to another index in uint32). Indices
    against the vertex count are the library's to check. O(M).
    """
    a = np.asarray(value)
    if a.size == 0 and a.dtype.kind not in "iu":
        a = a.astype(np.int64)
    if a.dtype.kind not in "iu":
        raise error(ERR_INVALID_ARGUMENT, f"{name}: expected integer indices, got dtype {a.dtype}")
    if a.ndim != 2 or a.shape[1] != width:
        raise error(ERR_INVALID_ARGUMENT, f"{name}: expected shape Mx{width}, got {a.shape}")
    if a.size and a.dtype != np.uint32:
        lo, hi = int(a.min()), int(a.max())
        if lo < 0 or hi > _U32_MAX:
            bad = lo if lo < 0 else hi
            raise error(ERR_OUT_OF_RANGE, f"{name}: index {bad} is outside 0..{_U32_MAX}")
    return np.ascontiguousarray(a, dtype=np.uint32)


def ptr(a: np.ndarray, ctype: Any) -> Any:
    """A ``ctype`` pointer to the data of ``a`` (which must stay alive during the call)."""
    return a.ctypes.data_as(ctypes.POINTER(ctype))


def set_fields(struct: ctypes.Structure, values: dict[str, Any]) -> None:
    """Sets the fields of ``struct`` named in ``values`` (``None`` = keep).

    Unsigned fields take ``bool`` or an int in range; they refuse negative or
    too large integers and non-integers (``InvalidArgumentError``; ctypes would
    wrap them silently); flag fields
    (``int32``) take ``bool`` or int; float fields take any real number, NaN
    and infinities included (the library answers ``NonFiniteError``).
    """
    types = dict(struct._fields_)
    for name, v in values.items():
        if v is None:
            continue
        t = types[name]
        if t in (ctypes.c_uint32, ctypes.c_uint64):
            bits = 8 * ctypes.sizeof(t)
            if not isinstance(v, (int, np.integer, np.bool_)) or not 0 <= v < 2**bits:
                raise error(ERR_INVALID_ARGUMENT, f"{name}: expected an integer in 0..2^{bits}-1, got {v!r}")
            v = int(v)
        elif t is ctypes.c_int32:
            if not isinstance(v, (bool, int, np.integer, np.bool_)) or not -(2**31) <= v < 2**31:
                raise error(ERR_INVALID_ARGUMENT, f"{name}: expected a bool or an int32, got {v!r}")
            v = int(v)
        elif t is ctypes.c_double:
            if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
                raise error(ERR_INVALID_ARGUMENT, f"{name}: expected a number, got {v!r}")
            v = float(v)
        setattr(struct, name, v)
