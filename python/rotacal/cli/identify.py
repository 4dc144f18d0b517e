# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal identify`` (location errors of a session, their uncertainty budget, the model file
and the history entry) and ``rotacal predict`` (a session predicted by a model file)."""

from __future__ import annotations

import argparse

from .. import _core, jsontext, units
from ..sessions import BALLBAR, PROBE, RTEST, by_kind, kind, save
from .options import (
    EPILOG,
    EXIT_OK,
    SEED,
    OptionError,
    budget_sizes,
    controller_text,
    number,
    path,
    say,
)
from .setups import add_db_arg, add_plausibility_arg, load_session


def _shown(unit: str) -> tuple[float, str]:
    """(factor, unit padded to 4) as identify's table prints a parameter of `unit`."""
    factor, shown = units.shown(unit)
    return factor, f"{shown:4s}"


def _fmt_value(v, unit: str) -> str:
    factor, shown = _shown(unit)
    return f"{v * factor:+9.3f} {shown}"


def print_noise_model(nm: dict) -> None:
    from ..results import noise_handling_words

    how = f"; {noise_handling_words(nm)}" if "gls_refit" in nm else ""
    print(f"noise model: {nm['summary']}{how}")


def print_budget(b: dict) -> None:
    from ..results import budget_why

    print(f"uncertainty budget (GUM; coverage {b['coverage'] * 100:.0f} %; um / urad):")
    print(
        f"  {'':6s} {'value':>10s} {'type A':>8s} {'u_c':>8s} {'U':>8s} {'k':>5s} {'nu_eff':>7s}  dominant left-out effect"
    )
    for name, e in b["location_errors"].items():
        if not e["observable"]:
            print(f"  {name:6s} unobservable")
            continue
        f = 1e6 if e["unit"] == "rad" else 1e3
        nu = "inf" if e["nu_eff"] is None else f"{e['nu_eff']:.0f}"
        dom = (
            e["dominant"][0]
            if e["dominant"]
            else (e["type_b"][0]["effect"] if e["type_b"] else "-")
        )
        line = e["type_b"][0] if e["type_b"] else None
        dom_u = ""
        if line is not None and dom == line["effect"]:
            dom_u = f" ({line['u'] * f:.3f}, {line['basis']})"
        print(
            f"  {name:6s} {e['value'] * f:+10.3f} {e['u_a'] * f:8.3f} {e['u_c'] * f:8.3f} "
            f"{e['expanded'] * f:8.3f} {e['k']:5.2f} {nu:>7s}  {dom}{dom_u}"
        )
    why = budget_why(b)
    if why:
        print("  " + why)


def _print_monte_carlo(mc: dict) -> None:
    noise = mc.get("noise") or f"white noise, {mc['noise_um']:.3f} um"
    print(
        f"Monte Carlo check of the 1-sigma, {mc['draws']} draws with {noise} "
        "(ratio = Monte Carlo sigma / reported sigma):"
    )
    for name, m in mc["parameters"].items():
        scale, unit = (1e6, "urad") if m["unit"] == "rad" else (1e3, "um")
        print(
            f"  {name:16s} reported {m['std_reported'] * scale:8.3f}  Monte Carlo {m['std_mc'] * scale:8.3f} "
            f"{unit:4s}  ratio {m['ratio']:.2f}"
        )


def print_identification(d: dict) -> None:
    print(
        f"{d['method']} identification, {d['machine']}, {d['n_samples']} samples, "
        f"residual RMS {d['residual_rms_um']:.3f} um"
    )
    budget = d.get("uncertainty_budget")
    for name, p in d["location_errors"].items():
        if p["value"] is None:
            print(f"  {name:6s}  unobservable")
            continue
        print(
            f"  {name:6s} {_fmt_value(p['value'], p['unit'])} +- {p['std'] * _shown(p['unit'])[0]:.3f}"
        )
    for axis, p in d.get("pivot", {}).items():
        print(
            f"  pivot {axis}  "
            + (
                "unobservable"
                if p["value"] is None
                else f"{p['value']:.4f} mm +- {p['std'] * 1e3:.3f} um"
            )
        )
    for eff in d.get("effects", []):
        for pname, p in eff["params"].items():
            what = f"{eff['id']} ({eff['cause']})"
            print(
                f"  {what}: "
                + (
                    "unobservable"
                    if p["value"] is None
                    else f"{pname} = {_fmt_value(p['value'], p['unit']).strip()} +- "
                    f"{p['std'] * _shown(p['unit'])[0]:.3f}"
                )
            )
    for u in d["unobservable"]:
        print(f"  not determined by these tests: {u}")
    for n in d.get("notes", []):
        print(f"  note: {n}")
    if "noise_model" in d:
        print_noise_model(d["noise_model"])
    if budget:
        print_budget(budget)
    if d.get("monte_carlo"):
        _print_monte_carlo(d["monte_carlo"])


