# SPDX-License-Identifier: BSD-3-Clause
"""Machines: loading one by built-in name or from a rotacal-machine/1 file, drawing it as text;
simulated machines: the paper's Table 2 machine, random location errors, effects, and the truth
a simulation runs on."""

from __future__ import annotations

import json
import os
from typing import Any, Mapping, Sequence, Union

import numpy as np

from . import _core

# Flynn et al. 2016, Table 2, uncompensated: the AC-trt machine of the paper's experiment (mm, rad).
TABLE2_ERRORS = {
    "E_Y0A": 0.0726,
    "E_Z0A": -0.0202,
    "E_B0A": 1.1284e-05,
    "E_C0A": -0.000113006,
    "E_X0C": 0.0283,
    "E_Y0C": 0.1041,
    "E_A0C": 5.1954e-06,
    "E_B0C": -4.1544e-05,
}

# A machine description is a few hundred bytes; a larger file is not one (and is not read whole).
MAX_DESCRIPTION_BYTES = 1 << 20


def _looks_like_path(text: str) -> bool:
    return os.path.exists(text) or text.lower().endswith(".json") or os.sep in text or "/" in text


def load_machine(machine: Any) -> _core.MachineType:
    """The machine ``machine`` names: a MachineType (returned as is), a built-in name
    (``_core.builtin_machine_names()``: 'AC-trt', 'B-head-C-table', ...) or the path of a
    rotacal-machine/1 JSON file (shared/spec/formats.md, "Any 5-axis machine"; docs/machines.md).

    Raises InvalidArgument for an unknown name (the message lists the built-ins) or a
    description that breaks the spec (the message names the file and the field), IoError for a
    file that cannot be read. A built-in name wins over a file of the same name in the working
    folder; write ./AC-trt to read such a file."""
    if isinstance(machine, _core.MachineType):
        return machine
    if isinstance(machine, os.PathLike):
        machine = os.fspath(machine)
    if not isinstance(machine, str):
        raise _core.InvalidArgument(
            f"machine: a built-in name or a file path, got {type(machine).__name__}"
        )
    if machine in _core.builtin_machine_names():
        return _core.parse_machine_type(machine)
    if not _looks_like_path(machine):
        _core.parse_machine_type(machine)  # raises: unknown machine, the built-ins named
    from .sessions import checked_path

    path = checked_path(machine, "machine description")
    if os.path.isdir(path):
        raise _core.IoError(f"{path}: is a directory, not a machine description file")
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_DESCRIPTION_BYTES + 1)
    except OSError as e:
        raise _core.IoError(f"{path}: cannot read the machine description: {e.strerror}") from None
    if len(data) > MAX_DESCRIPTION_BYTES:
        raise _core.InvalidArgument(
            f"{path}: larger than {MAX_DESCRIPTION_BYTES} bytes, not a machine description"
        )
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise _core.InvalidArgument(f"{path}: not UTF-8 text (byte {e.start + 1})") from None
    m = _core.MachineType.from_description(text, path)
    name = _core.machine_name(m)
    if not m.is_builtin and name in _core.builtin_machine_names():
        # Sessions, models and the history know a machine by its name: this one would be taken
        # for the built-in (its history merged into the built-in's).
        raise _core.InvalidArgument(
            f"{path}: name: '{name}' is a built-in machine's, whose kinematics differ from "
            "this description's: give the machine a name of its own"
        )
    return m


def machine_dict(machine: Any) -> dict:
    """What ``rotacal machines show --json`` prints: names, configuration, the location error
    names of each axis, the planner's defaults and the description itself."""
    m = load_machine(machine)
    desc = json.loads(m.description_json)
    names = list(_core.location_error_names(m))
    axes = []
    for k, (side, ax) in enumerate(_chain_axes(desc)):
        axes.append(
            {
                "name": ax["name"],
                "side": side,
                "role": "rotary" if ax["name"] == m.rot_axis else "tilt",
                "location_errors": names[4 * k : 4 * k + 4],
            }
        )
    return {
        "name": m.name,
        "configuration": m.configuration,
        "builtin": m.is_builtin,
        "axis_names": list(m.axis_names),
        "tilt_axis": m.tilt_axis,
        "rot_axis": m.rot_axis,
        "has_head": m.has_head,
        "axes": axes,
        "location_error_names": names,
        "default_tilt_range_deg": list(_core.default_tilt_range_deg(m)),
        "default_axial_c_tilt_deg": _core.default_axial_c_tilt_deg(m),
        "description": desc,
    }


def _chain_axes(desc: Mapping) -> list[tuple[str, dict]]:
    """(side, axis) in chain order: table axes from the bed outwards, then head axes."""
    return [("table", a) for a in desc["table_axes"]] + [("head", a) for a in desc["head_axes"]]


def _vec(v: Sequence[float]) -> str:
    return "(" + ", ".join(f"{x:.4g}" if abs(x) > 1e-12 else "0" for x in v) + ")"


