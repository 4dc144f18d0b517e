"""The ``rotacal`` command line: parses arguments, calls the package, prints.

Exit codes: 0 success; 2 usage error; 3 invalid input (a malformed file, a bad parameter, a
degenerate geometry); 4 I/O error (cannot read or write a file or device); 5 any other
rotacal error.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path
from typing import Any, Callable, Sequence

from . import _core, jsontext, rtest, units
from .command_files import check_command_files, rtest_truth_path
from .diagnosis import MAX_HARMONIC
from .machines import BALLBAR_NOISE_UM, PIVOT_ERROR_MM
from .outputs import write_output
from .sessions import BALLBAR, RTEST, by_kind, check_plausible, checked_path, load, save

EXIT_OK, EXIT_USAGE, EXIT_INPUT, EXIT_IO, EXIT_ERROR = 0, 2, 3, 4, 5

EPILOG = ("exit codes: 0 success, 2 usage error, 3 invalid input (malformed file, bad parameter, "
          "degenerate geometry), 4 I/O error, 5 other rotacal error")

# The CLI's C range: 0..359 deg, one step short of the full turn (the C++ default is 0..360).
CLI_C_RANGE = "0,359"


def _say(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


# ------------------------------------------------------------------------- option parsers
# One parser per kind of option. A bad value raises OptionError (exit 3, the option named);
# argparse would turn a ValueError into a usage error (exit 2), so OptionError is not one.

class OptionError(Exception):
    """An option value that is not acceptable; the message names the option."""


def number(option: str, lo: float, hi: float, unit: str = "", integer: bool = False,
           lo_open: bool = False) -> Callable[[str], float]:
    """argparse type: a finite number in [lo, hi] (or (lo, hi] with lo_open)."""
    def parse(text: str) -> float:
        try:
            v = int(text, 10) if integer else float(text)
        except ValueError:
            raise OptionError(f"{option}: '{text[:40]}' is not {'an integer' if integer else 'a number'}") from None
        if not math.isfinite(v) or v > hi or v < lo or (lo_open and v == lo):
            rng = f"{'(' if lo_open else '['}{lo:g}, {hi:g}]"
            raise OptionError(f"{option}: {text[:40]} is outside {rng}{' ' + unit if unit else ''}")
        return v
    return parse


def numbers(option: str, n: int, limit: float, unit: str = "") -> Callable[[str], list[float]]:
    """argparse type: n comma-separated finite numbers, each within +-limit."""
    def parse(text: str) -> list[float]:
        try:
            vals = [float(v) for v in text.split(",")]
        except ValueError:
            raise OptionError(f"{option}: '{text[:60]}' is not {n} comma-separated numbers") from None
        if len(vals) != n or not all(math.isfinite(v) for v in vals):
            raise OptionError(f"{option}: '{text[:60]}' must be {n} finite comma-separated numbers")
        if any(abs(v) > limit for v in vals):
            raise OptionError(f"{option}: '{text[:60]}': each value must be within +-{limit:g} {unit}".rstrip())
        return vals
    return parse


def number_list(option: str, lo: float, hi: float, unit: str = "", most: int = 50) -> Callable[[str], list[float]]:
    """argparse type: 1 to `most` comma-separated finite numbers, each in [lo, hi]."""
    def parse(text: str) -> list[float]:
        try:
            vals = [float(v) for v in text.split(",")]
        except ValueError:
            raise OptionError(f"{option}: '{text[:60]}' is not a comma-separated list of numbers") from None
        if not 1 <= len(vals) <= most or not all(math.isfinite(v) and lo <= v <= hi for v in vals):
            raise OptionError(f"{option}: '{text[:60]}': 1 to {most} values, each in [{lo:g}, {hi:g}] {unit}".rstrip())
        return vals
    return parse


def path(option: str) -> Callable[[str], str]:
    """argparse type: a file name (not empty, no NUL byte)."""
    def parse(text: str) -> str:
        try:
            return checked_path(text, option)
        except _core.InvalidArgument as e:
            raise OptionError(str(e)) from None
    return parse


SEED = number("--seed", 0, 2**32 - 1, integer=True)


def _run_time(text: str) -> float:
    """design --time: 0 (the default set-up's run time) or 1 s to 24 h; the predicted sigmas
    scale as 1/sqrt(time), so 1e-300 s printed 1e146 mm (issue 32)."""
    v = number("--time", 0.0, 86400.0, "s")(text)
    if 0.0 < v < 1.0:
        raise OptionError(f"--time: {text[:40]} s is no run time (0: the default set-up's, else 1 to 86400 s)")
    return v


def effects_option(items: Sequence[str] | None) -> dict[str, list[float]]:
    """--effect ID=P1,P2 (repeatable) -> {id: [values]}, counts checked against the catalogue."""
    out: dict[str, list[float]] = {}
    for item in items or []:
        key, _, val = item.partition("=")
        eff = _core.Effect(key.strip())
        out[eff.id] = numbers(f"--effect {key.strip()}", eff.num_params, 1e3)(val)
    return out


def errors_option(text: str) -> Any:
    """--errors: random, zero, table2 or NAME=VALUE,... (mm, rad); the names are checked
    against the machine by machines.location_errors."""
    if text in ("random", "zero", "table2"):
        return text
    out: dict[str, float] = {}
    for item in text.split(","):
        key, _, val = item.partition("=")
        out[key.strip()] = numbers(f"--errors {key.strip()}", 1, 10.0)(val)[0]
    return out


# ------------------------------------------------------------------------- plan and set-up

def _add_setup_args(p: argparse.ArgumentParser) -> None:
    d = _core.BallbarSetup()  # the C++ defaults (ballbar/plan.hpp), shown in the help
    g = p.add_argument_group("test set-up (Flynn et al. 2016, Table 1)")
    g.add_argument("--machine", metavar="NAME|FILE",
                   help=f"a built-in machine ({', '.join(_core.builtin_machine_names())}; rotacal machines) or a "
                        f"rotacal-machine/1 JSON file (docs/machines.md); default {_core.machine_name(d.machine)}")
    g.add_argument("--length", type=number("--length", 1.0, 2000.0, "mm"),
                   help=f"calibrated ballbar length L0, mm (default {d.ballbar_length:g})")
    g.add_argument("--pivot", type=numbers("--pivot", 3, 1e4, "mm"),
                   help="nominal pivot x,y,z on the table, mm (O_x, 0, O_z; default "
                        f"{','.join(f'{v:g}' for v in d.pivot)})")
    g.add_argument("--a-range", "--b-range", "--tilt-range", dest="tilt_range",
                   type=numbers("--a-range/--b-range", 2, 360.0, "deg"),
                   help="range of the tilt axis (A or B, on the table or in the head), deg (default: the "
                        "machine's, rotacal machines show NAME; "
                        f"{','.join(f'{v:g}' for v in _core.default_tilt_range_deg(d.machine))} on AC-trt)")
    g.add_argument("--c-range", default=CLI_C_RANGE, type=numbers("--c-range", 2, 720.0, "deg"),
                   help=f"range of the rotary axis C, deg (default {CLI_C_RANGE})")
    g.add_argument("--axial-c-tilt", type=number("--axial-c-tilt", -360.0, 360.0, "deg"), metavar="DEG",
                   help="tilt held during axial_C, deg (default: the machine's; 45 on a head-head machine, "
                        "where at tilt 0 the ball sits on the C axis, else 0)")
    g.add_argument("--step", type=number("--step", 0.01, 90.0, "deg", lo_open=False),
                   help=f"sample spacing, deg (default {d.step_deg:g})")
    g.add_argument("--feed", type=number("--feed", 1.0, 1e5, "mm/min"),
                   help=f"linear feed, mm/min (default {d.feed_mm_per_min:g})")
    g.add_argument("--rotary-feed", type=number("--rotary-feed", 1.0, 1e6, "deg/min"),
                   help=f"rotary feed, deg/min (default {d.feed_deg_per_min:g})")
    g.add_argument("--tests", default="", help="comma-separated test labels (default: the seven of Flynn et al.; "
                                              "tangential_A/B/C put the bar along the pivot's circle)")
    g.add_argument("--radial-c", help="radial C tool circle outside or inside the pivot's (default outside)")
    g.add_argument("--directions", default="",
                   help="directions every rotary test runs in, e.g. ccw,cw (default ccw; cw runs are "
                        "labelled _cw)")
    g.add_argument("--feed-factors", default="",
                   help="feeds every rotary test runs at, as factors of --feed/--rotary-feed starting "
                        "with 1, e.g. 1,2 (runs at other feeds are labelled _f<mm/min>)")


def _setup(a: argparse.Namespace) -> Any:
    """The C++ BallbarSetup with the options given laid over its defaults; the machine's own
    defaults (default_tilt_range_deg, default_axial_c_tilt_deg) for what is not given."""
    from .machines import load_machine
    s = _core.BallbarSetup() if a.machine is None else _core.BallbarSetup(load_machine(a.machine))
    for option, field in (("length", "ballbar_length"), ("step", "step_deg"), ("feed", "feed_mm_per_min"),
                          ("rotary_feed", "feed_deg_per_min"), ("pivot", "pivot"), ("tilt_range", "tilt_range_deg"),
                          ("c_range", "rot_range_deg"), ("axial_c_tilt", "axial_c_tilt_deg")):
        if getattr(a, option) is not None:
            setattr(s, field, getattr(a, option))
    if a.tests:
        s.tests = [_core.parse_ballbar_test(t.strip(), s.machine) for t in a.tests.split(",")]
    if a.radial_c is not None:
        s.radial_c_side = _core.parse_radial_side(a.radial_c)
    if a.directions:
        s.directions = [_core.parse_sweep_direction(t.strip()) for t in a.directions.split(",")]
    if a.feed_factors:
        s.feed_factors = [_float_list_item("--feed-factors", t) for t in a.feed_factors.split(",")]
    return s


def _float_list_item(option: str, text: str) -> float:
    """One number of a comma-separated option; refused by name (the plan checks its range)."""
    try:
        return float(text.strip())
    except ValueError:
        raise _core.InvalidArgument(f"{option}: '{text.strip()}' is not a number") from None


def _model(path: str | None) -> Any:
    """The ballbar model of a --model/--compensate file, or None."""
    if not path:
        return None
    from .models import ballbar_model_from_dict, load_model
    return ballbar_model_from_dict(load_model(path), path)


def cmd_plan(a: argparse.Namespace) -> int:
    from .ballbar import nc_program
    plan, text = nc_program(_setup(a), a.dialect, _model(a.compensate), a.compensate)
    write_output(a.output, text, [a.compensate] if a.compensate else [], [a.session] if a.session else [])
    _say(f"wrote {a.output}: {a.dialect} program, {plan.num_samples} points, {plan.duration:.0f} s"
         + (" (compensated)" if a.compensate else ""))
    if a.session:
        save(plan.commanded_session(), a.session, [a.compensate], [a.output])
        _say(f"wrote {a.session}: the commanded rows as a session template")
    return EXIT_OK


# ------------------------------------------------------------------------- machines

def cmd_machines(a: argparse.Namespace) -> int:
    """List the built-in machines, or show one (built-in or file): drawing, error names, JSON."""
    from .machines import load_machine, machine_dict, machine_drawing
    if a.action == "list":
        if a.machine is not None:
            raise OptionError(f"machines: 'list' takes no machine (got {a.machine[:60]!r}); "
                              "rotacal machines show NAME|FILE")
        rows = [machine_dict(n) for n in _core.builtin_machine_names()]
        if a.json:
            print(jsontext.dumps([{k: r[k] for k in ("name", "configuration", "axis_names", "tilt_axis", "rot_axis",
                                                     "axes", "location_error_names")} for r in rows]))
            return EXIT_OK
        print(f"{len(rows)} built-in machines (any other: a rotacal-machine/1 file, docs/machines.md):")
        for r in rows:
            sides = ", ".join(f"{ax['name']} {ax['side']}" for ax in r["axes"])
            print(f"  {r['name']:16s} {r['configuration']:12s} axes {''.join(r['axis_names'])} ({sides})")
        return EXIT_OK
    if a.machine is None:
        raise OptionError("machines show: give a built-in name or a rotacal-machine/1 file")
    d = machine_dict(a.machine)
    if a.json:
        print(jsontext.dumps(d))
        return EXIT_OK
    print(machine_drawing(a.machine), end="")
    print()
    print(f"location errors (LocationErrors order): {' '.join(d['location_error_names'])}")
    print(f"default test ranges: tilt {d['default_tilt_range_deg'][0]:g} .. {d['default_tilt_range_deg'][1]:g} deg, "
          f"tilt held during axial_{d['rot_axis']} {d['default_axial_c_tilt_deg']:g} deg")
    print("description (rotacal-machine/1, as a session's '# machine_description:' carries it):")
    print(load_machine(a.machine).description_json)
    return EXIT_OK


# ------------------------------------------------------------------------- simulate

def _truth(a: argparse.Namespace, setup: Any) -> dict:
    """The simulated ballbar machine of --errors, --effect, --pivot-error, --noise, --seed."""
    from .machines import ballbar_truth
    if a.noise * 1e-3 * 10 >= setup.ballbar_length:
        raise OptionError(f"--noise: {a.noise:g} um is too large for a {setup.ballbar_length:g} mm bar "
                          "(lengths would come out negative)")
    return ballbar_truth(setup.machine, errors_option(a.errors), effects_option(a.effect),
                         pivot_error_mm=a.pivot_error, noise_um=a.noise, seed=a.seed)


def _write_truth(truth: dict, path: str, other_outputs: Sequence[str | None] = ()) -> None:
    write_output(path, jsontext.dumps(truth) + "\n", other_outputs=[o for o in other_outputs if o])


def cmd_simulate(a: argparse.Namespace) -> int:
    from .machines import simulate_ballbar_test
    setup = _setup(a)
    truth = _truth(a, setup)
    session, model = simulate_ballbar_test(setup, truth)
    save(session, a.output, other_outputs=[a.truth])
    truth["pivot_actual"] = model.pivot.tolist()
    if a.truth:
        _write_truth(truth, a.truth, [a.output])
    _say(f"wrote {a.output}: {len(session)} samples on a simulated {_core.machine_name(setup.machine)}"
         + (f", truth in {a.truth}" if a.truth else ""))
    return EXIT_OK


def _rtest_inputs(a: argparse.Namespace) -> dict:
    """The pattern and simulated machine of `simulate rtest` / `virtual rtest` / `record rtest`:
    a grid or nests not given are the machine's default pattern (inside its rotary limits and
    travel: rtest.default_pattern; the paper's on BC-trt); given ones are checked later."""
    from . import rtest
    from .machines import load_machine
    mtype = load_machine(a.machine)
    default = rtest.default_pattern(mtype)

    def grid(given_range, step, fallback, what, full_turn=False):
        if given_range is None and step is None:
            return fallback
        lo, hi = min(fallback), max(fallback)
        if full_turn and len(fallback) > 1 and abs(hi + (fallback[1] - fallback[0]) - lo - 360.0) < 1e-9:
            hi = lo + 360.0  # the default turns a full circle: so does a new step
        lo, hi = given_range if given_range is not None else (lo, hi)
        return rtest.angle_grid(lo, hi, 30.0 if step is None else step, what, full_turn=full_turn)

    out = {"machine": mtype,
           "b_deg": grid(a.tilt_range, a.b_step, default["b_deg"], "--b-range/--b-step"),
           "c_deg": grid(a.c_range, a.c_step, default["c_deg"], "--c-range/--c-step", full_turn=True),
           "nests": a.nest if a.nest else default["nests"],
           "dwell_s": a.dwell, "probe_dirs": None}
    if getattr(a, "errors", None) is not None:
        out["errors"] = errors_option(a.errors)
        out["effects"] = effects_option(a.effect)
    if a.probe_dir:
        import numpy as np
        if len(a.probe_dir) != 3:
            raise OptionError(f"--probe-dir: give it 3 times (probes 1, 2, 3), got {len(a.probe_dir)}")
        dirs = np.array(a.probe_dir)
        norms = np.linalg.norm(dirs, axis=1, keepdims=True)
        if np.any(norms < 1e-9):
            raise OptionError("--probe-dir: a direction of length 0")
        out["probe_dirs"] = dirs / norms
    return out


def cmd_simulate_rtest(a: argparse.Namespace) -> int:
    truth_path = rtest_truth_path(a)
    r = _rtest_inputs(a)
    b_deg, c_deg, nests, dirs = r["b_deg"], r["c_deg"], r["nests"], r["probe_dirs"]
    if dirs is None and a.raw_only:
        raise OptionError("--raw-only needs the probe directions (--probe-dir x3)")
    mtype = r["machine"]
    session, truth = rtest.simulate_rtest(r["errors"], r["effects"], machine=mtype, b_deg=b_deg, c_deg=c_deg,
                                          nests=nests, noise_um=a.noise, probe_zero_um=a.probe_zero,
                                          probe_dirs=dirs, write_d=not a.raw_only, dwell_s=a.dwell,
                                          seed=a.seed)
    save(session, a.output, other_outputs=[truth_path])
    rtest.save_truth(truth, truth_path, other_outputs=[a.output])
    _say(f"wrote {a.output}: {len(session)} poses ({len(b_deg)} {mtype.tilt_axis} x {len(c_deg)} "
         f"{mtype.rot_axis} x {len(nests)} nests) on a simulated {_core.machine_name(mtype)}, truth in {truth_path}")
    return EXIT_OK


# ------------------------------------------------------------------------- analyse

def _load(path: str, a: argparse.Namespace | None = None) -> Any:
    """The session of ``path``; what its reader warned about (e.g. repeated rows) on stderr.
    With the command's arguments ``a``, the session is also checked against the nominal
    kinematics before any fit (--max-deviation widens the limit)."""
    s = load(path)
    for w in s.warnings:
        _say(f"rotacal: warning: {path}: {w}")
    if a is not None:
        from .circular import is_circular
        if is_circular(s) and getattr(a, "func", None) is not cmd_report:
            raise _core.InvalidArgument(
                f"{path}: holds ISO 230-4 circular tests of the linear axes ({', '.join(sorted(set(s.tests))[:3])}"
                f"{', ...' if len(set(s.tests)) > 3 else ''}), not a rotary-axis test: `rotacal circular analyze "
                f"{path}` gives G, G(b), H and their causes, `rotacal report {path} -o OUT.html` the report")
        if not is_circular(s):
            check_plausible(s, path, getattr(a, "max_deviation", None))
    return s


def _add_plausibility_arg(q: argparse.ArgumentParser) -> None:
    q.add_argument("--max-deviation", type=number("--max-deviation", 0.0, 1000.0, "mm", lo_open=True),
                   metavar="MM", help="largest |measured - nominal| a reading may have before the session is "
                   f"refused as implausible (default {_core.PlausibilityOptions().max_length_deviation_mm:g} mm)")


def _shown(unit: str) -> tuple[float, str]:
    """(factor, unit padded to 4) as identify's table prints a parameter of `unit`."""
    factor, shown = units.shown(unit)
    return factor, f"{shown:4s}"


def _fmt_value(v, unit: str) -> str:
    factor, shown = _shown(unit)
    return f"{v * factor:+9.3f} {shown}"


def _print_noise_model(nm: dict) -> None:
    from .results import noise_handling_words
    how = f"; {noise_handling_words(nm)}" if "gls_refit" in nm else ""
    print(f"noise model: {nm['summary']}{how}")


def _print_budget(b: dict) -> None:
    print(f"uncertainty budget (GUM; coverage {b['coverage'] * 100:.0f} %; um / urad):")
    print(f"  {'':6s} {'value':>10s} {'type A':>8s} {'u_c':>8s} {'U':>8s} {'k':>5s} {'nu_eff':>7s}  dominant left-out effect")
    for name, e in b["location_errors"].items():
        if not e["observable"]:
            print(f"  {name:6s} unobservable")
            continue
        f = 1e6 if e["unit"] == "rad" else 1e3
        nu = "inf" if e["nu_eff"] is None else f"{e['nu_eff']:.0f}"
        dom = e["dominant"][0] if e["dominant"] else (e["type_b"][0]["effect"] if e["type_b"] else "-")
        line = e["type_b"][0] if e["type_b"] else None
        dom_u = ""
        if line is not None and dom == line["effect"]:
            dom_u = f" ({line['u'] * f:.3f}, {line['basis']})"
        print(f"  {name:6s} {e['value'] * f:+10.3f} {e['u_a'] * f:8.3f} {e['u_c'] * f:8.3f} "
              f"{e['expanded'] * f:8.3f} {e['k']:5.2f} {nu:>7s}  {dom}{dom_u}")
    _print_budget_why(b)


def _print_budget_why(b: dict) -> None:
    from .results import budget_why
    why = budget_why(b)
    if why:
        print("  " + why)


def _print_identification(d: dict) -> None:
    print(f"{d['method']} identification, {d['machine']}, {d['n_samples']} samples, "
          f"residual RMS {d['residual_rms_um']:.3f} um")
    budget = d.get("uncertainty_budget")
    for name, p in d["location_errors"].items():
        if p["value"] is None:
            print(f"  {name:6s}  unobservable")
            continue
        line = f"  {name:6s} {_fmt_value(p['value'], p['unit'])} +- {p['std'] * _shown(p['unit'])[0]:.3f}"
        print(line)
    for axis, p in d.get("pivot", {}).items():
        print(f"  pivot {axis}  " + ("unobservable" if p["value"] is None else f"{p['value']:.4f} mm +- {p['std'] * 1e3:.3f} um"))
    for eff in d.get("effects", []):
        for pname, p in eff["params"].items():
            what = f"{eff['id']} ({eff['cause']})"
            print(f"  {what}: " + ("unobservable" if p["value"] is None
                                   else f"{pname} = {_fmt_value(p['value'], p['unit']).strip()} +- "
                                        f"{p['std'] * _shown(p['unit'])[0]:.3f}"))
    for u in d["unobservable"]:
        print(f"  not determined by these tests: {u}")
    for n in d.get("notes", []):
        print(f"  note: {n}")
    if "noise_model" in d:
        _print_noise_model(d["noise_model"])
    if budget:
        _print_budget(budget)
    mc = d.get("monte_carlo")
    if mc:
        noise = mc.get("noise") or f"white noise, {mc['noise_um']:.3f} um"
        print(f"Monte Carlo check of the 1-sigma, {mc['draws']} draws with {noise} "
              "(ratio = Monte Carlo sigma / reported sigma):")
        for name, m in mc["parameters"].items():
            scale, unit = (1e6, "urad") if m["unit"] == "rad" else (1e3, "um")
            print(f"  {name:16s} reported {m['std_reported'] * scale:8.3f}  Monte Carlo {m['std_mc'] * scale:8.3f} "
                  f"{unit:4s}  ratio {m['ratio']:.2f}")


def cmd_identify(a: argparse.Namespace) -> int:
    from . import ballbar as _ballbar, rtest as _rtest
    from .diagnosis import uncertainty_budget
    if a.store or a.machine_id is not None:  # refused before any work
        from .history import check_machine_id, parse_date
        if not a.store:
            raise OptionError("--machine-id: add --store to store the identification in the history")
        check_machine_id(a.machine_id)
        if a.date is not None:
            parse_date(a.date, "--date")
        from .history import open_history
        open_history(a.db).close()  # a store that cannot be opened is refused before the fit
    elif a.note is not None or a.date is not None or a.db is not None or (a.controller and not a.save_model):
        raise OptionError("--note, --date and --db go with --store --machine-id; --controller with --store or "
                          "--save-model")
    sizes = _budget_sizes(a.budget_sizes)  # refused before any work
    s = _load(a.file, a)

    def rtest_identify():
        if a.length_offset:
            raise _core.InvalidArgument("identify: --length-offset is for ballbar sessions")
        return _rtest.identify_rtest(s, a.method, noise=a.noise)

    result = by_kind(s, {BALLBAR: lambda: _ballbar.identify(s, a.method, fit_length_offset=a.length_offset,
                                                            noise=a.noise),
                         RTEST: rtest_identify}, "identify")()
    if a.method == "joint" and not a.no_budget:
        # The budget rests on the diagnosis of what the model leaves out (diagnose/uncertainty_budget.hpp).
        # R-test: raw d1,d2,d3 readings are converted as identify_rtest converts them.
        fitted = by_kind(s, {BALLBAR: lambda: s, RTEST: lambda: _rtest.with_displacements(s)[0]}, "identify")()
        result.budget = uncertainty_budget(fitted, sizes=sizes)
    d = result.to_dict()
    if a.monte_carlo:
        from .ballbar import monte_carlo
        d["monte_carlo"] = by_kind(s, {BALLBAR: lambda: monte_carlo(s, result, a.monte_carlo, seed=a.seed),
                                       RTEST: lambda: _rtest.monte_carlo_rtest(s, result, a.monte_carlo, seed=a.seed)},
                                   "--monte-carlo")()
    if a.save_model:
        from .models import save_model, source_dict
        # The C++ model writer is strict: a non-finite number is written null with its reason.
        source = source_dict(a.file)
        if a.controller:  # the kinematics the errors are relative to, for the export and the history
            source["controller_parameters"] = _controller_text(a.controller)
        save_model(result.model_dict() | {"source": source}, a.save_model, inputs=(a.file,))
        _say(f"wrote {a.save_model}")
    if a.store:
        from .models import source_dict
        from .history import open_history, redact
        controller = _controller_text(a.controller)
        with open_history(a.db) as h:
            entry = h.add_identification(a.machine_id, result.model_dict() | {"source": source_dict(a.file)},
                                         note=a.note, measured_at=a.date, details={"identification": d},
                                         controller=controller, where=a.file)
            _say(f"stored as entry {entry} of machine {a.machine_id!r} in {redact(h.location)}")
    if by_kind(s, {BALLBAR: a.json, RTEST: True}, "identify"):
        print(jsontext.dumps(d))
    else:
        _print_identification(d)
    return EXIT_OK


# ------------------------------------------------------------------------- history

def _controller_text(path: str | None) -> str | None:
    """The controller parameters active during the test, as the text of their file."""
    if path is None:
        return None
    from .exports import read_current
    return read_current(path)


def _read_json(path: str, option: str) -> tuple[dict, str]:
    """(object, sha256 of the bytes) of a JSON file: strict, bounded (jsonfile), errors naming it."""
    import hashlib
    from .exports import MAX_CURRENT_BYTES
    from .jsonfile import read_json
    doc, data = read_json(path, option, 64 * MAX_CURRENT_BYTES)  # a diagnosis of a long recording is large
    if not isinstance(doc, dict):
        raise _core.InvalidArgument(f"{option} {path}: expected a JSON object")
    return doc, hashlib.sha256(data).hexdigest()


def _budget_sizes(path: str | None) -> dict | None:
    """The --budget-sizes object, read once (bounded) and checked before any work; the budget
    then takes the object (a second reading of the file was refused: issue 32)."""
    if not path:
        return None
    from .diagnosis import plausible_sizes
    doc, _ = _read_json(path, "--budget-sizes")
    try:
        plausible_sizes(doc)
    except _core.InvalidArgument as e:
        raise _core.InvalidArgument(f"--budget-sizes {path}: {e}") from None
    return doc


def _tolerances(items: Sequence[str] | None) -> dict[str, float]:
    """--tolerance NAME=VALUE (um for positions, urad for orientations) -> native units (mm, rad)."""
    from .history import unit_of
    out: dict[str, float] = {}
    for item in items or []:
        key, eq, val = item.partition("=")
        key = key.strip()
        if not eq:
            raise OptionError(f"--tolerance: {item[:40]!r}: give NAME=VALUE, e.g. E_Y0A=5 or position=5 (um), "
                              "orientation=20 (urad)")
        v = number(f"--tolerance {key}", 0.0, 1e6, "um or urad", lo_open=True)(val)
        unit = "mm" if key == "position" else "rad" if key == "orientation" else unit_of(key)
        out[key] = v * (1e-3 if unit == "mm" else 1e-6)
    return out


def _um(v: float | None, unit: str, signed: bool = True) -> str:
    if v is None:
        return "-"
    k = 1e3 if unit == "mm" else 1e6
    return f"{v * k:+.3f}" if signed else f"{v * k:.3f}"


def _print_history(h: dict, max_flags: int = 20) -> None:
    cal = h["calibrations"]
    span = f", {cal[0]['at'][:10]} .. {cal[-1]['at'][:10]}" if cal else ""
    print(f"machine {h['machine_id']} ({h['machine_type']}): {h['identifications']} identifications, "
          f"{len(h['corrections'])} corrections (controller changes){span}; store {h['store']}")
    print("values: the machine's own (measured + compensation loaded), um / urad")
    print(f"  {'error':6s} {'n':>5s} {'latest':>10s} {'1-sigma':>8s} {'drift/month':>11s} {'+-':>7s} {'chi2/dof':>8s}")
    for name, e in h["location_errors"].items():
        if not e["points"]:
            print(f"  {name:6s} unobservable in every calibration")
            continue
        last = e["points"][-1]
        dr = e["drift_per_month"] or {}
        chi = dr.get("chi2_per_dof")
        print(f"  {name:6s} {len(e['points']):5d} {_um(last['value'], e['unit']):>10s} "
              f"{_um(last['std'], e['unit'], False):>8s} {_um(dr.get('value'), e['unit']):>11s} "
              f"{_um(dr.get('std'), e['unit'], False):>7s} {'-' if chi is None else f'{chi:.2f}':>8s}")
    from .history import DRIFT_SPAN_WHY, MIN_DRIFT_SPAN_DAYS
    if any(len(e["points"]) >= 2 and e["drift_per_month"] is None for e in h["location_errors"].values()):
        print(f"  drift '-': the calibrations span less than {MIN_DRIFT_SPAN_DAYS:g} days ({DRIFT_SPAN_WHY})")
    for c in h["corrections"]:
        amounts = ", ".join(f"{n} {_um(v, 'mm' if n[2] in 'XYZ' else 'rad')}" for n, v in c["amounts"].items())
        print(f"correction {c['at'][:10]} (entry {c['entry']}, {c['controller']}): {amounts}"
              + (f"  [{c['note']}]" if c["note"] else ""))
    flags = h["flags"]
    print(f"{len(flags)} changes between consecutive calibrations beyond the k=2 uncertainty or the tolerance"
          + (":" if flags else ""))
    for f in flags[:max_flags]:
        limit = f"U {_um(f['expanded_uncertainty'], f['unit'], False)}" + (
            f", tolerance {_um(f['tolerance'], f['unit'], False)}" if f["tolerance"] is not None else "")
        print(f"  {f['name']:6s} {f['from_at'][:10]} -> {f['to_at'][:10]}: {_um(f['change'], f['unit'])} "
              f"({limit}): {', '.join(f['why'])}")
    if len(flags) > max_flags:
        print(f"  ... {len(flags) - max_flags} more (--json lists them all)")


def cmd_history_add(a: argparse.Namespace) -> int:
    from .history import open_history, redact
    if (a.model is None) == (a.correction is None):
        raise OptionError("history add: give a model file (an identification) or --correction EXPORT.json")
    if a.correction is not None:
        if a.diagnosis or a.controller:
            raise OptionError("history add --correction: --diagnosis and --controller belong to an identification")
        export, sha = _read_json(a.correction, "--correction")
        with open_history(a.db) as h:
            entry = h.add_correction(a.machine_id, export, applied_at=a.date, note=a.note, source_sha256=sha,
                                     where=a.correction)
            _say(f"stored correction {a.correction} as entry {entry} of machine {a.machine_id!r} in {redact(h.location)}")
        return EXIT_OK
    from .models import load_model
    model = load_model(a.model)
    details = None
    if a.diagnosis:
        diag, _ = _read_json(a.diagnosis, "--diagnosis")
        if not isinstance(diag.get("findings"), list):
            raise _core.InvalidArgument(f"--diagnosis {a.diagnosis}: not the JSON of 'rotacal diagnose --json' (findings)")
        details = {"diagnosis": diag}
    controller = _controller_text(a.controller)
    with open_history(a.db) as h:
        entry = h.add_identification(a.machine_id, model, note=a.note, measured_at=a.date, details=details,
                                     controller=controller, where=a.model)
        _say(f"stored {a.model} as entry {entry} of machine {a.machine_id!r} in {redact(h.location)}")
    return EXIT_OK


def cmd_history_show(a: argparse.Namespace) -> int:
    from .history import open_history, write_plot
    tol = _tolerances(a.tolerance)
    with open_history(a.db) as h:
        summary = h.show(a.machine_id, tol)
    if a.plot:
        write_plot(summary, a.plot)
        _say(f"wrote {a.plot}")
    if a.json:
        print(jsontext.dumps(summary))
    else:
        _print_history(summary)
    return EXIT_OK


def cmd_history_list(a: argparse.Namespace) -> int:
    from .history import open_history, redact
    with open_history(a.db) as h:
        machines, where = h.machines(), redact(h.location)
    if a.json:
        print(jsontext.dumps({"store": where, "machines": machines}))
        return EXIT_OK
    print(f"{len(machines)} machines in {where}")
    for m in machines:
        print(f"  {m['machine_id']:24s} {m['machine_type']:7s} {m['identifications']:6d} identifications "
              f"{m['corrections']:4d} corrections  {(m['first'] or '')[:10]} .. {(m['last'] or '')[:10]}")
    return EXIT_OK


def _add_db_arg(q: argparse.ArgumentParser) -> None:
    from .history import ENV_STORE
    q.add_argument("--db", metavar="PATH|URL", type=path("--db"),
                   help="the history store: a SQLite file, or a postgresql://user@host/dbname URL; default "
                        f"${ENV_STORE}, else ~/.local/share/rotacal/history.sqlite (its folder is created)")


def _print_diagnosis(d: dict) -> None:
    b = d["baseline"]
    print(f"baseline: residual RMS {b['residual_rms_um']:.3f} um, noise {b['noise_um']:.3f} um "
          f"({b['noise_source']}), chi2/dof {b['chi2_per_dof']:.2f}")
    if not d["findings"]:
        print("no effect of the catalogue is significant")
    for i, f in enumerate(d["findings"], 1):
        g = f["gain"]
        if f["named"]:
            print(f"{i}. {f['effect']} (weight {f['weight']:.2f}): {f['cause']}")
        else:
            group = ", ".join(f"{m['effect']} ({'aliased' if m.get('aliased') else format(m['weight'], '.2f')})"
                              for m in f["group"])
            print(f"{i}. one of: {group}; this session cannot separate them (BIC weights). "
                  f"If it is {f['effect']}:")
        for name, p in f["parameters"].items():
            print(f"     {name} = {units.estimate_text(p['value'], p['std'], p['unit'])}")
        print(f"     RMS {g['rms_before_um']:.3f} -> {g['rms_after_um']:.3f} um, delta BIC {g['delta_bic']:.1f}, "
              f"CV RMS {g['cv_rms_before_um']:.3f} -> {g['cv_rms_after_um']:.3f} um")
        for r in f["rivals"]:
            if not r["in_group"]:
                print(f"     rather than {r['effect']}: that fits worse by delta BIC {r['delta_bic']:.1f} "
                      f"(weight {r['weight']:.2g})")
    for amb in d["ambiguous"]:
        print(f"cannot be told apart with this data: {', '.join(amb['effects'])} ({amb['separating_test']})")
    if d["unexplained"]["present"]:
        print(f"unexplained structure remains: {d['unexplained']['signature']}")
    print(f"{len(d['unobservable'])} catalogue entries are invisible to this session's tests "
          "(--json lists them with reasons)")


def _diagnosis_progress(a: argparse.Namespace):
    """A progress bar for a diagnosis that takes more than a second (a long recording), one
    fill per search round, and its callback; (None, None) with --no-progress."""
    from .progress import ProgressBar
    if a.no_progress:
        return None, None
    bar = ProgressBar("Diagnosis", 1, " candidates", delay_s=1.0)
    stage_now = [""]

    def update(stage: str, done: int, total: int) -> None:
        if stage != stage_now[0]:
            stage_now[0] = stage
            bar.reset(total)
        bar.update(done, note=stage)
    return bar, update


def cmd_diagnose(a: argparse.Namespace) -> int:
    from .diagnosis import diagnose, uncertainty_budget
    sizes = _budget_sizes(a.budget_sizes)  # refused before any work
    s = _load(a.file, a)
    bar, progress = _diagnosis_progress(a)
    try:
        result = diagnose(s, max_harmonic=a.max_harmonic, progress=progress)
    finally:
        if bar:
            bar.close()
    if not a.no_budget:  # what the left-out effects could still put on each location error
        result.budget = uncertainty_budget(s, result, sizes=sizes)
    d = result.to_dict()
    if a.report:
        from .analysis import write_diagnosis_report
        write_diagnosis_report(a.report, s, result, source=a.file, inputs=[a.file])
        _say(f"wrote {a.report}")
    if a.json:
        print(jsontext.dumps(d))
    else:
        _print_diagnosis(d)
    return EXIT_OK


def _comp_file(text: str) -> tuple[str, str]:
    axis, sep, file = text.partition("=")
    if not sep or axis not in ("B", "C") or not file:
        raise _core.InvalidArgument(f"--comp-file {text!r}: expected AXIS=FILE with AXIS B or C")
    return axis, checked_path(file, "--comp-file")


def cmd_design_separation(a: argparse.Namespace) -> int:
    from .ballbar import nc_program
    from .design import added_setup, design_separation, parameter_units, separation_dict
    if not a.after:
        raise OptionError("--separate: give the session it follows with --after SESSION")
    session = _load(a.after)
    if by_kind(session, {BALLBAR: False, RTEST: True}, "--after"):
        raise OptionError(f"--after {a.after}: an R-test session; design ballbar --separate needs a ballbar session")
    base = _setup(a)
    d = design_separation(session, [e.strip() for e in a.separate.split(",")], base=base, lengths=a.lengths,
                          pivot_r=a.pivot_r, pivot_angle=a.pivot_angle, pivot_z=a.pivot_z, travel=a.travel,
                          tilt_limits=a.tilt_limits, max_time_s=a.max_time, max_correlation=a.max_correlation,
                          noise_um=a.noise or 0.0)
    if a.output and d.found:
        plan, text = nc_program(added_setup(d), a.dialect, None, None)
        write_output(a.output, text, [a.after])
        _say(f"wrote {a.output}: {a.dialect} program of the added test, {plan.duration:.0f} s")
    elif a.output:
        _say(f"rotacal: {a.output} not written: no added test separates them")
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
    print(f"noise {d.noise_um:.3f} um per reading, {d.effective_per_reading:.2f} effective samples per reading "
          f"(from {after_path}); {d.candidates_tried} added tests tried")
    after = list(d.sigma_after) if d.candidates_tried else list(d.sigma_before)
    print("predicted 1-sigma, session alone -> with the added test (inf: not determined):")
    before = list(d.sigma_before) + [math.inf] * (len(d.names) - len(d.sigma_before))
    for n, b_, a_, (unit, k) in zip(d.names, before, after, units):
        print(f"  {n:28s} {b_ * k:10.4f} -> {a_ * k:10.4f} {unit}")


def cmd_design_ballbar(a: argparse.Namespace) -> int:
    from .ballbar import nc_program
    from .design import design_ballbar, design_dict
    if a.separate:
        return cmd_design_separation(a)
    if a.after:
        raise OptionError("--after: goes with --separate EFFECT,EFFECT")
    a.noise = 0.5 if a.noise is None else a.noise
    d = design_ballbar(_setup(a), lengths=a.lengths, pivot_x=a.pivot_x, pivot_z=a.pivot_z, travel=a.travel,
                       time_s=a.time, rate_hz=a.rate, noise_um=a.noise, rho=a.rho,
                       effects=[e.strip() for e in a.effects.split(",")] if a.effects else [])
    if a.output:
        plan, text = nc_program(d.best.setup, a.dialect, None, None)
        write_output(a.output, text)
        _say(f"wrote {a.output}: {a.dialect} program of the designed set-up, {plan.duration:.0f} s at the base feeds")
    if a.json:
        print(jsontext.dumps(design_dict(d)))
        return EXIT_OK
    feasible = sum(c.feasible for c in d.candidates)
    print(f"{len(d.candidates)} set-ups tried, {feasible} within the limits; run time {d.time_budget_s:.0f} s, "
          f"noise {a.noise:g} um at {a.rate:g} Hz" + (f", AR(1) rho {a.rho:g}" if a.rho else ""))
    for label, c in (("designed", d.best), ("default", d.baseline)):
        if not c.feasible:
            print(f"{label:9s} L0 {c.setup.ballbar_length:g} mm, pivot {tuple(map(float, c.setup.pivot))}: {c.why_not}")
            continue
        print(f"{label:9s} L0 {c.setup.ballbar_length:g} mm, pivot ({c.setup.pivot[0]:g}, {c.setup.pivot[1]:g}, "
              f"{c.setup.pivot[2]:g}) mm: largest expanded uncertainty (k=2) {c.worst_expanded_um:.3f} um "
              f"({c.worst_error})")
    if d.baseline.feasible:
        print(f"ratio designed / default: {d.ratio:.3f}")
    from .design import parameter_units
    names, sig = d.best.names, d.best.sigma
    print("predicted 1-sigma of the designed test (inf: this set-up cannot determine it):")
    for n, s_, (unit, k) in zip(names, sig, parameter_units(names)):
        print(f"  {n:24s} {s_ * k:10.4f} {unit}")
    for n, a_, b_ in zip(names[11:], d.best.effect_vs_location, d.best.effect_vs_effects):
        print(f"  {n}: largest correlation with a location error {a_:.2f}, with another effect {b_:.2f}")
    return EXIT_OK


def cmd_design_rtest_separation(a: argparse.Namespace) -> int:
    from .design import design_rtest_separation, parameter_units, rtest_separation_dict
    if not a.after:
        raise OptionError("--separate: give the session it follows with --after SESSION")
    session = _load(a.after)
    if by_kind(session, {BALLBAR: True, RTEST: False}, "--after"):
        raise OptionError(f"--after {a.after}: a ballbar session; design rtest --separate needs an R-test session")
    d = design_rtest_separation(session, [e.strip() for e in a.separate.split(",")], radii=a.radii,
                                angles=a.nest_angles, heights=a.heights, b_steps=a.b_steps, c_steps=a.c_steps,
                                b_limits=a.b_limits, travel=a.travel, dwell_s=a.dwell or 0.0, max_time_s=a.max_time,
                                max_correlation=a.max_correlation, noise_um=a.noise or 0.0)
    if a.json:
        print(jsontext.dumps(rtest_separation_dict(d)))
        return EXIT_OK
    _print_separation(d, a.after, parameter_units(d.names))
    if d.found:
        p = d.chosen.added
        b, c = list(p.b_deg), list(p.c_deg)
        print(f"run it with: --nest {','.join(f'{v:g}' for v in p.nests[0])} --b-range {b[0]:g},{b[-1]:g} "
              f"--b-step {b[1] - b[0] if len(b) > 1 else 0:g} --c-step {c[1] - c[0] if len(c) > 1 else 360:g} "
              f"--dwell {p.dwell_s:g}")
    return EXIT_OK


def cmd_design_rtest(a: argparse.Namespace) -> int:
    from .design import rtest_design_dict, design_rtest
    if a.separate:
        return cmd_design_rtest_separation(a)
    if a.after:
        raise OptionError("--after: goes with --separate EFFECT,EFFECT")
    a.noise = 0.3 if a.noise is None else a.noise
    d = design_rtest(radii=a.radii, heights=a.heights, b_steps=a.b_steps, c_steps=a.c_steps, b_limits=a.b_limits,
                     travel=a.travel, time_s=a.time, noise_um=a.noise, rho=a.rho, dwell_s=a.dwell)
    if a.json:
        print(jsontext.dumps(rtest_design_dict(d)))
        return EXIT_OK
    feasible = sum(c.feasible for c in d.candidates)
    print(f"{len(d.candidates)} patterns tried, {feasible} within the limits; run time {d.time_budget_s:.0f} s, "
          f"noise {a.noise:g} um per reading" + (f", AR(1) rho {a.rho:g}" if a.rho else ""))
    for label, c in (("designed", d.best), ("default", d.baseline)):
        p = c.pattern
        nests = "; ".join(",".join(f"{v:g}" for v in n) for n in p.nests)
        if not c.feasible:
            print(f"{label:9s} nests {nests}: {c.why_not}")
            continue
        print(f"{label:9s} nests {nests} mm, B {len(p.b_deg)} x C {len(p.c_deg)} poses, {c.duration_s:.0f} s: "
              f"largest expanded uncertainty (k=2) {c.worst_expanded_um:.3f} um ({c.worst_error})")
    if d.baseline.feasible:
        print(f"ratio designed / default: {d.ratio:.3f}")
    p = d.best.pattern
    b = list(p.b_deg)
    c = list(p.c_deg)
    step = lambda v: v[1] - v[0] if len(v) > 1 else 360.0  # noqa: E731
    print("run it with: " + " ".join(f"--nest {','.join(f'{v:g}' for v in n)}" for n in p.nests)
          + f" --b-range {b[0]:g},{b[-1]:g} --b-step {step(b):g} --c-step {step(c):g} --dwell {p.dwell_s:g}"
          + (f" (repeat it {d.time_budget_s / d.best.duration_s:.2f} times, or dwell longer, to fill the run time)"
             if d.best.duration_s < d.time_budget_s * 0.999 else ""))
    print("predicted 1-sigma of the location errors:")
    for i, (n, s_) in enumerate(zip(d.best.names[:8], d.best.sigma[:8])):
        unit, k = ("urad", 1e6) if i in (2, 3, 6, 7) else ("um", 1e3)
        print(f"  {n:8s} {s_ * k:10.4f} {unit}")
    return EXIT_OK


def cmd_export(a: argparse.Namespace) -> int:
    from .exports import export_controller, export_dict, linuxcnc_comp_table, residual_model
    from .models import load_model, save_model
    comp = dict(_comp_file(c) for c in a.comp_file or [])
    if comp and a.controller != "linuxcnc":
        raise _core.InvalidArgument("--comp-file: rotary compensation tables are written for linuxcnc")
    if bool(a.centres) != bool(a.centres_output) or (a.centres and a.controller != "isg"):
        raise _core.InvalidArgument("--centres and --centres-output go together, with --controller isg")
    ex = export_controller(a.model, a.controller, current=a.current, toolholder=a.toolholder)
    tables = {axis: linuxcnc_comp_table(load_model(a.model), axis, *a.comp_range, a.comp_step) for axis in comp}
    if a.centres:
        from .exports import isg_sphere_centres
        from .models import file_sha256
        text, what = isg_sphere_centres(load(a.centres), load_model(a.model), a.centres_setup,
                                        (int(a.isg_kinematic[0]), int(a.isg_kinematic[1])), a.centres_origin,
                                        session_sha256=file_sha256(a.centres))
        write_output(a.centres_output, text, inputs=[p for p in (a.model, a.current, a.centres) if p])
        _say(f"wrote {a.centres_output}: {what}")
    for axis, (text, what) in tables.items():
        write_output(comp[axis], text, inputs=[p for p in (a.model, a.current) if p])
        _say(f"wrote {comp[axis]}: {what}")
    if a.residual_model:
        save_model(residual_model(load_model(a.model), ex), a.residual_model, inputs=[a.model],
                   other_outputs=[a.output] if a.output else [])
        _say(f"wrote {a.residual_model}: the errors {ex.controller} cannot hold, for rotacal compensate --model")
    held = [e.name for e in ex.errors if e.held]
    left = [e.name for e in ex.errors if not e.held]
    if a.output:
        write_output(a.output, ex.text, inputs=[p for p in (a.model, a.current) if p])
        _say(f"wrote {a.output} ({ex.file_kind} for {ex.kinematics})")
    if a.json:
        print(jsontext.dumps(export_dict(ex)))
    elif not a.output:
        print(ex.text, end="")
    _say(f"held: {', '.join(held) or 'none'}; not held: {', '.join(left) or 'none'}"
         + ("" if ex.current_given else "; no --current: zero offsets assumed, the values are the corrections"))
    return EXIT_OK


def cmd_predict(a: argparse.Namespace) -> int:
    from .analysis import predict_session
    from .models import load_model
    model_dict = load_model(a.model)
    s = _load(a.session, a)
    out, line = predict_session(model_dict, s, a.probe_zeros, source=a.model)
    if line:
        _say(line)
    save(out, a.output, inputs=[a.session, a.model])
    _say(f"wrote {a.output}")
    return EXIT_OK


def _print_compensation(rows: list[dict]) -> None:
    print("error    uncompensated   compensated    change   (Flynn et al. Table 2 layout)")
    for r in rows:
        k, unit = (1e3, "um") if r["unit"] == "mm" else (1e6, "urad")
        print(f"{r['name']:6s} {r['before'] * k:+12.3f} {r['after'] * k:+12.3f} {unit:4s} {r['change_percent']:+8.1f} %")


def cmd_compensate(a: argparse.Namespace) -> int:
    if not a.model and not a.verify:
        raise OptionError("compensate: give --model MODEL.json (write a program) and/or --verify")
    setup = _setup(a)
    from .ballbar import nc_program, verify_compensation
    if a.model:
        _, text = nc_program(setup, a.dialect, _model(a.model), a.model)
        write_output(a.output, text, [a.model])
        _say(f"wrote {a.output}: compensated {a.dialect} program")
    if a.verify:
        truth = _truth(a, setup)
        _say("measuring, identifying, compensating and measuring again on the simulated machine ...")
        rows = verify_compensation(setup, truth)
        if a.json:
            print(jsontext.dumps(rows))
        else:
            _print_compensation(rows)
    return EXIT_OK


def cmd_report(a: argparse.Namespace) -> int:
    from .analysis import write_report
    extra, history = [], None
    if a.history:
        from .history import history_section, open_history
        with open_history(a.db) as h:  # an unknown machine id is refused before the fit
            history = h.show(a.history)
        extra.append(history_section(history))
    s = _load(a.file, a)
    if history is not None and history["machine_type"] != _core.machine_name(s.machine):
        raise _core.InvalidArgument(f"--history {a.history}: a {history['machine_type']} in the store, but {a.file} "
                                    f"is a session of a {_core.machine_name(s.machine)}: not the same machine")
    from .circular import analyze as analyze_circular, is_circular
    if is_circular(s):  # ISO 230-4 runs of the linear axes: their own report
        from .report import circular_report
        out = circular_report(a.output, analyze_circular(s, diagnose=not a.no_diagnosis, source=a.file),
                              source=a.file, inputs=[a.file], extra_sections=extra)
    else:
        out = write_report(a.output, s, a.method, with_diagnosis=not a.no_diagnosis, source=a.file,
                           inputs=[a.file], extra_sections=extra)
    print(Path(out).resolve())
    return EXIT_OK


def cmd_demo(a: argparse.Namespace) -> int:
    """Simulate a machine with errors and one hidden effect, measure, identify, diagnose,
    compensate, and write a report."""
    from .demo import run_demo
    r = run_demo(a.output, seed=a.seed, sag_mm=a.sag, say=_say)
    print(f"hidden effect: gravity_sag_A, s = {a.sag * 1e3:.1f} um")
    f = r["finding"]
    if f:
        name, p = next(iter(f["parameters"].items()))
        size = f"{name} = {units.estimate_text(p['value'], p['std'], p['unit'])}"
        if f["named"]:
            print(f"diagnosis found: {f['effect']} ({f['cause']}, weight {f['weight']:.2f}), {size}")
        else:
            group = ", ".join(f"{g['effect']} ({g['weight']:.2f})" for g in f["group"])
            print(f"diagnosis found one of: {group}, which this session cannot separate; if {f['effect']}: {size}")
    else:
        print("diagnosis found nothing significant")
    print(f"compensation reduced every location error by at least {-r['worst_change_percent']:.1f} %")
    print(f"report: {Path(r['report']).resolve()}")
    return EXIT_OK


def cmd_table2(a: argparse.Namespace) -> int:
    """Measured before/after identifications (default: Flynn et al.'s Table 2) against the
    simulated measure -> compensate -> measure-again chain: what falls outside, and why."""
    from . import flynn_table2 as t2
    table = t2.load_table2(a.table) if a.table else t2.load_table2()
    assumptions = t2.Assumptions(noise_um=a.noise, noise_rho=a.rho, hours_between_runs=a.hours, method=a.method)
    result = t2.analyse(table, assumptions, draws=a.draws, seed=a.seed, sweep=[] if a.no_sweep else None)
    print(jsontext.dumps(result) if a.json else t2.render(result))
    return EXIT_OK


# ------------------------------------------------------------------------- instruments

def _faults(a: argparse.Namespace):
    f = _core.FaultInjection()
    f.garbage_every, f.corrupt_every, f.drop_every = a.fault_garbage, a.fault_corrupt, a.fault_drop
    f.split_frames = a.fault_split
    f.close_after, f.silence_after = a.fault_unplug_after, a.fault_silence_after
    return f


def _serve(dev, what: str, a: argparse.Namespace, detail: str) -> int:
    """Print the device path, then serve until Ctrl-C or SIGTERM (or the program's end with
    --exit-when-done)."""
    import signal

    def stop(*_: Any) -> None:
        raise KeyboardInterrupt
    # Installed explicitly: a process started in the background by a shell script inherits
    # SIGINT ignored, and Python then leaves it ignored (the instrument never stopped).
    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    print(dev.port, flush=True)
    _say(f"virtual {what} on {dev.port} ({detail}); Ctrl-C to stop")
    try:
        while not (a.exit_when_done and dev.finished):
            time.sleep(0.05)
        time.sleep(0.5)  # let the host read the last bytes before the line goes away
    except KeyboardInterrupt:
        pass
    dev.stop()
    st = dev.stats()
    _say(f"virtual {what}: {st['frames_sent']} frames, {st['replies_sent']} replies, "
         f"{st['frames_dropped']} dropped and {st['frames_corrupted']} corrupted on purpose"
         + (", program finished" if st["finished"] else ""))
    return EXIT_OK


def cmd_virtual_ballbar(a: argparse.Namespace) -> int:
    from .instruments import virtual_ballbar
    setup = _setup(a)
    from .machines import ballbar_machine_model
    truth = _truth(a, setup)
    plan = _core.plan_ballbar_test(setup, None)
    model = ballbar_machine_model(setup, truth)
    truth["pivot_actual"] = model.pivot.tolist()
    if a.truth:
        _write_truth(truth, a.truth)
    dev = virtual_ballbar(plan, model, noise_um=a.noise, seed=a.seed, rate_hz=a.rate, speed=a.speed,
                          baud=a.baud, faults=_faults(a))
    return _serve(dev, "ballbar", a, f"{plan.duration:.1f} s program at {a.rate:g} Hz, speed x{a.speed:g}")


def cmd_virtual_rtest(a: argparse.Namespace) -> int:
    from .instruments import virtual_rtest
    r = _rtest_inputs(a)
    dev, truth = virtual_rtest(r["errors"], r["effects"], machine=r["machine"], b_deg=r["b_deg"], c_deg=r["c_deg"],
                               nests=r["nests"], dwell_s=r["dwell_s"], noise_um=a.noise, probe_zero_um=a.probe_zero,
                               probe_dirs=r["probe_dirs"], seed=a.seed, mode=a.mode, rate_hz=a.rate,
                               speed=a.speed, baud=a.baud, faults=_faults(a))
    if a.truth:
        _write_truth(truth, a.truth)
    return _serve(dev, "R-test", a, f"{a.mode} mode, {len(dev.program)} poses, speed x{a.speed:g}")


# Exit code of a recording by how it stopped: the data are in the file either way.
_RECORD_EXIT = {"end of program": EXIT_OK, "stopped": EXIT_OK, "device disconnected": EXIT_IO,
                "silence (timeout)": EXIT_IO, "no valid data": EXIT_IO}


def _report_recording(summary, path: str, json_out: bool) -> int:
    if json_out:
        print(jsontext.dumps({k: getattr(summary, k) for k in ("rows", "frames", "lost", "crc_errors", "malformed",
                                                                  "garbage_bytes", "over_range", "timeouts",
                                                                  "outside_window", "reason", "detail")} | {"path": path}, indent=None))
    if summary.rows == 0:  # nothing measured: the recorder left an existing file as it was
        _say(f"rotacal: {path} not written, no row was recorded: {summary.describe()}")
        return EXIT_IO
    _say(f"wrote {path}: {summary.describe()}")
    return _RECORD_EXIT[summary.reason]


def cmd_record_ballbar(a: argparse.Namespace) -> int:
    from .instruments import record_ballbar
    plan = _core.plan_ballbar_test(_setup(a), None)
    summary = record_ballbar(a.port, plan, a.output, baud=a.baud, rate_hz=a.rate, zero=a.zero,
                             silence_timeout_s=a.silence, progress=not a.no_progress)
    return _report_recording(summary, a.output, a.json)


def cmd_record_rtest(a: argparse.Namespace) -> int:
    from .instruments import record_rtest, rtest_program
    r = _rtest_inputs(a)
    program = rtest_program(r["machine"], r["b_deg"], r["c_deg"], r["nests"], r["dwell_s"])
    summary = record_rtest(a.port, program, a.output, mode=a.mode, dwell_s=r["dwell_s"], probe_dirs=r["probe_dirs"],
                           baud=a.baud, rate_hz=a.rate, speed=a.speed, silence_timeout_s=a.silence,
                           progress=not a.no_progress)
    return _report_recording(summary, a.output, a.json)


def _add_link_args(q: argparse.ArgumentParser, rate: float) -> None:
    g = q.add_argument_group("serial link")
    g.add_argument("--baud", type=number("--baud", 50, 4_000_000, integer=True), default=115200, help="baud rate (default 115200)")
    g.add_argument("--rate", type=number("--rate", 0.0, 1e5, "Hz", lo_open=True), default=rate, help=f"stream sample rate, Hz (default {rate:g})")


def _add_virtual_args(q: argparse.ArgumentParser) -> None:
    q.add_argument("--speed", type=number("--speed", 0.0, 1e4, lo_open=True), default=1.0, help="virtual seconds per real second (default 1: real time)")
    q.add_argument("--exit-when-done", action="store_true", help="stop serving when the program has run")
    q.add_argument("--truth", metavar="JSON", type=path("--truth"), help="write the simulated machine here")
    g = q.add_argument_group("faults to act out (for testing recorders; 0 or -1: never)")
    g.add_argument("--fault-garbage", type=number("--fault-garbage", -1, 1e9, integer=True), default=0, metavar="N", help="line noise after every Nth frame")
    g.add_argument("--fault-corrupt", type=number("--fault-corrupt", -1, 1e9, integer=True), default=0, metavar="N", help="flip a bit in every Nth frame")
    g.add_argument("--fault-drop", type=number("--fault-drop", -1, 1e9, integer=True), default=0, metavar="N", help="do not send every Nth frame")
    g.add_argument("--fault-split", action="store_true", help="send every frame in two writes")
    g.add_argument("--fault-unplug-after", type=number("--fault-unplug-after", -1, 1e9, integer=True), default=-1, metavar="N", help="hang up after N frames")
    g.add_argument("--fault-silence-after", type=number("--fault-silence-after", -1, 1e9, integer=True), default=-1, metavar="N", help="go silent after N frames")


def _add_record_args(q: argparse.ArgumentParser) -> None:
    q.add_argument("--port", required=True, help="serial port, e.g. /dev/ttyUSB0, /dev/serial/by-id/..., /dev/pts/N")
    q.add_argument("--silence", type=number("--silence", 0.0, 3600.0, "s", lo_open=True), default=3.0, help="stop after this many seconds without data")
    q.add_argument("--no-progress", action="store_true", help="no progress bar")
    q.add_argument("--json", action="store_true", help="print the recording summary as JSON")
    q.add_argument("-o", "--output", required=True, type=path("--output"))


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="rotacal", description="Calibration of the rotary axes of 5-axis machine tools.",
                                epilog=EPILOG)
    sub = p.add_subparsers(dest="command", required=True)

    q = sub.add_parser("plan", help="plan a test and write its NC program", epilog=EPILOG)
    q.add_argument("kind", choices=["ballbar"])
    _add_setup_args(q)
    q.add_argument("--dialect", default="linuxcnc", help="linuxcnc (machine axes), heidenhain, siemens, fanuc")
    q.add_argument("--compensate", metavar="MODEL.json", type=path("--compensate"), help="emit the program compensated for a fitted model")
    q.add_argument("--session", metavar="CSV", type=path("--session"),
                   help="also write the commanded rows as a session template")
    q.add_argument("-o", "--output", required=True, type=path("--output"))
    q.set_defaults(func=cmd_plan)

    q = sub.add_parser("machines", help="the built-in machines; show one (or a rotacal-machine/1 file) as text",
                       epilog=EPILOG + "; docs/machines.md")
    q.add_argument("action", nargs="?", choices=["list", "show"], default="list",
                   help="list (default): the built-ins; show NAME|FILE: drawing, location errors, description")
    q.add_argument("machine", nargs="?", metavar="NAME|FILE")
    q.add_argument("--json", action="store_true")
    q.set_defaults(func=cmd_machines)

    q = sub.add_parser("simulate", help="simulate a measurement on a machine with errors", epilog=EPILOG)
    kinds = q.add_subparsers(dest="kind", required=True, metavar="{ballbar,rtest}")
    k = kinds.add_parser("ballbar", help="the single set-up ballbar test (Flynn et al. 2016)", epilog=EPILOG)
    _add_setup_args(k)
    _add_truth_args(k)
    k.add_argument("--truth", metavar="JSON", type=path("--truth"), help="write the simulated machine here")
    k.add_argument("-o", "--output", required=True, type=path("--output"))
    k.set_defaults(func=cmd_simulate)
    k = kinds.add_parser("rtest", help="the R-test pattern of Oyama & Ibaraki Sec. 3.3 on a B/C table",
                         description="Writes a rotacal-rtest/1 session and, beside it, FILE.truth.json "
                                     "(the simulated machine, the probe zeros and the pattern).",
                         epilog=EPILOG)
    _add_rtest_sim_args(k)
    k.set_defaults(func=cmd_simulate_rtest)

    q = sub.add_parser("identify", help="identify location errors from a session", epilog=EPILOG)
    q.add_argument("file", type=path("FILE"))
    q.add_argument("--method", default="joint", choices=["joint", "paper"])
    q.add_argument("--length-offset", action="store_true", help="also fit an offset of L0 (joint)")
    q.add_argument("--json", action="store_true", help="print the result as JSON")
    q.add_argument("--save-model", metavar="MODEL.json", type=path("--save-model"),
                   help="write the fitted model (ballbar, or R-test joint: location errors, maps, covariance)")
    q.add_argument("--monte-carlo", type=number("--monte-carlo", 0, 10_000, integer=True), default=0, metavar="N",
                   help="check the 1-sigma by N simulated repeats of the session with its fitted noise model (progress bar)")
    q.add_argument("--seed", type=SEED, default=1, help="seed of the Monte Carlo draws")
    _add_plausibility_arg(q)
    q.add_argument("--noise", default="auto", choices=["auto", "white"],
                   help="auto (default): AR noise model of the residuals, GLS refit when correlated; "
                        "white: readings taken as independent")
    q.add_argument("--budget-sizes", metavar="SIZES.json", type=path("--budget-sizes"),
                   help="plausible sizes of left-out effects for the uncertainty budget (JSON object; "
                        "docs/json_schema.md)")
    q.add_argument("--no-budget", action="store_true",
                   help="skip the uncertainty budget (it runs a diagnosis of the left-out effects)")
    g = q.add_argument_group("calibration history (docs/history.md)")
    g.add_argument("--store", action="store_true", help="store the identification in the history (needs --machine-id)")
    g.add_argument("--machine-id", help="the physical machine, e.g. its serial number (the session's "
                                        "'# machine:' stays its kinematic type)")
    g.add_argument("--note", help="operator note stored with it")
    g.add_argument("--date", help="when it was measured, ISO 8601 (default: now)")
    g.add_argument("--controller", metavar="CURRENT", type=path("--controller"),
                   help="the controller parameters active during the test (HAL, MPF or JSON file), stored with it")
    _add_db_arg(g)
    q.set_defaults(func=cmd_identify)

    q = sub.add_parser("history", help="calibration history of physical machines: store, list, show drift",
                       epilog=EPILOG + "; docs/history.md")
    hs = q.add_subparsers(dest="action", required=True)
    k = hs.add_parser("add", help="store an identification (model file) or a correction loaded into the controller",
                      epilog=EPILOG)
    k.add_argument("model", nargs="?", type=path("MODEL"), help="model file (identify --save-model)")
    k.add_argument("--correction", metavar="EXPORT.json", type=path("--correction"),
                   help="instead of a model: the JSON of 'rotacal export --json' that was loaded into the "
                        "controller; later changes of the errors it holds are then not counted as drift")
    k.add_argument("--machine-id", required=True, help="the physical machine, e.g. its serial number")
    k.add_argument("--note", help="operator note")
    k.add_argument("--date", help="when it was measured (or the correction loaded), ISO 8601; default: the "
                                  "model's source.identified_at, else now")
    k.add_argument("--diagnosis", metavar="DIAG.json", type=path("--diagnosis"),
                   help="the findings of 'rotacal diagnose --json' on the same session, stored with it")
    k.add_argument("--controller", metavar="CURRENT", type=path("--controller"),
                   help="the controller parameters active during the test (HAL, MPF or JSON file)")
    _add_db_arg(k)
    k.set_defaults(func=cmd_history_add)
    k = hs.add_parser("show", help="each location error over time: 1-sigma, corrections, drift per month, flags",
                      epilog=EPILOG)
    k.add_argument("machine_id", metavar="MACHINE_ID")
    k.add_argument("--tolerance", action="append", metavar="NAME=VALUE",
                   help="also flag a change between two calibrations larger than VALUE (um for positions, urad "
                        "for orientations); NAME a location error, or position / orientation for all (repeatable)")
    k.add_argument("--plot", metavar="OUT.png|OUT.html", type=path("--plot"), help="write the history as figures")
    k.add_argument("--json", action="store_true")
    _add_db_arg(k)
    k.set_defaults(func=cmd_history_show)
    k = hs.add_parser("list", help="the machines in the store", epilog=EPILOG)
    k.add_argument("--json", action="store_true")
    _add_db_arg(k)
    k.set_defaults(func=cmd_history_list)

    q = sub.add_parser("diagnose", help="find what the model gets wrong and why", epilog=EPILOG)
    q.add_argument("file", type=path("FILE"))
    q.add_argument("--max-harmonic", type=number("--max-harmonic", 1, MAX_HARMONIC, integer=True),
                   help=f"highest harmonic order tried (1..{MAX_HARMONIC}; default {_core.DiagnosisOptions().max_harmonic})")
    q.add_argument("--json", action="store_true")
    q.add_argument("--report", metavar="OUT.html", type=path("--report"))
    q.add_argument("--budget-sizes", metavar="SIZES.json", type=path("--budget-sizes"),
                   help="plausible sizes of left-out effects for the uncertainty budget (docs/json_schema.md)")
    q.add_argument("--no-budget", action="store_true", help="skip the uncertainty budget")
    q.add_argument("--no-progress", action="store_true", help="no progress bar (drawn after 1 s of work)")
    _add_plausibility_arg(q)
    q.set_defaults(func=cmd_diagnose)

    q = sub.add_parser("predict", help="predict a session with a fitted model", epilog=EPILOG)
    q.add_argument("session", type=path("SESSION"))
    q.add_argument("--model", required=True, type=path("--model"))
    q.add_argument("--probe-zeros", choices=["none", "fitted"], default="none",
                   help="R-test: add the probe zeros fitted for the same set-ups (same nests), or none "
                        "(default: a new set-up's zeros are unknown)")
    q.add_argument("-o", "--output", required=True, type=path("--output"),
                   help="the session with predicted lengths (ballbar) or dx,dy,dz and dx_std,dy_std,dz_std (R-test)")
    _add_plausibility_arg(q)
    q.set_defaults(func=cmd_predict)

    q = sub.add_parser("design", help="design a test before the machine runs it", epilog=EPILOG + "; docs/design.md")
    dk = q.add_subparsers(dest="kind", required=True)
    k = dk.add_parser("ballbar", help="the pivot and bar length with the smallest predicted uncertainty",
                      epilog=EPILOG + "; docs/design.md")
    _add_setup_args(k)
    k.add_argument("--lengths", type=number_list("--lengths", 1.0, 2000.0, "mm", 10), default=[100.0, 150.0],
                   help="bar lengths available, mm (default 100,150)")
    k.add_argument("--pivot-x", type=number_list("--pivot-x", 0.0, 2000.0, "mm", 30),
                   help="pivot distances from the C axis to try, mm (default 60,90,120,150,180)")
    k.add_argument("--pivot-z", type=number_list("--pivot-z", -2000.0, 2000.0, "mm", 30),
                   help="pivot heights above the tilt axis to try, mm (default 20,40,60,90,120)")
    k.add_argument("--travel", type=numbers("--travel", 6, 1e5, "mm"),
                   help="xmin,xmax,ymin,ymax,zmin,zmax of X, Y, Z about the rotary axes' intersection, mm "
                        "(default -400,400,-300,300,-300,400)")
    k.add_argument("--time", type=_run_time, default=0.0,
                   help="run time to compare at, s (default: the default set-up's)")
    k.add_argument("--rate", type=number("--rate", 0.0, 1e5, "Hz", lo_open=True), default=100.0,
                   help="the recorder's sample rate, Hz (default 100)")
    k.add_argument("--noise", type=number("--noise", 0.0, 1000.0, "um", lo_open=True),
                   help="1-sigma noise per sample, um (default 0.5; with --after: the session's residual noise)")
    k.add_argument("--rho", type=number("--rho", 0.0, 0.999, ""), default=0.0,
                   help="AR(1) coefficient of the noise between samples (default 0: white)")
    k.add_argument("--effects", help="effects of concern, fitted along: catalogue ids, comma separated")
    g = k.add_argument_group("the test that separates two effects after a session (docs/design.md)")
    g.add_argument("--separate", metavar="EFFECT,EFFECT",
                   help="two catalogue ids the diagnosis could not tell apart: propose the smallest added test "
                        "that brings their correlation below --max-correlation, or say why none can")
    g.add_argument("--after", type=path("--after"), metavar="SESSION", help="the ballbar session they follow")
    g.add_argument("--max-time", type=number("--max-time", 0.0, 86400.0, "s", lo_open=True), default=600.0,
                   help="longest added test, s (default 600)")
    g.add_argument("--max-correlation", type=number("--max-correlation", 0.0, 1.0, "", lo_open=True), default=0.5,
                   help="target largest canonical correlation of the pair (default 0.5)")
    g.add_argument("--pivot-r", type=number_list("--pivot-r", 0.0, 2000.0, "mm", 30),
                   help="moved pivot: distances from the C axis, mm (default 0,60,120,180)")
    g.add_argument("--pivot-angle", type=number_list("--pivot-angle", -360.0, 360.0, "deg", 12),
                   help="moved pivot: angles about C from +X, deg (default 0,90)")
    g.add_argument("--tilt-limits", type=numbers("--tilt-limits", 2, 360.0, "deg"),
                   help="rotary limits of the tilt axis, deg (default -90,90)")
    k.add_argument("--dialect", default="linuxcnc", help="NC dialect of -o (as plan)")
    k.add_argument("-o", "--output", type=path("--output"),
                   help="write the designed test's NC program here (with --separate: the added test's)")
    k.add_argument("--json", action="store_true")
    k.set_defaults(func=cmd_design_ballbar)
    k = dk.add_parser("rtest", help="the R-test nests and B/C grid with the smallest predicted uncertainty",
                      epilog=EPILOG + "; docs/design.md")
    k.add_argument("--radii", type=number_list("--radii", 0.0, 2000.0, "mm", 20),
                   help="nest distances from the C axis to try, mm (default 50,100,150)")
    k.add_argument("--heights", type=number_list("--heights", -2000.0, 2000.0, "mm", 20),
                   help="nest heights above the B axis to try, mm (default 20,60,100,140)")
    k.add_argument("--b-steps", type=number_list("--b-steps", 0.1, 180.0, "deg", 20),
                   help="B grid steps to try, deg (default 15,30,45)")
    k.add_argument("--c-steps", type=number_list("--c-steps", 0.1, 359.0, "deg", 20),
                   help="C grid steps to try over a full turn, deg (default 30,45,60)")
    k.add_argument("--b-limits", type=numbers("--b-limits", 2, 360.0, "deg"), help="rotary limits of B, deg (default -90,90)")
    k.add_argument("--travel", type=numbers("--travel", 6, 1e5, "mm"),
                   help="xmin,xmax,ymin,ymax,zmin,zmax of X, Y, Z about the rotary axes' intersection, mm "
                        "(default -400,400,-300,300,-300,400)")
    k.add_argument("--time", type=_run_time, default=0.0,
                   help="run time to compare at, s (default: the default pattern's)")
    k.add_argument("--dwell", type=number("--dwell", 0.0, 3600.0, "s", lo_open=True),
                   help="time per pose, s (default 6)")
    k.add_argument("--noise", type=number("--noise", 0.0, 1000.0, "um", lo_open=True),
                   help="1-sigma noise per reading component, um (default 0.3; with --after: the session's)")
    k.add_argument("--rho", type=number("--rho", 0.0, 0.999, ""), default=0.0,
                   help="AR(1) coefficient of the noise between readings (default 0: white)")
    g = k.add_argument_group("the nest that separates two effects after a session (docs/design.md)")
    g.add_argument("--separate", metavar="EFFECT,EFFECT",
                   help="two catalogue ids the diagnosis could not tell apart: propose the smallest added nest "
                        "that brings their correlation below --max-correlation, or say why none can")
    g.add_argument("--after", type=path("--after"), metavar="SESSION", help="the R-test session they follow")
    g.add_argument("--max-time", type=number("--max-time", 0.0, 86400.0, "s", lo_open=True), default=600.0,
                   help="longest added nest, s (default 600)")
    g.add_argument("--max-correlation", type=number("--max-correlation", 0.0, 1.0, "", lo_open=True), default=0.5,
                   help="target largest canonical correlation of the pair (default 0.5)")
    g.add_argument("--nest-angles", type=number_list("--nest-angles", -360.0, 360.0, "deg", 12),
                   help="added nest: angles about C from +X, deg (default 0,90,180,270)")
    k.add_argument("--json", action="store_true")
    k.set_defaults(func=cmd_design_rtest)

    q = sub.add_parser("export", help="write the identified location errors into a controller's kinematic parameters",
                       epilog=EPILOG + "; the mapping field by field: docs/controller_exports.md")
    q.add_argument("--model", required=True, type=path("--model"), help="model file (identify --save-model)")
    q.add_argument("--controller", required=True, choices=["linuxcnc", "siemens", "isg", "heidenhain", "fanuc"])
    q.add_argument("--current", type=path("--current"),
                   help="the controller's values active during the test: its HAL file (linuxcnc), MPF (siemens) "
                        "or JSON {\"controller\": ..., \"parameters\": {...}}; default: zero offsets")
    q.add_argument("--toolholder", type=number("--toolholder", 1, 99, integer=True), default=1,
                   help="siemens: the $TC_CARR data set (default 1)")
    q.add_argument("-o", "--output", type=path("--output"), help="write the controller file here (default: print it)")
    q.add_argument("--residual-model", type=path("--residual-model"),
                   help="write a model of the errors the controller cannot hold (held ones zero), for compensate")
    q.add_argument("--centres", metavar="RTEST.csv", type=path("--centres"),
                   help="isg: the R-test session the model was fitted to; its measured sphere centres are written "
                        "for the ISG kinematic optimisation (SysCalibFitAddRecord.ecy) to --centres-output")
    q.add_argument("--centres-output", type=path("--centres-output"), help="isg: the NC program of the centres")
    q.add_argument("--centres-setup", help="isg: the set-up (nest) whose centres are written (default: the first)")
    q.add_argument("--centres-origin", type=numbers("--centres-origin", 3, 1e5, "mm"), default=[0.0, 0.0, 0.0],
                   help="isg: the rotary axes' intersection in the controller's machine coordinates, mm")
    q.add_argument("--isg-kinematic", type=numbers("--isg-kinematic", 2, 1e4), default=[80.0, 0.0],
                   help="isg: kinematic type and variant for SysCalibFitInit.ecy (default 80,0 as TF5245's example; "
                        "use your machine's)")
    q.add_argument("--comp-file", action="append", metavar="AXIS=FILE",
                   help="linuxcnc, R-test map of a BC-trt: the axis' positioning error as a [JOINT_n]COMP_FILE "
                        "(type 0) table; AXIS B or C (C needs the map's gamma terms); may be repeated")
    q.add_argument("--comp-range", type=numbers("--comp-range", 2, 720.0, "deg"), default=[-90.0, 90.0],
                   help="angles of the table, deg (default -90,90; C: e.g. 0,360)")
    q.add_argument("--comp-step", type=number("--comp-step", 0.01, 90.0, "deg"), default=1.0,
                   help="step of the table, deg (default 1; LinuxCNC reads at most 256 lines)")
    q.add_argument("--json", action="store_true", help="print the parameters and the errors held as JSON")
    q.set_defaults(func=cmd_export)

    q = sub.add_parser("compensate", help="compensated NC program, and its verification in simulation", epilog=EPILOG)
    _add_setup_args(q)
    _add_truth_args(q)
    q.add_argument("--model", metavar="MODEL.json", type=path("--model"), help="fitted model to compensate")
    q.add_argument("--dialect", default="linuxcnc")
    q.add_argument("-o", "--output", default="compensated.ngc", type=path("--output"))
    q.add_argument("--verify", action="store_true",
                   help="measure, identify, compensate and measure again on a simulated machine (--errors ...)")
    q.add_argument("--json", action="store_true")
    q.set_defaults(func=cmd_compensate)

    q = sub.add_parser("virtual", help="a virtual instrument on a pseudo-terminal (prints its path)",
                       epilog=EPILOG)
    kinds = q.add_subparsers(dest="kind", required=True)
    k = kinds.add_parser("ballbar", help="a ballbar on a simulated machine running the test program", epilog=EPILOG)
    _add_setup_args(k)
    _add_truth_args(k)
    _add_link_args(k, 1000.0)
    _add_virtual_args(k)
    k.set_defaults(func=cmd_virtual_ballbar)
    k = kinds.add_parser("rtest", help="an R-test on a simulated B/C table running the pattern", epilog=EPILOG)
    _add_rtest_pattern_args(k)
    _add_rtest_machine_args(k, "probe direction (give 3 times; default a 45-deg tripod)")
    k.add_argument("--mode", default="keyence", choices=["sylvac", "keyence", "stream"], help="probe protocol")
    _add_link_args(k, 100.0)
    _add_virtual_args(k)
    k.set_defaults(func=cmd_virtual_rtest)

    q = sub.add_parser("record", help="record a session from an instrument on a serial port",
                       epilog=EPILOG + "; a recording that ends by disconnect, silence or no valid data "
                                       "exits with 4, its rows kept in the file")
    kinds = q.add_subparsers(dest="kind", required=True)
    k = kinds.add_parser("ballbar", help="record a ballbar test (the same set-up options as plan)", epilog=EPILOG)
    _add_setup_args(k)
    _add_link_args(k, 1000.0)
    k.add_argument("--zero", action="store_true", help="zero the transducer before START (normally done in the calibrator)")
    _add_record_args(k)
    k.set_defaults(func=cmd_record_ballbar)
    k = kinds.add_parser("rtest", help="record an R-test (the same pattern options as simulate rtest)", epilog=EPILOG)
    _add_rtest_pattern_args(k)
    k.add_argument("--probe-dir", action="append", metavar="X,Y,Z", type=numbers("--probe-dir", 3, 1e3),
                   help="calibrated probe direction (give 3 times; default a 45-deg tripod)")
    k.add_argument("--mode", default="keyence", choices=["sylvac", "keyence", "stream"], help="probe protocol")
    k.add_argument("--speed", type=number("--speed", 0.0, 1e4, lo_open=True), default=1.0,
                   help="polled modes: the instrument's virtual seconds per real second (virtual instruments only)")
    _add_link_args(k, 100.0)
    _add_record_args(k)
    k.set_defaults(func=cmd_record_rtest)

    q = sub.add_parser("report", help="self-contained HTML report of a session", epilog=EPILOG)
    q.add_argument("file", type=path("FILE"))
    q.add_argument("--method", default="joint", choices=["joint", "paper"])
    q.add_argument("--no-diagnosis", action="store_true")
    q.add_argument("--history", metavar="MACHINE_ID",
                   help="add the machine's calibration history (rotacal history show) as plots and flags")
    _add_db_arg(q)
    q.add_argument("-o", "--output", required=True, type=path("--output"))
    _add_plausibility_arg(q)
    q.set_defaults(func=cmd_report)

    q = sub.add_parser("table2", help="measured before/after compensation (Flynn et al. Table 2) against "
                                      "the simulated chain: what falls outside, and which causes explain it",
                       epilog=EPILOG)
    q.add_argument("--table", type=path("--table"), metavar="FILE.json",
                   help="before/after values in the layout of rotacal/data/flynn2016_table2.json "
                        "(default: the paper's Table 2)")
    q.add_argument("--method", default="paper", choices=["paper", "joint"],
                   help="identification of both runs (the paper used its own chain)")
    q.add_argument("--noise", type=number("--noise", 0.0, 100.0, "um", lo_open=True), default=0.5,
                   help="assumed 1-sigma ballbar noise, um")
    q.add_argument("--rho", type=number("--rho", 0.0, 0.999), default=0.0,
                   help="assumed AR(1) correlation of successive samples")
    q.add_argument("--hours", type=number("--hours", 0.0, 10_000.0, "h"), default=1.0,
                   help="assumed time between the two runs, h")
    q.add_argument("--draws", type=number("--draws", 10, 100_000, integer=True), default=200)
    q.add_argument("--seed", type=SEED, default=1)
    q.add_argument("--no-sweep", action="store_true", help="skip the sweep over the unstated assumptions")
    q.add_argument("--json", action="store_true")
    q.set_defaults(func=cmd_table2)

    q = sub.add_parser("demo", help="the whole job on a simulated machine: plan, simulate, identify, "
                                    "diagnose, compensate, report", epilog=EPILOG)
    q.add_argument("-o", "--output", default="out/demo", type=path("--output"))
    q.add_argument("--seed", type=SEED, default=2016)
    q.add_argument("--sag", type=number("--sag", -1.0, 1.0, "mm"), default=0.004, help="hidden gravity sag of the A table, mm")
    q.set_defaults(func=cmd_demo)

    from .circular import add_cli as add_circular_cli
    add_circular_cli(sub)  # rotacal circular plan|simulate|analyze (circular.py)
    return p


