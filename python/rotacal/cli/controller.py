"""``rotacal export`` (the identified location errors as a controller's kinematic parameters,
LinuxCNC compensation tables, ISG sphere centres) and ``rotacal compensate`` (a compensated NC
program, and its verification in simulation)."""

from __future__ import annotations

import argparse

from .. import _core, jsontext
from ..outputs import write_output
from ..sessions import checked_path, load
from .options import EPILOG, EXIT_OK, OptionError, number, numbers, path, say
from .setups import add_setup_args, add_truth_args, ballbar_model, ballbar_setup, ballbar_truth


def _comp_file(text: str) -> tuple[str, str]:
    axis, sep, file = text.partition("=")
    if not sep or axis not in ("B", "C") or not file:
        raise _core.InvalidArgument(f"--comp-file {text!r}: expected AXIS=FILE with AXIS B or C")
    return axis, checked_path(file, "--comp-file")


def cmd_export(a: argparse.Namespace) -> int:
    from ..exports import export_controller, export_dict, linuxcnc_comp_table, residual_model
    from ..models import load_model, save_model

    comp = dict(_comp_file(c) for c in a.comp_file or [])
    if comp and a.controller != "linuxcnc":
        raise _core.InvalidArgument(
            "--comp-file: rotary compensation tables are written for linuxcnc"
        )
    if bool(a.centres) != bool(a.centres_output) or (a.centres and a.controller != "isg"):
        raise _core.InvalidArgument(
            "--centres and --centres-output go together, with --controller isg"
        )
    ex = export_controller(a.model, a.controller, current=a.current, toolholder=a.toolholder)
    tables = {
        axis: linuxcnc_comp_table(load_model(a.model), axis, *a.comp_range, a.comp_step)
        for axis in comp
    }
    if a.centres:
        from ..exports import isg_sphere_centres
        from ..models import file_sha256

        text, what = isg_sphere_centres(
            load(a.centres),
            load_model(a.model),
            a.centres_setup,
            (int(a.isg_kinematic[0]), int(a.isg_kinematic[1])),
            a.centres_origin,
            session_sha256=file_sha256(a.centres),
        )
        write_output(
            a.centres_output, text, inputs=[p for p in (a.model, a.current, a.centres) if p]
        )
        say(f"wrote {a.centres_output}: {what}")
    for axis, (text, what) in tables.items():
        write_output(comp[axis], text, inputs=[p for p in (a.model, a.current) if p])
        say(f"wrote {comp[axis]}: {what}")
    if a.residual_model:
        save_model(
            residual_model(load_model(a.model), ex),
            a.residual_model,
            inputs=[a.model],
            other_outputs=[a.output] if a.output else [],
        )
        say(
            f"wrote {a.residual_model}: the errors {ex.controller} cannot hold, for rotacal compensate --model"
        )
    held = [e.name for e in ex.errors if e.held]
    left = [e.name for e in ex.errors if not e.held]
    if a.output:
        write_output(a.output, ex.text, inputs=[p for p in (a.model, a.current) if p])
        say(f"wrote {a.output} ({ex.file_kind} for {ex.kinematics})")
    # The model's effects: which member of a diagnosis' group each is, and why (issue 50), so
    # that what is loaded into the controller says what model its values come from.
    effects = [
        {"id": e["id"], "held_because": e.get("held_because")}
        for e in load_model(a.model).get("effects", [])
    ]
    if a.json:
        print(jsontext.dumps(export_dict(ex) | {"model_effects": effects}))
    elif not a.output:
        print(ex.text, end="")
    for e in effects:
        say(
            f"the values come from a model with {e['id']}"
            + (f": it holds it because {e['held_because']}" if e["held_because"] else "")
        )
    say(
        f"held: {', '.join(held) or 'none'}; not held: {', '.join(left) or 'none'}"
        + (
            ""
            if ex.current_given
            else "; no --current: zero offsets assumed, the values are the corrections"
        )
    )
    return EXIT_OK


def _print_compensation(rows: list[dict]) -> None:
    print("error    uncompensated   compensated    change   (Flynn et al. Table 2 layout)")
    for r in rows:
        k, unit = (1e3, "um") if r["unit"] == "mm" else (1e6, "urad")
        print(
            f"{r['name']:6s} {r['before'] * k:+12.3f} {r['after'] * k:+12.3f} {unit:4s} {r['change_percent']:+8.1f} %"
        )


