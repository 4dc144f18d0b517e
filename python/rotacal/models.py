# SPDX-License-Identifier: BSD-3-Clause
"""Fitted machine models as JSON files (``rotacal-model/1``).

A model file holds what an identification or a diagnosis learnt about a machine, so that it
can predict sessions it was not fitted on (``rotacal predict``) or compensate NC programs::

    {"format": "rotacal-model/1", "kind": "ballbar", "machine": "AC-trt",
     "location_errors": {"E_Y0A": {"value": 0.07, "std": 1e-4, "unit": "mm"}, ...},
     "pivot": {"x": {...}, "y": {...}, "z": {...}},
     "effects": [{"id": "gravity_sag_A", "params": {"s": {"value": ..., "std": ..., "unit": "mm"}}}]}

Unobservable parameters are written with ``"value": null`` and are taken as zero (nominal)
when the model is used. Reading and writing go through the C++ implementation
(``rotacal/io/model_file.hpp``; the format field by field: docs/model_file.md), so both
languages read and write the same files: strict JSON (a non-finite number is written null,
its reason under ``"null_reasons"``), versioned (a newer major version is refused by name).
"""

from __future__ import annotations

import json

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from . import _core, jsontext

FORMAT = "rotacal-model/1"


def estimate_dict(p: Any) -> dict:
    """``{"value", "std", "unit"}`` of a ParameterEstimate; value/std are None if unobservable."""
    if not p.observable:
        return {"value": None, "std": None, "unit": p.unit, "observable": False}
    return {"value": float(p.value), "std": float(p.std), "unit": p.unit}


def machine_members(machine: Any) -> dict:
    """``{"machine": name}``, with the ``machine_description`` of every machine but the two
    tables formats.md names (the description then defines the machine; other tools can read it)."""
    out: dict[str, Any] = {"machine": _core.machine_name(machine)}
    if machine not in (_core.MachineType.AC_trt, _core.MachineType.BC_trt):
        out["machine_description"] = json.loads(machine.description_json)
    return out


def machine_of(d: dict, source: str) -> Any:
    """The machine a model dict names: its ``machine_description`` if it has one, else the
    built-in called ``machine``; errors name the file and the key."""
    if "machine_description" in d:
        desc = d["machine_description"]
        if not isinstance(desc, dict):
            raise _core.InvalidArgument(
                f"{source}: machine_description: must be a rotacal-machine/1 object"
            )
        return _core.MachineType.from_description(
            json.dumps(desc), f"{source}: machine_description"
        )
    try:
        return _core.parse_machine_type(str(d.get("machine", "")))
    except _core.InvalidArgument as e:
        raise _core.InvalidArgument(f"{source}: machine: {e}") from None


def convention_estimate_dict(p: Any) -> dict:
    """As estimate_dict, but a parameter of an unobservable combination keeps the value the fit
    gave it under its convention (the one it held keeps its start value), flagged
    ``observable: false`` with no std: what a model file needs to predict the readings as the
    fit did (on a head machine pivot z, the head's position along the spindle and the tool
    length are one such combination). It is not a measurement of that parameter."""
    if not p.observable:
        return {"value": float(p.value), "std": None, "unit": p.unit, "observable": False}
    return estimate_dict(p)


def ballbar_model_dict(
    machine: Any, parameters: list, effects: list[str], *, convention_values: bool = False
) -> dict:
    """Model dict from the parameter list of a ballbar fit (8 errors, pivot x y z, effects).
    ``convention_values``: keep the values of unobservable parameters (model files, see
    convention_estimate_dict); otherwise they are null."""
    est = convention_estimate_dict if convention_values else estimate_dict
    names = list(_core.location_error_names(machine))
    by_name = {p.name: p for p in parameters}
    out: dict[str, Any] = {
        "format": FORMAT,
        "kind": "ballbar",
        **machine_members(machine),
        "location_errors": {n: est(by_name[n]) for n in names},
        "pivot": {a: est(by_name["pivot_" + a]) for a in "xyz"},
        "effects": [],
    }
    for eid in effects:
        eff = _core.Effect(eid)
        params = {}
        for pname in eff.param_names:
            key = eid if eff.num_params == 1 else f"{eid}.{pname}"
            params[pname] = est(by_name[key])
        out["effects"].append({"id": eid, "cause": eff.cause, "params": params})
    return out


