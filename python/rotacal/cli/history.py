# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal history add|show|list``: the calibration history of physical machines."""

from __future__ import annotations

import argparse
from typing import Sequence

from .. import _core, jsontext
from .options import EPILOG, EXIT_OK, OptionError, controller_text, json_object, number, path, say
from .setups import add_db_arg


def tolerances(items: Sequence[str] | None) -> dict[str, float]:
    """--tolerance NAME=VALUE (um for positions, urad for orientations) -> native units (mm, rad)."""
    from ..history import unit_of

    out: dict[str, float] = {}
    for item in items or []:
        key, eq, val = item.partition("=")
        key = key.strip()
        if not eq:
            raise OptionError(
                f"--tolerance: {item[:40]!r}: give NAME=VALUE, e.g. E_Y0A=5 or position=5 (um), "
                "orientation=20 (urad)"
            )
        v = number(f"--tolerance {key}", 0.0, 1e6, "um or urad", lo_open=True)(val)
        unit = "mm" if key == "position" else "rad" if key == "orientation" else unit_of(key)
        out[key] = v * (1e-3 if unit == "mm" else 1e-6)
    return out


def _um(v: float | None, unit: str, signed: bool = True) -> str:
    if v is None:
        return "-"
    k = 1e3 if unit == "mm" else 1e6
    return f"{v * k:+.3f}" if signed else f"{v * k:.3f}"


def _print_flags(flags: list[dict], max_flags: int) -> None:
    print(
        f"{len(flags)} changes between consecutive calibrations beyond the k=2 uncertainty or the tolerance"
        + (":" if flags else "")
    )
    for f in flags[:max_flags]:
        limit = f"U {_um(f['expanded_uncertainty'], f['unit'], False)}" + (
            f", tolerance {_um(f['tolerance'], f['unit'], False)}"
            if f["tolerance"] is not None
            else ""
        )
        print(
            f"  {f['name']:6s} {f['from_at'][:10]} -> {f['to_at'][:10]}: {_um(f['change'], f['unit'])} "
            f"({limit}): {', '.join(f['why'])}"
        )
    if len(flags) > max_flags:
        print(f"  ... {len(flags) - max_flags} more (--json lists them all)")


def print_history(h: dict, max_flags: int = 20) -> None:
    from ..history import DRIFT_SPAN_WHY, MIN_DRIFT_SPAN_DAYS

    cal = h["calibrations"]
    span = f", {cal[0]['at'][:10]} .. {cal[-1]['at'][:10]}" if cal else ""
    print(
        f"machine {h['machine_id']} ({h['machine_type']}): {h['identifications']} identifications, "
        f"{len(h['corrections'])} corrections (controller changes){span}; store {h['store']}"
    )
    for (
        c
    ) in cal:  # the identifications, whatever their test (ballbar, rtest-joint, probe, multi, ...)
        print(
            f"  entry {c['entry']:<4d} {c['at']}  {c['test']:16s} {c['session'] or '-'}"
            + (f"  [{c['note']}]" if c["note"] else "")
        )
    print("values: the machine's own (measured + compensation loaded), um / urad")
    print(
        f"  {'error':6s} {'n':>5s} {'latest':>10s} {'1-sigma':>8s} {'drift/month':>11s} {'+-':>7s} {'chi2/dof':>8s}"
    )
    for name, e in h["location_errors"].items():
        if not e["points"]:
            print(f"  {name:6s} unobservable in every calibration")
            continue
        last = e["points"][-1]
        dr = e["drift_per_month"] or {}
        chi = dr.get("chi2_per_dof")
        print(
            f"  {name:6s} {len(e['points']):5d} {_um(last['value'], e['unit']):>10s} "
            f"{_um(last['std'], e['unit'], False):>8s} {_um(dr.get('value'), e['unit']):>11s} "
            f"{_um(dr.get('std'), e['unit'], False):>7s} {'-' if chi is None else f'{chi:.2f}':>8s}"
        )
    if any(
        len(e["points"]) >= 2 and e["drift_per_month"] is None
        for e in h["location_errors"].values()
    ):
        print(
            f"  drift '-': the calibrations span less than {MIN_DRIFT_SPAN_DAYS:g} days ({DRIFT_SPAN_WHY})"
        )
    for c in h["corrections"]:
        amounts = ", ".join(
            f"{n} {_um(v, 'mm' if n[2] in 'XYZ' else 'rad')}" for n, v in c["amounts"].items()
        )
        print(
            f"correction {c['at'][:10]} (entry {c['entry']}, {c['controller']}): {amounts}"
            + (f"  [{c['note']}]" if c["note"] else "")
        )
    _print_flags(h["flags"], max_flags)
    if h.get("thermal"):
        _print_thermal(h["thermal"])


