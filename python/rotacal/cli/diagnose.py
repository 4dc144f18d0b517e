# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal diagnose`` (what the model gets wrong and why) and ``rotacal report`` (the HTML
report of a session, rotary-axis test or ISO 230-4 circular tests)."""

from __future__ import annotations

import argparse
from pathlib import Path

from .. import _core, jsontext, units
from ..diagnosis import MAX_HARMONIC, group_text, model_text
from .options import EPILOG, EXIT_OK, budget_sizes, number, path, say
from .setups import add_db_arg, add_plausibility_arg, load_session


def print_diagnosis(d: dict) -> None:
    b = d["baseline"]
    print(
        f"baseline: residual RMS {b['residual_rms_um']:.3f} um, noise {b['noise_um']:.3f} um "
        f"({b['noise_source']}), chi2/dof {b['chi2_per_dof']:.2f}"
    )
    if not d["findings"]:
        print("no effect of the catalogue is significant")
    for i, f in enumerate(d["findings"], 1):
        g = f["gain"]
        if f["named"]:
            print(f"{i}. {f['effect']} (weight {f['weight']:.2f}): {f['cause']}")
        elif f.get("lack_of_fit"):
            print(
                f"{i}. not named, {f['effect']} (weight {f['weight']:.2g}): {f['lack_of_fit']}. If it is {f['effect']}:"
            )
        else:
            print(
                f"{i}. one of: {group_text(f)}; this session cannot separate them (BIC weights). "
                f"If it is {f['effect']}:"
            )
        print(f"     {model_text(f)}")
        for name, p in f["parameters"].items():
            print(f"     {name} = {units.estimate_text(p['value'], p['std'], p['unit'])}")
        print(
            f"     RMS {g['rms_before_um']:.3f} -> {g['rms_after_um']:.3f} um, delta BIC {g['delta_bic']:.1f}, "
            f"CV RMS {g['cv_rms_before_um']:.3f} -> {g['cv_rms_after_um']:.3f} um"
        )
        for r in f["rivals"]:
            if not r["in_group"]:
                print(
                    f"     rather than {r['effect']}: that fits worse by delta BIC {r['delta_bic']:.1f} "
                    f"(weight {r['weight']:.2g})"
                )
    for amb in d["ambiguous"]:
        print(
            f"cannot be told apart with this data: {', '.join(amb['effects'])} ({amb['separating_test']})"
        )
    if d["unexplained"]["present"]:
        print(f"unexplained structure remains: {d['unexplained']['signature']}")
        ns = d["unexplained"].get("noise_structure")
        if ns:
            where = (
                f"{d['unexplained']['axis']} {ns['at']:.4g} deg"
                if d["unexplained"]["axis"]
                else f"t {ns['at']:.4g} s"
            )
            source = (
                "its quiet channels" if ns["f_test_p"] < 1.0 else "the noise model's innovations"
            )
            print(
                f"     the instrument's noise is {ns['noise_um']:.2g} um ({source}): "
                f"the {ns['size_um']:.2g} um at {where} are structure, not noise"
            )
    print(
        f"{len(d['unobservable'])} catalogue entries are invisible to this session's tests "
        "(--json lists them with reasons)"
    )


def _diagnosis_progress(a: argparse.Namespace):
    """A progress bar for a diagnosis that takes more than a second (a long recording), one
    fill per search round, and its callback; (None, None) with --no-progress."""
    from ..progress import ProgressBar

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
    """One session, or several of one machine diagnosed together (diagnose/multi_session.hpp,
    issue 50): the same diagnosis and the same printout, several adding each session's lines."""
    from ..diagnosis import diagnose, uncertainty_budget
    from ..multi_diagnosis import print_several

    several = len(a.file) > 1
    if several and (a.report or a.budget_sizes):
        raise _core.InvalidArgument(
            "diagnose: --report and --budget-sizes are of one session; several sessions are "
            "diagnosed to the terminal or --json"
        )
    sizes = None if several else budget_sizes(a.budget_sizes)  # refused before any work
    sessions = [load_session(f, a, several=several) for f in a.file]
    stems = [Path(f).stem for f in a.file]
    if not several:
        what = sessions[0]
    elif len(set(stems)) == len(stems):  # each session's own effects named STEM:effect
        what = list(zip(stems, sessions))
    else:
        what = sessions
    bar, progress = _diagnosis_progress(a)
    try:
        result = diagnose(
            what, max_harmonic=a.max_harmonic, hold_by_weight=a.hold_by_weight, progress=progress
        )
    finally:
        if bar:
            bar.close()
    if not several and not a.no_budget:  # what left-out effects could put on each location error
        result.budget = uncertainty_budget(what, result, sizes=sizes)
    d = result.to_dict()
    thermal = not several and _core.is_thermal_session(a.file[0])
    if thermal:  # the drift's own test beside the pooled diagnosis (cli/thermal.py)
        from .thermal import thermal_finding

        d["thermal"] = thermal_finding(a.file[0])
    if a.report:
        from ..analysis import write_diagnosis_report

        write_diagnosis_report(a.report, what, result, source=a.file[0], inputs=[a.file[0]])
        say(f"wrote {a.report}")
    if a.json:
        print(jsontext.dumps(d))
    else:
        print_diagnosis(d)
        if thermal:
            from .thermal import print_thermal_finding

            print_thermal_finding(d["thermal"])
        if several:
            print_several(d)
    return EXIT_OK


