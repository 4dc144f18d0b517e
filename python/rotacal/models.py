"""Fitted machine models as JSON files (``rotacal-model/1``).

A model file holds what an identification or a diagnosis learnt about a machine, so that it
can predict sessions it was not fitted on (``rotacal predict``) or compensate NC programs::

    {"format": "rotacal-model/1", "kind": "ballbar", "machine": "AC-trt",
     "location_errors": {"E_Y0A": {"value": 0.07, "std": 1e-4, "unit": "mm"}, ...},
     "pivot": {"x": {...}, "y": {...}, "z": {...}},
     "effects": [{"id": "gravity_sag_A", "params": {"s": {"value": ..., "std": ..., "unit": "mm"}}}]}

Unobservable parameters are written with ``"value": null`` and are taken as zero (nominal)
when the model is used.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from . import _core

FORMAT = "rotacal-model/1"


def estimate_dict(p: Any) -> dict:
    """``{"value", "std", "unit"}`` of a ParameterEstimate; value/std are None if unobservable."""
    if not p.observable:
        return {"value": None, "std": None, "unit": p.unit, "observable": False}
    return {"value": float(p.value), "std": float(p.std), "unit": p.unit}


def ballbar_model_dict(machine: Any, parameters: list, effects: list[str]) -> dict:
    """Model dict from the parameter list of a ballbar fit (8 errors, pivot x y z, effects)."""
    names = list(_core.location_error_names(machine))
    by_name = {p.name: p for p in parameters}
    out: dict[str, Any] = {
        "format": FORMAT,
        "kind": "ballbar",
        "machine": _core.machine_name(machine),
        "location_errors": {n: estimate_dict(by_name[n]) for n in names},
        "pivot": {a: estimate_dict(by_name["pivot_" + a]) for a in "xyz"},
        "effects": [],
    }
    for eid in effects:
        eff = _core.Effect(eid)
        params = {}
        for pname in eff.param_names:
            key = eid if eff.num_params == 1 else f"{eid}.{pname}"
            params[pname] = estimate_dict(by_name[key])
        out["effects"].append({"id": eid, "cause": eff.cause, "params": params})
    return out


def _value(d: dict, where: str) -> float:
    if "value" not in d:
        raise _core.InvalidArgument(f"{where}: missing 'value'")
    v = d["value"]
    if v is None:
        return 0.0  # unobservable: nominal
    if not isinstance(v, (int, float)) or not math.isfinite(v):
        raise _core.InvalidArgument(f"{where}: 'value' must be a finite number, got {v!r}")
    return float(v)


def ballbar_model_from_dict(d: dict, source: str = "<model>") -> _core.BallbarMachineModel:
    """BallbarMachineModel from a model dict; errors name the file and the key."""
    if d.get("format") != FORMAT:
        raise _core.InvalidArgument(f"{source}: not a {FORMAT} file (format: {d.get('format')!r})")
    if d.get("kind") != "ballbar":
        raise _core.InvalidArgument(f"{source}: kind {d.get('kind')!r} is not a ballbar model")
    machine = _core.parse_machine_type(d.get("machine", ""))
    names = list(_core.location_error_names(machine))
    le = d.get("location_errors", {})
    missing = [n for n in names if n not in le]
    if missing:
        raise _core.InvalidArgument(f"{source}: location_errors lacks {', '.join(missing)}")
    errors = np.array([_value(le[n], f"{source}: location_errors.{n}") for n in names])
    pv = d.get("pivot", {})
    pivot = np.array([_value(pv.get(a, {}), f"{source}: pivot.{a}") for a in "xyz"])
    ids, params = [], []
    for k, e in enumerate(d.get("effects", [])):
        eff = _core.Effect(e["id"])
        ids.append(e["id"])
        for pname in eff.param_names:
            params.append(_value(e.get("params", {}).get(pname, {}), f"{source}: effects[{k}].{pname}"))
    return _core.BallbarMachineModel(machine, errors, pivot, ids, params)


def save_model(model: dict, path: str | Path) -> None:
    """Write a model dict as JSON (to a temporary file first, so a crash never leaves half a file)."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(model, indent=2) + "\n")
    tmp.replace(path)


def load_model(path: str | Path) -> dict:
    """Read a model file; raises rotacal.InvalidArgument naming the file if it is not one."""
    path = Path(path)
    try:
        d = json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise _core.InvalidArgument(f"{path}:{e.lineno}:{e.colno}: not valid JSON: {e.msg}") from None
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        raise _core.InvalidArgument(f"{path}: not a {FORMAT} file")
    return d


def fit_model_dict(machine: Any, parameters: list, effects: list[str]) -> dict:
    """Model dict of a diagnosis' final fit: a ballbar model (with its pivot), or for R-test
    the location errors, the probe zero of each set-up and the effects."""
    if any(p.name == "pivot_x" for p in parameters):
        return ballbar_model_dict(machine, parameters, effects)
    names = list(_core.location_error_names(machine))
    by_name = {p.name: p for p in parameters}
    zeros: dict[str, dict] = {}
    for p in parameters:
        if p.name.startswith("zero."):
            _, setup, axis = p.name.split(".")
            zeros.setdefault(setup, {})[axis] = estimate_dict(p)
    out = {"format": FORMAT, "kind": "rtest-diagnosis", "machine": _core.machine_name(machine),
           "location_errors": {n: estimate_dict(by_name[n]) for n in names},
           "probe_zeros": zeros, "effects": []}
    for eid in effects:
        eff = _core.Effect(eid)
        out["effects"].append({"id": eid, "cause": eff.cause, "params": {
            pn: estimate_dict(by_name[eid if eff.num_params == 1 else f"{eid}.{pn}"]) for pn in eff.param_names}})
    return out