def refuse_history_options(a: argparse.Namespace) -> None:
    """The history options, refused before any work: --store needs --machine-id, a store that
    can be opened, a valid date; the others go with --store (--controller also --save-model)."""
    if a.store or a.machine_id is not None:
        from ..history import refuse_before_storing

        if not a.store:
            raise OptionError(
                "--machine-id: add --store to store the identification in the history"
            )
        refuse_before_storing(a.db, a.machine_id, a.date)
    elif (
        a.note is not None
        or a.date is not None
        or a.db is not None
        or (a.controller and not a.save_model)
    ):
        raise OptionError(
            "--note, --date and --db go with --store --machine-id; --controller with --store or "
            "--save-model"
        )


def print_joint_identification(d: dict) -> None:
    """The joint result of several sessions (rotacal.multi): the one set of location errors, each
    session's own parameters and its location errors alone, and where the sessions disagree."""
    print(f"joint identification, {d['machine']}, {len(d['sessions'])} sessions")
    for name, p in d["location_errors"].items():
        if p["value"] is None:
            print(f"  {name:6s}  unobservable")
            continue
        f = _shown(p["unit"])[0]
        alone = "  ".join(
            f"{s['name']}: "
            + (
                "unobservable"
                if a["value"] is None
                else f"{a['value'] * f:+.3f} +- {a['std'] * f:.3f}"
            )
            for s in d["sessions"]
            for a in (s["alone"][name],)
        )
        print(
            f"  {name:6s} {_fmt_value(p['value'], p['unit'])} +- {p['std'] * f:.3f}   (alone: {alone})"
        )
    for name, p in d["effects"].items():
        shown = (
            "unobservable"
            if p["value"] is None
            else f"{_fmt_value(p['value'], p['unit']).strip()} +- {p['std'] * _shown(p['unit'])[0]:.3f}"
        )
        print(f"  {name} (shared): {shown}")
    for s in d["sessions"]:
        own = ", ".join(
            f"{n} = " + ("unobservable" if p["value"] is None else f"{p['value']:.4f} {p['unit']}")
            for n, p in s["nuisances"].items()
        )
        print(
            f"  session {s['name']} ({s['instrument']}, {s['n_residuals']} residuals, RMS "
            f"{s['residual_rms_um']:.3f} um): {own}"
        )
        print("    ", end="")
        print_noise_model(s["noise_model"])
    t = d["disagreement_test"]
    print(
        f"  sessions alone compared {t['comparisons']} times; a disagreement is |z| > {t['z']:.2f}, "
        "more where a sigma rests on few samples (1 % chance of any for one machine)"
    )
    for g in d["disagreements"]:
        f, shown = _shown(g["unit"])
        print(
            f"  DISAGREE {g['parameter']}: {g['sessions'][0]} - {g['sessions'][1]} = {g['difference'] * f:+.3f} "
            f"+- {g['sigma'] * f:.3f} {shown.strip()} (z = {g['z']:+.1f} of {g['threshold']:.2f})"
        )
    for u in d["unobservable"]:
        print(f"  not determined by these sessions: {u}")
    for n in d["notes"]:
        print(f"  note: {n}")


def _keep(a: argparse.Namespace, result, d: dict, files) -> None:
    """--save-model and --store of any identification: the model file (rotacal-model/1, written
    by the C++ writer, strict: a non-finite number is written null with its reason) and the
    history entry. ``files``: the session, or the list of sessions of a joint identification."""
    from ..analysis import identification_document

    inputs = tuple(files) if isinstance(files, list) else (files,)
    if a.save_model:
        from ..models import save_model

        save_model(
            identification_document(result, files, controller_text(a.controller)),
            a.save_model,
            inputs=inputs,
        )
        say(f"wrote {a.save_model}")
    if a.store:
        from .history import store_identification

        store_identification(
            a,
            identification_document(result, files),
            {"identification": d},
            ", ".join(inputs),
            controller_text(a.controller),
        )