def _print_thermal(thermal: dict) -> None:
    """The thermal tests' lags over time: tau (min) and each gain (um or urad per unit of heat
    input, u = speed / 100 rev/min), the latest value, its change from the test before and the
    drift per month."""
    print(
        "thermal tests: each lag's tau (min) and gains (um, urad per unit of u = speed / 100 rev/min)"
    )
    print(
        f"  {'parameter':14s} {'n':>3s} {'latest':>10s} {'1-sigma':>8s} {'change':>10s} "
        f"{'beyond k=2':>10s} {'drift/month':>11s}"
    )
    for name, e in thermal.items():
        if not e["points"]:
            print(f"  {name:14s} unobservable in every thermal test")
            continue
        k = 1 / 60 if e["unit"] == "s" else (1e3 if e["unit"] == "mm" else 1e6)

        def fmt(v, signed=True, k=k):
            return "-" if v is None else f"{v * k:+.3f}" if signed else f"{v * k:.3f}"

        last, dr = e["points"][-1], e["drift_per_month"] or {}
        beyond = "-" if "change" not in last else "yes" if last["exceeds_uncertainty"] else "no"
        print(
            f"  {name:14s} {len(e['points']):3d} {fmt(last['value']):>10s} "
            f"{fmt(last['std'], False):>8s} {fmt(last.get('change')):>10s} {beyond:>10s} "
            f"{fmt(dr.get('value')):>11s}"
        )


def store_identification(
    a: argparse.Namespace,
    model: dict,
    details: dict | None,
    where: str,
    controller: str | None = None,
    label: str = "",
) -> None:
    """--store, and history add: the model (a rotacal-model/1 dict) as an entry of --machine-id
    in the history at --db, with --note and --date; says where it went."""
    from ..history import open_history, redact

    with open_history(a.db) as h:
        entry = h.add_identification(
            a.machine_id,
            model,
            note=a.note,
            measured_at=a.date,
            details=details,
            controller=controller,
            where=where,
        )
        say(
            f"stored {label + ' ' if label else ''}as entry {entry} of machine {a.machine_id!r} "
            f"in {redact(h.location)}"
        )


def cmd_history_add(a: argparse.Namespace) -> int:
    from ..history import open_history, redact

    if (a.model is None) == (a.correction is None):
        raise OptionError(
            "history add: give a model file (an identification) or --correction EXPORT.json"
        )
    if a.correction is not None:
        if a.diagnosis or a.controller:
            raise OptionError(
                "history add --correction: --diagnosis and --controller belong to an identification"
            )
        export, sha = json_object(a.correction, "--correction")
        with open_history(a.db) as h:
            entry = h.add_correction(
                a.machine_id,
                export,
                applied_at=a.date,
                note=a.note,
                source_sha256=sha,
                where=a.correction,
            )
            say(
                f"stored correction {a.correction} as entry {entry} of machine {a.machine_id!r} in {redact(h.location)}"
            )
        return EXIT_OK
    from ..models import load_model

    model = load_model(a.model)
    details = None
    if a.diagnosis:
        diag, _ = json_object(a.diagnosis, "--diagnosis")
        if not isinstance(diag.get("findings"), list):
            raise _core.InvalidArgument(
                f"--diagnosis {a.diagnosis}: not the JSON of 'rotacal diagnose --json' (findings)"
            )
        details = {"diagnosis": diag}
    store_identification(a, model, details, a.model, controller_text(a.controller), a.model)
    return EXIT_OK