def covariance_dict(parameters: list, covariance: Any) -> dict | None:
    """``{"parameters": names, "matrix": rows}`` of a fit's covariance (parameter order), with
    null for entries of unobservable parameters; None when the fit has no covariance."""
    cov = np.asarray(covariance, dtype=float)
    names = [p.name for p in parameters]
    if cov.shape != (len(names), len(names)):
        return None
    ok = [bool(p.observable) for p in parameters]
    rows = [
        [
            float(cov[i, j]) if ok[i] and ok[j] and math.isfinite(cov[i, j]) else None
            for j in range(len(names))
        ]
        for i in range(len(names))
    ]
    return {"parameters": names, "matrix": rows}


def file_sha256(path: str | Path) -> str:
    """The SHA-256 of a file's bytes, read in blocks (a session can be large)."""
    import hashlib

    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def source_dict(session_path: str | Path | list | tuple) -> dict:
    """The ``source`` member of a model file: the session it was identified from (as named, and
    its SHA-256), when, and by which rotacal; exports and the history quote it. Several sessions
    (a joint identification): ``session`` names them all (", "), ``session_sha256`` is the
    SHA-256 of their SHA-256s in order, and ``sessions`` lists each with its own."""
    import datetime
    import hashlib
    from .version import __version__

    when = {
        "identified_at": datetime.datetime.now(datetime.timezone.utc).strftime(
            "%Y-%m-%dT%H:%M:%SZ"
        ),
        "rotacal": __version__,
    }
    if not isinstance(session_path, (list, tuple)):
        return {
            "session": os.fspath(session_path),
            "session_sha256": file_sha256(session_path),
        } | when
    each = [{"session": os.fspath(p), "session_sha256": file_sha256(p)} for p in session_path]
    joint = hashlib.sha256("".join(s["session_sha256"] for s in each).encode()).hexdigest()
    return (
        {"session": ", ".join(s["session"] for s in each), "session_sha256": joint}
        | when
        | {"sessions": each}
    )


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
    """BallbarMachineModel from a model dict, validated by the C++ reader (io/model_file.hpp);
    errors name the file and the member."""
    if isinstance(d, dict) and d.get("kind") not in (None, "ballbar"):
        raise _core.InvalidArgument(f"{source}: kind {d.get('kind')!r} is not a ballbar model")
    return _core.ballbar_model_from_document(d, source)


def save_model(
    model: dict, path: str | Path, inputs: tuple = (), other_outputs: tuple = ()
) -> None:
    """Write a model dict through the C++ writer: validated as the reader would, strict JSON
    (a non-finite number is written null, its reason under "null_reasons"), by the output rule
    of rotacal.outputs (regular files replaced atomically, devices written through)."""
    _core.write_model_document(
        model,
        os.fspath(path),
        [os.fspath(p) for p in inputs],
        [os.fspath(p) for p in other_outputs],
    )


def load_model(path: str | Path) -> dict:
    """Read a model file through the C++ reader; raises rotacal.ParseError naming the file,
    line and column (syntax) or member (content), rotacal.IoError if it cannot be read."""
    return _core.read_model_document(os.fspath(path))


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
    out = {
        "format": FORMAT,
        "kind": "rtest-diagnosis",
        **machine_members(machine),
        "location_errors": {n: estimate_dict(by_name[n]) for n in names},
        "probe_zeros": zeros,
        "effects": [],
    }
    for eid in effects:
        eff = _core.Effect(eid)
        out["effects"].append(
            {
                "id": eid,
                "cause": eff.cause,
                "params": {
                    pn: estimate_dict(by_name[eid if eff.num_params == 1 else f"{eid}.{pn}"])
                    for pn in eff.param_names
                },
            }
        )
    return out


# ------------------------------------------------------------------------- R-test joint model

RTEST_KIND = "rtest-joint"


def rtest_model_dict(ident: Any, nests: dict) -> dict:
    """Model dict (``kind: rtest-joint``) of a joint R-test identification on any machine:
    location errors, on a machine with head axes tool_offset_Z, the two maps' coefficients
    (named after the machine's axes, e.g. ``dz_BY.b2``, ``dx_CZ.cos2.b0``) and their covariance,
    the basis and its definition, the nests and the fitted probe zero of each set-up.
    Parameters of an unobservable combination keep the value the fit gave them under its
    convention (``observable: false``, no std), so that the file predicts as the fit did.
    Written by the C++ implementation (rotacal/rtest/model_document.hpp)."""
    return _core.rtest_joint_model_document(
        ident, {str(k): np.asarray(v, dtype=float) for k, v in nests.items()}
    )


def _int_field(d: dict, key: str, where: str) -> int:
    v = d.get(key)
    if not isinstance(v, int) or isinstance(v, bool) or v < 0:
        raise _core.InvalidArgument(f"{where}.{key}: must be an integer >= 0, got {v!r}")
    return v


