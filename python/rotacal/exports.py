# SPDX-License-Identifier: BSD-3-Clause
"""Identified location errors written into a controller's own kinematic parameters
(``rotacal export``): LinuxCNC's trt kinematics (HAL pins), SINUMERIK toolholder data
($TC_CARR, type P), ISG's universal kinematic, and the field mappings of HEIDENHAIN and FANUC.
The work is done in C++ (``rotacal/io/controller_export.hpp``); the mapping field by field,
with its sources: docs/controller_exports.md."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Sequence

import numpy as np

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
        raise _core.InvalidArgument(
            f"{p}: more than {MAX_CURRENT_BYTES} bytes: not a controller parameter file"
        )
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = data[: e.start].count(b"\n") + 1
        raise _core.ParseError(f"{p}:{line}: byte 0x{data[e.start]:02x} is not UTF-8") from None


def export_controller(
    model: str | Path,
    controller: str,
    current: str | Path | None = None,
    toolholder: int = 1,
    generated_at: str = "",
    thermal_at_s: float | None = None,
    thermal_state: list[float] | None = None,
) -> Any:
    """A ``rotacal._core.ControllerExport`` of a model file: ``.text`` is the file for the
    controller, ``.values`` the parameters (current, corrected, 1-sigma), ``.errors`` which of
    the location errors it holds. ``current``: the controller's values active during the test
    (its HAL or MPF file, or ``{"controller": ..., "parameters": {...}}`` JSON); without it the
    values the model keeps (``source.controller_parameters``, from ``identify --controller``),
    else zero offsets, which the output says. A thermal model (docs/thermal.md) is exported at
    ``thermal_at_s`` (s of the test's duty) or ``thermal_state`` (y per lag)."""
    if current is not None:
        text, where = read_current(current), os.fspath(current)
    else:  # the values the model says were active (identify --controller), if any
        from .models import load_model

        text = load_model(model).get("source", {}).get("controller_parameters")
        where = f"{os.fspath(model)}: source.controller_parameters"
    return _core.export_controller(
        os.fspath(model),
        controller,
        text,
        where,
        int(toolholder),
        generated_at,
        thermal_at_s,
        thermal_state,
    )


def export_dict(ex: Any) -> dict:
    """The JSON of ``rotacal export --json``."""
    return {
        "controller": ex.controller,
        "kinematics": ex.kinematics,
        "current_given": ex.current_given,
        "parameters": [
            {
                "name": v.name,
                "current": v.current,
                "corrected": v.corrected,
                "std": v.std,
                "unit": v.unit,
                "from": v.source,
            }
            for v in ex.values
        ],
        "location_errors": [
            {
                "name": e.name,
                "value": e.value if e.observable else None,
                "std": e.std if e.observable else None,
                "held": e.held,
                "where": e.where,
            }
            for e in ex.errors
        ],
    }


def residual_model(model: dict, ex: Any, tables: Any = None) -> dict:
    """The model with the errors the controller now holds set to zero: what NC compensation
    (``rotacal compensate --model``) must still correct once the export is loaded. Its
    ``source.residual_after`` names the export. The covariance, which every model kind but the
    ballbar's must carry, keeps its rows: those of the held terms are zero (their residual is
    exactly zero, the export holds the identified value). ``tables``: the compensation tables
    written with it (``controller_tables``); the model terms they hold (effects, R-test map
    coefficients) are zeroed too, so the NC program does not correct them a second time."""
    out = dict(model)
    errors = {name: dict(est) for name, est in model["location_errors"].items()}
    held = {e.name for e in ex.errors if e.held}
    for name in held:
        unit = errors[name].get("unit")  # optional in a model file: kept only if given
        errors[name] = {"value": 0.0, "std": 0.0} | ({"unit": unit} if unit else {})
    out["location_errors"] = errors
    in_tables = {h for t in (tables.tables if tables is not None else []) for h in t.holds}
    if in_tables and "effects" in model:
        out["effects"] = [
            dict(f, params={k: dict(v, value=0.0, std=0.0) for k, v in f["params"].items()})
            if f.get("id") in in_tables
            else f
            for f in model["effects"]
        ]
    if in_tables and "map_coefficients" in model:
        out["map_coefficients"] = {
            k: (dict(v, value=0.0, std=0.0) if isinstance(v, dict) else 0.0)
            if k in in_tables
            else v
            for k, v in model["map_coefficients"].items()
        }

    def zeroed(name: str) -> bool:
        return name in held or name in in_tables or name.split(".", 1)[0] in in_tables

    cov = model.get("covariance")
    if isinstance(cov, dict) and "parameters" in cov and "matrix" in cov:
        zero = [k for k, n in enumerate(cov["parameters"]) if zeroed(n)]
        matrix = [list(row) for row in cov["matrix"]]
        for k in zero:
            for j in range(len(matrix)):
                matrix[k][j] = 0.0 if matrix[k][j] is not None else None
                matrix[j][k] = 0.0 if matrix[j][k] is not None else None
        out["covariance"] = dict(cov) | {"matrix": matrix}
    else:
        out.pop("covariance", None)
    what = f"{ex.controller} export ({ex.kinematics})"
    if in_tables:
        what += " and its tables (" + ", ".join(sorted(in_tables)) + ")"
    out["source"] = dict(model.get("source", {})) | {"residual_after": what}
    return out


def controller_tables(
    model: str | Path,
    controller: str,
    directory: str | Path,
    spacing_deg: float = 5.0,
    ranges: dict[str, Sequence[float]] | None = None,
    axis_names: dict[str, str] | None = None,
    max_points: int = 0,
    generated_at: str = "",
    file_names: dict[str, str] | None = None,
    fanuc: dict[str, float] | None = None,
    max_cross_points: int = 0,
    isg_axis_numbers: dict[str, int] | None = None,
) -> Any:
    """The controller's compensation tables of a model's errors that move with a rotary axis
    (``rotacal export --tables``), computed in C++ (``rotacal/io/compensation_table.hpp``): a
    ``rotacal._core.CompensationTables`` whose ``tables`` each carry ``file_name`` (in
    ``directory``) and ``text``, and (LinuxCNC) ``ini`` the lines that load them. LinuxCNC
    COMP_FILEs, SINUMERIK EEC and CEC programs, ISG kw.ssfk and kw.crosscomp lists, FANUC pitch
    error data; HEIDENHAIN is refused by name (docs/controller_exports.md). ``max_points`` 0: the
    controller's own limit; ``max_cross_points`` likewise for a cross table (SINUMERIK MD18342,
    ISG kw.crosscomp). ``isg_axis_numbers``: ISG logical axis numbers by letter. ``file_names``:
    LinuxCNC, the file of an axis' table (default ``directory/comp_<axis>.txt``). ``fanuc``: the
    fields of ``rotacal._core.FanucPitchOptions`` (detection unit, data numbers, value range,
    magnification) for FANUC's pitch error compensation data."""
    rng = {k: [float(v[0]), float(v[1])] for k, v in (ranges or {}).items()}
    d = os.path.abspath(os.fspath(directory))
    if controller == "linuxcnc":
        names = {a: os.path.join(d, f"comp_{a}.txt") for a in "ABC"}
        names |= {a: os.path.abspath(os.fspath(f)) for a, f in (file_names or {}).items()}
        return _core.linuxcnc_comp_tables(
            os.fspath(model), float(spacing_deg), rng, names, int(max_points), generated_at
        )
    if controller == "siemens":
        return _core.sinumerik_tables(
            os.fspath(model),
            float(spacing_deg),
            rng,
            axis_names or {},
            int(max_points),
            int(max_cross_points),
            generated_at,
        )
    if controller == "isg":
        return _core.isg_tables(
            os.fspath(model),
            float(spacing_deg),
            rng,
            isg_axis_numbers or {},
            int(max_points),
            int(max_cross_points),
            generated_at,
        )
    if controller == "fanuc":
        o = _core.FanucPitchOptions()
        for k, v in (fanuc or {}).items():
            setattr(o, k, v)
        return _core.fanuc_pitch_tables(os.fspath(model), float(spacing_deg), rng, o, generated_at)
    mapping = (
        ": HEIDENHAIN is mapping only, its .COM/.CMA table layout and the sign of their values "
        "are only partly public (a rotary axis' positioning would be a .COM column C = F(C), "
        "its translations columns X, Y, Z = F(C), assigned in a .CMA)"
        if controller == "heidenhain"
        else ""
    )
    raise _core.InvalidArgument(
        f"--tables: compensation tables are written for linuxcnc, siemens, isg and fanuc; "
        f"{controller}'s are not{mapping} (docs/controller_exports.md, the table of error terms "
        "x controller)"
    )


def isg_sphere_centres(
    session: Any,
    model: dict,
    setup: str | None,
    kinematic: tuple[int, int],
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    precision_mm: float = 0.06,
    session_sha256: str | None = None,
) -> tuple[str, str]:
    """The measured sphere centres of an R-test set-up as the ISG kinematic optimisation takes
    them from third-party measuring equipment (TF5245, "sphere centre points already
    calculated"): an NC program that calls ``SysCalibFitInit.ecy`` (kinematic type, variant,
    number of poses), ``SysCalibFitAddRecord.ecy`` once per pose (centre X, Y, Z in mm; A, B, C
    in deg) and ``SysCalibFit.ecy`` (list format 1, precision).

    The centre of the table-fixed nest at a pose is where the machine put it: the tool-side
    sphere's commanded position minus the reading turned into the machine frame,
    ``xyz - Ry(B) Rz(C) (d - zero)`` (to first order in the errors), with the set-up's probe zero
    from the model (an rtest-joint fit of the same session), plus ``origin``: the rotary axes'
    intersection in the controller's machine coordinates. Returns (program, description).

    The probe zeros hold only for the session the model was fitted to: a session of other bytes
    (``session_sha256`` against the model's ``source``) or other nests is refused."""
    if model.get("kind") != "rtest-joint":
        raise _core.InvalidArgument(
            "--centres: needs the rtest-joint model of the same session (its probe zeros)"
        )
    fitted = (model.get("source") or {}).get("session_sha256")
    if session_sha256 is not None and fitted is not None and fitted != session_sha256:
        raise _core.InvalidArgument(
            "--centres: the model was fitted to another session "
            f"({(model.get('source') or {}).get('session', '?')}, SHA-256 {fitted[:12]}...): "
            "its probe zeros do not hold for this one"
        )
    s, _ = _rtest_displacements(session)
    setups = list(dict.fromkeys(s.setups))
    label = setup if setup is not None else setups[0]
    if label not in setups:
        raise _core.InvalidArgument(
            f"--centres-setup {label!r}: the session's set-ups are {', '.join(setups)}"
        )
    zeros = model.get("probe_zeros", {})
    if label not in zeros:
        raise _core.InvalidArgument(
            f"--centres: the model has no probe zero for set-up {label!r} "
            "(fit the same session: rotacal identify RTEST --save-model)"
        )
    nest = (model.get("nests") or {}).get(label)
    here = np.asarray(session.nests[label], dtype=float)
    if nest is None or not np.allclose(np.asarray(nest, dtype=float), here, rtol=0.0, atol=1e-3):
        raise _core.InvalidArgument(
            f"--centres: set-up {label!r} has its nest at {', '.join(f'{v:.3f}' for v in here)} mm, the model's "
            + (
                "has none"
                if nest is None
                else "at " + ", ".join(f"{float(v):.3f}" for v in nest) + " mm"
            )
            + ": the probe zeros are of another session"
        )
    zero = np.array([zeros[label][a]["value"] or 0.0 for a in "xyz"])
    rows = [i for i, x in enumerate(s.setups) if x == label]
    xyz, ang, d = (
        np.asarray(s.xyz)[rows],
        np.radians(np.asarray(s.angles_deg)[rows]),
        np.asarray(s.d)[rows],
    )
    o = np.asarray(origin, dtype=float)
    # The set-up label is the session's text: comments only through the ISG comment writer.
    lines = [
        line
        for text in (
            "rotacal export: measured sphere centres for the ISG kinematic optimisation (TF5245)",
            f"set-up {label}, {len(rows)} poses; centre = commanded sphere - Ry(B) Rz(C) (reading - probe zero)",
            f"origin (rotary axes' intersection, machine coordinates): {o[0]:.6f}, {o[1]:.6f}, {o[2]:.6f} mm",
        )
        for line in _core.comment_lines("isg", text)
    ]
    lines += [
        "#VAR",
        f"V.L.KIN_TYP = {int(kinematic[0])}",
        f"V.L.KIN_VARIANT = {int(kinematic[1])}",
        f"V.L.NUMBER_OF_POSES = {len(rows)}",
        "#ENDVAR",
        'L CYCLE [NAME = "SysCalibFitInit.ecy" @P1 = V.L.KIN_TYP @P2 = V.L.KIN_VARIANT '
        "@P3 = V.L.NUMBER_OF_POSES]",
    ]
    # The reading turned into the machine frame by the nominal table pose (the one forward
    # kinematics, no errors: Ry(B) Rz(C)).
    turned = _core.forward(session.machine, np.zeros(8), ang, d - zero)
    for p, (b, c), t in zip(xyz, ang, turned):
        centre = o + p - t
        lines.append(
            f'L CYCLE [NAME = "SysCalibFitAddRecord.ecy" @P1 = {centre[0]:.6f} @P2 = {centre[1]:.6f} '
            f"@P3 = {centre[2]:.6f} @P4 = 0 @P5 = {np.degrees(b):.6f} @P6 = {np.degrees(c):.6f}]"
        )
    lines += [
        "#VAR",
        "V.P.MAX_PRECISION = " + f"{precision_mm:g}",
        "V.P.LIST_FORMAT = 1",
        "#ENDVAR",
        'L CYCLE [NAME = "SysCalibFit.ecy" @P1 = V.P.LIST_FORMAT @P2 = V.P.MAX_PRECISION]',
        "M30",
    ]
    return "\n".join(
        lines
    ) + "\n", f"{len(rows)} measured sphere centres of set-up {label} for SysCalibFitAddRecord.ecy"


def _rtest_displacements(session: Any) -> tuple[Any, list]:
    from .rtest import with_displacements

    if session.machine != _core.MachineType.BC_trt:
        raise _core.InvalidArgument("--centres: an R-test session of a BC-trt machine")
    return with_displacements(session)
