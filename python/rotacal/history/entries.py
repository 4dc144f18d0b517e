# SPDX-License-Identifier: BSD-3-Clause
"""The entries of a calibration history: what an identification or a correction stores,
checked (machine id, date, note, estimates, correction amounts)."""

from __future__ import annotations

import datetime
import hashlib
import json
import math
from dataclasses import dataclass, field
from typing import Any, Mapping

from .. import _core

MAX_MACHINE_ID = 100
# The largest location error a model file may hold (io/model_file.hpp, kMaxModelPositionError
# and kMaxModelAngleError): a correction beyond it is a typo or wrong units, not a machine.
MAX_ERROR = {"mm": 100.0, "rad": 0.5}
MAX_NOTE = 2000

IDENTIFICATION, CORRECTION = "identification", "correction"


def now_utc() -> str:
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def parse_date(text: str, what: str = "date") -> str:
    """ISO 8601 date or date-time as stored: UTC, ``YYYY-MM-DDTHH:MM:SSZ`` (so that the text
    sorts as the time does). A time without zone is taken as UTC."""
    if not isinstance(text, str):
        raise _core.InvalidArgument(f"{what}: expected an ISO 8601 date, got {type(text).__name__}")
    t = text.strip()
    try:
        d = datetime.datetime.fromisoformat(t[:-1] + "+00:00" if t.endswith("Z") else t)
    except ValueError:
        raise _core.InvalidArgument(
            f"{what}: {t[:40]!r} is not an ISO 8601 date (e.g. 2026-03-01 or 2026-03-01T14:30:00Z)"
        ) from None
    if d.tzinfo is None:
        d = d.replace(tzinfo=datetime.timezone.utc)
    d = d.astimezone(datetime.timezone.utc)
    if not 1970 <= d.year <= 9999:
        raise _core.InvalidArgument(f"{what}: {t[:40]!r} is outside the years 1970..9999")
    return d.strftime("%Y-%m-%dT%H:%M:%SZ")


def check_machine_id(machine_id: Any) -> str:
    """The id of a physical machine: 1..100 printable characters, not only blanks."""
    if not isinstance(machine_id, str) or not machine_id.strip():
        raise _core.InvalidArgument(
            "--machine-id: give the id of the physical machine (e.g. its serial number)"
        )
    if len(machine_id) > MAX_MACHINE_ID or not machine_id.isprintable():
        raise _core.InvalidArgument(
            f"--machine-id: {machine_id[:40]!r}: at most {MAX_MACHINE_ID} printable characters"
        )
    return machine_id


def check_note(note: Any) -> str | None:
    if note is None:
        return None
    if not isinstance(note, str) or len(note) > MAX_NOTE or "\x00" in note:
        raise _core.InvalidArgument(f"--note: at most {MAX_NOTE} characters of text")
    return note


def unit_of(name: str) -> str:
    """Unit of a location error by its ISO 230-7 name: E_X.., E_Y.., E_Z.. are positions (mm),
    E_A.., E_B.., E_C.. orientations (rad)."""
    return "mm" if name[2:3] in ("X", "Y", "Z") else "rad"


def sha256_of_json(doc: Any) -> str:
    return hashlib.sha256(
        json.dumps(doc, sort_keys=True, separators=(",", ":")).encode()
    ).hexdigest()


@dataclass
class Estimate:
    value: float | None  # None: unobservable
    std: float | None
    unit: str


@dataclass
class Entry:
    """One identification or correction of a machine, as show reads it."""

    id: int
    kind: str
    test: str  # ballbar / rtest-joint / ... ; for a correction the controller
    measured_at: str
    session: str | None
    source_sha256: str
    note: str | None
    estimates: dict[str, Estimate] = field(default_factory=dict)