def cmd_history_show(a: argparse.Namespace) -> int:
    from ..history import open_history, write_plot

    tol = tolerances(a.tolerance)
    with open_history(a.db) as h:
        summary = h.show(a.machine_id, tol)
    if a.plot:
        write_plot(summary, a.plot)
        say(f"wrote {a.plot}")
    if a.json:
        print(jsontext.dumps(summary))
    else:
        print_history(summary)
    return EXIT_OK


def cmd_history_list(a: argparse.Namespace) -> int:
    from ..history import open_history, redact

    with open_history(a.db) as h:
        machines, where = h.machines(), redact(h.location)
    if a.json:
        print(jsontext.dumps({"store": where, "machines": machines}))
        return EXIT_OK
    print(f"{len(machines)} machines in {where}")
    for m in machines:
        print(
            f"  {m['machine_id']:24s} {m['machine_type']:7s} {m['identifications']:6d} identifications "
            f"{m['corrections']:4d} corrections  {(m['first'] or '')[:10]} .. {(m['last'] or '')[:10]}"
        )
    return EXIT_OK


def add_history(sub: argparse._SubParsersAction) -> argparse._SubParsersAction:
    q = sub.add_parser(
        "history",
        help="calibration history of physical machines: store, list, show drift",
        epilog=EPILOG + "; docs/history.md",
    )
    hs = q.add_subparsers(dest="action", required=True)
    k = hs.add_parser(
        "add",
        help="store an identification (model file) or a correction loaded into the controller",
        epilog=EPILOG,
    )
    k.add_argument(
        "model", nargs="?", type=path("MODEL"), help="model file (identify --save-model)"
    )
    k.add_argument(
        "--correction",
        metavar="EXPORT.json",
        type=path("--correction"),
        help="instead of a model: the JSON of 'rotacal export --json' that was loaded into the "
        "controller; later changes of the errors it holds are then not counted as drift",
    )
    k.add_argument(
        "--machine-id", required=True, help="the physical machine, e.g. its serial number"
    )
    k.add_argument("--note", help="operator note")
    k.add_argument(
        "--date",
        help="when it was measured (or the correction loaded), ISO 8601; default: the "
        "model's source.identified_at, else now",
    )
    k.add_argument(
        "--diagnosis",
        metavar="DIAG.json",
        type=path("--diagnosis"),
        help="the findings of 'rotacal diagnose --json' on the same session, stored with it",
    )
    k.add_argument(
        "--controller",
        metavar="CURRENT",
        type=path("--controller"),
        help="the controller parameters active during the test (HAL, MPF or JSON file)",
    )
    add_db_arg(k)
    k.set_defaults(func=cmd_history_add)
    k = hs.add_parser(
        "show",
        help="each location error over time: 1-sigma, corrections, drift per month, flags",
        epilog=EPILOG,
    )
    k.add_argument("machine_id", metavar="MACHINE_ID")
    k.add_argument(
        "--tolerance",
        action="append",
        metavar="NAME=VALUE",
        help="also flag a change between two calibrations larger than VALUE (um for positions, urad "
        "for orientations); NAME a location error, or position / orientation for all (repeatable)",
    )
    k.add_argument(
        "--plot",
        metavar="OUT.png|OUT.html",
        type=path("--plot"),
        help="write the history as figures",
    )
    k.add_argument("--json", action="store_true")
    add_db_arg(k)
    k.set_defaults(func=cmd_history_show)
    k = hs.add_parser("list", help="the machines in the store", epilog=EPILOG)
    k.add_argument("--json", action="store_true")
    add_db_arg(k)
    k.set_defaults(func=cmd_history_list)
    return hs


COMMANDS = {"history": add_history}
