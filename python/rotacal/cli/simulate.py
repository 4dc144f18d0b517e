# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal simulate ballbar|rtest``: a measurement on a simulated machine with errors."""

from __future__ import annotations

import argparse

from .. import _core, rtest
from ..command_files import rtest_truth_path
from ..sessions import save
from .options import EPILOG, EXIT_OK, OptionError, path, say
from .setups import (
    add_rtest_machine_args,
    add_rtest_pattern_args,
    add_setup_args,
    add_truth_args,
    ballbar_setup,
    ballbar_truth,
    rtest_inputs,
    write_truth,
)


def cmd_simulate(a: argparse.Namespace) -> int:
    from ..machines import simulate_ballbar_test

    setup = ballbar_setup(a)
    truth = ballbar_truth(a, setup)
    session, model = simulate_ballbar_test(setup, truth)
    save(session, a.output, other_outputs=[a.truth])
    truth["pivot_actual"] = model.pivot.tolist()
    if a.truth:
        write_truth(truth, a.truth, [a.output])
    say(
        f"wrote {a.output}: {len(session)} samples on a simulated {_core.machine_name(setup.machine)}"
        + (f", truth in {a.truth}" if a.truth else "")
    )
    return EXIT_OK


def cmd_simulate_rtest(a: argparse.Namespace) -> int:
    truth_path = rtest_truth_path(a)
    r = rtest_inputs(a)
    b_deg, c_deg, nests, dirs = r["b_deg"], r["c_deg"], r["nests"], r["probe_dirs"]
    if dirs is None and a.raw_only:
        raise OptionError("--raw-only needs the probe directions (--probe-dir x3)")
    mtype = r["machine"]
    session, truth = rtest.simulate_rtest(
        r["errors"],
        r["effects"],
        machine=mtype,
        b_deg=b_deg,
        c_deg=c_deg,
        nests=nests,
        noise_um=a.noise,
        probe_zero_um=a.probe_zero,
        probe_dirs=dirs,
        write_d=not a.raw_only,
        dwell_s=a.dwell,
        seed=a.seed,
    )
    save(session, a.output, other_outputs=[truth_path])
    rtest.save_truth(truth, truth_path, other_outputs=[a.output])
    say(
        f"wrote {a.output}: {len(session)} poses ({len(b_deg)} {mtype.tilt_axis} x {len(c_deg)} "
        f"{mtype.rot_axis} x {len(nests)} nests) on a simulated {_core.machine_name(mtype)}, truth in {truth_path}"
    )
    return EXIT_OK


def add_simulate(sub: argparse._SubParsersAction) -> argparse._SubParsersAction:
    q = sub.add_parser(
        "simulate", help="simulate a measurement on a machine with errors", epilog=EPILOG
    )
    kinds = q.add_subparsers(dest="kind", required=True, metavar="{ballbar,rtest}")
    k = kinds.add_parser(
        "ballbar", help="the single set-up ballbar test (Flynn et al. 2016)", epilog=EPILOG
    )
    add_setup_args(k)
    add_truth_args(k)
    k.add_argument(
        "--truth", metavar="JSON", type=path("--truth"), help="write the simulated machine here"
    )
    k.add_argument("-o", "--output", required=True, type=path("--output"))
    k.set_defaults(func=cmd_simulate)
    k = kinds.add_parser(
        "rtest",
        help="the R-test pattern of Oyama & Ibaraki Sec. 3.3 on a B/C table",
        description="Writes a rotacal-rtest/1 session and, beside it, FILE.truth.json "
        "(the simulated machine, the probe zeros and the pattern).",
        epilog=EPILOG,
    )
    add_rtest_pattern_args(k)
    add_rtest_machine_args(
        k, "probe direction (give 3 times, normalised): also write raw d1,d2,d3 with probe.N.dir"
    )
    k.add_argument(
        "--raw-only", action="store_true", help="with --probe-dir: write d1,d2,d3 but no dx,dy,dz"
    )
    k.add_argument(
        "--truth",
        metavar="JSON",
        type=path("--truth"),
        help="where to write the truth (default: FILE.truth.json)",
    )
    k.add_argument("-o", "--output", required=True, type=path("--output"))
    k.set_defaults(func=cmd_simulate_rtest)
    return kinds


COMMANDS = {"simulate": add_simulate}
