# SPDX-License-Identifier: BSD-3-Clause
"""Argument groups that several commands share, and what they read: the ballbar test set-up
(plan, simulate, design, compensate, virtual, record), the simulated machine, the R-test
pattern, the session a command analyses, and the history store."""

from __future__ import annotations

import argparse
from typing import Any, Sequence

from .. import _core, jsontext, rtest
from ..machines import BALLBAR_NOISE_UM, PIVOT_ERROR_MM
from ..outputs import write_output
from ..sessions import check_plausible, kind, load
from .options import (
    SEED,
    OptionError,
    effects_option,
    errors_option,
    float_list_item,
    number,
    numbers,
    path,
    say,
    shell_word,
)

# The CLI's C range: 0..359 deg, one step short of the full turn (the C++ default is 0..360).
CLI_C_RANGE = "0,359"


# ------------------------------------------------------------------------- ballbar set-up


def add_setup_args(p: argparse.ArgumentParser) -> None:
    d = _core.BallbarSetup()  # the C++ defaults (ballbar/plan.hpp), shown in the help
    g = p.add_argument_group("test set-up (Flynn et al. 2016, Table 1)")
    g.add_argument(
        "--machine",
        metavar="NAME|FILE",
        help=f"a built-in machine ({', '.join(_core.builtin_machine_names())}; rotacal machines) or a "
        f"rotacal-machine/1 JSON file (docs/machines.md); default {_core.machine_name(d.machine)}",
    )
    g.add_argument(
        "--length",
        type=number("--length", 1.0, 2000.0, "mm"),
        help=f"calibrated ballbar length L0, mm (default {d.ballbar_length:g})",
    )
    g.add_argument(
        "--pivot",
        type=numbers("--pivot", 3, 1e4, "mm"),
        help="nominal pivot x,y,z on the table, mm (O_x, 0, O_z; default "
        f"{','.join(f'{v:g}' for v in d.pivot)})",
    )
    g.add_argument(
        "--a-range",
        "--b-range",
        "--tilt-range",
        dest="tilt_range",
        type=numbers("--a-range/--b-range", 2, 360.0, "deg"),
        help="range of the tilt axis (A or B, on the table or in the head), deg (default: the "
        "machine's, rotacal machines show NAME; "
        f"{','.join(f'{v:g}' for v in _core.default_tilt_range_deg(d.machine))} on AC-trt)",
    )
    g.add_argument(
        "--c-range",
        default=CLI_C_RANGE,
        type=numbers("--c-range", 2, 720.0, "deg"),
        help=f"range of the rotary axis C, deg (default {CLI_C_RANGE})",
    )
    g.add_argument(
        "--axial-c-tilt",
        type=number("--axial-c-tilt", -360.0, 360.0, "deg"),
        metavar="DEG",
        help="tilt held during axial_C, deg (default: the machine's; 45 on a head-head machine, "
        "where at tilt 0 the ball sits on the C axis, else 0)",
    )
    g.add_argument(
        "--step",
        type=number("--step", 0.01, 90.0, "deg", lo_open=False),
        help=f"sample spacing, deg (default {d.step_deg:g})",
    )
    g.add_argument(
        "--feed",
        type=number("--feed", 1.0, 1e5, "mm/min"),
        help=f"linear feed, mm/min (default {d.feed_mm_per_min:g})",
    )
    g.add_argument(
        "--rotary-feed",
        type=number("--rotary-feed", 1.0, 1e6, "deg/min"),
        help=f"rotary feed, deg/min (default {d.feed_deg_per_min:g})",
    )
    g.add_argument(
        "--tests",
        default="",
        help="comma-separated test labels (default: the seven of Flynn et al.; "
        "tangential_A/B/C put the bar along the pivot's circle)",
    )
    g.add_argument(
        "--radial-c", help="radial C tool circle outside or inside the pivot's (default outside)"
    )
    g.add_argument(
        "--directions",
        default="",
        help="directions every rotary test runs in, e.g. ccw,cw (default ccw; cw runs are "
        "labelled _cw)",
    )
    g.add_argument(
        "--feed-factors",
        default="",
        help="feeds every rotary test runs at, as factors of --feed/--rotary-feed starting "
        "with 1, e.g. 1,2 (runs at other feeds are labelled _f<mm/min>)",
    )


