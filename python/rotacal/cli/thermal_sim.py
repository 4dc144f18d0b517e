# SPDX-License-Identifier: BSD-3-Clause
"""The thermal test's duty and epochs on the command line (issue 53): ``rotacal simulate
thermal`` on rotacal's own simulators (probe/simulate.hpp, rtest/simulate.hpp with a
ThermalSimSpec; the one lag of kinematics/thermal_lag.hpp). The test itself, its duty and its
epochs, is the same one ``rotacal plan thermal`` writes (cli/thermal_plan.py)."""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass

import numpy as np

from .. import _core
from ..machines import PIVOT_ERROR_MM, effect_parameters, load_machine, location_errors
from ..outputs import write_output
from ..sessions import session_text
from .options import EPILOG, EXIT_OK, SEED, OptionError, effects_option, errors_option
from .options import number, numbers, path, say
from .setups import write_truth
from .thermal import duration

TABLE_POINT_GAINS = ("q_x", "q_y", "q_z")
DEFAULT_NEST = (100.0, 0.0, 60.0)  # the shared thermal_rtest_bc.csv's nest
PROBE_EPOCH_S = 16.0 * 8  # 8 poses, 16 s apart (probe/simulate.hpp's pose_dt_s)
RTEST_DWELL_S = 6.0


@dataclass
class ThermalTestPlan:
    """The duty and epochs of a thermal test: `axis` at `speed` rev/min for `heat_s`, then at
    rest for `cool_s`, an epoch every `interval_s` from 0 (the first one cold)."""

    axis: str
    speed: float
    heat_s: float
    cool_s: float
    interval_s: float

    def duty(self) -> list[tuple[float, dict[str, float]]]:
        out = [(0.0, {self.axis: self.speed})]
        if self.cool_s > 0:
            out.append((self.heat_s, {self.axis: 0.0}))
        return out

    def epoch_starts(self) -> list[float]:
        n = int(np.floor((self.heat_s + self.cool_s) / self.interval_s + 1e-9)) + 1
        return [self.interval_s * e for e in range(n)]

    def duty_lines(self) -> list[str]:
        """The session's `# duty.N:` lines (formats.md)."""
        return [
            f"# duty.{n}: {t:g}, " + ", ".join(f"{a}={v:g}" for a, v in s.items())
            for n, (t, s) in enumerate(self.duty(), start=1)
        ]


def axis_limits(machine: _core.MachineType, axis: str) -> tuple[float, float] | None:
    """[min, max] deg of a rotary axis of the machine, None when endless."""
    d = json.loads(machine.description_json)
    for a in d.get("table_axes", []) + d.get("head_axes", []):
        if a["name"] == axis and "limits_deg" in a:
            return float(a["limits_deg"][0]), float(a["limits_deg"][1])
    return None


def epoch_poses(machine: _core.MachineType) -> np.ndarray:
    """An epoch's 8 poses (tilt, rot deg), as in the shared thermal files: the rotary axis every
    90 deg at tilt 0, then the tilt at -60, -30, 30, 60 deg at rotary 0 (inside its limits: the
    four spread over them where they exclude these)."""
    lim = axis_limits(machine, machine.tilt_axis)
    tilts = [-60.0, -30.0, 30.0, 60.0]
    if lim is not None and not all(lim[0] <= t <= lim[1] for t in tilts):
        lo, hi = max(lim[0], -60.0), min(lim[1], 60.0 if lim[0] < 0 else 90.0)
        tilts = [t for t in np.linspace(lo, hi, 5) if abs(t) > 1e-9][:4]
    rots = [0.0, 90.0, 180.0, 270.0]
    rlim = axis_limits(machine, machine.rot_axis)
    if rlim is not None and not all(rlim[0] <= r <= rlim[1] for r in rots):
        rots = list(np.linspace(rlim[0], rlim[1], 4))
    return np.array([(0.0, r) for r in rots] + [(t, rots[0]) for t in tilts], float)


def test_plan(a: argparse.Namespace, machine: _core.MachineType) -> ThermalTestPlan:
    axis = a.axis or machine.rot_axis
    if axis not in machine.axis_names:
        raise OptionError(
            f"--axis {axis}: machine {_core.machine_name(machine)} has rotary axes "
            f"{', '.join(machine.axis_names)}"
        )
    if a.interval <= 0:
        raise OptionError("--interval must be > 0")
    if a.heat + a.cool < a.interval:
        raise OptionError("--heat + --cool must hold at least one --interval")
    return ThermalTestPlan(axis, a.speed, a.heat, a.cool, a.interval)


# The thermal test's options and their defaults (simulate thermal, plan thermal).
TEST_DEFAULTS = {
    "speed": 300.0,
    "heat": 4 * 3600.0,
    "cool": 2 * 3600.0,
    "interval": 600.0,
    "instrument": "probe",
    "max_speed": 500.0,
}


