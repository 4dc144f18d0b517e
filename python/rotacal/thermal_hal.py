# SPDX-License-Identifier: BSD-3-Clause
"""A thermal model run in LinuxCNC's servo thread by LinuxCNC's own HAL components
(``rotacal export --controller linuxcnc --thermal-chain``; docs/thermal.md, issue 53).

The heat input u = |speed| / 100 rev/min is |joint.N.vel-cmd| / 600 (deg/s); each lag
tau dy/dt = u - y is a ``lowpass`` with gain 1 - exp(-T/tau), T the servo period: the exact
solution over a period of constant u (a zero-order hold), as ``kinematics/thermal_lag.hpp``
solves it on pieces of constant u. Each pin the export writes is affine in the location errors,
so pin(y) = pin(0) + sum_l G_l y_l, with pin(0) and pin(e_l) the C++ export's values at the cold
state and at the unit state of lag l (``export_controller``, thermal_state): the chain is
``scale`` by G_l per lag and pin, then ``sum2`` with the cold value as offset. ``rotacal-kins``
takes the states themselves on its pins y1, y2 (its blob holds the gains)."""

from __future__ import annotations

import math
import os
from pathlib import Path
from . import _core
from .exports import export_controller
from .models import load_model

SPEED_PER_U = 600.0  # deg/s of 100 rev/min: u = |speed| / 100 rev/min
PREFIX = "rotacal-th"  # the names of the chain's components and signals
# The heated axis' joint in the trt modules (joints X Y Z tilt C) and in rotacal-kins
# (coordinates=XYZABC, docs/linuxcnc_kins.md).
TRT_JOINT = {"A": 3, "B": 3, "C": 4}
ROTACAL_KINS_JOINT = {"A": 3, "B": 4, "C": 5}


def _lags(doc: dict, where: str) -> list[dict]:
    th = doc.get("thermal")
    if doc.get("kind") != "thermal" or not isinstance(th, dict):
        raise _core.InvalidArgument(
            f"{where}: --thermal-chain needs a thermal model (kind thermal)"
        )
    lags = th["lags"]
    for k, lag in enumerate(lags):
        tau = lag["tau"].get("value")
        if tau is None or not tau > 0:
            raise _core.InvalidArgument(f"{where}: thermal.lags[{k}].tau: not determined")
    return lags


def lowpass_gain(period_s: float, tau_s: float) -> float:
    """The weight of u in one step of the lag over a period of constant u: y <- y + g (u - y),
    g = 1 - exp(-T/tau) (LinuxCNC's lowpass gain; a PLC's b = g, a = 1 - g)."""
    return 1.0 - math.exp(-period_s / tau_s)


def parameter_gains(
    model: str | Path, controller: str, current: str | Path | None, cold, lags: int, **options
) -> list[list[float]]:
    """Per parameter of the controller's export `cold` (at the cold state), its change per unit
    of each lag's state: the export at the unit state of lag l less the cold one (each parameter
    is affine in the location errors, the errors in the states)."""
    unit = [
        export_controller(
            model,
            controller,
            current=current,
            thermal_state=[float(i == k) for i in range(lags)],
            **options,
        )
        for k in range(lags)
    ]
    return [
        [unit[k].values[i].corrected - v.corrected for k in range(lags)]
        for i, v in enumerate(cold.values)
    ]