def _joint_report(a: argparse.Namespace, extra: list, history: dict | None) -> int:
    from ..analysis import write_joint_report

    if a.method != "joint":
        raise _core.InvalidArgument(
            "report: several sessions are reported by their joint fit (--method joint)"
        )
    sessions = [load_session(f, a) for f in a.file]
    if history is not None and history["machine_type"] != _core.machine_name(sessions[0].machine):
        raise _core.InvalidArgument(
            f"--history {a.history}: a {history['machine_type']} in the store, but the "
            f"sessions are of a {_core.machine_name(sessions[0].machine)}: not the same machine"
        )
    out = write_joint_report(
        a.output,
        sessions,
        list(a.file),
        source=", ".join(a.file),
        inputs=list(a.file),
        extra_sections=extra,
    )
    print(Path(out).resolve())
    return EXIT_OK


def cmd_report(a: argparse.Namespace) -> int:
    from ..analysis import write_report

    extra, history = [], None
    if a.history:
        from ..history import history_section, open_history

        with open_history(a.db) as h:  # an unknown machine id is refused before the fit
            history = h.show(a.history)
        extra.append(history_section(history))
    if len(a.file) == 1 and _core.is_thermal_session(a.file[0]):
        from ..report.thermal import thermal_report

        if a.controller:
            raise _core.InvalidArgument("report --controller: export a thermal model --at a time")
        out = thermal_report(a.output, a.file[0], inputs=a.file, extra_sections=extra)
        print(Path(out).resolve())
        return EXIT_OK
    if len(a.file) > 1:  # one identification from several sessions of one machine
        if a.controller:
            raise _core.InvalidArgument("report --controller: one session (export the joint model)")
        return _joint_report(a, extra, history)
    a.file = a.file[0]
    s = load_session(a.file, a, circular_tests=True)
    if history is not None and history["machine_type"] != _core.machine_name(s.machine):
        raise _core.InvalidArgument(
            f"--history {a.history}: a {history['machine_type']} in the store, but {a.file} "
            f"is a session of a {_core.machine_name(s.machine)}: not the same machine"
        )
    from ..circular import analyze as analyze_circular, is_circular

    if is_circular(s):  # ISO 230-4 runs of the linear axes: their own report
        from ..report import circular_report

        out = circular_report(
            a.output,
            analyze_circular(s, diagnose=not a.no_diagnosis, source=a.file),
            source=a.file,
            inputs=[a.file],
            extra_sections=extra,
        )
    else:
        out = write_report(
            a.output,
            s,
            a.method,
            with_diagnosis=not a.no_diagnosis,
            source=a.file,
            inputs=[a.file],
            extra_sections=extra,
            controller=a.controller,
        )
    print(Path(out).resolve())
    return EXIT_OK


def add_diagnose(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser("diagnose", help="find what the model gets wrong and why", epilog=EPILOG)
    q.add_argument(
        "file",
        type=path("FILE"),
        nargs="+",
        help="a session; several (ballbar, R-test, touch probe) of one machine are diagnosed "
        "together: machine effects shared, each session's own named NAME:effect (NAME: its file's stem)",
    )
    q.add_argument(
        "--max-harmonic",
        type=number("--max-harmonic", 1, MAX_HARMONIC, integer=True),
        help=f"highest harmonic order tried (1..{MAX_HARMONIC}; default {_core.DiagnosisOptions().max_harmonic})",
    )
    q.add_argument(
        "--hold-by-weight",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the extended model holds each group's member of the highest weight with a "
        "determined parameter (a nested one within delta BIC 2), not the search's pick "
        f"(default: {'on' if _core.DiagnosisOptions().hold_by_weight else 'off'} for one session, "
        "off for several)",
    )
    q.add_argument("--json", action="store_true")
    q.add_argument("--report", metavar="OUT.html", type=path("--report"))
    q.add_argument(
        "--budget-sizes",
        metavar="SIZES.json",
        type=path("--budget-sizes"),
        help="plausible sizes of left-out effects for the uncertainty budget (docs/json_schema.md)",
    )
    q.add_argument("--no-budget", action="store_true", help="skip the uncertainty budget")
    q.add_argument(
        "--no-progress", action="store_true", help="no progress bar (drawn after 1 s of work)"
    )
    add_plausibility_arg(q)
    q.set_defaults(func=cmd_diagnose)


def add_report(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "report",
        help="self-contained HTML report of a session, or of the joint identification of "
        "several sessions of one machine",
        epilog=EPILOG,
    )
    q.add_argument(
        "file",
        type=path("FILE"),
        nargs="+",
        help="a session; several (ballbar, R-test, touch probe) of one machine are reported jointly",
    )
    q.add_argument("--method", default="joint", choices=["joint", "paper"])
    q.add_argument("--no-diagnosis", action="store_true")
    q.add_argument(
        "--history",
        metavar="MACHINE_ID",
        help="add the machine's calibration history (rotacal history show) as plots and flags",
    )
    add_db_arg(q)
    q.add_argument(
        "--controller",
        choices=["linuxcnc", "siemens", "isg", "heidenhain", "fanuc"],
        help="add what this controller's export and tables correct and what remains (one session)",
    )
    q.add_argument("-o", "--output", required=True, type=path("--output"))
    add_plausibility_arg(q)
    q.set_defaults(func=cmd_report)


COMMANDS = {"diagnose": add_diagnose, "report": add_report}
