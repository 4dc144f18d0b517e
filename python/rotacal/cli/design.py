# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal design ballbar|rtest``: the test set-up with the smallest predicted uncertainty,
or the added test that separates two effects a session could not tell apart."""

from __future__ import annotations

import argparse
import math
from typing import Any, Sequence

from .. import _core, jsontext
from ..command_files import separation_template_path
from ..outputs import write_output
from ..sessions import BALLBAR, PROBE, RTEST, kind, save
from .options import EPILOG, EXIT_OK, OptionError, number, number_list, numbers, path, say
from .setups import add_setup_args, ballbar_setup, load_session


def _run_time(text: str) -> float:
    """design --time: 0 (the default set-up's run time) or 1 s to 24 h; the predicted sigmas
    scale as 1/sqrt(time), so 1e-300 s printed 1e146 mm (issue 32)."""
    v = number("--time", 0.0, 86400.0, "s")(text)
    if 0.0 < v < 1.0:
        raise OptionError(
            f"--time: {text[:40]} s is no run time (0: the default set-up's, else 1 to 86400 s)"
        )
    return v


def _session_after(a: argparse.Namespace, wanted: str) -> Any:
    """The session of --after that a --separate design follows, of the instrument designed."""
    if not a.after:
        raise OptionError("--separate: give the session it follows with --after SESSION")
    session = load_session(a.after)
    if kind(session) != wanted:
        words = {
            BALLBAR: ("a ballbar session", "ballbar"),
            RTEST: ("an R-test session", "rtest"),
            PROBE: ("a touch-probe session", "probe"),
        }
        raise OptionError(
            f"--after {a.after}: {words[kind(session)][0]}; design {words[wanted][1]} --separate "
            f"needs {words[wanted][0]}"
        )
    return session


def cmd_design_separation(a: argparse.Namespace) -> int:
    from ..ballbar import nc_program
    from ..design import added_setup, design_separation, parameter_units, separation_dict

    session = _session_after(a, BALLBAR)
    base = ballbar_setup(a)
    d = design_separation(
        session,
        [e.strip() for e in a.separate.split(",")],
        base=base,
        lengths=a.lengths,
        pivot_r=a.pivot_r,
        pivot_angle=a.pivot_angle,
        pivot_z=a.pivot_z,
        travel=a.travel,
        tilt_limits=a.tilt_limits,
        max_time_s=a.max_time,
        max_correlation=a.max_correlation,
        noise_um=a.noise or 0.0,
    )
    template = separation_template_path(a)
    if (a.output or template) and d.found:
        plan, text = nc_program(added_setup(d), a.dialect, None, None)
        if a.output:
            write_output(a.output, text, [a.after], [template] if template else [])
            say(f"wrote {a.output}: {a.dialect} program of the added test, {plan.duration:.0f} s")
        if template:  # as plan --session: what record/import of the measured test fills in
            save(plan.commanded_session(), template, [a.after], [a.output] if a.output else [])
            say(f"wrote {template}: the added test's commanded rows as a session template")
    elif a.output or template:
        say("rotacal: -o/--session not written: no added test separates them")
    if a.json:
        print(jsontext.dumps(separation_dict(d)))
        return EXIT_OK
    _print_separation(d, a.after, parameter_units(d.names))
    return EXIT_OK


def _print_separation(d: Any, after_path: str, units: Sequence[tuple[str, float]]) -> None:
    """The verdict of a --separate design and the predicted 1-sigma before and after."""
    print(d.verdict)
    if d.motion.same_motion:
        return
    print(
        f"noise {d.noise_um:.3f} um per reading, {d.effective_per_reading:.2f} effective samples per reading "
        f"(from {after_path}); {d.candidates_tried} added tests tried"
    )
    after = list(d.sigma_after) if d.candidates_tried else list(d.sigma_before)
    print("predicted 1-sigma, session alone -> with the added test (inf: not determined):")
    before = list(d.sigma_before) + [math.inf] * (len(d.names) - len(d.sigma_before))
    for n, b_, a_, (unit, k) in zip(d.names, before, after, units):
        print(f"  {n:28s} {b_ * k:10.4f} -> {a_ * k:10.4f} {unit}")


def cmd_design_ballbar(a: argparse.Namespace) -> int:
    from ..ballbar import nc_program
    from ..design import design_ballbar, design_dict

    if a.separate:
        return cmd_design_separation(a)
    if a.after:
        raise OptionError("--after: goes with --separate EFFECT,EFFECT")
    if a.session:
        raise OptionError("--session: goes with --separate (the added test's template)")
    a.noise = 0.5 if a.noise is None else a.noise
    d = design_ballbar(
        ballbar_setup(a),
        lengths=a.lengths,
        pivot_x=a.pivot_x,
        pivot_z=a.pivot_z,
        travel=a.travel,
        time_s=a.time,
        rate_hz=a.rate,
        noise_um=a.noise,
        rho=a.rho,
        effects=[e.strip() for e in a.effects.split(",")] if a.effects else [],
    )
    if a.output:
        plan, text = nc_program(d.best.setup, a.dialect, None, None)
        write_output(a.output, text)
        say(
            f"wrote {a.output}: {a.dialect} program of the designed set-up, {plan.duration:.0f} s at the base feeds"
        )
    if a.json:
        print(jsontext.dumps(design_dict(d)))
        return EXIT_OK
    feasible = sum(c.feasible for c in d.candidates)
    print(
        f"{len(d.candidates)} set-ups tried, {feasible} within the limits; run time {d.time_budget_s:.0f} s, "
        f"noise {a.noise:g} um at {a.rate:g} Hz" + (f", AR(1) rho {a.rho:g}" if a.rho else "")
    )
    for label, c in (("designed", d.best), ("default", d.baseline)):
        if not c.feasible:
            print(
                f"{label:9s} L0 {c.setup.ballbar_length:g} mm, pivot {tuple(map(float, c.setup.pivot))}: {c.why_not}"
            )
            continue
        print(
            f"{label:9s} L0 {c.setup.ballbar_length:g} mm, pivot ({c.setup.pivot[0]:g}, {c.setup.pivot[1]:g}, "
            f"{c.setup.pivot[2]:g}) mm: largest expanded uncertainty (k=2) {c.worst_expanded_um:.3f} um "
            f"({c.worst_error})"
        )
    if d.baseline.feasible:
        print(f"ratio designed / default: {d.ratio:.3f}")
    from ..design import parameter_units

    names, sig = d.best.names, d.best.sigma
    print("predicted 1-sigma of the designed test (inf: this set-up cannot determine it):")
    for n, s_, (unit, k) in zip(names, sig, parameter_units(names)):
        print(f"  {n:24s} {s_ * k:10.4f} {unit}")
    for n, a_, b_ in zip(names[11:], d.best.effect_vs_location, d.best.effect_vs_effects):
        print(
            f"  {n}: largest correlation with a location error {a_:.2f}, with another effect {b_:.2f}"
        )
    return EXIT_OK


def cmd_design_rtest_separation(a: argparse.Namespace) -> int:
    from ..design import design_rtest_separation, parameter_units, rtest_separation_dict

    session = _session_after(a, RTEST)
    d = design_rtest_separation(
        session,
        [e.strip() for e in a.separate.split(",")],
        radii=a.radii,
        angles=a.nest_angles,
        heights=a.heights,
        b_steps=a.b_steps,
        c_steps=a.c_steps,
        b_limits=a.b_limits,
        travel=a.travel,
        dwell_s=a.dwell or 0.0,
        max_time_s=a.max_time,
        max_correlation=a.max_correlation,
        noise_um=a.noise or 0.0,
    )
    if a.session and d.found:  # as plan --session: the pattern's commanded rows, to be measured
        from ..instruments import rtest_program

        p = d.chosen.added
        template = rtest_program(
            _core.machine_name(session.machine), p.b_deg, p.c_deg, p.nests, p.dwell_s
        )
        save(template, a.session, [a.after])
        say(f"wrote {a.session}: the added nest's commanded rows as a session template")
    elif a.session:
        say("rotacal: --session not written: no added nest separates them")
    if a.json:
        print(jsontext.dumps(rtest_separation_dict(d)))
        return EXIT_OK
    _print_separation(d, a.after, parameter_units(d.names))
    if d.found:
        p = d.chosen.added
        b, c = list(p.b_deg), list(p.c_deg)
        print(
            f"run it with: --nest {','.join(f'{v:g}' for v in p.nests[0])} --b-range {b[0]:g},{b[-1]:g} "
            f"--b-step {b[1] - b[0] if len(b) > 1 else 0:g} --c-step {c[1] - c[0] if len(c) > 1 else 360:g} "
            f"--dwell {p.dwell_s:g}"
        )
    return EXIT_OK


def cmd_design_rtest(a: argparse.Namespace) -> int:
    from ..design import rtest_design_dict, design_rtest

    if a.separate:
        return cmd_design_rtest_separation(a)
    if a.after:
        raise OptionError("--after: goes with --separate EFFECT,EFFECT")
    if a.session:
        raise OptionError("--session: goes with --separate (the added nest's template)")
    a.noise = 0.3 if a.noise is None else a.noise
    d = design_rtest(
        radii=a.radii,
        heights=a.heights,
        b_steps=a.b_steps,
        c_steps=a.c_steps,
        b_limits=a.b_limits,
        travel=a.travel,
        time_s=a.time,
        noise_um=a.noise,
        rho=a.rho,
        dwell_s=a.dwell,
    )
    if a.json:
        print(jsontext.dumps(rtest_design_dict(d)))
        return EXIT_OK
    feasible = sum(c.feasible for c in d.candidates)
    print(
        f"{len(d.candidates)} patterns tried, {feasible} within the limits; run time {d.time_budget_s:.0f} s, "
        f"noise {a.noise:g} um per reading" + (f", AR(1) rho {a.rho:g}" if a.rho else "")
    )
    for label, c in (("designed", d.best), ("default", d.baseline)):
        p = c.pattern
        nests = "; ".join(",".join(f"{v:g}" for v in n) for n in p.nests)
        if not c.feasible:
            print(f"{label:9s} nests {nests}: {c.why_not}")
            continue
        print(
            f"{label:9s} nests {nests} mm, B {len(p.b_deg)} x C {len(p.c_deg)} poses, {c.duration_s:.0f} s: "
            f"largest expanded uncertainty (k=2) {c.worst_expanded_um:.3f} um ({c.worst_error})"
        )
    if d.baseline.feasible:
        print(f"ratio designed / default: {d.ratio:.3f}")
    p = d.best.pattern
    b = list(p.b_deg)
    c = list(p.c_deg)
    step = lambda v: v[1] - v[0] if len(v) > 1 else 360.0  # noqa: E731
    print(
        "run it with: "
        + " ".join(f"--nest {','.join(f'{v:g}' for v in n)}" for n in p.nests)
        + f" --b-range {b[0]:g},{b[-1]:g} --b-step {step(b):g} --c-step {step(c):g} --dwell {p.dwell_s:g}"
        + (
            f" (repeat it {d.time_budget_s / d.best.duration_s:.2f} times, or dwell longer, to fill the run time)"
            if d.best.duration_s < d.time_budget_s * 0.999
            else ""
        )
    )
    print("predicted 1-sigma of the location errors:")
    for i, (n, s_) in enumerate(zip(d.best.names[:8], d.best.sigma[:8])):
        unit, k = ("urad", 1e6) if i in (2, 3, 6, 7) else ("um", 1e3)
        print(f"  {n:8s} {s_ * k:10.4f} {unit}")
    return EXIT_OK


def add_separation_group(k: argparse.ArgumentParser, added: str, session: str) -> Any:
    """--separate, --after, --max-time, --max-correlation of `design KIND` (docs/design.md)."""
    g = k.add_argument_group(
        f"the {added} that separates two effects after a session (docs/design.md)"
    )
    g.add_argument(
        "--separate",
        metavar="EFFECT,EFFECT",
        help=f"two catalogue ids the diagnosis could not tell apart: propose the smallest added {added} "
        "that brings their correlation below --max-correlation, or say why none can",
    )
    g.add_argument(
        "--after", type=path("--after"), metavar="SESSION", help=f"the {session} they follow"
    )
    g.add_argument(
        "--max-time",
        type=number("--max-time", 0.0, 86400.0, "s", lo_open=True),
        default=600.0,
        help=f"longest added {added}, s (default 600)",
    )
    g.add_argument(
        "--max-correlation",
        type=number("--max-correlation", 0.0, 1.0, "", lo_open=True),
        default=0.5,
        help="target largest canonical correlation of the pair (default 0.5)",
    )
    return g


def add_design(sub: argparse._SubParsersAction) -> argparse._SubParsersAction:
    q = sub.add_parser(
        "design",
        help="design a test before the machine runs it",
        epilog=EPILOG + "; docs/design.md",
    )
    dk = q.add_subparsers(dest="kind", required=True)
    _add_design_ballbar(dk)
    _add_design_rtest(dk)
    return dk


def _add_design_ballbar(dk: argparse._SubParsersAction) -> None:
    k = dk.add_parser(
        "ballbar",
        help="the pivot and bar length with the smallest predicted uncertainty",
        epilog=EPILOG + "; docs/design.md",
    )
    add_setup_args(k)
    k.add_argument(
        "--lengths",
        type=number_list("--lengths", 1.0, 2000.0, "mm", 10),
        default=[100.0, 150.0],
        help="bar lengths available, mm (default 100,150)",
    )
    k.add_argument(
        "--pivot-x",
        type=number_list("--pivot-x", 0.0, 2000.0, "mm", 30),
        help="pivot distances from the C axis to try, mm (default 60,90,120,150,180)",
    )
    k.add_argument(
        "--pivot-z",
        type=number_list("--pivot-z", -2000.0, 2000.0, "mm", 30),
        help="pivot heights above the tilt axis to try, mm (default 20,40,60,90,120)",
    )
    k.add_argument(
        "--travel",
        type=numbers("--travel", 6, 1e5, "mm"),
        help="xmin,xmax,ymin,ymax,zmin,zmax of X, Y, Z about the rotary axes' intersection, mm "
        "(default -400,400,-300,300,-300,400)",
    )
    k.add_argument(
        "--time",
        type=_run_time,
        default=0.0,
        help="run time to compare at, s (default: the default set-up's)",
    )
    k.add_argument(
        "--rate",
        type=number("--rate", 0.0, 1e5, "Hz", lo_open=True),
        default=100.0,
        help="the recorder's sample rate, Hz (default 100)",
    )
    k.add_argument(
        "--noise",
        type=number("--noise", 0.0, 1000.0, "um", lo_open=True),
        help="1-sigma noise per sample, um (default 0.5; with --after: the session's residual noise)",
    )
    k.add_argument(
        "--rho",
        type=number("--rho", 0.0, 0.999, ""),
        default=0.0,
        help="AR(1) coefficient of the noise between samples (default 0: white)",
    )
    k.add_argument(
        "--effects", help="effects of concern, fitted along: catalogue ids, comma separated"
    )
    g = add_separation_group(k, "test", "ballbar session")
    g.add_argument(
        "--pivot-r",
        type=number_list("--pivot-r", 0.0, 2000.0, "mm", 30),
        help="moved pivot: distances from the C axis, mm (default 0,60,120,180)",
    )
    g.add_argument(
        "--pivot-angle",
        type=number_list("--pivot-angle", -360.0, 360.0, "deg", 12),
        help="moved pivot: angles about C from +X, deg (default 0,90)",
    )
    g.add_argument(
        "--tilt-limits",
        type=numbers("--tilt-limits", 2, 360.0, "deg"),
        help="rotary limits of the tilt axis, deg (default -90,90)",
    )
    k.add_argument("--dialect", default="linuxcnc", help="NC dialect of -o (as plan)")
    k.add_argument(
        "-o",
        "--output",
        type=path("--output"),
        help="write the designed test's NC program here (with --separate: the added test's, and "
        "its session template beside it as .csv unless --session names one)",
    )
    k.add_argument(
        "--session",
        type=path("--session"),
        metavar="TEMPLATE.csv",
        help="with --separate: write the added test's commanded rows as a session template here",
    )
    k.add_argument("--json", action="store_true")
    k.set_defaults(func=cmd_design_ballbar)


def _add_design_rtest(dk: argparse._SubParsersAction) -> None:
    k = dk.add_parser(
        "rtest",
        help="the R-test nests and B/C grid with the smallest predicted uncertainty",
        epilog=EPILOG + "; docs/design.md",
    )
    k.add_argument(
        "--radii",
        type=number_list("--radii", 0.0, 2000.0, "mm", 20),
        help="nest distances from the C axis to try, mm (default 50,100,150)",
    )
    k.add_argument(
        "--heights",
        type=number_list("--heights", -2000.0, 2000.0, "mm", 20),
        help="nest heights above the B axis to try, mm (default 20,60,100,140)",
    )
    k.add_argument(
        "--b-steps",
        type=number_list("--b-steps", 0.1, 180.0, "deg", 20),
        help="B grid steps to try, deg (default 15,30,45)",
    )
    k.add_argument(
        "--c-steps",
        type=number_list("--c-steps", 0.1, 359.0, "deg", 20),
        help="C grid steps to try over a full turn, deg (default 30,45,60)",
    )
    k.add_argument(
        "--b-limits",
        type=numbers("--b-limits", 2, 360.0, "deg"),
        help="rotary limits of B, deg (default -90,90)",
    )
    k.add_argument(
        "--travel",
        type=numbers("--travel", 6, 1e5, "mm"),
        help="xmin,xmax,ymin,ymax,zmin,zmax of X, Y, Z about the rotary axes' intersection, mm "
        "(default -400,400,-300,300,-300,400)",
    )
    k.add_argument(
        "--time",
        type=_run_time,
        default=0.0,
        help="run time to compare at, s (default: the default pattern's)",
    )
    k.add_argument(
        "--dwell",
        type=number("--dwell", 0.0, 3600.0, "s", lo_open=True),
        help="time per pose, s (default 6)",
    )
    k.add_argument(
        "--noise",
        type=number("--noise", 0.0, 1000.0, "um", lo_open=True),
        help="1-sigma noise per reading component, um (default 0.3; with --after: the session's)",
    )
    k.add_argument(
        "--rho",
        type=number("--rho", 0.0, 0.999, ""),
        default=0.0,
        help="AR(1) coefficient of the noise between readings (default 0: white)",
    )
    g = add_separation_group(k, "nest", "R-test session")
    g.add_argument(
        "--nest-angles",
        type=number_list("--nest-angles", -360.0, 360.0, "deg", 12),
        help="added nest: angles about C from +X, deg (default 0,90,180,270)",
    )
    g.add_argument(
        "--session",
        type=path("--session"),
        metavar="CSV",
        help="write the added nest's commanded rows (set-up, time, B, C, X, Y, Z) as a session "
        "template here: the pattern record rtest runs, diagnosed with --after's session "
        "(rotacal diagnose SESSION CSV)",
    )
    k.add_argument("--json", action="store_true")
    k.set_defaults(func=cmd_design_rtest)


COMMANDS = {"design": add_design}