def cmd_compensate(a: argparse.Namespace) -> int:
    if not a.model and not a.verify:
        raise OptionError("compensate: give --model MODEL.json (write a program) and/or --verify")
    setup = ballbar_setup(a)
    from ..ballbar import nc_program, verify_compensation

    if a.model:
        _, text = nc_program(setup, a.dialect, ballbar_model(a.model), a.model)
        write_output(a.output, text, [a.model])
        say(f"wrote {a.output}: compensated {a.dialect} program")
    if a.verify:
        truth = ballbar_truth(a, setup)
        say("measuring, identifying, compensating and measuring again on the simulated machine ...")
        rows = verify_compensation(setup, truth)
        if a.json:
            print(jsontext.dumps(rows))
        else:
            _print_compensation(rows)
    return EXIT_OK


def add_export(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "export",
        help="write the identified location errors into a controller's kinematic parameters",
        epilog=EPILOG + "; the mapping field by field: docs/controller_exports.md",
    )
    q.add_argument(
        "--model", required=True, type=path("--model"), help="model file (identify --save-model)"
    )
    q.add_argument(
        "--controller", required=True, choices=["linuxcnc", "siemens", "isg", "heidenhain", "fanuc"]
    )
    q.add_argument(
        "--current",
        type=path("--current"),
        help="the controller's values active during the test: its HAL file (linuxcnc), MPF (siemens) "
        'or JSON {"controller": ..., "parameters": {...}}; default: zero offsets',
    )
    q.add_argument(
        "--toolholder",
        type=number("--toolholder", 1, 99, integer=True),
        default=1,
        help="siemens: the $TC_CARR data set (default 1)",
    )
    q.add_argument(
        "-o",
        "--output",
        type=path("--output"),
        help="write the controller file here (default: print it)",
    )
    q.add_argument(
        "--residual-model",
        type=path("--residual-model"),
        help="write a model of the errors the controller cannot hold (held ones zero), for compensate",
    )
    q.add_argument(
        "--centres",
        metavar="RTEST.csv",
        type=path("--centres"),
        help="isg: the R-test session the model was fitted to; its measured sphere centres are written "
        "for the ISG kinematic optimisation (SysCalibFitAddRecord.ecy) to --centres-output",
    )
    q.add_argument(
        "--centres-output", type=path("--centres-output"), help="isg: the NC program of the centres"
    )
    q.add_argument(
        "--centres-setup",
        help="isg: the set-up (nest) whose centres are written (default: the first)",
    )
    q.add_argument(
        "--centres-origin",
        type=numbers("--centres-origin", 3, 1e5, "mm"),
        default=[0.0, 0.0, 0.0],
        help="isg: the rotary axes' intersection in the controller's machine coordinates, mm",
    )
    q.add_argument(
        "--isg-kinematic",
        type=numbers("--isg-kinematic", 2, 1e4),
        default=[80.0, 0.0],
        help="isg: kinematic type and variant for SysCalibFitInit.ecy (default 80,0 as TF5245's example; "
        "use your machine's)",
    )
    q.add_argument(
        "--comp-file",
        action="append",
        metavar="AXIS=FILE",
        help="linuxcnc, R-test map of a BC-trt: the axis' positioning error as a [JOINT_n]COMP_FILE "
        "(type 0) table; AXIS B or C (C needs the map's gamma terms); may be repeated",
    )
    q.add_argument(
        "--comp-range",
        type=numbers("--comp-range", 2, 720.0, "deg"),
        default=[-90.0, 90.0],
        help="angles of the table, deg (default -90,90; C: e.g. 0,360)",
    )
    q.add_argument(
        "--comp-step",
        type=number("--comp-step", 0.01, 90.0, "deg"),
        default=1.0,
        help="step of the table, deg (default 1; LinuxCNC reads at most 256 lines)",
    )
    q.add_argument(
        "--json", action="store_true", help="print the parameters and the errors held as JSON"
    )
    q.set_defaults(func=cmd_export)


def add_compensate(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "compensate",
        help="compensated NC program, and its verification in simulation",
        epilog=EPILOG,
    )
    add_setup_args(q)
    add_truth_args(q)
    q.add_argument(
        "--model", metavar="MODEL.json", type=path("--model"), help="fitted model to compensate"
    )
    q.add_argument("--dialect", default="linuxcnc")
    q.add_argument("-o", "--output", default="compensated.ngc", type=path("--output"))
    q.add_argument(
        "--verify",
        action="store_true",
        help="measure, identify, compensate and measure again on a simulated machine (--errors ...)",
    )
    q.add_argument("--json", action="store_true")
    q.set_defaults(func=cmd_compensate)


COMMANDS = {"export": add_export, "compensate": add_compensate}