def _add_rtest_pattern_args(q: argparse.ArgumentParser) -> None:
    g = q.add_argument_group("measurement pattern (Oyama & Ibaraki Sec. 3.3; left out: the machine's "
                             "default pattern inside its limits and travel, the paper's on BC-trt)")
    g.add_argument("--machine", default="BC-trt", type=path("--machine"), metavar="NAME|FILE",
                   help="a built-in (`rotacal machines`) or a rotacal-machine/1 description file (default BC-trt)")
    g.add_argument("--b-range", dest="tilt_range", default=None, type=numbers("--b-range", 2, 360.0, "deg"),
                   help="tilt axis range, deg (inclusive; default the machine's, -90,90 on BC-trt)")
    g.add_argument("--b-step", type=number("--b-step", 0.0, 360.0, "deg"), default=None,
                   help="tilt step, deg (default 30)")
    g.add_argument("--c-range", default=None, type=numbers("--c-range", 2, 720.0, "deg"),
                   help="rotary axis range, deg (inclusive; an end one full turn after the start is left out; "
                        "default 0,360)")
    g.add_argument("--c-step", type=number("--c-step", 0.0, 360.0, "deg"), default=None,
                   help="rotary axis step, deg (default 30)")
    g.add_argument("--nest", action="append", metavar="X,Y,Z", type=numbers("--nest", 3, 1e4, "mm"),
                   help="nominal ball centre of a sensor nest, table frame, mm (repeatable; default "
                        "the paper's two: 100,0,60 and 0,-120,140)")
    g.add_argument("--dwell", type=number("--dwell", 0.0, 3600.0, "s", lo_open=True), default=rtest.DEFAULT_DWELL_S,
                   help="time between poses, s; each pose is held at rest and read in the middle 80 %% of it "
                        "(docs/protocols.md)")