def ballbar_setup(a: argparse.Namespace) -> Any:
    """The C++ BallbarSetup with the options given laid over its defaults; the machine's own
    defaults (default_tilt_range_deg, default_axial_c_tilt_deg) for what is not given."""
    from ..machines import load_machine

    s = _core.BallbarSetup() if a.machine is None else _core.BallbarSetup(load_machine(a.machine))
    for option, field in (
        ("length", "ballbar_length"),
        ("step", "step_deg"),
        ("feed", "feed_mm_per_min"),
        ("rotary_feed", "feed_deg_per_min"),
        ("pivot", "pivot"),
        ("tilt_range", "tilt_range_deg"),
        ("c_range", "rot_range_deg"),
        ("axial_c_tilt", "axial_c_tilt_deg"),
    ):
        if getattr(a, option) is not None:
            setattr(s, field, getattr(a, option))
    if a.tests:
        s.tests = [_core.parse_ballbar_test(t.strip(), s.machine) for t in a.tests.split(",")]
    if a.radial_c is not None:
        s.radial_c_side = _core.parse_radial_side(a.radial_c)
    if a.directions:
        s.directions = [_core.parse_sweep_direction(t.strip()) for t in a.directions.split(",")]
    if a.feed_factors:
        s.feed_factors = [float_list_item("--feed-factors", t) for t in a.feed_factors.split(",")]
    return s


def ballbar_model(path: str | None) -> Any:
    """The ballbar model of a --model/--compensate file, or None."""
    if not path:
        return None
    from ..models import ballbar_model_from_dict, load_model

    return ballbar_model_from_dict(load_model(path), path)


# ------------------------------------------------------------------------- simulated ballbar machine


def add_truth_args(q: argparse.ArgumentParser) -> None:
    g = q.add_argument_group("simulated machine")
    g.add_argument(
        "--errors",
        default="random",
        help="random (seeded), table2 (Flynn et al.), zero, or NAME=VALUE,... (mm, rad)",
    )
    g.add_argument(
        "--effect",
        action="append",
        metavar="ID=P1,P2",
        help="hide a catalogue effect, e.g. gravity_sag_A=0.004 (repeatable)",
    )
    g.add_argument(
        "--pivot-error",
        type=number("--pivot-error", 0.0, 10.0, "mm"),
        default=PIVOT_ERROR_MM,
        help="1-sigma pivot placement error, mm",
    )
    g.add_argument(
        "--noise",
        type=number("--noise", 0.0, 1000.0, "um"),
        default=BALLBAR_NOISE_UM,
        help="1-sigma reading noise, um",
    )
    g.add_argument("--seed", type=SEED, default=1)


def ballbar_truth(a: argparse.Namespace, setup: Any) -> dict:
    """The simulated ballbar machine of --errors, --effect, --pivot-error, --noise, --seed."""
    from ..machines import ballbar_truth as truth

    if a.noise * 1e-3 * 10 >= setup.ballbar_length:
        raise OptionError(
            f"--noise: {a.noise:g} um is too large for a {setup.ballbar_length:g} mm bar "
            "(lengths would come out negative)"
        )
    return truth(
        setup.machine,
        errors_option(a.errors),
        effects_option(a.effect),
        pivot_error_mm=a.pivot_error,
        noise_um=a.noise,
        seed=a.seed,
    )


def write_truth(truth: dict, path: str, other_outputs: Sequence[str | None] = ()) -> None:
    write_output(path, jsontext.dumps(truth) + "\n", other_outputs=[o for o in other_outputs if o])


