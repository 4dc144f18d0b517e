# SPDX-License-Identifier: BSD-3-Clause
"""R-test (Oyama & Ibaraki): simulation, probe calibration, identification of the location
errors and error maps of the two rotary axes of any machine (table-table, head-table,
head-head; "B" and "C" name the tilt and the rotary axis), model files and prediction, on
numpy-backed RtestSession objects. Angles are in degrees here (as in the files); the C++ core
takes radians.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from . import _core
from .machines import Errors, machine_truth  # noqa: F401  (rotacal.rtest.machine_truth)
from .models import (
    estimate_dict,
    machine_members,
    machine_of,
    rtest_model_dict,
    rtest_model_from_dict,
)
from .results import budget_dict, noise_model_dict

# The C++ simulator's defaults (rtest/simulate.hpp: RtestSimOptions, RtestPattern): the
# measurement pattern of Oyama Sec. 3.3 (also the map grid by default) and the two nests of
# the paper's set-up (as in ../shared/data/rtest_bc_oyama.csv), table frame, mm.
_SIM_DEFAULTS = _core.RtestSimOptions()
B_GRID = [float(b) for b in _SIM_DEFAULTS.pattern.b_deg]
C_GRID = [float(c) for c in _SIM_DEFAULTS.pattern.c_deg]
DEFAULT_NESTS = [tuple(float(x) for x in row) for row in _SIM_DEFAULTS.pattern.nests]
DEFAULT_NOISE_UM = _SIM_DEFAULTS.noise_um
DEFAULT_PROBE_ZERO_UM = _SIM_DEFAULTS.probe_zero_um
DEFAULT_DWELL_S = _SIM_DEFAULTS.pattern.dwell_s
# Bounds of a pattern: positions per axis and poses in all (a day of 6-s dwells is 14400).
MAX_GRID_POINTS = 3600
MAX_POSES = 100_000


@dataclass
class RtestIdentification:
    """Result of identify_rtest; ``to_dict()`` is the JSON of ``rotacal identify --json``."""

    raw: Any
    machine: Any
    nests: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    budget: Any = None  # _core.UncertaintyBudget, attached by the CLI / uncertainty_budget

    def error_map(
        self,
        fmt: str = "json",
        b_deg: Sequence[float] | None = None,
        c_deg: Sequence[float] | None = None,
    ) -> str:
        """The error map as JSON or CSV text: on the grid (deg; tilt and rotary axis, default
        the machine's default pattern) for the joint model, at the measured grid for the paper's
        method."""
        if self.raw.method == "joint":
            grid = default_pattern(self.machine)
            b_deg = grid["b_deg"] if b_deg is None else b_deg
            c_deg = grid["c_deg"] if c_deg is None else c_deg
            return _core.rtest_error_map(self.raw, list(b_deg), list(c_deg), fmt)
        return _core.rtest_error_map(self.raw, fmt)

    def model_dict(self) -> dict:
        """The fitted joint model as a ``rotacal-model/1`` dict of kind ``rtest-joint``
        (rotacal.models), for ``save_model`` and ``predict_rtest``."""
        if self.raw.method != "joint":
            raise _core.InvalidArgument(
                "identify --save-model: the paper method's map exists only at the measured angles and "
                "predicts no other pose; use --method joint for a model file"
            )
        return rtest_model_dict(self.raw, self.nests)

    def to_dict(self) -> dict:
        r = self.raw
        out = {
            "method": r.method,
            "machine": _core.machine_name(self.machine),
            "residual_rms_um": float(r.residual_rms_um),
            "n_samples": int(r.n_samples),
            "unobservable": list(r.unobservable),
            "notes": list(self.notes) + list(r.notes),
            "error_map": json.loads(self.error_map("json")),
        }
        if r.method == "joint":
            names = list(_core.location_error_names(self.machine))
            by_name = {p.name: p for p in r.parameters}
            out["location_errors"] = {n: estimate_dict(by_name[n]) for n in names}
            if self.machine.has_head:  # minus the error of pivot_length + tool_length
                out["tool_offset_Z"] = estimate_dict(by_name["tool_offset_Z"])
            out["probe_zeros"] = {k: np.asarray(v).tolist() for k, v in r.probe_zeros.items()}
            out["converged"] = bool(r.converged)
            out["sigma_um"] = float(r.sigma_um)
            out["noise_model"] = noise_model_dict(r.noise, r.noise_refit, r.noise_correction)
        if self.budget is not None:
            out["uncertainty_budget"] = budget_dict(self.budget)
        return out


def has_displacements(session: _core.RtestSession) -> bool:
    """Whether every row has dx,dy,dz (else only raw d1,d2,d3)."""
    try:
        session.d
    except _core.InvalidArgument:
        return False
    return True


def with_displacements(
    session: _core.RtestSession, dirs: np.ndarray | None = None
) -> tuple[_core.RtestSession, list[str]]:
    """The session with dx,dy,dz filled from raw d1,d2,d3 where missing, and a note saying so.

    ``dirs`` (3, 3), rows = probe directions, e.g. from ``calibrate_probes``; by default the
    file's ``probe.N.dir``. Rows that already have dx,dy,dz keep them.
    """
    if dirs is None and has_displacements(session):
        return session, []
    out = _core.displacements_from_raw(
        session, None if dirs is None else np.asarray(dirs, dtype=float)
    )
    src = "the calibrated directions given" if dirs is not None else "the file's probe.N.dir"
    return out, [f"dx,dy,dz computed from raw d1,d2,d3 with {src} (d = Dirs^-1 raw)"]


def identify_rtest(
    session: _core.RtestSession,
    method: str = "joint",
    basis: Any | None = None,
    noise: str = "auto",
) -> RtestIdentification:
    """Identify an R-test session: method "joint" (Ceres fit with smooth maps, default) or
    "paper" (Oyama & Ibaraki's Eqs. 10-22). A session with raw d1,d2,d3 only is converted
    with its probe.N.dir first (said in the notes). ``basis``: a rotacal._core.RtestBasis for
    the joint fit (default: B polynomial to b^6, C harmonics 1-2, degree 1 in B). ``noise``:
    "auto" (AR noise model per nest and channel, GLS refit when correlated) or "white"."""
    s, notes = with_displacements(session)
    nests = {k: np.asarray(v) for k, v in session.nests.items()}
    if method == "joint":
        raw = _core.identify_rtest_joint(
            s, basis if basis is not None else _core.RtestBasis(), noise
        )
        return RtestIdentification(raw, session.machine, nests, notes)
    if basis is not None:
        raise _core.InvalidArgument("identify_rtest: the paper method takes no basis")
    if method == "paper":
        return RtestIdentification(_core.identify_rtest_paper(s), session.machine, nests, notes)
    raise _core.InvalidArgument(
        f"identify_rtest: method must be 'joint' or 'paper', got {method!r}"
    )


def monte_carlo_rtest(
    session: _core.RtestSession,
    result: RtestIdentification,
    draws: int = 100,
    *,
    seed: int = 1,
    basis: Any | None = None,
    progress: bool = True,
) -> dict:
    """Check an R-test joint fit's 1-sigma by Monte Carlo: the identified model's readings plus
    noise drawn from the noise model fitted to the session (AR per nest and channel: probe
    zeros that wander between poses are re-simulated) when the fit used it, else white; each
    draw refitted the same way. Same dict as rotacal.ballbar.monte_carlo."""
    from .progress import ProgressBar

    if result.raw.method != "joint":
        raise _core.InvalidArgument("monte_carlo: only an R-test joint fit is supported")
    s, _ = with_displacements(session)
    bar = ProgressBar("Monte Carlo", draws, " draws") if progress else None
    mc = _core.monte_carlo_rtest(
        s,
        result.raw,
        draws,
        seed,
        basis if basis is not None else _core.RtestBasis(),
        progress=(lambda done, total: bar.update(done)) if bar else None,
    )
    if bar:
        bar.close()
    from .results import monte_carlo_dict

    return monte_carlo_dict(mc, draws, result.raw.sigma_um, keep=lambda name: name.startswith("E_"))


# ------------------------------------------------------------------------- prediction


def predict_rtest(
    model: Mapping, session: _core.RtestSession, probe_zeros: str = "none", source: str = "<model>"
) -> _core.RtestSession:
    """The session with dx,dy,dz predicted by an ``rtest-joint`` model dict (``load_model``),
    plus 1-sigma columns dx_std, dy_std, dz_std (mm).

    probe_zeros : "none" (default) predicts the table's error as a nest with zero probe offsets
        reads it, the only choice for a new set-up, whose probe zeros are unknown; "fitted" adds
        the probe zeros fitted for the set-ups of the same label, which must be at the same nest
        position (the same physical set-up, e.g. held-out poses of the fitted session).
    """
    m, nests, zeros = rtest_model_from_dict(dict(model), source)
    if probe_zeros == "none":
        return _core.predict_rtest_session(m, session)
    if probe_zeros != "fitted":
        raise _core.InvalidArgument(
            f"predict: probe_zeros must be 'none' or 'fitted', got {probe_zeros!r}"
        )
    for setup in dict.fromkeys(session.setups):
        if setup not in zeros or setup not in nests:
            raise _core.InvalidArgument(f"{source}: no fitted probe zero for set-up '{setup}'")
        here = np.asarray(session.nests[setup])
        if np.max(np.abs(here - nests[setup])) > 1e-6:
            raise _core.InvalidArgument(
                f"{source}: set-up '{setup}' was fitted with its nest at {nests[setup].tolist()}, the "
                f"session has it at {here.tolist()}: fitted probe zeros belong to the fitted set-up"
            )
    return _core.predict_rtest_session(
        m, session, {k: zeros[k] for k in dict.fromkeys(session.setups)}
    )


def prediction_rms_um(
    model: Mapping, session: _core.RtestSession, source: str = "<model>"
) -> float:
    """RMS (um) of measured - predicted readings after one constant offset per set-up (its
    probe zero), over all components; raw-only sessions are converted with probe.N.dir."""
    m, _, _ = rtest_model_from_dict(dict(model), source)
    s, _ = with_displacements(session)
    return float(_core.rtest_prediction_rms_um(m, s))


# ------------------------------------------------------------------------- simulation


def angle_grid(
    start: float, stop: float, step: float, what: str, full_turn: bool = False
) -> list[float]:
    """start, start + step, ... up to stop (inclusive, deg). With ``full_turn`` an end at
    start + 360 is left out: it is the start position again."""
    if (
        not (np.isfinite(start) and np.isfinite(stop) and np.isfinite(step))
        or step <= 0
        or stop < start
    ):
        raise _core.InvalidArgument(
            f"{what}: need start <= stop and step > 0, got {start:g},{stop:g} step {step:g}"
        )
    n = int(np.floor((stop - start) / step + 1e-9))
    if n + 1 > MAX_GRID_POINTS:
        raise _core.InvalidArgument(
            f"{what}: {start:g} to {stop:g} in steps of {step:g} deg is {n + 1} positions, "
            f"more than {MAX_GRID_POINTS}"
        )
    grid = [start + k * step for k in range(n + 1)]
    if full_turn and abs(grid[-1] - (start + 360.0)) < 1e-9 and len(grid) > 1:
        grid.pop()
    return [round(g, 9) for g in grid]


def default_pattern(machine: str | Any) -> dict:
    """The default pattern of a machine (name or MachineType): ``b_deg`` (tilt axis), ``c_deg``
    (rotary axis), ``nests``, fitted to its rotary limits and travel (the paper's on BC-trt)."""
    mtype = machine if isinstance(machine, _core.MachineType) else _core.parse_machine_type(machine)
    p = _core.default_rtest_pattern(mtype)
    return {
        "b_deg": [float(b) for b in p.b_deg],
        "c_deg": [float(c) for c in p.c_deg],
        "nests": [tuple(float(x) for x in row) for row in p.nests],
    }


def simulate_rtest(
    errors: Errors = "random",
    effects: Mapping[str, Any] | None = None,
    *,
    machine: str = "BC-trt",
    b_deg: Sequence[float] | None = None,
    c_deg: Sequence[float] | None = None,
    nests: Sequence[Sequence[float]] | None = None,
    noise_um: float = DEFAULT_NOISE_UM,
    probe_zero_um: float = DEFAULT_PROBE_ZERO_UM,
    probe_dirs: np.ndarray | None = None,
    write_d: bool = True,
    dwell_s: float = DEFAULT_DWELL_S,
    seed: int = 1,
) -> tuple[_core.RtestSession, dict]:
    """Simulate an R-test session (Oyama Sec. 3.3 pattern: B outer, C inner, one nest after the
    other) on a machine with location errors and catalogue effects (shared/spec/effects.md).

    Parameters
    ----------
    errors : "random" (N(0, 30 um), N(0, 50 urad), seeded), "zero", a dict NAME -> value
        (mm, rad; others zero) or the 8 values in location_error_names order.
    effects : catalogue id -> parameter value (one-parameter effects) or list of values,
        e.g. {"gravity_sag_B": 0.006, "coning_B": 1.45e-4, "axial_motion_C_h2": [0.002, -0.001]}.
    machine : a built-in name (``rotacal._core.builtin_machine_names()``); on a machine with
        head axes ``effects`` may hold ``tool_offset_Z`` (minus the error of pivot + tool length).
    b_deg, c_deg : the grid (deg) of the tilt and the rotary axis. nests : nominal ball centres,
        table frame (mm). Each left out is the machine's default (``default_pattern``); a pattern
        outside the machine's rotary limits or travel is refused, naming the axis.
    noise_um : 1-sigma per reading (um). probe_zero_um : 1-sigma of each set-up's probe zero.
    probe_dirs : (3, 3), rows = unit probe directions: raw d1,d2,d3 with probe.N.dir are written
        (and dx,dy,dz unless ``write_d`` is False).
    seed : draws the random errors, the probe zeros and the noise.

    Returns
    -------
    (session, truth) where truth has the shape of ../shared/data/*.truth.json: errors, effects,
    nests, noise_um, plus probe_zeros (mm per set-up), the pattern, seed and probe_dirs.
    """
    mtype, e, ids, params, effects_out = machine_truth(errors, effects, machine, seed)
    default = default_pattern(mtype)
    b_deg = default["b_deg"] if b_deg is None else b_deg
    c_deg = default["c_deg"] if c_deg is None else c_deg
    nests = default["nests"] if nests is None else nests
    nest_arr = np.asarray(nests, dtype=float).reshape(-1, 3)
    n_poses = len(b_deg) * len(c_deg) * len(nest_arr)
    if n_poses > MAX_POSES:
        raise _core.InvalidArgument(
            f"simulate_rtest: {len(b_deg)} B x {len(c_deg)} C x {len(nest_arr)} nests is "
            f"{n_poses} poses, more than {MAX_POSES}"
        )
    if not (np.isfinite(dwell_s) and dwell_s > 0):
        raise _core.InvalidArgument(
            f"simulate_rtest: dwell_s must be > 0 s (time must increase), got {dwell_s:g}"
        )
    if not (
        np.isfinite(noise_um)
        and noise_um >= 0
        and np.isfinite(probe_zero_um)
        and probe_zero_um >= 0
    ):
        raise _core.InvalidArgument(
            "simulate_rtest: noise_um and probe_zero_um must be finite and >= 0"
        )
    if not 0 <= int(seed) < 2**32:
        raise _core.InvalidArgument(f"simulate_rtest: seed must be in [0, 2^32 - 1], got {seed}")
    dirs = None if probe_dirs is None else np.asarray(probe_dirs, dtype=float)
    session, zeros = _core.simulate_rtest(
        mtype,
        e,
        ids,
        params,
        list(map(float, b_deg)),
        list(map(float, c_deg)),
        nest_arr,
        float(dwell_s),
        float(noise_um),
        float(probe_zero_um),
        dirs,
        bool(write_d),
        int(seed),
    )
    truth = {
        "errors": dict(zip(_core.location_error_names(mtype), e.tolist())),
        "effects": effects_out,
        "nests": nest_arr.tolist(),
        "noise_um": float(noise_um),
        "probe_zeros": np.asarray(zeros).tolist(),
        "probe_zero_um": float(probe_zero_um),
        **machine_members(mtype),
        "pattern": {
            "b_deg": list(map(float, b_deg)),
            "c_deg": list(map(float, c_deg)),
            "dwell_s": float(dwell_s),
        },
        "seed": int(seed),
    }
    if dirs is not None:
        truth["probe_dirs"] = dirs.tolist()
    return session, truth


def truth_readings(
    truth: Mapping, session: _core.RtestSession, probe_zeros: bool = True
) -> np.ndarray:
    """Noise-free dx,dy,dz (N, 3) of every row of a session on the machine of a truth dict
    (``simulate_rtest``), with the truth's probe zero of each set-up (set-up "k" is nest k)
    unless ``probe_zeros`` is False."""
    mtype = machine_of({"machine": "BC-trt", **truth}, "truth")
    names = list(_core.location_error_names(mtype))
    e = np.array([truth["errors"][n] for n in names])
    ids = list(truth.get("effects", {}))
    params = [float(v) for i in ids for v in np.atleast_1d(truth["effects"][i])]
    setups = np.asarray(session.setups, dtype=object)
    angles = np.radians(np.asarray(session.angles_deg))
    time = np.asarray(session.time)
    out = np.zeros((len(setups), 3))
    a_ref = np.asarray(session.xyz).mean(axis=0)  # effects.md: the session's mean commanded xyz
    for setup in dict.fromkeys(setups):
        sel = setups == setup
        q = np.asarray(session.nests[setup])
        out[sel] = _core.rtest_readings(mtype, e, ids, params, q, angles[sel], time[sel], a_ref)
        if probe_zeros:
            out[sel] += np.asarray(truth["probe_zeros"][int(setup) - 1])
    return out


def save_truth(truth: Mapping, path: str | Path, other_outputs: Sequence[str | Path] = ()) -> None:
    """Write a truth dict as strict JSON by the output rule (rotacal.outputs)."""
    from . import jsontext
    from .outputs import write_output

    write_output(
        path, jsontext.dumps(dict(truth)) + "\n", other_outputs=[str(o) for o in other_outputs]
    )


# ------------------------------------------------------------------------- device calibration


def calibrate_probes(moves: np.ndarray, readings: np.ndarray) -> Any:
    """Identify the probe directions of an R-test nest (Oyama Sec. 3.2) from known linear moves.

    With the rotary axes at 0 the sphere is moved by commanded steps ``moves`` (N, 3, mm,
    machine = table frame) and the three probes read ``readings`` (N, 3, mm). Per probe i,
    reading_ik = g_i . move_k + zero_i is solved by linear least squares; dir_i = g_i / |g_i|.
    Needs >= 5 moves spanning 3-D (e.g. ``rotacal._core.default_calibration_moves()``).

    Returns a ProbeCalibration: ``dirs`` (3, 3, rows = unit directions), ``gains``, ``zeros``
    (mm), ``direction_std_rad`` and ``gain_std`` (1 sigma), ``residuals``, ``sigma_um``.
    Raises InvalidArgument (too few moves) or DegenerateGeometry (moves not spanning 3-D).
    """
    return _core.calibrate_probe_directions(
        np.asarray(moves, dtype=float), np.asarray(readings, dtype=float)
    )


def calibrate_sphere_offset(
    dirs: np.ndarray, spindle_deg: Sequence[float], readings: np.ndarray
) -> Any:
    """The sphere's offset from the spindle axis from spindle indexing (Oyama Sec. 3.2).

    The spindle is turned to the angles ``spindle_deg`` (N,) with the machine at rest; the
    probes (directions ``dirs``, rows, e.g. from ``calibrate_probes``) read ``readings``
    (N, 3, mm). The sphere centre runs on a circle c + Rz(theta) o about the spindle axis,
    fitted linearly. Needs >= 3 distinct angles.

    Returns a SphereOffsetCalibration: ``offset`` (x, y at spindle angle 0, mm), ``offset_std``,
    ``centre`` and ``residual_rms_um``. Use ``compensate_sphere_offset`` on a session measured
    with that spindle orientation.
    """
    return _core.calibrate_sphere_offset(
        np.asarray(dirs, dtype=float),
        np.radians(np.asarray(spindle_deg, dtype=float)),
        np.asarray(readings, dtype=float),
    )


def compensate_sphere_offset(
    session: _core.RtestSession, offset: Sequence[float]
) -> _core.RtestSession:
    """The session with a sphere offset (x, y, mm, spindle frame: it turns with a head) taken out
    of every dx,dy,dz, on any machine."""
    s, _ = with_displacements(session)
    return _core.compensate_sphere_offset(s, np.asarray(offset, dtype=float))