def _add_rtest_machine_args(q: argparse.ArgumentParser, probe_dir_help: str) -> None:
    g = q.add_argument_group("simulated machine and instrument")
    g.add_argument("--errors", default="random",
                   help="location errors: random (seeded), zero, or NAME=VALUE,... (mm, rad)")
    g.add_argument("--effect", action="append", metavar="ID=P1,P2",
                   help="position-dependent error from the effects catalogue, e.g. gravity_sag_B=0.006 "
                        "or axial_motion_C_h2=0.002,-0.001 (repeatable)")
    g.add_argument("--noise", type=number("--noise", 0.0, 1000.0, "um"), default=rtest.DEFAULT_NOISE_UM, help="1-sigma reading noise, um")
    g.add_argument("--probe-zero", type=number("--probe-zero", 0.0, 1e4, "um"), default=rtest.DEFAULT_PROBE_ZERO_UM, help="1-sigma probe zero per set-up, um")
    g.add_argument("--probe-dir", action="append", metavar="X,Y,Z", type=numbers("--probe-dir", 3, 1e3),
                   help=probe_dir_help)
    g.add_argument("--seed", type=SEED, default=1)


def _add_rtest_sim_args(q: argparse.ArgumentParser) -> None:
    _add_rtest_pattern_args(q)
    _add_rtest_machine_args(q, "probe direction (give 3 times, normalised): also write raw d1,d2,d3 "
                               "with probe.N.dir")
    q.add_argument("--raw-only", action="store_true", help="with --probe-dir: write d1,d2,d3 but no dx,dy,dz")
    q.add_argument("--truth", metavar="JSON", type=path("--truth"), help="where to write the truth (default: FILE.truth.json)")
    q.add_argument("-o", "--output", required=True, type=path("--output"))


