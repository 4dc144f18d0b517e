# SPDX-License-Identifier: BSD-3-Clause
"""A thermal model as a small state-space predictor that a controller's PLC runs each cycle
(``rotacal export --controller X --thermal-predictor --cycle 10ms``; docs/thermal.md, issue 53
item 5), for the controllers whose kinematics have no HAL to run the lag in (SINUMERIK, ISG,
HEIDENHAIN, FANUC; LinuxCNC has ``--thermal-chain``).

Each cycle of T seconds, with u = |speed of the heated axis| / 100 rev/min:
    y_l <- a_l y_l + b_l u,   a_l = exp(-T/tau_l), b_l = 1 - a_l   (y_l = 0 when cold)
    p   <- p_cold + sum_l G_pl y_l   for every parameter p the controller's export writes.
That is the lag of ``kinematics/thermal_lag.hpp`` solved exactly over a cycle of constant u,
and p_cold, G_pl are the C++ export's values at the cold state and their change per unit of
each state (``thermal_hal.parameter_gains``): the PLC computes what ``export --state y``
writes, to the departure from linearity of a parameter that is a direction's cosine (stated per
parameter at the steady state of the tested speed; about 1e-11 for the shared test's drift)."""

from __future__ import annotations

import os
from pathlib import Path

from . import _core
from .exports import export_controller
from .models import load_model
from .thermal_hal import lowpass_gain, parameter_gains

FORMAT = "rotacal-thermal-predictor/1"


def predictor(
    model: str | Path,
    controller: str,
    cycle_s: float,
    current: str | Path | None = None,
    toolholder: int = 1,
) -> dict:
    """The predictor's document: the cycle, each lag's a and b, the parameters it rewrites with
    their cold value and gains, the constant ones, and the steady-state size of what the
    controller's parameters do not hold."""
    where = os.fspath(model)
    doc = load_model(model)
    th = doc.get("thermal")
    if doc.get("kind") != "thermal" or not isinstance(th, dict):
        raise _core.InvalidArgument(f"{where}: --thermal-predictor needs a thermal model")
    if not 1e-4 <= cycle_s <= 60.0:
        raise _core.InvalidArgument(f"--cycle {cycle_s:g} s: not 0.1 ms to 60 s")
    lags = th["lags"]
    taus = [lag["tau"].get("value") for lag in lags]
    for k, tau in enumerate(taus):
        if tau is None or not tau > 0:
            raise _core.InvalidArgument(f"{where}: thermal.lags[{k}].tau: not determined")
    L = len(lags)
    opts = {"toolholder": toolholder}
    cold = export_controller(model, controller, current=current, thermal_state=[0.0] * L, **opts)
    gains = parameter_gains(model, controller, current, cold, L, **opts)
    u_ss = float(th["tested_speed_rpm"]) / 100.0
    # A direction's cosines are not affine in the errors: the linear rewrite's departure from
    # the export at the steady state (the largest state of the tested duty) is stated.
    steady = export_controller(model, controller, current=current, thermal_state=[u_ss] * L, **opts)
    rewrites, constant = [], []
    for v, g, s in zip(cold.values, gains, steady.values):
        entry = {"name": v.name, "unit": v.unit, "cold": v.corrected}
        if any(x != 0.0 for x in g):
            linear = v.corrected + sum(x * u_ss for x in g)
            rewrites.append(
                entry | {"gains": g, "nonlinearity_at_steady_state": s.corrected - linear}
            )
        else:
            constant.append(entry)
    held = {e.name for e in cold.errors if e.held}
    not_held = {}
    for name in lags[0]["gains"]:
        if name in held:
            continue
        g = [lag["gains"][name].get("value") for lag in lags]
        not_held[name] = None if all(x is None for x in g) else sum((x or 0.0) * u_ss for x in g)
    return {
        "format": FORMAT,
        "controller": controller,
        "kinematics": cold.kinematics,
        "model": Path(where).name,
        "axis": th["axis"],
        "input": f"u = abs(speed of axis {th['axis']} in rev/min) / 100, 0 when it stands",
        "cycle_s": cycle_s,
        "lags": [
            {"tau_s": tau, "a": 1.0 - lowpass_gain(cycle_s, tau), "b": lowpass_gain(cycle_s, tau)}
            for tau in taus
        ],
        "update": "each cycle: y[l] = a[l] * y[l] + b[l] * u (y = 0 cold); then every "
        "parameter of 'rewrites' = cold + sum over l of gains[l] * y[l]",
        "rewrites": rewrites,
        "constant": constant,
        "not_held_steady_state": {
            "tested_speed_rpm": float(th["tested_speed_rpm"]),
            "values": not_held,
            "why": "location errors the controller's parameters do not hold, and the "
            "instrument's table-side point: their drift at the tested speed stays uncorrected",
        },
    }
