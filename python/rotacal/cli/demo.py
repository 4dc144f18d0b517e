# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal demo`` (the whole job on a simulated machine) and ``rotacal table2`` (Flynn et
al.'s measured Table 2 against the simulated measure -> compensate -> measure-again chain)."""

from __future__ import annotations

import argparse
from pathlib import Path

from .. import jsontext, units
from .options import EPILOG, EXIT_OK, SEED, number, path, say


def cmd_demo(a: argparse.Namespace) -> int:
    """Simulate a machine with errors and one hidden effect, measure, identify, diagnose,
    compensate, and write a report."""
    from ..demo import run_demo
    from ..diagnosis import group_text, model_text

    r = run_demo(a.output, seed=a.seed, sag_mm=a.sag, say=say)
    print(f"hidden effect: gravity_sag_A, s = {a.sag * 1e3:.1f} um")
    f = r["finding"]
    if f:
        name, p = next(iter(f["parameters"].items()))
        size = f"{name} = {units.estimate_text(p['value'], p['std'], p['unit'])}"
        if f["named"]:
            print(
                f"diagnosis found: {f['effect']} ({f['cause']}, weight {f['weight']:.2f}), {size}"
            )
        else:
            print(
                f"diagnosis found one of: {group_text(f)}, which this session cannot separate "
                f"(BIC weights); if {f['effect']}: {size}"
            )
        print(model_text(f))
    else:
        print("diagnosis found nothing significant")
    if r["loop"]:
        print_loop(r["loop"])
    print(
        f"compensation reduced every location error by at least {-r['worst_change_percent']:.1f} %"
    )
    print(f"report: {Path(r['report']).resolve()}")
    return EXIT_OK


def print_loop(loop: dict) -> None:
    """The loop of a group (demo.close_the_loop): the deciding test, both sessions together, the
    gain and the location errors of the final model."""

    for t in loop["tried"]:
        print(f"deciding test for {' and '.join(t['pair'])}: {t['verdict']}")
    if not loop.get("added_test"):
        print("no added test separates the group's members: the model rule decides between them")
        return
    if not _print_joint_step(loop, "the session and the added test together", "both sessions"):
        return
    o = loop.get("other_instrument")
    if not o:
        return
    print(f"no added ballbar test separates what is left; the other instrument: {o['test']}")
    _print_joint_step(o, "the three sessions together", "the three sessions")


def cmd_table2(a: argparse.Namespace) -> int:
    """Measured before/after identifications (default: Flynn et al.'s Table 2) against the
    simulated measure -> compensate -> measure-again chain: what falls outside, and why."""
    from .. import flynn_table2 as t2

    table = t2.load_table2(a.table) if a.table else t2.load_table2()
    assumptions = t2.Assumptions(
        noise_um=a.noise, noise_rho=a.rho, hours_between_runs=a.hours, method=a.method
    )
    result = t2.analyse(
        table, assumptions, draws=a.draws, seed=a.seed, sweep=[] if a.no_sweep else None
    )
    print(jsontext.dumps(result) if a.json else t2.render(result))
    return EXIT_OK


def add_table2(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "table2",
        help="measured before/after compensation (Flynn et al. Table 2) against "
        "the simulated chain: what falls outside, and which causes explain it",
        epilog=EPILOG,
    )
    q.add_argument(
        "--table",
        type=path("--table"),
        metavar="FILE.json",
        help="before/after values in the layout of rotacal/data/flynn2016_table2.json "
        "(default: the paper's Table 2)",
    )
    q.add_argument(
        "--method",
        default="paper",
        choices=["paper", "joint"],
        help="identification of both runs (the paper used its own chain)",
    )
    q.add_argument(
        "--noise",
        type=number("--noise", 0.0, 100.0, "um", lo_open=True),
        default=0.5,
        help="assumed 1-sigma ballbar noise, um",
    )
    q.add_argument(
        "--rho",
        type=number("--rho", 0.0, 0.999),
        default=0.0,
        help="assumed AR(1) correlation of successive samples",
    )
    q.add_argument(
        "--hours",
        type=number("--hours", 0.0, 10_000.0, "h"),
        default=1.0,
        help="assumed time between the two runs, h",
    )
    q.add_argument("--draws", type=number("--draws", 10, 100_000, integer=True), default=200)
    q.add_argument("--seed", type=SEED, default=1)
    q.add_argument(
        "--no-sweep", action="store_true", help="skip the sweep over the unstated assumptions"
    )
    q.add_argument("--json", action="store_true")
    q.set_defaults(func=cmd_table2)


def add_demo(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "demo",
        help="the whole job on a simulated machine: plan, simulate, identify, "
        "diagnose, compensate, report",
        epilog=EPILOG,
    )
    q.add_argument("-o", "--output", default="out/demo", type=path("--output"))
    q.add_argument("--seed", type=SEED, default=2016)
    q.add_argument(
        "--sag",
        type=number("--sag", -1.0, 1.0, "mm"),
        default=0.004,
        help="hidden gravity sag of the A table, mm",
    )
    q.set_defaults(func=cmd_demo)


COMMANDS = {"table2": add_table2, "demo": add_demo}


def _print_joint_step(step: dict, together: str, sessions: str) -> bool:
    """One step of the loop: what the sessions diagnosed together found, each session's residual
    before and after, and the final model's location errors; False where nothing was found."""
    from ..diagnosis import group_text, model_text

    f = step["finding"]
    if f is None:
        print(f"{together}: nothing significant")
        return False
    if f["named"]:
        print(f"{together}: {f['effect']} alone (weight {f['weight']:.2f})")
    else:
        print(f"{together}: one of {group_text(f)}")
    print(model_text(f))
    for x in step["sessions"]:
        print(
            f"  {x['name']}: residual RMS {x['residual_rms_before_um']:.3f} -> "
            f"{x['residual_rms_after_um']:.3f} um"
        )
    print(f"location errors of the final model ({sessions}):")
    for name, p in step["location_errors"].items():
        print(f"  {name} = {units.estimate_text(p['value'], p['std'], p['unit'])}")
    return True