def _add_truth_args(q: argparse.ArgumentParser) -> None:
    g = q.add_argument_group("simulated machine")
    g.add_argument("--errors", default="random",
                   help="random (seeded), table2 (Flynn et al.), zero, or NAME=VALUE,... (mm, rad)")
    g.add_argument("--effect", action="append", metavar="ID=P1,P2",
                   help="hide a catalogue effect, e.g. gravity_sag_A=0.004 (repeatable)")
    g.add_argument("--pivot-error", type=number("--pivot-error", 0.0, 10.0, "mm"), default=PIVOT_ERROR_MM,
                   help="1-sigma pivot placement error, mm")
    g.add_argument("--noise", type=number("--noise", 0.0, 1000.0, "um"), default=BALLBAR_NOISE_UM,
                   help="1-sigma reading noise, um")
    g.add_argument("--seed", type=SEED, default=1)


# Options whose values may start with '-' ("--a-range -90,90"): argparse would take the value
# for an option, so such pairs are joined as "--a-range=-90,90" before parsing.
_SIGNED_VALUE_OPTIONS = {"--a-range", "--b-range", "--tilt-range", "--c-range", "--axial-c-tilt", "--pivot", "--errors", "--nest", "--probe-dir",
                         "--comp-range", "--travel", "--pivot-z", "--centres-origin"}


