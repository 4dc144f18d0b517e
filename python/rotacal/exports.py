"""Identified location errors written into a controller's own kinematic parameters
(``rotacal export``): LinuxCNC's trt kinematics (HAL pins), SINUMERIK toolholder data
($TC_CARR, type P), ISG's universal kinematic, and the field mappings of HEIDENHAIN and FANUC.
The work is done in C++ (``rotacal/io/controller_export.hpp``); the mapping field by field,
with its sources: docs/controller_exports.md."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from . import _core

CONTROLLERS = ("linuxcnc", "siemens", "isg", "heidenhain", "fanuc")
# A controller's parameter file is a few kB; anything much larger is not one.
MAX_CURRENT_BYTES = 1 << 20


def read_current(path: str | Path) -> str:
    """The text of a file of current controller values (HAL, MPF or JSON), bounded and UTF-8."""
    p = os.fspath(path)
    try:
        with open(p, "rb") as f:
            data = f.read(MAX_CURRENT_BYTES + 1)
    except IsADirectoryError:
        raise _core.IoError(f"{p}: is a directory, not a file") from None
    except OSError as e:
        raise _core.IoError(f"{p}: cannot read: {e.strerror}") from None
    if len(data) > MAX_CURRENT_BYTES:
        raise _core.InvalidArgument(f"{p}: more than {MAX_CURRENT_BYTES} bytes: not a controller parameter file")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = data[:e.start].count(b"\n") + 1
        raise _core.ParseError(f"{p}:{line}: byte 0x{data[e.start]:02x} is not UTF-8") from None


def export_controller(model: str | Path, controller: str, current: str | Path | None = None,
                      toolholder: int = 1, generated_at: str = "") -> Any:
    """A ``rotacal._core.ControllerExport`` of a model file: ``.text`` is the file for the
    controller, ``.values`` the parameters (current, corrected, 1-sigma), ``.errors`` which of
    the location errors it holds. ``current``: the controller's values active during the test
    (its HAL or MPF file, or ``{"controller": ..., "parameters": {...}}`` JSON); without it zero
    offsets are assumed and the output says so."""
    text = read_current(current) if current is not None else None
    return _core.export_controller(os.fspath(model), controller, text, os.fspath(current or "<current>"),
                                   int(toolholder), generated_at)


def export_dict(ex: Any) -> dict:
    """The JSON of ``rotacal export --json``."""
    return {"controller": ex.controller, "kinematics": ex.kinematics, "current_given": ex.current_given,
            "parameters": [{"name": v.name, "current": v.current, "corrected": v.corrected, "std": v.std,
                            "unit": v.unit, "from": v.source} for v in ex.values],
            "location_errors": [{"name": e.name, "value": e.value if e.observable else None,
                                 "std": e.std if e.observable else None, "held": e.held, "where": e.where}
                                for e in ex.errors]}


def residual_model(model: dict, ex: Any) -> dict:
    """The model with the errors the controller now holds set to zero: what NC compensation
    (``rotacal compensate --model``) must still correct once the export is loaded. Its
    ``source.residual_after`` names the export. The covariance is dropped (it describes the
    identification, not this difference)."""
    out = dict(model)
    errors = {name: dict(est) for name, est in model["location_errors"].items()}
    for e in ex.errors:
        if e.held:
            errors[e.name] = {"value": 0.0, "std": 0.0, "unit": errors[e.name].get("unit", "")}
    out["location_errors"] = errors
    out.pop("covariance", None)
    out["source"] = dict(model.get("source", {})) | {"residual_after": f"{ex.controller} export ({ex.kinematics})"}
    return out