def _uv(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The u, v of a nutating axis (formats.md): e the first of +X, +Y, +Z with |e.n| <= 0.5,
    u = unit(e x n), v = n x u."""
    n = n / np.linalg.norm(n)
    e = next(e for e in np.eye(3) if abs(e @ n) <= 0.5)
    u = np.cross(e, n)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def machine_drawing(machine: Any) -> str:
    """The machine as text: its chain from the tool to the workpiece, each rotary axis with its
    side, role, direction, point, limits and location error names (formats.md)."""
    m = load_machine(machine)
    d = json.loads(m.description_json)
    names = list(_core.location_error_names(m))
    chain = _chain_axes(d)
    out = [
        f"{m.name}: {m.configuration}, rotary axes {', '.join(m.axis_names)} in chain order; "
        f"tilt axis {m.tilt_axis}, rotary axis {m.rot_axis}",
        "",
    ]

    def axis_block(k: int, side: str, ax: dict, carries: str) -> list[str]:
        n = np.asarray(ax["direction"], float)
        frame = "relative to the controlled point" if side == "head" else "machine frame"
        lim = ax.get("limits_deg")
        e = names[4 * k : 4 * k + 4]
        role = "rotary" if ax["name"] == m.rot_axis else "tilt"
        lines = [
            f"  [{ax['name']}]  {side} axis {'T' if side == 'table' else 'H'}"
            f"{1 + sum(1 for s, _ in chain[:k] if s == side)} ({role}), carries {carries}",
            f"   |    direction {_vec(n)}, through {_vec(ax.get('point', [0, 0, 0]))} mm ({frame}), "
            + (f"limits {lim[0]:g} .. {lim[1]:g} deg" if lim else "endless"),
            f"   |    location errors: {e[0]}, {e[1]} (line position, mm); {e[2]}, {e[3]} (direction, rad)",
        ]
        if e[0].startswith("E_U0"):
            u, v = _uv(n)
            lines.append(f"   |    nutating: u = {_vec(u)}, v = {_vec(v)}")
        return lines

    heads = [(k, a) for k, (s, a) in enumerate(chain) if s == "head"]
    tables = [(k, a) for k, (s, a) in enumerate(chain) if s == "table"]
    L = d["pivot_length"] + d["tool_length"]
    if heads:
        out.append(
            f"  (o)  tool ball: t = (0, 0, {-L:g}) mm from the controlled point "
            f"(pivot_length {d['pivot_length']:g} + tool_length {d['tool_length']:g})"
        )
        out.append("   |")
        for i, (k, a) in reversed(list(enumerate(heads))):
            carries = (
                "the spindle" if i == len(heads) - 1 else f"head axis {heads[i + 1][1]['name']}"
            )
            out += axis_block(k, "head", a, carries) + ["   |"]
    else:
        out.append("  (o)  tool ball = the controlled point (no head axes)")
        out.append("   |")
    travel = d.get("travel_mm")
    out.append(
        "  XYZ  linear axes: the controlled point (the X, Y, Z of sessions and programs)"
        + (
            "; travel "
            + ", ".join(f"{c} {lo:g} .. {hi:g}" for c, (lo, hi) in zip("XYZ", travel))
            + " mm"
            if travel
            else ""
        )
    )
    out.append("   |")
    out.append("  ===  bed")
    for i, (k, a) in enumerate(tables):
        out.append("   |")
        carries = (
            "the workpiece" if i == len(tables) - 1 else f"table axis {tables[i + 1][1]['name']}"
        )
        out += axis_block(k, "table", a, carries)
    out.append("   |")
    out.append(
        "  [W]  workpiece (table frame" + (")" if tables else " = machine frame: no table axes)")
    )
    return "\n".join(out) + "\n"


# Defaults of a simulated ballbar machine: 1-sigma pivot placement error (mm) and reading noise (um).
PIVOT_ERROR_MM = 0.02
BALLBAR_NOISE_UM = 0.5

# "random", "zero", "table2", NAME -> value (others zero), or the 8 values in location_error_names order.
Errors = Union[str, Mapping[str, float], Sequence[float], np.ndarray]


def random_location_errors(
    machine: Any, rng: np.random.Generator, position_mm: float = 0.03, angle_rad: float = 5e-5
) -> np.ndarray:
    """Location errors drawn as N(0, position_mm) and N(0, angle_rad), in the machine's order."""
    # Order of every errors vector: tilt position (2), tilt orientation (2), C position (2),
    # C orientation (2).
    scale = np.array([position_mm] * 2 + [angle_rad] * 2 + [position_mm] * 2 + [angle_rad] * 2)
    return rng.normal(0.0, 1.0, 8) * scale


def location_errors(errors: Errors, machine: Any, rng: np.random.Generator) -> np.ndarray:
    """The 8 location errors (mm, rad, location_error_names order) described by ``errors``.
    Only "random" draws from ``rng``, so a seed gives the same pivot error whatever the errors."""
    names = list(_core.location_error_names(machine))
    if isinstance(errors, str):
        if errors == "random":
            return random_location_errors(machine, rng)
        if errors == "zero":
            return np.zeros(8)
        if errors == "table2":
            if machine != _core.MachineType.AC_trt:
                raise _core.InvalidArgument("--errors table2 is the paper's AC-trt machine")
            return np.array([TABLE2_ERRORS[n] for n in names])
        raise _core.InvalidArgument(
            f"errors: 'random', 'zero', 'table2' or NAME=VALUE pairs, got {errors!r}"
        )
    if isinstance(errors, Mapping):
        unknown = [k for k in errors if k not in names]
        if unknown:
            raise _core.InvalidArgument(
                f"--errors: {', '.join(map(repr, unknown))} not a location error of "
                f"{_core.machine_name(machine)} ({', '.join(names)})"
            )
        v = np.array([float(errors.get(n, 0.0)) for n in names])
    else:
        v = np.asarray(errors, dtype=float)
        if v.shape != (8,):
            raise _core.InvalidArgument(
                f"errors: expected 8 values in the order {', '.join(names)}"
            )
    if not np.all(np.isfinite(v)):
        raise _core.InvalidArgument("--errors: values must be finite")
    return v


def effect_parameters(
    effects: Mapping[str, Any] | None,
) -> tuple[list[str], list[float], dict[str, list[float]]]:
    """Catalogue effects id -> value or values as (ids, parameters back to back, id -> values),
    each checked against its catalogue entry (shared/spec/effects.md)."""
    ids: list[str] = []
    params: list[float] = []
    out: dict[str, list[float]] = {}
    for eid, val in (effects or {}).items():
        eff = _core.Effect(eid)
        vals = [float(v) for v in np.atleast_1d(np.asarray(val, dtype=float))]
        if len(vals) != eff.num_params:
            raise _core.InvalidArgument(
                f"--effect {eid}: takes {eff.num_params} values "
                f"({', '.join(eff.param_names)}), got {len(vals)}"
            )
        if not all(np.isfinite(vals)):
            raise _core.InvalidArgument(f"--effect {eid}: values must be finite")
        ids.append(eff.id)
        params.extend(vals)
        out[eff.id] = vals
    return ids, params, out


def machine_truth(errors: Errors, effects: Mapping[str, Any] | None, machine: str, seed: int):
    """The simulated machine: (machine type, 8 location errors, effect ids, their parameters back
    to back, effects as given for the truth file). Random errors are drawn from ``seed``."""
    mtype = load_machine(machine)
    e = location_errors(errors, mtype, np.random.default_rng(seed))
    ids, params, values = effect_parameters(effects)
    return mtype, e, ids, params, {k: (v[0] if len(v) == 1 else v) for k, v in values.items()}


# ------------------------------------------------------------------------- ballbar


def ballbar_truth(
    machine: Any,
    errors: Errors = "random",
    effects: Mapping[str, Any] | None = None,
    *,
    pivot_error_mm: float = PIVOT_ERROR_MM,
    noise_um: float = BALLBAR_NOISE_UM,
    seed: int = 1,
) -> dict:
    """The machine a ballbar simulation runs on, as the truth file holds it: errors by name,
    the pivot set-up error (N(0, pivot_error_mm) per axis), effects, noise and seed. One
    generator from ``seed`` draws random errors first, then the pivot error."""
    names = list(_core.location_error_names(machine))
    rng = np.random.default_rng(seed)
    e = location_errors(errors, machine, rng)
    _, _, values = effect_parameters(effects)
    return {
        "errors": dict(zip(names, e.tolist())),
        "pivot_error": rng.normal(0.0, pivot_error_mm, 3).tolist(),
        "effects": values,
        "noise_um": noise_um,
        "seed": seed,
    }


def ballbar_machine_model(setup: Any, truth: Mapping) -> _core.BallbarMachineModel:
    """The simulated machine of a ballbar truth dict (errors, pivot error, effects) on ``setup``."""
    names = list(_core.location_error_names(setup.machine))
    ids, params, _ = effect_parameters(truth["effects"])
    return _core.BallbarMachineModel(
        setup.machine,
        np.array([truth["errors"][n] for n in names]),
        np.asarray(setup.pivot) + np.array(truth["pivot_error"]),
        ids,
        params,
    )


def simulate_ballbar_test(
    setup: Any, truth: Mapping
) -> tuple[_core.BallbarSession, _core.BallbarMachineModel]:
    """Plan the test of ``setup``, run it on the machine of ``truth``: (session, machine model)."""
    plan = _core.plan_ballbar_test(setup, None)
    model = ballbar_machine_model(setup, truth)
    return _core.simulate_ballbar(
        plan.commanded_session(), model, truth["noise_um"], truth["seed"]
    ), model