def _cmd_identify_joint(a: argparse.Namespace) -> int:
    """Several sessions of one machine: one joint identification (rotacal.multi)."""
    from ..multi import identify_sessions

    given = [
        o
        for o, on in (
            (f"--method {a.method}", a.method != "joint"),
            ("--length-offset", a.length_offset),
            ("--monte-carlo", a.monte_carlo),
            ("--budget-sizes", a.budget_sizes),
        )
        if on
    ]
    if given:
        raise OptionError(
            f"{', '.join(given)}: not available for a joint identification of several sessions"
        )
    refuse_history_options(a)
    sessions = [load_session(f, a) for f in a.file]
    result = identify_sessions(sessions, list(a.file), noise=a.noise, inflate_sigma=a.inflate_sigma)
    d = result.to_dict()
    if not d["converged"]:
        raise _core.DegenerateGeometry(
            "identify: the joint fit of the sessions did not converge: "
            + "; ".join(n for n in d["notes"] if "converge" in n)
        )
    keeps = a.save_model or a.store
    if keeps and d["disagreements"] and not d["sigma_inflated"]:
        _print_joint(a, d)  # what disagrees, then the refusal: nothing is written
        _core.refuse_disagreeing(result.raw)
    _keep(a, result, d, list(a.file))
    _print_joint(a, d)
    return EXIT_OK


def _print_joint(a: argparse.Namespace, d: dict) -> None:
    if a.json:
        print(jsontext.dumps(d))
    else:
        print_joint_identification(d)


def cmd_identify(a: argparse.Namespace) -> int:
    from ..analysis import identification_budget, identify, monte_carlo

    if len(a.file) > 1:
        return _cmd_identify_joint(a)
    if a.inflate_sigma:
        raise OptionError("--inflate-sigma: for a joint identification of several sessions")
    a.file = a.file[0]
    refuse_history_options(a)
    sizes = budget_sizes(a.budget_sizes)  # refused before any work
    s = load_session(a.file, a)
    if kind(s) == PROBE:  # the touch probe's options and fit: cli/probe.py
        from .probe import identify_probe_session, print_probe_identification

        result, d = identify_probe_session(a, s, sizes)
        _keep(a, result, d, a.file)
        if a.json:
            print(jsontext.dumps(d))
        else:
            print_probe_identification(d)
            if "noise_model" in d:
                print_noise_model(d["noise_model"])
            if d.get("uncertainty_budget"):
                print_budget(d["uncertainty_budget"])
            if d.get("monte_carlo"):
                _print_monte_carlo(d["monte_carlo"])
        return EXIT_OK
    if a.length_offset and kind(s) == RTEST:
        raise _core.InvalidArgument("identify: --length-offset is for ballbar sessions")
    result = identify(s, a.method, fit_length_offset=a.length_offset, noise=a.noise)
    if a.method == "joint" and not a.no_budget:
        result.budget = identification_budget(s, sizes, result)
    d = result.to_dict()
    if a.monte_carlo:
        d["monte_carlo"] = monte_carlo(s, result, a.monte_carlo, seed=a.seed)
    _keep(a, result, d, a.file)
    if by_kind(s, {BALLBAR: a.json, RTEST: True}, "identify"):
        print(jsontext.dumps(d))
    else:
        print_identification(d)
    return EXIT_OK


def cmd_predict_joints(a: argparse.Namespace) -> int:
    """predict --joints: the tool relative to the workpiece by the controller's real-time
    evaluation (realtime/evaluate.hpp), of a model file or of the blob a controller loads."""
    from .. import realtime
    from ..outputs import write_output

    model = realtime.load_realtime(a.model)
    joints = realtime.read_joints(a.joints)
    tip, direction = realtime.forward(model, joints, a.tool_length, a.y1, a.y2)
    write_output(a.output, realtime.joints_csv(joints, tip, direction), inputs=[a.joints, a.model])
    say(f"wrote {a.output}: the tool tip and direction of {len(joints)} joint positions")
    return EXIT_OK


def cmd_predict(a: argparse.Namespace) -> int:
    from ..analysis import predict_session
    from ..models import load_model

    if (a.session is None) == (a.joints is None):
        raise _core.InvalidArgument("predict: give a SESSION or --joints, one of them")
    if a.joints is not None:
        return cmd_predict_joints(a)
    model_dict = load_model(a.model)
    s = load_session(a.session, a)
    out, line = predict_session(model_dict, s, a.probe_zeros, source=a.model)
    if line:
        say(line)
    save(out, a.output, inputs=[a.session, a.model])
    say(f"wrote {a.output}")
    return EXIT_OK