def estimates_of(
    model: Mapping[str, Any], where: str
) -> list[tuple[str, str, float | None, float | None, str]]:
    """(part, name, value, std, unit) of a model's location errors and map coefficients, and of a
    thermal model's lags (part ``thermal``: ``lag1.tau`` in s, ``lag1.E_X0C`` per unit of heat
    input), checked: a value finite or null, a std finite and >= 0 or null."""
    rows = []
    for part in ("location_errors", "map_coefficients"):
        block = model.get(part, {})
        if not isinstance(block, Mapping):
            raise _core.InvalidArgument(f"{where}: {part}: must be an object")
        for name, est in block.items():
            default = unit_of(name) if part == "location_errors" else ""
            rows.append(_estimate_row(part, str(name), est, default, f"{where}: {part}.{name}"))
    if model.get("kind") == "thermal":
        lags = (
            model.get("thermal", {}).get("lags")
            if isinstance(model.get("thermal"), Mapping)
            else None
        )
        if not isinstance(lags, list):
            raise _core.InvalidArgument(f"{where}: thermal.lags: must be a list")
        for k, lag in enumerate(lags, start=1):
            at = f"{where}: thermal.lags[{k - 1}]"
            if not isinstance(lag, Mapping) or not isinstance(lag.get("gains"), Mapping):
                raise _core.InvalidArgument(f"{at}: needs tau and gains")
            rows.append(_estimate_row("thermal", f"lag{k}.tau", lag.get("tau"), "s", f"{at}.tau"))
            for name, est in lag["gains"].items():
                rows.append(
                    _estimate_row("thermal", f"lag{k}.{name}", est, "", f"{at}.gains.{name}")
                )
    return rows


def _estimate_row(
    part: str, name: str, est: Any, default_unit: str, where: str
) -> tuple[str, str, float | None, float | None, str]:
    if not isinstance(est, Mapping):
        raise _core.InvalidArgument(f"{where}: must be an estimate object")
    v, s = est.get("value"), est.get("std")
    for key, x in (("value", v), ("std", s)):
        if x is not None and (
            isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x)
        ):
            raise _core.InvalidArgument(
                f"{where}.{key}: must be a finite number or null, got {x!r}"
            )
    if s is not None and s < 0:
        raise _core.InvalidArgument(f"{where}.std: must be >= 0, got {s!r}")
    unit = est.get("unit", default_unit)
    return (
        part,
        name,
        None if v is None else float(v),
        None if v is None or s is None else float(s),
        str(unit),
    )


def correction_amounts(export: Mapping[str, Any], where: str = "<export>") -> dict[str, float]:
    """The change of compensation a controller export loads, by location error: each error the
    controller holds is now compensated by its identified value, so a later calibration
    measures the machine less that value (docs/history.md)."""
    errors = export.get("location_errors") if isinstance(export, Mapping) else None
    if not isinstance(errors, list) or not isinstance(export.get("controller"), str):
        raise _core.InvalidArgument(
            f"{where}: not the JSON of 'rotacal export --json' (controller, location_errors)"
        )
    out: dict[str, float] = {}
    for i, e in enumerate(errors):
        if (
            not isinstance(e, Mapping)
            or not isinstance(e.get("name"), str)
            or not isinstance(e.get("held"), bool)
        ):
            raise _core.InvalidArgument(f"{where}: location_errors[{i}]: needs name and held")
        v = e.get("value")
        if not e["held"] or v is None:
            continue  # not loaded, or unobservable (the export leaves it at its current value)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise _core.InvalidArgument(
                f"{where}: location_errors[{i}].value: must be a finite number, got {v!r}"
            )
        limit = MAX_ERROR.get(unit_of(e["name"]))
        if limit is not None and abs(v) > limit:
            raise _core.InvalidArgument(
                f"{where}: location_errors[{i}].value: {v:g} {unit_of(e['name'])} is beyond "
                f"+-{limit:g}: no machine tool has such a location error"
            )
        out[e["name"]] = float(v)
    if not out:
        raise _core.InvalidArgument(
            f"{where}: the export holds none of the location errors: no correction to record"
        )
    return out
