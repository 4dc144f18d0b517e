# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal identify`` of a thermal session (issue 53; formats.md "Thermal test of a rotary
axis"): a probe or R-test file with an ``epoch`` column and ``# duty.N:`` lines is identified by
one joint fit over every row (probe/thermal.hpp, rtest/thermal.hpp), and its summary printed:
per location error the steady-state change at the tested speed, whether it is significant, and
after how long from cold it may exceed ``--tolerance``; ``--save-model`` writes the thermal model
file (io/thermal_model.hpp). Any other file goes to cli/identify.py.

``rotacal predict --model THERMAL_MODEL --duty FILE``: the location errors that model predicts
over the times of another duty. Any other predict goes to cli/identify.py.
"""

from __future__ import annotations

import argparse
import re

from .. import _core, jsontext
from . import identify
from .options import EXIT_OK, OptionError, number, path, say

# --tolerance units -> (native unit, factor to it)
_TOLERANCE_UNITS = {
    "nm": ("mm", 1e-6),
    "um": ("mm", 1e-3),
    "mm": ("mm", 1.0),
    "urad": ("rad", 1e-6),
    "mrad": ("rad", 1e-3),
    "rad": ("rad", 1.0),
}
# Options of `identify` a thermal session uses; the others are refused rather than ignored.
_THERMAL_DESTS = {
    "command",
    "func",
    "file",
    "json",
    "noise",
    "tolerance",
    "lags",
    "peer",
    "save_model",
    "store",
    "machine_id",
    "db",
    "note",
    "date",
}
_DURATION_UNITS = {"ms": 1e-3, "s": 1.0, "min": 60.0, "h": 3600.0}


def duration(option: str):
    """argparse type: a time such as 2h, 10min, 90s, 10ms or 600 (s), 0 to 1e8 s."""

    def parse(text: str) -> float:
        m = re.fullmatch(r"\s*([0-9.eE+-]+)\s*(ms|s|min|h)?\s*", text)
        if not m:
            raise OptionError(f"{option}: '{text[:40]}' is not a time such as 2h, 10min or 600s")
        value = number(option, 0.0, 1e8, "s")(m.group(1)) * _DURATION_UNITS[m.group(2) or "s"]
        if not value <= 1e8:
            raise OptionError(f"{option}: {text[:40]} is beyond 1e8 s")
        return value

    return parse


def durations(option: str):
    """argparse type: comma-separated times (see duration), at most 100000."""
    one = duration(option)

    def parse(text: str) -> list[float]:
        parts = text.split(",")
        if len(parts) > 100_000:
            raise OptionError(f"{option}: more than 100000 times")
        return [one(p) for p in parts]

    return parse


def tolerance(text: str) -> tuple[str, float]:
    """argparse type: '5um', '10urad' -> ('mm', 0.005), ('rad', 1e-5)."""
    m = re.fullmatch(r"\s*([0-9.eE+-]+)\s*([a-z]+)\s*", text)
    if not m or m.group(2) not in _TOLERANCE_UNITS:
        raise OptionError(
            f"--tolerance: '{text[:40]}' is not a number with a unit "
            f"({', '.join(_TOLERANCE_UNITS)}), e.g. 5um or 10urad"
        )
    unit, factor = _TOLERANCE_UNITS[m.group(2)]
    value = number("--tolerance", 0.0, 1e6, lo_open=True)(m.group(1))
    return unit, value * factor


def add_identify(sub: argparse._SubParsersAction) -> None:
    identify.add_identify(sub)
    q = sub.choices["identify"]
    q.add_argument(
        "--tolerance",
        action="append",
        type=tolerance,
        metavar="VALUE",
        help="thermal session: the drift tolerated, e.g. 5um (positions, the table-side point) "
        "or 10urad (orientations); repeat for both. The summary says after how long at the tested "
        "speed from cold each error's 95 %% upper bound exceeds it",
    )
    q.add_argument(
        "--lags",
        type=number("--lags", 1, 2, integer=True),
        default=1,
        help="thermal session: first-order lags of the drift, 1 (default) or 2",
    )
    q.add_argument(
        "--peer",
        action="store_true",
        help="thermal probe session: also the per-epoch peer (each epoch identified alone, then "
        "one lag fitted to the series: what a kinematics cycle re-run at intervals gives)",
    )
    q.set_defaults(func=cmd_identify)
    defaults = {act.dest: act.default for act in q._actions if act.dest not in _THERMAL_DESTS}
    q.set_defaults(_identify_defaults=defaults)


def _refuse_other_options(a: argparse.Namespace) -> None:
    for dest, default in a._identify_defaults.items():
        if dest != "help" and getattr(a, dest, default) != default:
            raise OptionError(
                f"--{dest.replace('_', '-')}: not for a thermal session (yet); "
                "its options are --tolerance, --lags, --peer, --noise, --json, --save-model and --store"
            )


def cmd_identify(a: argparse.Namespace) -> int:
    if len(a.file) != 1 or not _core.is_thermal_session(a.file[0]):
        if a.tolerance or a.lags != 1 or a.peer:
            raise OptionError(
                "--tolerance, --lags, --peer: for a thermal session (an epoch column and duty lines)"
            )
        return identify.cmd_identify(a)
    _refuse_other_options(a)
    identify.refuse_history_options(a)
    tol = {}
    for unit, value in a.tolerance or []:
        if unit in tol:
            raise OptionError(f"--tolerance: given twice in {'um' if unit == 'mm' else 'urad'}")
        tol[unit] = value
    d = _core.identify_thermal(
        a.file[0],
        a.lags,
        tol.get("mm"),
        tol.get("rad"),
        noise=a.noise,
        peer=a.peer,
        model=bool(a.save_model or a.store),
    )
    if a.save_model or a.store:
        _keep_thermal(a, d.pop("model"), d)
    for w in d["warnings"]:
        say(f"rotacal: warning: {w}")
    if a.json:
        print(jsontext.dumps(d))
    else:
        print_thermal(d)
        if "peer" in d:
            print("\nthe per-epoch peer (each epoch alone, then one lag fitted to the series):")
            print_thermal(d["peer"])
    return EXIT_OK


def _keep_thermal(a: argparse.Namespace, model: dict, d: dict) -> None:
    """--save-model writes the thermal model file; --store keeps it in the calibration history
    (its cold errors beside the other calibrations, its taus and gains followed by history show)."""
    from ..models import save_model, source_dict

    model = model | {"source": source_dict(a.file[0])}
    if a.save_model:
        save_model(model, a.save_model, inputs=(a.file[0],))
        say(f"wrote {a.save_model}: the thermal model (docs/thermal.md)")
    if a.store:
        details = {"identification": d["identification"], "summary": d["summary"]}
        from .history import store_identification

        store_identification(a, model, details, a.file[0])


def _minutes(seconds: float) -> str:
    return f"{seconds / 60:.1f} min" if seconds < 7200 else f"{seconds / 3600:.2f} h"


def _value(x: float, unit: str) -> str:
    return f"{x * 1e3:+.3f} um" if unit == "mm" else f"{x * 1e6:+.3f} urad"


def _drift_test_line(t: dict) -> str:
    p = "p < 1e-300" if t["p_value"] == 0 else f"p = {t['p_value']:.3g}"
    dof = f"F({t['gains']}, {t['residual_dof']:.0f})" if t["residual_dof"] else "chi-square"
    return (
        f"joint test of the {t['gains']} gains against 0 ({dof}): W = {t['statistic']:.1f}, {p}: "
        + ("thermal drift found" if t["drift_found"] else f"no drift at {t['level']:g}")
    )


def thermal_finding(path: str) -> dict:
    """What `rotacal diagnose` says of a thermal session's drift: the joint fit's drift test
    (one test of every gain against 0 at 1 %), each lag's tau and the errors whose drift is
    significant alone. The catalogue's effects beside it are still tested with the epochs
    pooled (issue 53 item 4: the drift is not yet in their baseline)."""
    s = _core.identify_thermal(path)["summary"]
    found = s["drift_test"]["drift_found"]
    return {
        "axis": s["axis"],
        "drift_found": found,
        "drift_test": s["drift_test"],
        "lags": s["lags"] if found else [],
        "significant": [e["name"] for e in s["drifts"] if found and e.get("significant")],
        "baseline": "epochs pooled: the catalogue's effects are tested without the drift",
    }


def print_thermal_finding(f: dict) -> None:
    if not f["drift_test"]["gains"]:
        print("thermal: no gain determined (no heat input): no thermal finding")
        return
    print(f"thermal, axis {f['axis'] or '-'}: {_drift_test_line(f['drift_test'])}")
    if f["drift_found"]:
        taus = ", ".join(_minutes(lag["tau_s"]) for lag in f["lags"] if lag["observable"])
        print(f"  tau {taus or 'unobservable'}; drifting alone beyond 3 sigma: "
              f"{', '.join(f['significant']) or 'none'}")  # fmt: skip
    print(f"  {f['baseline']} (rotacal identify fits the drift)")


def print_thermal(d: dict) -> None:
    ident, s = d["identification"], d["summary"]
    axis = s["axis"] or "-"
    rms = ident["residual_rms_um"]  # 0 for the peer, whose residuals are per epoch
    print(
        f"thermal test of axis {axis} at {s['tested_speed_rpm']:g} rev/min: "
        f"{ident['n_samples']} rows in {ident['n_epochs']} epochs"
        f"{f', residual RMS {rms:.3f} um' if rms > 0 else ''}"
        f"{'' if ident['converged'] else ' (NOT converged)'}"
    )
    if ident["noise_model"]:
        print(f"noise model: {ident['noise_model']}")
    for k, lag in enumerate(s["lags"], start=1):
        tau = (
            f"{_minutes(lag['tau_s'])} +- {_minutes(lag['tau_std_s'])}"
            if lag["observable"]
            else "unobservable"
        )
        print(f"lag {k}: tau = {tau}")
    if s["drift_test"]["gains"]:
        print(_drift_test_line(s["drift_test"]))
    if s["no_significant_drift"]:
        print("no significant drift of any location error: tau rests on the noise alone")
    print(f"steady-state change after long turning at {s['tested_speed_rpm']:g} rev/min:")
    for e in s["drifts"]:
        if not e["observable"]:
            print(f"  {e['name']:<8} unobservable: {e['reason']}")
            continue
        change = (
            f"{_value(e['steady_change'], e['unit'])} +- {_value(e['steady_std'], e['unit'])[1:]}"
        )
        line = f"  {e['name']:<8} {change:<28}"
        line += "significant" if e["significant"] else "no significant drift"
        if "tolerance" in e:
            tol = _value(e["tolerance"], e["unit"])[1:]
            after = e["exceeds_after_s"]
            line += (
                f"; may exceed {tol} after {_minutes(after)}"
                if after is not None
                else f"; never exceeds {tol}"
            )
        print(line)
    for n in ident["notes"]:
        print(f"note: {n}")


def add_predict(sub: argparse._SubParsersAction) -> None:
    identify.add_predict(sub)
    q = sub.choices["predict"]
    q._option_string_actions["--output"].required = False  # the thermal prediction prints
    g = q.add_argument_group("a thermal model (docs/thermal.md)")
    g.add_argument(
        "--duty",
        type=path("--duty"),
        help="instead of a session: a file of '# duty.N: TIME, AXIS=SPEED, ...' lines (from cold "
        "at 0 s), or a thermal session (its duty and epochs); prints the location errors the "
        "thermal --model predicts over time (CSV, or -o FILE, or --json)",
    )
    g.add_argument(
        "--times",
        type=durations("--times"),
        help="--duty: the times, e.g. 0,30min,2h (default: every --step to 5 taus after the "
        "duty's last entry)",
    )
    g.add_argument(
        "--step",
        type=duration("--step"),
        default=600.0,
        help="--duty: between the default times (default 10min)",
    )
    g.add_argument("--json", action="store_true", help="--duty: print the prediction as JSON")
    q.set_defaults(func=cmd_predict)


def cmd_predict(a: argparse.Namespace) -> int:
    if a.duty is None:
        if a.times is not None or a.json or a.step != 600.0:
            raise OptionError("--times, --step, --json: for a thermal prediction (--duty)")
        if a.output is None:
            raise OptionError("predict: -o/--output is required")
        return identify.cmd_predict(a)
    if a.session is not None or a.joints is not None:
        raise OptionError("predict --duty: no SESSION or --joints with it")
    if not a.step > 0:
        raise OptionError("--step: must be > 0")
    d = _core.predict_thermal(a.model, a.duty, a.times, a.step)
    text = jsontext.dumps(d) + "\n" if a.json else prediction_csv(d)
    if a.output:
        from ..outputs import write_output

        write_output(a.output, text, inputs=[a.model, a.duty])
        say(f"wrote {a.output}: the location errors at {len(d['times_s'])} times")
    else:
        print(text, end="")
    return EXIT_OK


def prediction_csv(d: dict) -> str:
    """time_s, each lag's y, then each location error and its 1 sigma (mm, rad)."""
    lags = len(d["states"][0]) if d["states"] else 0
    head = ["time_s", *(f"y{k + 1}" for k in range(lags))]
    for e in d["errors"]:
        head += [e["name"], f"{e['name']}_std"]
    rows = [",".join(head)]
    for i, t in enumerate(d["times_s"]):
        row = [f"{t:.3f}", *(f"{y:.9f}" for y in d["states"][i])]
        for e in d["errors"]:
            row += [f"{e['value'][i]:.9g}", f"{e['std'][i]:.3g}"]
        rows.append(",".join(row))
    return "\n".join(rows) + "\n"


COMMANDS = {"identify": add_identify, "predict": add_predict}