def add_test_args(k: argparse.ArgumentParser, defaults: bool = True) -> None:
    """The duty and epochs (simulate thermal and plan thermal). Without `defaults` (the plan
    parser, which other kinds share) they stay None and fill_test_defaults fills them."""
    d = TEST_DEFAULTS if defaults else {}
    g = k.add_argument_group("the thermal test (plan thermal, simulate thermal)")
    g.add_argument("--axis", help="the rotary axis that turns (default: the machine's rotary axis)")
    g.add_argument(
        "--speed", type=number("--speed", 0.0, 1e5, "rev/min"), default=d.get("speed"),
        help="rev/min while heating (default 300); of an axis with limits, its mean speed",
    )  # fmt: skip
    g.add_argument("--heat", type=duration("--heat"), default=d.get("heat"), help="default 4h")
    g.add_argument("--cool", type=duration("--cool"), default=d.get("cool"), help="default 2h")
    g.add_argument(
        "--interval", type=duration("--interval"), default=d.get("interval"),
        help="from one epoch's start to the next's, default 10min",
    )  # fmt: skip
    g.add_argument(
        "--instrument", choices=["probe", "rtest"], default=d.get("instrument"),
        help="default probe",
    )  # fmt: skip


def fill_test_defaults(a: argparse.Namespace) -> None:
    for k, v in TEST_DEFAULTS.items():
        if getattr(a, k, None) is None:
            setattr(a, k, v)


def given_test_options(a: argparse.Namespace) -> list[str]:
    """The thermal test's options given on the command line (refused by other plan kinds)."""
    return [
        f"--{k.replace('_', '-')}"
        for k in ("axis", *TEST_DEFAULTS)
        if k != "max_speed" and getattr(a, k, None) is not None
    ]


def _lags(a: argparse.Namespace, machine: _core.MachineType) -> tuple[list, dict]:
    """(binding's lags, the truth's "thermal" list) from --tau and --gain."""
    taus = a.tau or [1800.0]
    if len(taus) > 2:
        raise OptionError("--tau: one lag or two")
    names = list(_core.location_error_names(machine))
    gains: list[dict[str, float]] = [{} for _ in taus]
    for item in a.gain or []:
        name, _, values = item.partition("=")
        if name not in names and name not in TABLE_POINT_GAINS:
            raise OptionError(
                f"--gain {item[:60]}: {name[:40]} is neither a location error ({', '.join(names)}) "
                f"nor a table-side point gain ({', '.join(TABLE_POINT_GAINS)})"
            )
        try:
            k = [float(v) for v in values.split(",")]
        except ValueError:
            raise OptionError(f"--gain {item[:60]}: not NAME=K or NAME=K1,K2") from None
        if len(k) != len(taus) or not all(np.isfinite(k)):
            raise OptionError(f"--gain {item[:60]}: one finite gain per --tau ({len(taus)})")
        for g, v in zip(gains, k):
            g[name] = v
    out, truth = [], []
    for tau, g in zip(taus, gains):
        if not tau > 0:
            raise OptionError("--tau must be > 0")
        k = np.array([g.get(n, 0.0) for n in names])
        kq = np.array([g.get(n, 0.0) for n in TABLE_POINT_GAINS])
        out.append((tau, k, kq))
        truth.append({"axis": a.axis or machine.rot_axis, "tau_s": tau, "gains": g})
    return out, truth


def cmd_simulate_thermal(a: argparse.Namespace) -> int:
    machine = load_machine(a.machine)
    plan = test_plan(a, machine)
    rng = np.random.default_rng(a.seed)
    errors = location_errors(errors_option(a.errors), machine, rng)
    offset = rng.normal(0.0, a.sphere_error, 3) if a.instrument == "probe" else np.zeros(3)
    ids, params, values = effect_parameters(effects_option(a.effect))
    lags, lag_truth = _lags(a, machine)
    point = a.point or (
        (150.0, 0.0, 80.0) if a.instrument == "probe" else DEFAULT_NEST
    )  # probe: probe/simulate.hpp's sphere
    poses = epoch_poses(machine)
    session, epoch, actual = _core.simulate_thermal(
        a.instrument, machine, errors, ids, params, plan.duty(), plan.epoch_starts(), plan.axis,
        lags, poses, a.noise, a.rho, a.seed, np.array([point], float), offset,
        a.probe_zero, RTEST_DWELL_S,
    )  # fmt: skip
    text = thermal_session_text(session, plan, epoch)
    write_output(a.output, text, [], [a.truth] if a.truth else [])
    truth = {
        "machine": _core.machine_name(machine),
        "instrument": a.instrument,
        "errors": dict(zip(_core.location_error_names(machine), errors.tolist())),
        "effects": {k: (v[0] if len(v) == 1 else v) for k, v in values.items()},
        "thermal": lag_truth,
        "duty": [[t, s] for t, s in plan.duty()],
        "noise_um": a.noise,
        "rho": a.rho,
        "seed": a.seed,
    }
    if a.instrument == "probe":
        truth["sphere_actual"] = np.asarray(actual, float)[0].tolist()
    else:
        truth["nests"] = [list(point)]
        truth["probe_zeros"] = np.asarray(actual, float).tolist()
    if a.truth:
        write_truth(truth, a.truth, [a.output])
    say(
        f"wrote {a.output}: {len(session)} rows in {max(epoch)} epochs on a simulated "
        f"{_core.machine_name(machine)}, {plan.axis} at {plan.speed:g} rev/min for "
        f"{plan.heat_s / 3600:g} h then at rest for {plan.cool_s / 3600:g} h, "
        f"{len(lags)} lag(s)" + (f", truth in {a.truth}" if a.truth else "")
    )
    return EXIT_OK


