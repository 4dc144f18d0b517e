"""Strict JSON text: never NaN or Infinity; a number that is not finite is written as null and the reason listed."""
from __future__ import annotations

import json
import math
from typing import Any

from . import _core


def _clean(v: Any, where: str, reasons: list[dict]) -> Any:
    if isinstance(v, dict):
        return {k: _clean(x, f"{where}.{k}" if where else str(k), reasons) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_clean(x, f"{where}[{i}]", reasons) for i, x in enumerate(v)]
    if isinstance(v, float) and not math.isfinite(v):
        reasons.append({"field": where, "value": repr(v),
                        "reason": "not a finite number: the data do not determine it"})
        return None
    return v


def non_finite_fields(data: Any) -> list[dict]:
    """[{"field", "value", "reason"}] for every NaN or infinite number in ``data``."""
    reasons: list[dict] = []
    _clean(data, "", reasons)
    return reasons


def dumps(data: Any, indent: int | None = 1) -> str:
    """JSON text of ``data`` that every strict parser reads: each NaN or infinity becomes null,
    and a dict gets a "non_finite" list saying which fields and why."""
    reasons: list[dict] = []
    clean = _clean(data, "", reasons)
    if reasons and isinstance(clean, dict):
        clean["non_finite"] = reasons
    return json.dumps(clean, indent=indent, allow_nan=False)


def require_finite(data: Any, what: str) -> None:
    """Refuse data with a NaN or infinity (InvalidArgument naming the fields), e.g. a model
    file, where null would silently mean "nominal"."""
    bad = non_finite_fields(data)
    if bad:
        fields = ", ".join(f"{b['field']} = {b['value']}" for b in bad[:5])
        raise _core.InvalidArgument(f"{what}: not finite: {fields}"
                                    + (f" and {len(bad) - 5} more" if len(bad) > 5 else ""))
