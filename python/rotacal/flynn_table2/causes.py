# SPDX-License-Identifier: BSD-3-Clause
"""What the paper does not give (the assumptions) and the causes the analysis tries: every
sized catalogue effect constant in both runs, and the changes between the runs, each with its
plausible size."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np

from .. import _core
from .table import NAMES, SCALE as _SCALE, UNIT as _UNIT


@dataclass(frozen=True)
class Assumptions:
    """What the paper does not give. Defaults: rotacal's default single set-up test."""

    ballbar_length: float = 100.0  # mm
    pivot: tuple = (120.0, 0.0, 60.0)  # table frame, mm (O_x, 0, O_z)
    tilt_range_deg: tuple = (-90.0, 90.0)
    rot_range_deg: tuple = (0.0, 360.0)
    step_deg: float = 1.0
    noise_um: float = 0.5  # marginal sigma of the ballbar reading
    noise_rho: float = 0.0  # AR(1) correlation of successive samples
    hours_between_runs: float = 1.0
    thermal_time_constant_h: float = 1.0  # of the machine structure (1 - exp(-dt/tau))
    method: str = "paper"  # identification of both runs, as in the paper

    def setup(self):
        s = _core.BallbarSetup()
        s.machine = _core.MachineType.AC_trt
        s.ballbar_length = float(self.ballbar_length)
        s.pivot = np.array(self.pivot, dtype=float)
        s.tilt_range_deg = np.array(self.tilt_range_deg, dtype=float)
        s.rot_range_deg = np.array(self.rot_range_deg, dtype=float)
        s.step_deg = float(self.step_deg)
        return s

    def check(self) -> None:
        if not (self.noise_um > 0 and math.isfinite(self.noise_um)):
            raise _core.InvalidArgument(f"assumptions.noise_um must be > 0, got {self.noise_um}")
        if not (0.0 <= self.noise_rho < 1.0):
            raise _core.InvalidArgument(
                f"assumptions.noise_rho must be in [0, 1), got {self.noise_rho}"
            )
        if not (self.hours_between_runs >= 0 and math.isfinite(self.hours_between_runs)):
            raise _core.InvalidArgument(
                f"assumptions.hours_between_runs must be >= 0, got {self.hours_between_runs}"
            )
        if not self.thermal_time_constant_h > 0:
            raise _core.InvalidArgument("assumptions.thermal_time_constant_h must be > 0")
        if self.method not in ("paper", "joint"):
            raise _core.InvalidArgument(
                f"assumptions.method must be 'paper' or 'joint', got {self.method!r}"
            )


# Plausible sizes (half-widths of a rectangular distribution, as in GUM type B): the brief's
# table (squareness 20 urad, straightness 5 um over 300 mm, drift 2 um over the test, tool
# length 10 um, bar length calibration 1 um) and, for the rest, typical sizes of a
# machining centre stated here as assumptions. Keys are effect-id prefixes; values in the
# effect's own unit, except "*_over_test" (mm over the test duration).
PLAUSIBLE_CONSTANT = {
    "ballbar_length_offset": 0.001,
    "ballbar_thermal_drift_over_test": 0.002,
    "tool_offset_Z": 0.010,
    "tool_offset_X": 0.010,
    "tool_offset_Y": 0.010,
    "rotary_zero_offset": 50e-6,
    "angular_positioning": 25e-6,
    "radial_motion": 0.002,
    "axial_motion": 0.002,
    "tilt_motion": 5e-6,
    "gravity_sag": 0.005,
    "coning": 20e-6,
    "linear_squareness": 20e-6,
    "linear_scale": 20e-6,
    "thermal_drift_over_test": 0.002,
    "pivot": 0.010,
    "straightness_c2": 0.005 / 1.5**2,  # 5 um at u = 1.5 (150 mm from the middle of 300 mm)
}
# Changes between the runs. Thermal ones reach these sizes after a full warm-up and scale with
# (1 - exp(-dt/tau)); set-up ones (tool, bar, drift rate) do not depend on dt.
PLAUSIBLE_CHANGE = {
    "axis_position": 0.010,
    "axis_orientation": 10e-6,
    "table_shift": 0.010,
    "tool_offset_Z": 0.010,
    "ballbar_length_offset": 0.001,
    "drift_over_test": 0.002,
    "pivot": 0.005,
    "linear_squareness": 5e-6,
    "linear_scale": 12e-6,
}
_THERMAL_CHANGES = {
    "axis_position",
    "axis_orientation",
    "table_shift",
    "linear_squareness",
    "linear_scale",
    "pivot",
}


