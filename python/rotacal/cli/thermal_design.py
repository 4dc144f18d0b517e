# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal design thermal`` (issue 53, item 1): the interval and the epoch's poses of a thermal
probe test, at a prior tau and prior gains, in a given test time. Each candidate is measured
once on rotacal's own simulator at the prior (simulate_thermal, 0.5 um noise by default) and
identified (identify_thermal); its figure is the largest U(k=2)/abs(prior) = 2 sigma/abs(prior) over
the gains and tau, sigma the fit's own (the bench, bench/thermal_bench.py, measures it at the
Cramer-Rao bound on the reference simulator). The design also says how much the lag state
changes within one epoch (the axis held: y decays by 1 - exp(-T_epoch/tau))."""

from __future__ import annotations

import argparse
import math
import tempfile
from pathlib import Path

import numpy as np

from .. import _core, jsontext
from ..machines import load_machine
from .options import EPILOG, EXIT_OK, OptionError, number_list, path
from .thermal import duration
from .thermal_sim import (
    _lags,
    epoch_poses,
    fill_test_defaults,
    test_plan,
    thermal_session_text,
)

# The shared thermal_probe_ac.truth.json's gains to 2 digits (mm, rad per 100 rev/min): the
# default prior.
DEFAULT_PRIOR_GAINS = [
    "E_X0C=-0.0077", "E_Y0C=-0.0037", "E_A0C=-7.0e-6", "E_B0C=-3.8e-6", "E_Y0A=-0.0063",
    "E_Z0A=0.0010", "E_B0A=8.4e-6", "E_C0A=-1.1e-6", "q_x=0.0031", "q_y=0.00090", "q_z=0.00014",
]  # fmt: skip


def candidate_poses(machine: _core.MachineType) -> dict[str, np.ndarray]:
    """Epoch pose sets: 6 (C every 120 deg, 3 tilts), 8 (the shared files'), 12 (C every 60)."""
    base = epoch_poses(machine)
    rot = base[:4, 1]
    tilts = base[4:, 0]
    c6 = [(0.0, float(r)) for r in np.linspace(rot[0], rot[0] + 240.0, 3)]
    c12 = [(0.0, float(r)) for r in np.linspace(rot[0], rot[0] + 300.0, 6)] + [
        (t, rot[0]) for t in tilts
    ]
    return {
        "6 poses": np.array(c6 + [(tilts[0], rot[0]), (tilts[1], rot[0]), (tilts[-1], rot[0])]),
        "8 poses": base,
        "10 poses": np.array(c12),
    }


def evaluate(machine, plan, poses, lags, noise_um, seed, tmp: Path) -> dict:
    session, epoch, _ = _core.simulate_thermal(
        "probe", machine, np.zeros(8), [], [], plan.duty(), plan.epoch_starts(), plan.axis, lags,
        poses, noise_um, 0.0, seed, np.array([[150.0, 0.0, 80.0]]), np.zeros(3), 0.0, 6.0,
    )  # fmt: skip
    f = tmp / "candidate.csv"
    f.write_text(thermal_session_text(session, plan, epoch))
    d = _core.identify_thermal(str(f), noise="white")["identification"]
    lag = d["lags"][0]
    worst, what = 2.0 * lag["tau_std_s"] / lag["tau_s"] if lag["tau_s"] else math.inf, "tau"
    unobservable = []
    for g, k in zip(lag["gains"], lags[0][1].tolist() + lags[0][2].tolist()):
        if k == 0.0:
            continue
        if not g["observable"]:
            unobservable.append(g["name"])
            continue
        u = 2.0 * g["std"] / abs(k)
        if u > worst:
            worst, what = u, g["name"]
    return {
        "worst": math.inf if unobservable else worst,
        "worst_of": what,
        "unobservable": unobservable,
    }


def cmd_design_thermal(a: argparse.Namespace) -> int:
    fill_test_defaults(a)
    machine = load_machine(a.machine)
    a.gain = a.gain or DEFAULT_PRIOR_GAINS
    lags, _ = _lags(a, machine)
    if len(lags) != 1:
        raise OptionError("design thermal: one prior lag (--tau once)")
    tau = lags[0][0]
    rows = []
    with tempfile.TemporaryDirectory(prefix="rotacal-design-thermal-") as d:
        for minutes in a.intervals:
            a.interval = 60.0 * minutes
            for name, poses in candidate_poses(machine).items():
                epoch_s = 16.0 * len(poses)
                if a.interval <= epoch_s:
                    continue
                plan = test_plan(a, machine)
                r = evaluate(machine, plan, poses, lags, a.noise, a.seed, Path(d))
                r.update(interval_min=minutes, poses=name, epoch_s=epoch_s,
                         poses_deg=";".join(f"{t:g},{c:g}" for t, c in poses),
                         epochs=len(plan.epoch_starts()), state_change=1.0 - math.exp(-epoch_s / tau))  # fmt: skip
                rows.append(r)
    if not rows:
        raise OptionError("design thermal: no --intervals longer than an epoch")
    best = min(rows, key=lambda r: (r["worst"], r["epochs"]))
    if a.json:
        print(jsontext.dumps({"candidates": rows, "best": best}))
        return EXIT_OK
    print(f"design thermal: {a.axis or machine.rot_axis} at {a.speed:g} rev/min, {a.heat / 3600:g} h + "
          f"{a.cool / 3600:g} h, prior tau {tau / 60:g} min, noise {a.noise:g} um")  # fmt: skip
    print("  interval  poses     epochs  largest U(k=2)/abs(prior)  state change in an epoch")
    for r in rows:
        u = (
            "unobservable: " + ", ".join(r["unobservable"])
            if r["unobservable"]
            else f"{r['worst']:.3f} ({r['worst_of']})"
        )
        print(
            f"  {r['interval_min']:5g} min  {r['poses']:9s} {r['epochs']:5d}  {u:24s} {100 * r['state_change']:.1f} %"
        )
    print(f"best: every {best['interval_min']:g} min, {best['poses']} ({best['epoch_s']:g} s an epoch, "
          f"the lag state changes {100 * best['state_change']:.1f} % within one)")  # fmt: skip
    print(
        f'  rotacal plan thermal --interval {best["interval_min"]:g}min --poses "{best["poses_deg"]}" ...'
    )
    return EXIT_OK


def add_design_thermal(kinds: argparse._SubParsersAction) -> None:
    k = kinds.add_parser(
        "thermal",
        help="the interval and epoch poses of a thermal probe test at a prior tau and gains",
        epilog=EPILOG,
    )
    k.add_argument("--machine", default="AC-trt", type=path("--machine"), metavar="NAME|FILE")
    k.add_argument("--axis")
    k.add_argument("--speed", type=float, default=None, help="rev/min (default 300)")
    k.add_argument("--heat", type=duration("--heat"), default=None, help="default 4h")
    k.add_argument("--cool", type=duration("--cool"), default=None, help="default 2h")
    k.add_argument(
        "--intervals", type=number_list("--intervals", 1.0, 600.0, "min", 20), default=[5, 10, 20, 30],
        help="candidate intervals, min (default 5,10,20,30)",
    )  # fmt: skip
    k.add_argument(
        "--tau", action="append", type=duration("--tau"), help="prior tau (default 30min)"
    )
    k.add_argument(
        "--gain", action="append", metavar="NAME=K", help="prior gains (default: the shared file's)"
    )
    k.add_argument("--noise", type=float, default=0.5, help="1-sigma per coordinate, um")
    k.add_argument("--seed", type=int, default=1)
    k.add_argument("--json", action="store_true")
    k.set_defaults(func=cmd_design_thermal, instrument="probe", interval=None, max_speed=None)


KINDS = {"design": add_design_thermal}
COMMANDS: dict = {}