def chain(
    model: str | Path,
    target: str = "trt",
    current: str | Path | None = None,
    servo_period_ns: int = 1_000_000,
    joint: int | None = None,
) -> tuple[str, dict]:
    """(HAL text, what it holds) of the chain for `target` "trt" (the pins of xyzac- /
    xyzbc-trt-kins) or "rotacal-kins" (its y1, y2 pins)."""
    where = os.fspath(model)
    doc = load_model(model)
    lags = _lags(doc, where)
    th = doc["thermal"]
    axis, rpm = th["axis"], float(th["tested_speed_rpm"])
    if not 1_000 <= servo_period_ns <= 100_000_000:
        raise _core.InvalidArgument(f"--servo-period {servo_period_ns}: not 1 us to 100 ms")
    t = servo_period_ns * 1e-9
    if joint is None:
        joint = (TRT_JOINT if target == "trt" else ROTACAL_KINS_JOINT)[axis]
    if not 0 <= joint < 16:  # EMCMOT_MAX_JOINTS
        raise _core.InvalidArgument(f"--heat-joint {joint}: not a LinuxCNC joint (0 to 15)")
    L = len(lags)
    cold = export_controller(model, "linuxcnc", current=current, thermal_state=[0.0] * L)
    kins = cold.kinematics
    held = {e.name for e in cold.errors if e.held}
    lines = [
        f"# rotacal: the thermal model {Path(where).name} run in the servo thread ({target}).",
        f"# u = |joint.{joint}.vel-cmd| / {SPEED_PER_U:g} (deg/s: axis {axis} at 100 rev/min"
        " is u = 1); per lag tau dy/dt = u - y as lowpass gain = 1 - exp(-T/tau),"
        f" T = {servo_period_ns} ns ([EMCMOT]SERVO_PERIOD): change it with the period.",
    ]
    gain = [lowpass_gain(t, float(lag["tau"]["value"])) for lag in lags]
    for k, lag in enumerate(lags):
        lines.append(f"# lag{k + 1}: tau {lag['tau']['value']:.6g} s, lowpass gain {gain[k]:.12g}")
    readers: list[list[str]] = [[] for _ in range(L)]  # the inputs each lag's state feeds
    pins, per_pin, scales, sums = [], [], [], []
    if target == "rotacal-kins":
        for k in range(L):
            readers[k].append(f"rotacal-kins.y{k + 1}")
    else:
        for v, g in zip(cold.values, parameter_gains(model, "linuxcnc", current, cold, L)):
            if not v.name.startswith(kins + "."):
                continue  # an INI value (HOME_OFFSET): no pin to feed
            pin = v.name[len(kins) + 1 :]
            pins.append({"pin": v.name, "cold": v.corrected, "gains": g})
            for k in range(L):
                name = f"{PREFIX}-k{k + 1}-{pin}"
                scales.append(name)
                readers[k].append(f"{name}.in")
                per_pin += [
                    f"setp {name}.gain {g[k]:.17g}",
                    f"setp {name}.offset 0",
                    f"net {PREFIX}-{pin}-{k + 1} {name}.out => {PREFIX}-{pin}.in{k}",
                ]
            sums.append(f"{PREFIX}-{pin}")
            per_pin += [
                f"setp {PREFIX}-{pin}.offset {v.corrected:.17g}",
                f"net {PREFIX}-{pin} {PREFIX}-{pin}.out => {v.name}",
            ]
    lag_names = [f"{PREFIX}-lag{k + 1}" for k in range(L)]
    cmds = [
        f"loadrt abs names={PREFIX}-speed",
        f"loadrt scale names={','.join([f'{PREFIX}-u'] + scales)}",
        f"loadrt lowpass names={','.join(lag_names)}",
    ] + ([f"loadrt sum2 names={','.join(sums)}"] if sums else [])
    funcs = [f"{PREFIX}-speed", f"{PREFIX}-u"] + lag_names + scales + sums
    nets = [
        f"net {PREFIX}-vel joint.{joint}.vel-cmd => {PREFIX}-speed.in",
        f"net {PREFIX}-abs {PREFIX}-speed.out => {PREFIX}-u.in",
        f"setp {PREFIX}-u.gain {1.0 / SPEED_PER_U:.17g}",
        f"setp {PREFIX}-u.offset 0",
        f"net {PREFIX}-u {PREFIX}-u.out => " + " ".join(f"{n}.in" for n in lag_names),
    ]
    for k in range(L):
        nets += [
            f"setp {lag_names[k]}.gain {gain[k]:.17g}",
            f"net {PREFIX}-y{k + 1} {lag_names[k]}.out => " + " ".join(readers[k]),
        ]
    nets += per_pin
    u_ss = rpm / 100.0
    errors = [e.name for e in cold.errors]
    not_held = [n for n in errors if n not in held or target == "rotacal-kins"]
    others = [n for n in lags[0]["gains"] if n not in errors]  # the table-side point
    lines.append(
        f"# Not held by this chain (steady state at the tested {rpm:g} rev/min, u = {u_ss:g}):"
        if target == "trt"
        else "# The gains are the blob's (export --controller realtime); steady states at the"
        f" tested {rpm:g} rev/min (u = {u_ss:g}):"
    )
    steady = {}
    for n in (not_held if target == "trt" else errors) + others:
        g = [lag["gains"][n].get("value") for lag in lags]
        if all(x is None for x in g):
            lines.append(f"#   {n}: gain not determined")
            continue
        size = sum((x or 0.0) * u_ss for x in g)
        unit = "rad" if n not in others and n[2] in "ABC" else "mm"
        steady[n] = size
        why = " (the instrument's table-side point)" if n in others else ""
        lines.append(f"#   {n}: {size:+.6g} {unit}{why}")
    text = "\n".join(lines + cmds + [f"addf {f} servo-thread" for f in funcs] + nets) + "\n"
    info = {
        "kinematics": kins,
        "joint": joint,
        "lowpass_gains": gain,
        "servo_period_ns": servo_period_ns,
        "pins": pins,
        "not_held_steady_state": steady,
    }
    return text, info