@dataclass
class Candidate:
    """One cause: how it changes the simulated machine in run 1 and run 2, for a size s."""

    id: str
    kind: str  # "constant" or "between_runs"
    cause: str
    unit: str  # display unit of the size
    display: float  # display value = display * size (internal unit)
    plausible: float  # half-width, internal unit
    family: str
    # (errors delta (8), {effect: params}, pivot delta (3)) of run 1 and run 2 for size s
    runs: Callable[[float], tuple] = field(repr=False)


def _effect_size(eid: str, duration: float) -> Optional[tuple]:
    """(plausible size, display factor, display unit) for a one-parameter effect or a
    parameter of a harmonic one; None if the table gives no size."""
    for key, val in PLAUSIBLE_CONSTANT.items():
        if key.endswith("_over_test"):
            prefix = key[: -len("_over_test")]
            if eid.startswith(prefix):
                return val / duration, 1e3 * duration, "um over the test"
        elif eid.startswith(key):
            unit = _core.Effect(eid).param_units[0]
            factor, disp = {
                "mm": (1e3, "um"),
                "rad": (1e6, "urad"),
                "mm/mm": (1e6, "um/m"),
                "rad/rad": (1e6, "urad/rad"),
            }.get(unit, (1.0, unit))
            return val, factor, disp
    return None


def no_change(_size: float = 0.0) -> tuple:
    return np.zeros(8), {}, np.zeros(3)


def candidates(a: Assumptions, duration: float) -> list[Candidate]:
    """Every cause the analysis tries: each sized parameter of each catalogue effect that
    exists for AC-trt, constant in both runs; and the changes between the runs."""
    return constant_candidates(duration) + between_run_candidates(a, duration)


def constant_candidates(duration: float) -> list[Candidate]:
    """Each sized parameter of each catalogue effect that exists for AC-trt, and the pivot's
    set-up error, the same in both runs."""
    out: list[Candidate] = []
    for eff in _core.effect_catalogue(_core.MachineType.AC_trt, 2):
        eid = eff.id
        if eid.startswith("straightness_"):
            names = [n for n in eff.param_names]
            if "c2" not in names:
                continue
            sized = (PLAUSIBLE_CONSTANT["straightness_c2"], 1e3, "um at u = 1")
            params = ["c2"]
        else:
            sized = _effect_size(eid, duration)
            params = list(eff.param_names) if not eid.startswith("thermal_warmup") else []
        if sized is None or not params:
            continue
        plaus, disp, unit = sized
        for pname in params:
            k = list(eff.param_names).index(pname)

            def runs(s, eid=eid, k=k, n=eff.num_params):
                p = [0.0] * n
                p[k] = s
                return (np.zeros(8), {eid: p}, np.zeros(3)), (np.zeros(8), {eid: p}, np.zeros(3))

            cid = eid if eff.num_params == 1 else f"{eid}.{pname}"
            out.append(
                Candidate(
                    f"constant:{cid}",
                    "constant",
                    eff.cause,
                    unit,
                    disp,
                    plaus,
                    family=eid.rsplit("_h", 1)[0] if "_h" in eid else eid,
                    runs=runs,
                )
            )

    # The pivot ball placed off its nominal position (set-up), the same in both runs.
    for axis in "XYZ":
        piv = np.eye(3)["XYZ".index(axis)]
        out.append(
            Candidate(
                f"constant:pivot_{axis}",
                "constant",
                f"pivot placed off its nominal position along {axis}",
                "um",
                1e3,
                PLAUSIBLE_CONSTANT["pivot"],
                "pivot",
                runs=lambda s, piv=piv: ((np.zeros(8), {}, piv * s),) * 2,
            )
        )

    return out