def rtest_model_from_dict(d: dict, source: str = "<model>") -> tuple[Any, dict, dict]:
    """(RtestJointModel, nests, probe zeros) from a ``rtest-joint`` model dict; errors name the
    file and the key. Unobservable parameters (``observable: false``) keep the value written
    (null: zero) and are flagged unobservable, so that predictions they enter carry no
    uncertainty (NaN)."""
    if d.get("format") != FORMAT:
        raise _core.InvalidArgument(f"{source}: not a {FORMAT} file (format: {d.get('format')!r})")
    if d.get("kind") != RTEST_KIND:
        raise _core.InvalidArgument(
            f"{source}: kind {d.get('kind')!r} is not an R-test joint model ('{RTEST_KIND}')"
        )
    machine = machine_of(d, source)
    b = d.get("basis")
    if not isinstance(b, dict):
        raise _core.InvalidArgument(f"{source}: missing 'basis'")
    if not isinstance(b.get("gamma_cb"), bool):
        raise _core.InvalidArgument(f"{source}: basis.gamma_cb: must be true or false")
    basis = _core.RtestBasis(
        _int_field(b, "b_degree", f"{source}: basis"),
        _int_field(b, "c_harmonics", f"{source}: basis"),
        _int_field(b, "c_b_degree", f"{source}: basis"),
        b["gamma_cb"],
    )
    head = ["tool_offset_Z"] if machine.has_head else []
    if not head and "tool_offset_Z" in d:
        raise _core.InvalidArgument(
            f"{source}: tool_offset_Z: only a machine with head axes has it; "
            f"{_core.machine_name(machine)} has none"
        )
    names = (
        list(_core.location_error_names(machine)) + head + list(basis.coefficient_names(machine))
    )
    values: dict[str, dict] = {}
    for n in head:
        if not isinstance(d.get(n), dict):
            raise _core.InvalidArgument(
                f"{source}: {n}: a machine with head axes needs its estimate"
            )
        values[n] = d[n]
    for key in ("location_errors", "map_coefficients"):
        part = d.get(key, {})
        if not isinstance(part, dict):
            raise _core.InvalidArgument(f"{source}: {key}: must be an object")
        for n, est in part.items():
            values[n] = est if isinstance(est, dict) else {"value": est}
    missing = [n for n in names if n not in values]
    unknown = [n for n in values if n not in names]
    if missing or unknown:
        raise _core.InvalidArgument(
            f"{source}: the parameters do not match basis {b['b_degree']}/{b['c_harmonics']}/"
            f"{b['c_b_degree']}"
            + (f"; missing: {', '.join(missing[:5])}" if missing else "")
            + (f"; unknown: {', '.join(unknown[:5])}" if unknown else "")
        )
    params = np.array([_value(values[n], f"{source}: {n}") for n in names])
    observable = [
        values[n].get("value") is not None and values[n].get("observable", True) is not False
        for n in names
    ]
    cov = d.get("covariance", {})
    if not isinstance(cov, dict) or cov.get("parameters") != names:
        raise _core.InvalidArgument(
            f"{source}: covariance.parameters must list the {len(names)} "
            "parameters in model order (location errors, tool_offset_Z on a "
            "machine with head axes, map coefficients)"
        )
    try:
        matrix = np.array(cov.get("matrix"), dtype=float)
    except (TypeError, ValueError):
        raise _core.InvalidArgument(
            f"{source}: covariance.matrix: not a matrix of numbers"
        ) from None
    if matrix.shape != (len(names), len(names)):
        raise _core.InvalidArgument(
            f"{source}: covariance.matrix: shape {matrix.shape}, expected "
            f"({len(names)}, {len(names)})"
        )
    # Then the C++ reader's full check (units, bounds, basis.maps), so both languages refuse the
    # same files; the checks above name the commoner mistakes more precisely.
    _core.parse_model_document(jsontext.dumps(d), source)
    model = _core.RtestJointModel(machine, basis, params, matrix, observable)
    nests = {
        str(k): np.array(_floats_of(v, 3, f"{source}: nests.{k}"))
        for k, v in d.get("nests", {}).items()
    }
    zeros = {}
    for setup, z in d.get("probe_zeros", {}).items():
        zeros[str(setup)] = np.array(
            [_value(z.get(a, {}), f"{source}: probe_zeros.{setup}.{a}") for a in "xyz"]
        )
    return model, nests, zeros


def _floats_of(v: Any, n: int, where: str) -> list[float]:
    if (
        not isinstance(v, list)
        or len(v) != n
        or not all(isinstance(x, (int, float)) and math.isfinite(x) for x in v)
    ):
        raise _core.InvalidArgument(f"{where}: must be {n} finite numbers, got {v!r}")
    return [float(x) for x in v]