def thermal_session_text(session, plan: ThermalTestPlan, epoch: list[int]) -> str:
    """The session's text with the duty lines after its metadata and the `epoch` column last
    (formats.md "Thermal test of a rotary axis")."""
    lines = session_text(session, "simulate thermal").splitlines()
    head = [ln for ln in lines if ln.startswith("#")]
    body = [ln for ln in lines if ln and not ln.startswith("#")]
    if len(body) != len(epoch) + 1:
        raise _core.Error("simulate thermal: the session's rows and epochs differ in number")
    rows = [body[0] + ",epoch"] + [f"{r},{e}" for r, e in zip(body[1:], epoch)]
    return "\n".join(head + plan.duty_lines() + rows) + "\n"


def add_simulate_thermal(kinds: argparse._SubParsersAction) -> None:
    k = kinds.add_parser(
        "thermal",
        help="a thermal test of a rotary axis: its duty, an epoch of a few poses every interval, "
        "the axis lines drifting as one or two lags (formats.md, effects.md thermal_location_R)",
        epilog=EPILOG,
    )
    k.add_argument(
        "--machine", default="AC-trt", type=path("--machine"), metavar="NAME|FILE",
        help="a built-in (`rotacal machines`) or a rotacal-machine/1 file (default AC-trt)",
    )  # fmt: skip
    add_test_args(k)
    g = k.add_argument_group("simulated machine")
    g.add_argument(
        "--errors", default="random",
        help="cold location errors: random (seeded), zero, or NAME=VALUE,... (mm, rad)",
    )  # fmt: skip
    g.add_argument(
        "--effect", action="append", metavar="ID=P1,P2",
        help="another catalogue effect beside the drift, e.g. radial_motion_C_h2=0.002,0 (repeatable)",
    )  # fmt: skip
    g.add_argument(
        "--tau", action="append", type=duration("--tau"), metavar="TIME",
        help="a lag's time constant, e.g. 40min (give twice for two lags; default 30min)",
    )  # fmt: skip
    g.add_argument(
        "--gain", action="append", metavar="NAME=K[,K2]",
        help="steady-state change after long turning at 100 rev/min of a location error (mm, "
        "rad) or of the table-side point q_x, q_y, q_z (mm), one per lag (repeatable; none: no drift)",
    )  # fmt: skip
    g.add_argument(
        "--point", type=numbers("--point", 3, 1e4, "mm"), metavar="X,Y,Z",
        help="probe: the nominal sphere centre (default 150,0,80); rtest: the nest (default 100,0,60)",
    )  # fmt: skip
    g.add_argument(
        "--sphere-error", type=number("--sphere-error", 0.0, 10.0, "mm"), default=PIVOT_ERROR_MM,
        help="probe: 1-sigma set-up error of the sphere centre per axis, mm",
    )  # fmt: skip
    g.add_argument(
        "--probe-zero", type=number("--probe-zero", 0.0, 1e4, "um"), default=20.0,
        help="rtest: 1-sigma of each component of the nest's probe zero, um",
    )  # fmt: skip
    g.add_argument(
        "--noise", type=number("--noise", 0.0, 1000.0, "um"), default=0.5,
        help="1-sigma noise per coordinate (probe) or reading (rtest), um",
    )  # fmt: skip
    g.add_argument(
        "--rho", type=number("--rho", 0.0, 0.999), default=0.0,
        help="AR(1) coefficient of the noise from row to row (0: white)",
    )  # fmt: skip
    g.add_argument("--seed", type=SEED, default=1)
    k.add_argument("--truth", metavar="JSON", type=path("--truth"), help="write the truth here")
    k.add_argument("-o", "--output", required=True, type=path("--output"))
    k.set_defaults(func=cmd_simulate_thermal)


KINDS = {"simulate": add_simulate_thermal}
COMMANDS: dict = {}