def _join_signed_values(argv: Sequence[str]) -> list[str]:
    out: list[str] = []
    it = iter(argv)
    for tok in it:
        if tok in _SIGNED_VALUE_OPTIONS:
            nxt = next(it, None)
            out.append(tok if nxt is None else f"{tok}={nxt}")
        else:
            out.append(tok)
    return out


def _message(e: BaseException, limit: int = 2000) -> str:
    """An error message fit for a terminal: bounded (a file's line may be megabytes long)."""
    text = str(e)
    return text if len(text) <= limit else text[:limit] + f"... ({len(text) - limit} more characters)"


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code. Every failure ends in a one-line message
    and the documented code, never a traceback (ROTACAL_TRACEBACK=1 shows it for debugging)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        args = build_parser().parse_args(_join_signed_values(argv))
        check_command_files(args)  # every output against every input and output, before any work
        code = args.func(args)
        sys.stdout.flush()  # a reader that went away is seen here, inside the handlers below
        return code
    except (OptionError, _core.ParseError, _core.InvalidArgument, _core.DegenerateGeometry) as e:
        _say(f"rotacal: error: {_message(e)}")
        return EXIT_INPUT
    except BrokenPipeError:  # `rotacal history show M | head`: the reader has what it wanted
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no second error at exit
        except OSError:
            pass
        return EXIT_OK
    except UnicodeError as e:  # text that is not UTF-8 where the reader did not say so itself
        _say(f"rotacal: error: input is not UTF-8 text: {_message(e)}")
        return EXIT_INPUT
    except (_core.IoError, OSError, MemoryError) as e:
        _say(f"rotacal: error: {_message(e) or type(e).__name__}")
        return EXIT_IO
    except _core.Error as e:
        _say(f"rotacal: error: {_message(e)}")
        return EXIT_ERROR
    except KeyboardInterrupt:
        _say("rotacal: interrupted")
        return 130
    except Exception as e:  # a bug: say what and where, without a traceback
        if os.environ.get("ROTACAL_TRACEBACK"):
            raise
        tb = e.__traceback__
        while tb is not None and tb.tb_next is not None:
            tb = tb.tb_next
        where = f" at {Path(tb.tb_frame.f_code.co_filename).name}:{tb.tb_lineno}" if tb else ""
        _say(f"rotacal: internal error ({type(e).__name__}{where}): {_message(e)}")
        return EXIT_ERROR


if __name__ == "__main__":
    sys.exit(main())
