"""The ctypes declarations match include/abgs.h: a C program compiled against
the header prints every struct's size and every field's offset, and the
constants; the library's version equals the header's."""

from __future__ import annotations

import ctypes
import shutil
import subprocess
from pathlib import Path

import pytest

import abgs
from abgs import _ffi
from abgs import errors as E

from conftest import REPO

HEADER = REPO / "include" / "abgs.h"

CONSTANTS = {
    "ABGS_NO_HINT": _ffi.NO_HINT,
    "ABGS_METHOD_LBO": _ffi.METHOD_LBO,
    "ABGS_METHOD_GCN": _ffi.METHOD_GCN,
    "ABGS_SELECTION_GLOBAL": _ffi.SELECTION_GLOBAL,
    "ABGS_SELECTION_BATCHED": _ffi.SELECTION_BATCHED,
    "ABGS_STOP_CONVERGED": _ffi.STOP_CONVERGED,
    "ABGS_STOP_MAX_ITERATIONS": _ffi.STOP_MAX_ITERATIONS,
    "ABGS_STOP_CANCELLED": _ffi.STOP_CANCELLED,
    "ABGS_SOURCE_POINT": _ffi.SOURCE_POINT,
    "ABGS_SOURCE_SEGMENT": _ffi.SOURCE_SEGMENT,
    "ABGS_SOURCE_TRIANGLE": _ffi.SOURCE_TRIANGLE,
    "ABGS_VERSION_MAJOR": None,
    "ABGS_VERSION_MINOR": None,
    "ABGS_VERSION_PATCH": None,
}
STATUSES = {n: getattr(E, n) for n in dir(E) if n == "OK" or n.startswith("ERR_")}


@pytest.fixture(scope="module")
def header_facts(tmp_path_factory: pytest.TempPathFactory) -> dict[str, int]:
    """``name -> value`` printed by a C program built against the header:
    ``sizeof:<struct>``, ``offsetof:<struct>.<field>``, constants and statuses."""
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    lines = []
    for cname, cls in _ffi.STRUCTS.items():
        lines.append(f'printf("sizeof:{cname} %zu\\n", sizeof({cname}));')
        for field, _ in cls._fields_:
            lines.append(f'printf("offsetof:{cname}.{field} %zu\\n", offsetof({cname}, {field}));')
    for c in CONSTANTS:
        lines.append(f'printf("{c} %llu\\n", (unsigned long long)({c}));')
    for s in STATUSES:
        lines.append(f'printf("ABGS_{s} %d\\n", (int)(ABGS_{s}));')
    src = "#include <stdio.h>\n#include <stddef.h>\n#include \"abgs.h\"\nint main(void) {\n"
    src += "\n".join(lines) + "\nreturn 0;\n}\n"
    d = tmp_path_factory.mktemp("abi")
    (d / "facts.c").write_text(src)
    subprocess.run([cc, "-std=c11", "-I", str(HEADER.parent), "facts.c", "-o", "facts"], cwd=d, check=True)
    out = subprocess.run([str(d / "facts")], capture_output=True, text=True, check=True).stdout
    return {k: int(v) for k, v in (line.split() for line in out.splitlines())}


def test_struct_layouts(header_facts: dict[str, int]) -> None:
    """Every struct: same sizeof, every field at the same offset."""
    for cname, cls in _ffi.STRUCTS.items():
        assert ctypes.sizeof(cls) == header_facts[f"sizeof:{cname}"], cname
        for field, _ in cls._fields_:
            assert getattr(cls, field).offset == header_facts[f"offsetof:{cname}.{field}"], f"{cname}.{field}"


def test_every_header_struct_is_declared() -> None:
    """No struct of the header is missing here (a new one needs a declaration)."""
    import re

    declared = set(re.findall(r"\}\s*(abgs_\w+)\s*;", HEADER.read_text())) - {"abgs_status"}
    assert declared == set(_ffi.STRUCTS), declared ^ set(_ffi.STRUCTS)


def test_every_header_function_is_declared() -> None:
    """Every function of the header has a prototype here."""
    import re

    functions = set(re.findall(r"^(?:const )?\w+ \*?(abgs_\w+)\(", HEADER.read_text(), re.M))
    assert functions == set(_ffi._PROTOTYPES), functions ^ set(_ffi._PROTOTYPES)


def test_constants_and_version(header_facts: dict[str, int]) -> None:
    """Constants and status numbers equal the header's; the library is the header's version."""
    for c, v in CONSTANTS.items():
        if v is not None:
            assert header_facts[c] == v, c
    for s, v in STATUSES.items():
        assert header_facts[f"ABGS_{s}"] == v, s
    want = "{}.{}.{}".format(*(header_facts[f"ABGS_VERSION_{p}"] for p in ("MAJOR", "MINOR", "PATCH")))
    assert abgs.version() == want
    assert Path(abgs.library_path()).is_file()
