# SPDX-License-Identifier: BSD-3-Clause
"""JSON files the package reads itself (budget sizes, exports, diagnoses, Flynn's table):
strict (no NaN, Infinity or numbers beyond double), bounded in size, and bounded in nesting
and in objects and arrays per byte by the rule of the C++ readers (core/json_text.hpp), so
that no file exhausts the stack or the memory. Every error names the file (and the option
it came from), with the line and column where there is one."""

from __future__ import annotations

import json
import math
import os
from typing import Any, Union

from . import _core

# A JSON file the command line reads beside a session is a few kB; 1 MB leaves room.
MAX_JSON_BYTES = 1 << 20


def _finite(text: str) -> float:
    v = float(text)
    if not math.isfinite(v):
        raise ValueError(f"{text[:40]} is beyond the range of a double")
    return v


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")


def loads(data: Union[bytes, str], where: str) -> Any:
    """The document of JSON text ``data``; ``where`` names it in every error (ParseError)."""
    raw = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    _core.check_json_bounds(raw, where)  # before the parser: depth and objects per byte
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise _core.ParseError(f"{where}: byte {e.start}: not UTF-8 text") from None
    try:
        return json.loads(text, parse_constant=_no_constant, parse_float=_finite)
    except json.JSONDecodeError as e:
        raise _core.ParseError(f"{where}:{e.lineno}:{e.colno}: not valid JSON: {e.msg}") from None
    except ValueError as e:  # NaN, Infinity, 1e999
        raise _core.ParseError(f"{where}: not valid JSON: {e}") from None


def read_json(
    path: Union[str, "os.PathLike[str]"], what: str = "", max_bytes: int = MAX_JSON_BYTES
) -> tuple[Any, bytes]:
    """(document, bytes) of the JSON file ``path``; ``what`` (e.g. the option) prefixes its name
    in errors. IoError if it cannot be read, InvalidArgument if larger than ``max_bytes``,
    ParseError if it is not strict JSON within the bounds."""
    p = os.fspath(path)
    where = f"{what} {p}" if what else p
    if os.path.isdir(p):
        raise _core.IoError(f"{where}: is a directory, not a file")
    try:
        with open(p, "rb") as f:
            data = f.read(max_bytes + 1)
    except OSError as e:
        raise _core.IoError(f"{where}: cannot read: {e.strerror}") from None
    if len(data) > max_bytes:
        raise _core.InvalidArgument(f"{where}: larger than {max_bytes} bytes")
    return loads(data, where), data