def between_run_candidates(a: Assumptions, duration: float) -> list[Candidate]:
    """The changes between the two runs: location errors (thermal state), the table shifted,
    the pivot moved, the tool and bar lengths, the drifts, squareness and scale."""
    out: list[Candidate] = []
    f = 1.0 - math.exp(-a.hours_between_runs / a.thermal_time_constant_h)

    def change(cid, cause, family, unit, disp, plaus, run2):
        scale = f if family in _THERMAL_CHANGES else 1.0
        out.append(
            Candidate(
                f"between_runs:{cid}",
                "between_runs",
                cause,
                unit,
                disp,
                plaus * scale,
                family,
                runs=lambda s: (no_change(s), run2(s)),
            )
        )

    for k, n in enumerate(NAMES):
        pos = k % 4 < 2
        d = np.zeros(8)
        d[k] = 1.0
        change(
            n,
            f"{n} changed between the runs (thermal state of the rotary axes)",
            "axis_position" if pos else "axis_orientation",
            _UNIT[k],
            _SCALE[k],
            PLAUSIBLE_CHANGE["axis_position" if pos else "axis_orientation"],
            lambda s, d=d: (d * s, {}, np.zeros(3)),
        )
    # The whole table (both rotary axes and the pivot on it) shifted in the machine frame:
    # X moves the C axis, Y both axes, Z the A axis (C's Z position is no location error).
    for axis, idx in (("X", [4]), ("Y", [0, 5]), ("Z", [1])):
        d = np.zeros(8)
        d[idx] = 1.0
        piv = np.eye(3)["XYZ".index(axis)]
        change(
            f"table_shift_{axis}",
            f"table (both rotary axes and the pivot) shifted along {axis} between the runs",
            "table_shift",
            "um",
            1e3,
            PLAUSIBLE_CHANGE["table_shift"],
            lambda s, d=d, piv=piv: (d * s, {}, piv * s),
        )
    # The pivot ball alone moved on the table (its stand warmed, or it was re-seated): run 2's
    # sphere arcs locate it again, so the chain should not see it; tried to show that.
    for axis in "XYZ":
        piv = np.eye(3)["XYZ".index(axis)]
        change(
            f"pivot_{axis}",
            f"pivot moved along {axis} on the table between the runs",
            "pivot",
            "um",
            1e3,
            PLAUSIBLE_CHANGE["pivot"],
            lambda s, piv=piv: (np.zeros(8), {}, piv * s),
        )
    change(
        "tool_offset_Z",
        "tool length differs between the runs (re-measured, re-clamped, spindle growth)",
        "tool_offset_Z",
        "um",
        1e3,
        PLAUSIBLE_CHANGE["tool_offset_Z"],
        lambda s: (np.zeros(8), {"tool_offset_Z": [s]}, np.zeros(3)),
    )
    change(
        "ballbar_length_offset",
        "ballbar length differs between the runs (bar temperature, recalibration)",
        "ballbar_length_offset",
        "um",
        1e3,
        PLAUSIBLE_CHANGE["ballbar_length_offset"],
        lambda s: (np.zeros(8), {"ballbar_length_offset": [s]}, np.zeros(3)),
    )
    for eid in ("thermal_drift_X", "thermal_drift_Y", "thermal_drift_Z", "ballbar_thermal_drift"):
        change(
            f"{eid}",
            f"drift during run 2 differs from run 1 ({_core.Effect(eid).cause})",
            "drift_over_test",
            "um over the test",
            1e3 * duration,
            PLAUSIBLE_CHANGE["drift_over_test"] / duration,
            lambda s, eid=eid: (np.zeros(8), {eid: [s]}, np.zeros(3)),
        )
    for eid in ("linear_squareness_XY", "linear_squareness_YZ", "linear_squareness_ZX"):
        change(
            eid,
            f"{_core.Effect(eid).cause}: changed between the runs (thermal bending)",
            "linear_squareness",
            "urad",
            1e6,
            PLAUSIBLE_CHANGE["linear_squareness"],
            lambda s, eid=eid: (np.zeros(8), {eid: [s]}, np.zeros(3)),
        )
    for eid in ("linear_scale_X", "linear_scale_Y", "linear_scale_Z"):
        change(
            eid,
            f"{_core.Effect(eid).cause}: changed between the runs (temperature of the scale)",
            "linear_scale",
            "um/m",
            1e6,
            PLAUSIBLE_CHANGE["linear_scale"],
            lambda s, eid=eid: (np.zeros(8), {eid: [s]}, np.zeros(3)),
        )
    return out
