# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal plan``: the NC program of a test (and its commanded rows as a session template)."""

from __future__ import annotations

import argparse

from ..outputs import write_output
from ..sessions import save
from .options import EPILOG, EXIT_OK, OptionError, path, say
from .probe import add_plan_probe_args, refuse_probe_options
from .setups import add_setup_args, ballbar_model, ballbar_setup
from .thermal_plan import add_plan_thermal_args
from .thermal_sim import add_test_args, given_test_options


def cmd_plan(a: argparse.Namespace) -> int:
    if a.kind == "thermal":  # the thermal test's program: cli/thermal_plan.py
        from .thermal_plan import cmd_plan_thermal

        return cmd_plan_thermal(a)
    given = given_test_options(a) + (["--max-speed"] if a.max_speed is not None else [])
    if given:
        raise OptionError(f"plan {a.kind}: {', '.join(given)} belong to plan thermal")
    if a.kind == "probe":  # the touch probe's program: cli/probe.py
        from .probe import cmd_plan_probe

        return cmd_plan_probe(a)
    from ..ballbar import nc_program

    refuse_probe_options(a)
    plan, text = nc_program(ballbar_setup(a), a.dialect, ballbar_model(a.compensate), a.compensate)
    write_output(
        a.output, text, [a.compensate] if a.compensate else [], [a.session] if a.session else []
    )
    say(
        f"wrote {a.output}: {a.dialect} program, {plan.num_samples} points, {plan.duration:.0f} s"
        + (" (compensated)" if a.compensate else "")
    )
    if a.session:
        save(plan.commanded_session(), a.session, [a.compensate], [a.output])
        say(f"wrote {a.session}: the commanded rows as a session template")
    return EXIT_OK


def add_plan(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser("plan", help="plan a test and write its NC program", epilog=EPILOG)
    q.add_argument("kind", choices=["ballbar", "probe", "thermal"])
    add_setup_args(q)
    add_plan_probe_args(q)
    add_test_args(q, defaults=False)
    add_plan_thermal_args(q)
    q.add_argument(
        "--dialect", default="linuxcnc", help="linuxcnc (machine axes), heidenhain, siemens, fanuc"
    )
    q.add_argument(
        "--compensate",
        metavar="MODEL.json",
        type=path("--compensate"),
        help="emit the program compensated for a fitted model",
    )
    q.add_argument(
        "--session",
        metavar="CSV",
        type=path("--session"),
        help="also write the commanded rows as a session template",
    )
    q.add_argument("-o", "--output", required=True, type=path("--output"))
    q.set_defaults(func=cmd_plan)


COMMANDS = {"plan": add_plan}