# ------------------------------------------------------------------------- R-test pattern


def add_rtest_pattern_args(q: argparse.ArgumentParser) -> None:
    g = q.add_argument_group(
        "measurement pattern (Oyama & Ibaraki Sec. 3.3; left out: the machine's "
        "default pattern inside its limits and travel, the paper's on BC-trt)"
    )
    g.add_argument(
        "--machine",
        default="BC-trt",
        type=path("--machine"),
        metavar="NAME|FILE",
        help="a built-in (`rotacal machines`) or a rotacal-machine/1 description file (default BC-trt)",
    )
    g.add_argument(
        "--b-range",
        dest="tilt_range",
        default=None,
        type=numbers("--b-range", 2, 360.0, "deg"),
        help="tilt axis range, deg (inclusive; default the machine's, -90,90 on BC-trt)",
    )
    g.add_argument(
        "--b-step",
        type=number("--b-step", 0.0, 360.0, "deg"),
        default=None,
        help="tilt step, deg (default 30)",
    )
    g.add_argument(
        "--c-range",
        default=None,
        type=numbers("--c-range", 2, 720.0, "deg"),
        help="rotary axis range, deg (inclusive; an end one full turn after the start is left out; "
        "default 0,360)",
    )
    g.add_argument(
        "--c-step",
        type=number("--c-step", 0.0, 360.0, "deg"),
        default=None,
        help="rotary axis step, deg (default 30)",
    )
    g.add_argument(
        "--nest",
        action="append",
        metavar="X,Y,Z",
        type=numbers("--nest", 3, 1e4, "mm"),
        help="nominal ball centre of a sensor nest, table frame, mm (repeatable; default "
        "the paper's two: 100,0,60 and 0,-120,140)",
    )
    g.add_argument(
        "--dwell",
        type=number("--dwell", 0.0, 3600.0, "s", lo_open=True),
        default=rtest.DEFAULT_DWELL_S,
        help="time between poses, s; each pose is held at rest and read in the middle 80 %% of it "
        "(docs/protocols.md)",
    )


def add_rtest_machine_args(q: argparse.ArgumentParser, probe_dir_help: str) -> None:
    g = q.add_argument_group("simulated machine and instrument")
    g.add_argument(
        "--errors",
        default="random",
        help="location errors: random (seeded), zero, or NAME=VALUE,... (mm, rad)",
    )
    g.add_argument(
        "--effect",
        action="append",
        metavar="ID=P1,P2",
        help="position-dependent error from the effects catalogue, e.g. gravity_sag_B=0.006 "
        "or axial_motion_C_h2=0.002,-0.001 (repeatable)",
    )
    g.add_argument(
        "--noise",
        type=number("--noise", 0.0, 1000.0, "um"),
        default=rtest.DEFAULT_NOISE_UM,
        help="1-sigma reading noise, um",
    )
    g.add_argument(
        "--probe-zero",
        type=number("--probe-zero", 0.0, 1e4, "um"),
        default=rtest.DEFAULT_PROBE_ZERO_UM,
        help="1-sigma probe zero per set-up, um",
    )
    g.add_argument(
        "--probe-dir",
        action="append",
        metavar="X,Y,Z",
        type=numbers("--probe-dir", 3, 1e3),
        help=probe_dir_help,
    )
    g.add_argument("--seed", type=SEED, default=1)


