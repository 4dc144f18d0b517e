# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal virtual ballbar|rtest`` (a virtual instrument on a pseudo-terminal, for testing
recorders without a machine) and ``rotacal record ballbar|rtest`` (a session from an
instrument on a serial port)."""

from __future__ import annotations

import argparse

from .. import _core
from . import serial_link
from .options import EPILOG, numbers, number
from .serial_link import add_link_args, add_record_args, add_virtual_args, faults, report_recording
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


def cmd_virtual_ballbar(a: argparse.Namespace) -> int:
    from ..instruments import virtual_ballbar

    setup = ballbar_setup(a)
    from ..machines import ballbar_machine_model

    truth = ballbar_truth(a, setup)
    plan = _core.plan_ballbar_test(setup, None)
    model = ballbar_machine_model(setup, truth)
    truth["pivot_actual"] = model.pivot.tolist()
    if a.truth:
        write_truth(truth, a.truth)
    dev = virtual_ballbar(
        plan,
        model,
        noise_um=a.noise,
        seed=a.seed,
        rate_hz=a.rate,
        speed=a.speed,
        baud=a.baud,
        faults=faults(a),
    )
    return serial_link.serve(
        dev, "ballbar", a, f"{plan.duration:.1f} s program at {a.rate:g} Hz, speed x{a.speed:g}"
    )


def cmd_virtual_rtest(a: argparse.Namespace) -> int:
    from ..instruments import virtual_rtest

    r = rtest_inputs(a)
    dev, truth = virtual_rtest(
        r["errors"],
        r["effects"],
        machine=r["machine"],
        b_deg=r["b_deg"],
        c_deg=r["c_deg"],
        nests=r["nests"],
        dwell_s=r["dwell_s"],
        noise_um=a.noise,
        probe_zero_um=a.probe_zero,
        probe_dirs=r["probe_dirs"],
        seed=a.seed,
        mode=a.mode,
        rate_hz=a.rate,
        speed=a.speed,
        baud=a.baud,
        faults=faults(a),
    )
    if a.truth:
        write_truth(truth, a.truth)
    return serial_link.serve(
        dev, "R-test", a, f"{a.mode} mode, {len(dev.program)} poses, speed x{a.speed:g}"
    )


def cmd_record_ballbar(a: argparse.Namespace) -> int:
    from ..instruments import record_ballbar

    plan = _core.plan_ballbar_test(ballbar_setup(a), None)
    summary = record_ballbar(
        a.port,
        plan,
        a.output,
        baud=a.baud,
        rate_hz=a.rate,
        zero=a.zero,
        silence_timeout_s=a.silence,
        progress=not a.no_progress,
    )
    return report_recording(summary, a.output, a.json)


def cmd_record_rtest(a: argparse.Namespace) -> int:
    from ..instruments import record_rtest, rtest_program

    r = rtest_inputs(a)
    program = rtest_program(r["machine"], r["b_deg"], r["c_deg"], r["nests"], r["dwell_s"])
    summary = record_rtest(
        a.port,
        program,
        a.output,
        mode=a.mode,
        dwell_s=r["dwell_s"],
        probe_dirs=r["probe_dirs"],
        baud=a.baud,
        rate_hz=a.rate,
        speed=a.speed,
        silence_timeout_s=a.silence,
        progress=not a.no_progress,
    )
    return report_recording(summary, a.output, a.json)


def add_virtual(sub: argparse._SubParsersAction) -> argparse._SubParsersAction:
    q = sub.add_parser(
        "virtual", help="a virtual instrument on a pseudo-terminal (prints its path)", epilog=EPILOG
    )
    kinds = q.add_subparsers(dest="kind", required=True)
    k = kinds.add_parser(
        "ballbar", help="a ballbar on a simulated machine running the test program", epilog=EPILOG
    )
    add_setup_args(k)
    add_truth_args(k)
    add_link_args(k, 1000.0)
    add_virtual_args(k)
    k.set_defaults(func=cmd_virtual_ballbar)
    k = kinds.add_parser(
        "rtest", help="an R-test on a simulated B/C table running the pattern", epilog=EPILOG
    )
    add_rtest_pattern_args(k)
    add_rtest_machine_args(k, "probe direction (give 3 times; default a 45-deg tripod)")
    k.add_argument(
        "--mode", default="keyence", choices=["sylvac", "keyence", "stream"], help="probe protocol"
    )
    add_link_args(k, 100.0)
    add_virtual_args(k)
    k.set_defaults(func=cmd_virtual_rtest)
    return kinds


def add_record(sub: argparse._SubParsersAction) -> argparse._SubParsersAction:
    q = sub.add_parser(
        "record",
        help="record a session from an instrument on a serial port",
        epilog=EPILOG + "; a recording that ends by disconnect, silence or no valid data "
        "exits with 4, its rows kept in the file",
    )
    kinds = q.add_subparsers(dest="kind", required=True)
    k = kinds.add_parser(
        "ballbar", help="record a ballbar test (the same set-up options as plan)", epilog=EPILOG
    )
    add_setup_args(k)
    add_link_args(k, 1000.0)
    k.add_argument(
        "--zero",
        action="store_true",
        help="zero the transducer before START (normally done in the calibrator)",
    )
    add_record_args(k)
    k.set_defaults(func=cmd_record_ballbar)
    k = kinds.add_parser(
        "rtest", help="record an R-test (the same pattern options as simulate rtest)", epilog=EPILOG
    )
    add_rtest_pattern_args(k)
    k.add_argument(
        "--probe-dir",
        action="append",
        metavar="X,Y,Z",
        type=numbers("--probe-dir", 3, 1e3),
        help="calibrated probe direction (give 3 times; default a 45-deg tripod)",
    )
    k.add_argument(
        "--mode", default="keyence", choices=["sylvac", "keyence", "stream"], help="probe protocol"
    )
    k.add_argument(
        "--speed",
        type=number("--speed", 0.0, 1e4, lo_open=True),
        default=1.0,
        help="polled modes: the instrument's virtual seconds per real second (virtual instruments only)",
    )
    add_link_args(k, 100.0)
    add_record_args(k)
    k.set_defaults(func=cmd_record_rtest)
    return kinds


COMMANDS = {"virtual": add_virtual, "record": add_record}