def add_identify(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "identify",
        help="identify location errors from a session, or jointly from several "
        "sessions of one machine",
        epilog=EPILOG,
    )
    q.add_argument(
        "file",
        type=path("FILE"),
        nargs="+",
        help="a session; several (ballbar, R-test, touch probe) of one machine are identified jointly",
    )
    q.add_argument(
        "--method",
        default="joint",
        choices=["joint", "paper", "cycles", "cycles-free-radius"],
        help="joint (default); paper (ballbar, R-test); cycles, cycles-free-radius (touch probe: the "
        "controller cycles' method, radius known or fitted per pose)",
    )
    q.add_argument("--length-offset", action="store_true", help="also fit an offset of L0 (joint)")
    q.add_argument("--json", action="store_true", help="print the result as JSON")
    q.add_argument(
        "--save-model",
        metavar="MODEL.json",
        type=path("--save-model"),
        help="write the fitted model (ballbar; R-test joint: location errors, maps, covariance; touch probe "
        "joint fit; several sessions' joint identification)",
    )
    q.add_argument(
        "--monte-carlo",
        type=number("--monte-carlo", 0, 10_000, integer=True),
        default=0,
        metavar="N",
        help="check the 1-sigma by N simulated repeats of the session with its fitted noise model (progress bar)",
    )
    q.add_argument("--seed", type=SEED, default=1, help="seed of the Monte Carlo draws")
    add_plausibility_arg(q)
    q.add_argument(
        "--inflate-sigma",
        action="store_true",
        help="several sessions that disagree: widen the sigma of each parameter they disagree on "
        "by its Birge ratio and keep the joint model (without it, no model is saved, stored or "
        "exported while they disagree: exit 3)",
    )
    q.add_argument(
        "--noise",
        default="auto",
        choices=["auto", "white"],
        help="auto (default): AR noise model of the residuals, GLS refit when correlated; "
        "white: readings taken as independent",
    )
    q.add_argument(
        "--budget-sizes",
        metavar="SIZES.json",
        type=path("--budget-sizes"),
        help="plausible sizes of left-out effects for the uncertainty budget (JSON object; "
        "docs/json_schema.md)",
    )
    q.add_argument(
        "--no-budget",
        action="store_true",
        help="skip the uncertainty budget (it runs a diagnosis of the left-out effects)",
    )
    g = q.add_argument_group("calibration history (docs/history.md)")
    g.add_argument(
        "--store",
        action="store_true",
        help="store the identification in the history (needs --machine-id)",
    )
    g.add_argument(
        "--machine-id",
        help="the physical machine, e.g. its serial number (the session's "
        "'# machine:' stays its kinematic type)",
    )
    g.add_argument("--note", help="operator note stored with it")
    g.add_argument("--date", help="when it was measured, ISO 8601 (default: now)")
    g.add_argument(
        "--controller",
        metavar="CURRENT",
        type=path("--controller"),
        help="the controller parameters active during the test (HAL, MPF or JSON file), stored with it",
    )
    add_db_arg(g)
    q.set_defaults(func=cmd_identify)


def add_predict(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser("predict", help="predict a session with a fitted model", epilog=EPILOG)
    q.add_argument("session", nargs="?", type=path("SESSION"))
    q.add_argument(
        "--model",
        required=True,
        type=path("--model"),
        help="model file, or with --joints also the blob of export --controller realtime",
    )
    q.add_argument(
        "--joints",
        type=path("--joints"),
        help="instead of a session: a CSV x,y,z,tilt,rot (mm, deg) of joint positions; the output "
        "holds the tool tip and direction relative to the workpiece, computed by the controller's "
        "real-time evaluation (docs/realtime.md)",
    )
    q.add_argument(
        "--tool-length",
        type=number("--tool-length", 0.0, 1e4, "mm"),
        default=0.0,
        help="--joints: spindle nose to tool tip (head machines; table machines: the tip below "
        "X, Y, Z), mm",
    )
    q.add_argument(
        "--y1", type=number("--y1", -10.0, 10.0), default=0.0, help="--joints: thermal lag state"
    )
    q.add_argument(
        "--y2", type=number("--y2", -10.0, 10.0), default=0.0, help="--joints: thermal lag state"
    )
    q.add_argument(
        "--probe-zeros",
        choices=["none", "fitted"],
        default="none",
        help="R-test: add the probe zeros fitted for the same set-ups (same nests), or none "
        "(default: a new set-up's zeros are unknown)",
    )
    q.add_argument(
        "-o",
        "--output",
        required=True,
        type=path("--output"),
        help="the session with predicted lengths (ballbar) or dx,dy,dz and dx_std,dy_std,dz_std "
        "(R-test); with --joints the CSV of the tool's tip and direction",
    )
    add_plausibility_arg(q)
    q.set_defaults(func=cmd_predict)


COMMANDS: dict = {}  # identify and predict: cli/thermal.py (which calls add_identify, add_predict)
