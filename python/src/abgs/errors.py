"""Exceptions carrying the library's status (number and name) and message.

Every failing call raises ``AbgsError`` or, for the statuses listed in
``_CLASSES``, a subclass of it that is also the matching built-in exception
(``InvalidArgumentError`` is a ``ValueError``, ``IoError`` an ``OSError``, ...),
so both ``except abgs.AbgsError`` and ``except ValueError`` catch bad input.
"""

from __future__ import annotations

from ._ffi import lib

#: Status numbers of ``include/abgs.h`` (stable across releases).
OK = 0
ERR_NULL = 1
ERR_INVALID_ARGUMENT = 2
ERR_OUT_OF_RANGE = 3
ERR_NON_FINITE = 4
ERR_INVALID_SIZE = 5
ERR_IO = 6
ERR_PARSE = 7
ERR_UNSUPPORTED_FORMAT = 8
ERR_BUFFER_TOO_SMALL = 9
ERR_EMPTY = 10
ERR_NO_SIZES = 11
ERR_BUSY = 12
ERR_CANCELLED = 13
ERR_NOT_AVAILABLE = 14
ERR_INTERNAL = 99


def status_name(status: int) -> str:
    """The library's name of ``status``, e.g. ``"ABGS_ERR_NULL"``
    (``"ABGS_UNKNOWN_STATUS"`` for a number that is no status)."""
    return lib.abgs_status_name(int(status)).decode()


def status_description(status: int) -> str:
    """One line saying what ``status`` means (the header's comment on it)."""
    return lib.abgs_status_description(int(status)).decode()


class AbgsError(Exception):
    """A call into libabgs failed.

    Attributes: ``status`` (the number, e.g. 2), ``name`` (the library's name
    of it, e.g. ``"ABGS_ERR_INVALID_ARGUMENT"``) and ``message`` (the text of
    ``abgs_last_error_message`` for that failure, or this package's own text
    when it refused the input before calling the library).
    """

    def __init__(self, status: int, message: str) -> None:
        """Builds the error for ``status`` with ``message``."""
        self.status = int(status)
        self.name = status_name(status)
        self.message = message
        super().__init__(f"{self.name} ({self.status}): {message}")


class NullError(AbgsError):
    """ABGS_ERR_NULL: a required pointer was NULL."""


class InvalidArgumentError(AbgsError, ValueError):
    """ABGS_ERR_INVALID_ARGUMENT: counts, lengths, options or shapes are malformed."""


class OutOfRangeError(AbgsError, IndexError):
    """ABGS_ERR_OUT_OF_RANGE: an index is out of range."""


class NonFiniteError(AbgsError, ValueError):
    """ABGS_ERR_NON_FINITE: a coordinate or parameter is NaN or infinite."""


class InvalidSizeError(AbgsError, ValueError):
    """ABGS_ERR_INVALID_SIZE: a size is not finite and > 0."""


class IoError(AbgsError, OSError):
    """ABGS_ERR_IO: a file could not be opened, read or written."""


class ParseError(AbgsError, ValueError):
    """ABGS_ERR_PARSE: a file's content is malformed."""


class UnsupportedFormatError(AbgsError, ValueError):
    """ABGS_ERR_UNSUPPORTED_FORMAT: the file extension names no supported format."""


class EmptyError(AbgsError, ValueError):
    """ABGS_ERR_EMPTY: the grid would have no triangles."""


class NoSizesError(AbgsError):
    """ABGS_ERR_NO_SIZES: the grid has no sizes yet."""


class BusyError(AbgsError):
    """ABGS_ERR_BUSY: the grid is in use by another call (nothing was changed)."""


class NotAvailableError(AbgsError):
    """ABGS_ERR_NOT_AVAILABLE: the feature is not in this build of the library."""


class InternalError(AbgsError):
    """ABGS_ERR_INTERNAL: a bug in abgs (a caught panic); the message says where."""


_CLASSES: dict[int, type[AbgsError]] = {
    ERR_NULL: NullError,
    ERR_INVALID_ARGUMENT: InvalidArgumentError,
    ERR_OUT_OF_RANGE: OutOfRangeError,
    ERR_NON_FINITE: NonFiniteError,
    ERR_INVALID_SIZE: InvalidSizeError,
    ERR_IO: IoError,
    ERR_PARSE: ParseError,
    ERR_UNSUPPORTED_FORMAT: UnsupportedFormatError,
    ERR_EMPTY: EmptyError,
    ERR_NO_SIZES: NoSizesError,
    ERR_BUSY: BusyError,
    ERR_NOT_AVAILABLE: NotAvailableError,
    ERR_INTERNAL: InternalError,
}


def error(status: int, message: str) -> AbgsError:
    """The exception for ``status`` with ``message`` (the subclass where there is one)."""
    return _CLASSES.get(int(status), AbgsError)(status, message)


def check(status: int) -> None:
    """Raises the exception for a non-zero ``status`` with the library's last
    message on this thread; returns for ``OK``."""
    if status != OK:
        raise error(status, lib.abgs_last_error_message().decode(errors="replace"))
