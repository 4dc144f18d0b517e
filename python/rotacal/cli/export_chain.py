# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal export --controller linuxcnc --thermal-chain trt|rotacal-kins``: a thermal model
as a HAL file that runs its lags in the servo thread with LinuxCNC's own components
(rotacal/thermal_hal.py, docs/thermal.md)."""

from __future__ import annotations

import argparse

from .. import _core, jsontext
from ..outputs import write_output
from .options import EXIT_OK, say


def add_options(q: argparse.ArgumentParser) -> None:
    q.add_argument(
        "--thermal-chain",
        choices=["trt", "rotacal-kins"],
        help="linuxcnc, a thermal model: a HAL file whose lowpass components run the lags from "
        "the heated joint's speed, into the trt module's pins or rotacal-kins' y1, y2",
    )
    q.add_argument(
        "--servo-period",
        type=int,
        default=1_000_000,
        help="--thermal-chain: the servo thread's period, ns ([EMCMOT]SERVO_PERIOD; default 1000000)",
    )
    q.add_argument(
        "--heat-joint",
        type=int,
        help="--thermal-chain: the joint of the heated axis (default: the trt modules' joints "
        "X Y Z tilt C; rotacal-kins coordinates=XYZABC)",
    )


def add_predictor_options(q: argparse.ArgumentParser) -> None:
    from .thermal import duration

    q.add_argument(
        "--thermal-predictor",
        action="store_true",
        help="a thermal model: the state-space predictor a PLC runs each --cycle to rewrite the "
        "controller's parameters as the axis warms (JSON, docs/thermal.md)",
    )
    q.add_argument(
        "--cycle",
        type=duration("--cycle"),
        default=0.01,
        help="--thermal-predictor: the PLC's cycle (default 10ms)",
    )


def _refused_options(a: argparse.Namespace, *more: tuple) -> list:
    """The export options given that a thermal chain or predictor does not take."""
    options = (
        ("--at/--state", a.at is not None or a.state is not None),
        ("--residual-model", a.residual_model),
        ("--tables", a.tables),
        ("--comp-file", a.comp_file),
        *more,
    )
    return [o for o, v in options if v]


def cmd_predictor(a: argparse.Namespace) -> int:
    from ..thermal_predictor import predictor

    given = _refused_options(a, ("--thermal-chain", getattr(a, "thermal_chain", None)))
    if given:
        raise _core.InvalidArgument("--thermal-predictor: not with " + ", ".join(given))
    doc = predictor(a.model, a.controller, a.cycle, a.current, a.toolholder)
    text = jsontext.dumps(doc) + "\n"
    if a.output:
        write_output(a.output, text, inputs=[p for p in (a.model, a.current) if p])
        say(
            f"wrote {a.output}: the thermal predictor for {doc['kinematics']}, "
            f"{len(doc['rewrites'])} parameters rewritten every {a.cycle:g} s"
        )
    else:
        print(text, end="")
    return EXIT_OK


def cmd(a: argparse.Namespace) -> int:
    from ..thermal_hal import chain

    given = _refused_options(a)
    if a.controller != "linuxcnc" or given:
        raise _core.InvalidArgument(
            "--thermal-chain: with --controller linuxcnc only, and not with "
            + (", ".join(given) or "another controller")
        )
    text, info = chain(a.model, a.thermal_chain, a.current, a.servo_period, a.heat_joint)
    if a.output:
        write_output(a.output, text, inputs=[p for p in (a.model, a.current) if p])
        say(f"wrote {a.output}: the thermal chain for {info['kinematics']} ({a.thermal_chain})")
    if a.json:
        print(jsontext.dumps(info))
    elif not a.output:
        print(text, end="")
    return EXIT_OK