def rtest_inputs(a: argparse.Namespace) -> dict:
    """The pattern and simulated machine of `simulate rtest` / `virtual rtest` / `record rtest`:
    a grid or nests not given are the machine's default pattern (inside its rotary limits and
    travel: rtest.default_pattern; the paper's on BC-trt); given ones are checked later."""
    from ..machines import load_machine

    mtype = load_machine(a.machine)
    default = rtest.default_pattern(mtype)

    def grid(given_range, step, fallback, what, full_turn=False):
        if given_range is None and step is None:
            return fallback
        lo, hi = min(fallback), max(fallback)
        if (
            full_turn
            and len(fallback) > 1
            and abs(hi + (fallback[1] - fallback[0]) - lo - 360.0) < 1e-9
        ):
            hi = lo + 360.0  # the default turns a full circle: so does a new step
        lo, hi = given_range if given_range is not None else (lo, hi)
        return rtest.angle_grid(lo, hi, 30.0 if step is None else step, what, full_turn=full_turn)

    out = {
        "machine": mtype,
        "b_deg": grid(a.tilt_range, a.b_step, default["b_deg"], "--b-range/--b-step"),
        "c_deg": grid(a.c_range, a.c_step, default["c_deg"], "--c-range/--c-step", full_turn=True),
        "nests": a.nest if a.nest else default["nests"],
        "dwell_s": a.dwell,
        "probe_dirs": None,
    }
    if getattr(a, "errors", None) is not None:
        out["errors"] = errors_option(a.errors)
        out["effects"] = effects_option(a.effect)
    if a.probe_dir:
        import numpy as np

        if len(a.probe_dir) != 3:
            raise OptionError(
                f"--probe-dir: give it 3 times (probes 1, 2, 3), got {len(a.probe_dir)}"
            )
        dirs = np.array(a.probe_dir)
        norms = np.linalg.norm(dirs, axis=1, keepdims=True)
        if np.any(norms < 1e-9):
            raise OptionError("--probe-dir: a direction of length 0")
        out["probe_dirs"] = dirs / norms
    return out


# ------------------------------------------------------------------------- the session analysed


def add_plausibility_arg(q: argparse.ArgumentParser) -> None:
    q.add_argument(
        "--max-deviation",
        type=number("--max-deviation", 0.0, 1000.0, "mm", lo_open=True),
        metavar="MM",
        help="largest abs(measured - nominal) a reading may have before the session is "
        f"refused as implausible (default {_core.PlausibilityOptions().max_length_deviation_mm:g} mm)",
    )


def load_session(
    path: str,
    a: argparse.Namespace | None = None,
    circular_tests: bool = False,
    several: bool = False,
) -> Any:
    """The session of ``path``; what its reader warned about (e.g. repeated rows) on stderr.
    With the command's arguments ``a``, the session is also checked against the nominal
    kinematics before any fit (--max-deviation widens the limit); ISO 230-4 circular tests
    are refused unless the command reads them (``circular_tests``: `rotacal report`). A
    touch-probe session of a diagnosis of ``several`` may hold one pose (an added test that
    continues the session it was designed after: diagnose/multi_session.hpp)."""
    s = load(path)
    for w in s.warnings:
        say(f"rotacal: warning: {path}: {w}")
    if a is not None:
        from ..circular import is_circular

        if is_circular(s) and not circular_tests:
            raise _core.InvalidArgument(
                f"{path}: holds ISO 230-4 circular tests of the linear axes ({', '.join(sorted(set(s.tests))[:3])}"
                f"{', ...' if len(set(s.tests)) > 3 else ''}), not a rotary-axis test: `rotacal circular analyze "
                f"{shell_word(path)}` gives G, G(b), H and their causes, `rotacal report {shell_word(path)} -o OUT.html` the report"
            )
        if not is_circular(s):
            rest = several and kind(s) == "probe"
            check_plausible(s, path, getattr(a, "max_deviation", None), rotary_axes_may_rest=rest)
    return s


def add_db_arg(q: Any) -> None:
    from ..history import ENV_STORE

    q.add_argument(
        "--db",
        metavar="PATH|URL",
        type=path("--db"),
        help="the history store: a SQLite file, or a postgresql://user@host/dbname URL; default "
        f"${ENV_STORE}, else ~/.local/share/rotacal/history.sqlite (its folder is created)",
    )
