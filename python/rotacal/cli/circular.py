# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal circular plan|simulate|virtual|record|analyze``: ISO 230-4 circular tests of the
linear axes with the ballbar (the library: rotacal.circular)."""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from .. import _core, jsontext
from ..circular import (
    AXES,
    PLANES,
    analyze,
    errors,
    nc_program,
    plan,
    polar_plot,
    record_ballbar,
    simulation_options,
    truth_dict,
    virtual_ballbar,
)
from ..outputs import write_output
from ..sessions import load, save
from . import serial_link
from .options import EPILOG, EXIT_OK, axis_values, names, number, number_list, numbers, path, say
from .serial_link import add_record_args, add_virtual_args, faults, report_recording


def _add_plan_args(q: argparse.ArgumentParser) -> None:
    g = q.add_argument_group("the test (ISO 230-4)")
    g.add_argument(
        "--machine",
        default=None,
        help="built-in machine or rotacal-machine/1 file (default AC-trt); rotary axes stay at 0",
    )
    g.add_argument(
        "--length",
        type=number("--length", 0.0, 1e4, "mm", lo_open=True),
        default=100.0,
        help="bar length L0 = radius, mm",
    )
    g.add_argument(
        "--pivot",
        type=numbers("--pivot", 3, 1e5, "mm"),
        default=[120.0, 0.0, 60.0],
        help="centre pivot, table frame at rotary zero, mm (default 120,0,60: the rotary test's)",
    )
    g.add_argument(
        "--planes",
        type=names("--planes", PLANES),
        default=list(PLANES),
        help="XY,YZ,ZX (default all)",
    )
    g.add_argument(
        "--feeds",
        type=number_list("--feeds", 1.0, 1e5, "mm/min", most=8),
        default=[1000.0, 3000.0],
        help="path feeds, mm/min (default 1000,3000)",
    )
    g.add_argument(
        "--directions",
        type=names("--directions", ("ccw", "cw")),
        default=["ccw", "cw"],
        help="ccw,cw (default both)",
    )
    g.add_argument(
        "--start",
        type=number("--start", -3600.0, 3600.0, "deg"),
        default=0.0,
        help="start of the data arc, deg (--start=-20 for a negative one)",
    )
    g.add_argument(
        "--span",
        type=number("--span", 0.0, 360.0, "deg", lo_open=True),
        default=360.0,
        help="data arc, deg (e.g. 220 for a partial arc)",
    )
    g.add_argument(
        "--run-in",
        type=number("--run-in", 0.0, 360.0, "deg"),
        default=45.0,
        help="arc before the data arc, deg",
    )
    g.add_argument(
        "--overshoot",
        type=number("--overshoot", 0.0, 360.0, "deg"),
        default=45.0,
        help="arc after the data arc, deg",
    )
    g.add_argument(
        "--rate",
        type=number("--rate", 0.0, 1e5, "Hz", lo_open=True),
        default=250.0,
        help="ballbar sample rate, Hz",
    )


def _add_machine_args(k: argparse.ArgumentParser) -> None:
    g = k.add_argument_group("simulated machine (units as named; default: no error)")
    g.add_argument(
        "--squareness",
        type=axis_values("--squareness", PLANES, -1e4, 1e4),
        metavar="XY=S,...",
        help="urad; XY: x += s y, YZ: y += s z, ZX: z += s x",
    )
    g.add_argument(
        "--scale", type=axis_values("--scale", AXES, -1e4, 1e4), metavar="X=K,...", help="um/m"
    )
    g.add_argument(
        "--straightness",
        type=axis_values("--straightness", ["XY", "XZ", "YX", "YZ", "ZX", "ZY"], -1e3, 1e3),
        metavar="YX=C,...",
        help="um at 100 mm from the centre (DA: error direction D, moving axis A)",
    )
    g.add_argument(
        "--backlash",
        type=axis_values("--backlash", AXES, 0.0, 1e3),
        metavar="X=B,...",
        help="lost motion, um",
    )
    g.add_argument(
        "--spike",
        type=axis_values("--spike", AXES, 0.0, 1e3),
        metavar="X=H,...",
        help="reversal spike height, um",
    )
    g.add_argument(
        "--spike-tau",
        type=axis_values("--spike-tau", AXES, 0.1, 1e4),
        metavar="X=T,...",
        help="reversal spike decay time, ms (default 15)",
    )
    g.add_argument(
        "--servo-lag",
        type=axis_values("--servo-lag", AXES, 0.0, 1e3),
        metavar="X=T,...",
        help="position-loop time constant 1/Kv, ms",
    )
    g.add_argument(
        "--cyclic",
        type=axis_values("--cyclic", AXES, -1e3, 1e3, per_key=2),
        metavar="X=C:S,...",
        help="cyclic error, um: cos and sin amplitudes over the screw lead",
    )
    g.add_argument(
        "--pitch",
        type=axis_values("--pitch", AXES, 0.01, 1e4),
        metavar="X=P,...",
        help="screw leads, mm (default 10)",
    )
    g.add_argument(
        "--centring-error",
        type=numbers("--centring-error", 3, 10.0, "mm"),
        default=None,
        help="pivot ball off the commanded centre, mm (default: random, 5 um 1-sigma, seeded)",
    )
    g.add_argument(
        "--length-error",
        type=number("--length-error", -1e4, 1e4, "um"),
        default=0.0,
        help="bar calibration error, um",
    )
    g.add_argument(
        "--noise",
        type=number("--noise", 0.0, 1000.0, "um"),
        default=0.3,
        help="1-sigma reading noise, um",
    )
    g.add_argument(
        "--rho",
        type=number("--rho", 0.0, 0.999, ""),
        default=0.9,
        help="AR(1) correlation between readings",
    )
    g.add_argument("--seed", type=number("--seed", 0, 2**32 - 1, integer=True), default=1)


def _machine_options(a: argparse.Namespace) -> tuple[Any, Any]:
    """The simulated machine of the options (``errors``, ``simulation_options``) and its truth JSON."""
    e = errors(
        squareness_urad=a.squareness,
        scale_um_per_m=a.scale,
        straightness_um=a.straightness,
        backlash_um=a.backlash,
        spike_um=a.spike,
        spike_tau_ms=a.spike_tau,
        servo_lag_ms=a.servo_lag,
        cyclic_um=a.cyclic,
        screw_pitch_mm=a.pitch,
    )
    rng = np.random.default_rng(a.seed)
    centring = (
        a.centring_error if a.centring_error is not None else (rng.normal(0.0, 0.005, 3)).tolist()
    )  # a pivot set by hand: ~5 um
    o = simulation_options(
        e,
        centring_error_mm=centring,
        length_error_mm=a.length_error * 1e-3,
        noise_um=a.noise,
        noise_rho=a.rho,
        seed=a.seed,
    )
    return o, truth_dict(e, centring, a.length_error * 1e-3, a.noise, a.rho, a.seed)


def _planned(a: argparse.Namespace) -> Any:
    return plan(
        a.planes,
        a.feeds,
        a.directions,
        machine=a.machine,
        radius=a.length,
        centre=a.pivot,
        start_deg=a.start,
        span_deg=a.span,
        run_in_deg=a.run_in,
        overshoot_deg=a.overshoot,
        sample_rate_hz=a.rate,
    )


def _cmd_plan(a: argparse.Namespace) -> int:
    planned = _planned(a)
    write_output(a.output, nc_program(planned, a.dialect), [], [a.session] if a.session else [])
    last = planned.runs[-1]
    say(
        f"wrote {a.output}: {a.dialect} program, {len(planned.runs)} runs, "
        f"{planned.num_samples()} readings, {last.time[-1]:.0f} s of data and moves"
    )
    if a.session:
        save(_core.circular_commanded_session(planned), a.session, [], [a.output])
        say(f"wrote {a.session}: the commanded rows as a session template")
    return EXIT_OK


def _cmd_simulate(a: argparse.Namespace) -> int:
    planned = _planned(a)
    o, data = _machine_options(a)
    session = _core.simulate_circular(planned, o)
    save(session, a.output, [], [a.truth] if a.truth else [])
    say(f"wrote {a.output}: {len(planned.runs)} circular runs, {planned.num_samples()} readings")
    if a.truth:
        write_output(a.truth, jsontext.dumps(data) + "\n", [], [a.output])
        say(f"wrote {a.truth}: the simulated machine")
    return EXIT_OK


def _cmd_virtual(a: argparse.Namespace) -> int:
    planned = _planned(a)
    o, data = _machine_options(a)
    if a.truth:
        write_output(a.truth, jsontext.dumps(data) + "\n")
    dev = virtual_ballbar(planned, o, speed=a.speed, baud=a.baud, faults=faults(a))
    last = planned.runs[-1]
    return serial_link.serve(
        dev,
        "ballbar",
        a,
        f"circular program, {len(planned.runs)} runs, {last.time[-1]:.0f} s, "
        f"{a.rate:g} Hz, speed x{a.speed:g}",
    )


def _cmd_record(a: argparse.Namespace) -> int:
    planned = _planned(a)
    summary = record_ballbar(
        a.port,
        planned,
        a.output,
        baud=a.baud,
        zero=a.zero,
        silence_timeout_s=a.silence,
        progress=not a.no_progress,
    )
    return report_recording(summary, a.output, a.json)


def _cmd_analyze(a: argparse.Namespace) -> int:
    session = load(a.file)
    pitch = [10.0, 10.0, 10.0]
    for k, v in (a.pitch or {}).items():
        pitch[AXES.index(k)] = v
    result = analyze(session, diagnose=not a.no_diagnose, screw_pitch_mm=pitch, source=a.file)
    if a.json:
        print(jsontext.dumps(result.to_dict()))
    else:
        print(result.text(), end="")
    if a.plot:
        polar_plot(result, a.plot, [a.file])
        say(f"wrote {a.plot}: polar plot of the radial deviations")
    return EXIT_OK


def add_circular(sub: argparse._SubParsersAction) -> argparse._SubParsersAction:
    """Register ``rotacal circular plan|simulate|virtual|record|analyze`` on the CLI's subparsers."""
    q = sub.add_parser(
        "circular",
        help="ISO 230-4 circular tests of the linear axes with the ballbar",
        description="Circular tests of the linear axes (ISO 230-4) with the same ballbar, set-up and "
        "rotacal-ballbar/1 files as the rotary test: plan writes the NC program, simulate a "
        "session with circular_* tests, virtual serves a simulated ballbar playing the "
        "program on a pseudo-terminal, record reads a ballbar into a session, analyze "
        "prints G, G(b), H and the named causes.",
        epilog=EPILOG,
    )
    acts = q.add_subparsers(dest="action", required=True)

    k = acts.add_parser("plan", help="write the NC program of the circular tests", epilog=EPILOG)
    _add_plan_args(k)
    k.add_argument("--dialect", default="linuxcnc", help="linuxcnc, heidenhain, siemens, fanuc")
    k.add_argument(
        "--session",
        metavar="CSV",
        type=path("--session"),
        help="also write the commanded rows as a session template",
    )
    k.add_argument("-o", "--output", required=True, type=path("--output"))
    k.set_defaults(func=_cmd_plan)

    k = acts.add_parser(
        "simulate", help="simulate the ballbar on a machine with linear-axis errors", epilog=EPILOG
    )
    _add_plan_args(k)
    _add_machine_args(k)
    k.add_argument(
        "--truth", metavar="JSON", type=path("--truth"), help="write the simulated machine here"
    )
    k.add_argument("-o", "--output", required=True, type=path("--output"))
    k.set_defaults(func=_cmd_simulate)

    # The two ends of a serial line: the plan's options (and --rate as the stream's rate) and a baud rate.
    for name, summary, text in (
        (
            "virtual",
            "a virtual ballbar on a pseudo-terminal playing the circular program",
            "Serves the ballbar protocol (docs/protocols.md) on a pseudo-terminal while a simulated machine with the "
            "given linear-axis errors runs the planned circular program (the options of plan and simulate); prints "
            "the port. Record it with `rotacal circular record --port PORT` and the same plan options.",
        ),
        (
            "record",
            "record a circular test from a ballbar on a serial port",
            "Reads the ballbar on --port while the machine runs the planned circular program (the same plan options "
            "as `plan`; --rate is the requested sample rate) and writes a rotacal-ballbar/1 file as it goes: rows on "
            "a data arc labelled with their run (circular_XY_ccw, ...), the others 'transition'. `rotacal circular "
            "analyze` reads it.",
        ),
    ):
        k = acts.add_parser(name, help=summary, description=text, epilog=EPILOG)
        _add_plan_args(k)
        k.add_argument(
            "--baud",
            type=number("--baud", 50, 4_000_000, integer=True),
            default=115200,
            help="baud rate (default 115200)",
        )
        if name == "virtual":
            _add_machine_args(k)
            add_virtual_args(k)
            k.set_defaults(func=_cmd_virtual)
        else:
            k.add_argument("--zero", action="store_true", help="send ZERO before START")
            add_record_args(k)
            k.set_defaults(func=_cmd_record)

    k = acts.add_parser(
        "analyze", help="G, G(b), H per plane and the causes the data support", epilog=EPILOG
    )
    k.add_argument("file", type=path("FILE"))
    k.add_argument(
        "--pitch",
        type=axis_values("--pitch", AXES, 0.01, 1e4),
        metavar="X=P,...",
        help="screw leads for the cyclic-error entries, mm (default 10)",
    )
    k.add_argument("--no-diagnose", action="store_true", help="the ISO 230-4 results only")
    k.add_argument("--json", action="store_true")
    k.add_argument(
        "--plot", metavar="PNG", type=path("--plot"), help="polar plot of the radial deviations"
    )
    k.set_defaults(func=_cmd_analyze)
    return acts


COMMANDS = {"circular": add_circular}
