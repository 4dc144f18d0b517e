# SPDX-License-Identifier: BSD-3-Clause
"""Strict JSON text: never NaN or Infinity; a number that is not finite is written null and its reason listed under "null_reasons"."""

from __future__ import annotations

import json
import math
from typing import Any

# The convention of the model file (docs/model_file.md): "null_reasons" maps the JSON pointer
# (RFC 6901) of each null that stands for a non-finite number to why.
NULL_REASONS = "null_reasons"


def _pointer_token(key: Any) -> str:
    return str(key).replace("~", "~0").replace("/", "~1")


def _why(v: float) -> str:
    name = "NaN" if math.isnan(v) else ("+Infinity" if v > 0 else "-Infinity")
    return f"{name}: not determined by the data"


def _clean(v: Any, pointer: str, reasons: dict[str, str]) -> Any:
    if isinstance(v, dict):
        return {k: _clean(x, f"{pointer}/{_pointer_token(k)}", reasons) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_clean(x, f"{pointer}/{i}", reasons) for i, x in enumerate(v)]
    if isinstance(v, float) and not math.isfinite(v):
        reasons[pointer] = _why(v)
        return None
    return v


def non_finite(data: Any) -> dict[str, str]:
    """JSON pointer -> reason of every NaN or infinite number in ``data``."""
    reasons: dict[str, str] = {}
    _clean(data, "", reasons)
    return reasons


def dumps(data: Any, indent: int | None = 1) -> str:
    """JSON text of ``data`` that every strict parser reads: each NaN or infinity becomes null,
    and a dict gets "null_reasons" saying which fields and why."""
    reasons: dict[str, str] = {}
    clean = _clean(data, "", reasons)
    if reasons and isinstance(clean, dict):
        clean[NULL_REASONS] = reasons
    return json.dumps(clean, indent=indent, allow_nan=False)
