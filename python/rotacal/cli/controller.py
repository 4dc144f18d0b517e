# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal export`` (the identified location errors as a controller's kinematic parameters,
LinuxCNC compensation tables, ISG sphere centres) and ``rotacal compensate`` (a compensated NC
program, and its verification in simulation)."""

from __future__ import annotations

import argparse
from types import SimpleNamespace

from .. import _core, jsontext
from ..outputs import write_output
from ..sessions import checked_path, load
from .options import EPILOG, EXIT_OK, OptionError, number, number_list, numbers, path, say
from .setups import add_setup_args, add_truth_args, ballbar_model, ballbar_setup, ballbar_truth


def _comp_file(text: str) -> tuple[str, str]:
    axis, sep, file = text.partition("=")
    if not sep or axis not in ("A", "B", "C") or not file:
        raise _core.InvalidArgument(f"--comp-file {text!r}: expected AXIS=FILE with AXIS A, B or C")
    return axis, checked_path(file, "--comp-file")


def _write_comp_files(a: argparse.Namespace, comp: dict[str, str]) -> object:
    """--comp-file AXIS=FILE: the axis' COMP_FILE of --tables (one writer, in C++), over
    --comp-range every --comp-step, written to FILE; the INI lines are printed."""
    import os

    from ..exports import controller_tables

    tabs = controller_tables(
        a.model,
        "linuxcnc",
        os.path.dirname(os.path.abspath(next(iter(comp.values())))),
        a.comp_step,
        {axis: list(a.comp_range) for axis in comp},
        file_names=comp,
    )
    written = {t.axis: t for t in tabs.tables}
    missing = [axis for axis in comp if axis not in written]
    if missing:
        raise _core.InvalidArgument(
            f"--comp-file {', '.join(missing)}: the model holds no positioning error of that "
            f"axis (tables: {', '.join(sorted(written)) or 'none'})"
        )
    for axis, file in comp.items():
        write_output(file, written[axis].text, inputs=[a.model])
        say(f"wrote {file}: {written[axis].summary}")
    # The [JOINT_n] blocks of the axes asked for.
    blocks = [("[" + b if k else b).rstrip("\n") for k, b in enumerate(tabs.ini.split("\n["))]
    wanted = [f"COMP_FILE = {written[axis].file_name}" for axis in comp]
    ini = "\n".join(b for b in blocks if any(w in b for w in wanted))
    say("the INI lines that load them:\n" + ini)
    return SimpleNamespace(tables=[written[axis] for axis in comp])  # what --residual-model zeroes


def cmd_export_realtime(a: argparse.Namespace) -> int:
    """export --controller realtime: the whole model as the blob a controller's real-time path
    loads (include/rotacal/realtime/blob.hpp), binary, so -o is required."""
    given = [
        o
        for o, v in (
            ("--current", a.current),
            ("--residual-model", a.residual_model),
            ("--centres", a.centres),
            ("--comp-file", a.comp_file),
            ("--json", a.json),
            ("--tables", a.tables),
            ("--at/--state", a.at is not None or a.state is not None),
            ("--thermal-chain", a.thermal_chain),
        )
        if v
    ]
    if given:
        raise _core.InvalidArgument(f"{', '.join(given)}: not with --controller realtime")
    if not a.output:
        raise _core.InvalidArgument("--controller realtime writes a binary blob: give -o FILE")
    from ..realtime import is_thermal_model

    thermal = is_thermal_model(a.model)
    model = _core.realtime_model_of_file(a.model, thermal=thermal)
    write_output(a.output, model.blob(), inputs=[a.model])
    say(
        f"wrote {a.output}: the real-time model blob ({model.num_effects} effects, every location "
        f"error{', the cold ones and their thermal gains' if thermal else ''}; machine "
        f"fingerprint {model.fingerprint:016x}); docs/realtime.md"
    )
    return EXIT_OK


def _table_range(text: str) -> tuple[str, list[float]]:
    axis, sep, rng = text.partition("=")
    parts = rng.split(",")
    try:
        lo, hi = (float(v.strip().removesuffix("deg")) for v in parts) if len(parts) == 2 else ()
    except ValueError:
        lo = hi = float("nan")
    if not sep or axis not in ("A", "B", "C") or not (lo < hi):
        raise _core.InvalidArgument(
            f"--table-range {text!r}: expected AXIS=LO,HI in deg, AXIS A, B or C, LO < HI"
        )
    return axis, [lo, hi]


def _spacing(text: str) -> float:
    try:
        v = float(text.strip().removesuffix("deg").strip())
    except ValueError:
        v = float("nan")
    if not (0.001 <= v <= 90.0):
        raise _core.InvalidArgument(f"--spacing {text!r}: a number of deg, 0.001 to 90 (5deg)")
    return v


def _isg_axis(text: str) -> tuple[str, int]:
    axis, sep, number_text = text.partition("=")
    if not sep or axis not in ("X", "Y", "Z", "A", "B", "C") or not number_text.isdigit():
        raise _core.InvalidArgument(
            f"--isg-axis {text!r}: expected AXIS=N, AXIS X, Y, Z, A, B or C, N its logical number"
        )
    return axis, int(number_text)


def _write_tables(a: argparse.Namespace) -> object:
    import os

    from ..exports import controller_tables

    directory = a.tables_dir or (os.path.dirname(os.fspath(a.output)) if a.output else ".")
    ranges = dict(_table_range(t) for t in a.table_range or [])
    names = {}
    for text in a.siemens_axis or []:
        axis, sep, name = text.partition("=")
        if not sep or axis not in ("A", "B", "C", "X", "Y", "Z"):
            raise _core.InvalidArgument(
                f"--siemens-axis {text!r}: expected AXIS=NAME, AXIS A, B, C, X, Y or Z"
            )
        names[axis] = name
    fanuc = {
        k: v
        for k, v in (
            ("detection_unit_deg", a.fanuc_unit),
            ("first_number", a.fanuc_first_number),
            ("last_number", a.fanuc_last_number),
            ("max_value", a.fanuc_max_value),
            ("magnification", a.fanuc_magnification),
        )
        if v is not None
    }
    tabs = controller_tables(
        a.model,
        a.controller,
        directory,
        _spacing(a.spacing),
        ranges,
        names,
        a.max_points or 0,
        fanuc=fanuc,
        max_cross_points=a.max_cross_points or 0,
        isg_axis_numbers=dict(_isg_axis(t) for t in a.isg_axis or []),
    )
    for t in tabs.tables:
        out = os.path.join(os.path.abspath(directory), os.path.basename(t.file_name))
        write_output(out, t.text, inputs=[a.model])
        say(f"wrote {out}: {t.summary}")
    if tabs.ini:
        ini = os.path.join(os.path.abspath(directory), "comp_tables.ini")
        write_output(ini, tabs.ini, inputs=[a.model])
        say(f"wrote {ini}: the [JOINT_n] lines that load them")
    for n in tabs.not_held:
        say(f"not in a table: {n}; left to rotacal compensate")
    return tabs


def cmd_export(a: argparse.Namespace) -> int:
    if a.controller == "realtime":
        return cmd_export_realtime(a)
    if a.thermal_chain or a.thermal_predictor:
        from . import export_chain

        return export_chain.cmd_predictor(a) if a.thermal_predictor else export_chain.cmd(a)
    from ..exports import export_controller, export_dict, residual_model
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
    thermal = {"thermal_at_s": a.at, "thermal_state": a.state}  # a thermal model's lag state
    if (a.at is not None or a.state is not None) and (a.residual_model or a.tables or comp):
        raise _core.InvalidArgument(
            "--at/--state: the parameters at that state only (no --residual-model, --tables, "
            "--comp-file)"
        )
    ex = export_controller(
        a.model, a.controller, current=a.current, toolholder=a.toolholder, **thermal
    )
    if comp and a.tables:
        raise _core.InvalidArgument("--comp-file and --tables: give one of them")
    tabs = _write_tables(a) if a.tables else (_write_comp_files(a, comp) if comp else None)
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
    if a.residual_model:
        save_model(
            residual_model(load_model(a.model), ex, tabs),
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


def _add_table_args(q: argparse.ArgumentParser) -> None:
    """export --tables and its options."""
    q.add_argument(
        "--tables",
        action="store_true",
        help="also write each table axis' positioning error as the controller's table: linuxcnc "
        "[JOINT_n]COMP_FILE (type 1) and the INI lines (comp_tables.ini); siemens EEC "
        "($AA_ENC_COMP) programs eec_<axis>.mpf and, for the axes' translations, CEC ($AN_CEC) "
        "programs cec_<axis>.mpf; isg kw.ssfk lists ssfk_<axis>.lis and kw.crosscomp lists "
        "crosscomp_<X|Y|Z>.lis; fanuc pitch error compensation data "
        "pitch_<axis>.txt (parameters 3620-3625, values by data number)",
    )
    q.add_argument(
        "--spacing", default="5deg", help="--tables: between table points (default 5deg)"
    )
    q.add_argument(
        "--table-range",
        action="append",
        metavar="AXIS=LO,HI",
        help="--tables: the angles a table spans, deg (default: the axis' limits, an endless "
        "axis -360,360); a continuously turning C needs what the program turns through",
    )
    q.add_argument(
        "--siemens-axis",
        action="append",
        metavar="AXIS=NAME",
        help="--tables, siemens: the machine axis identifier of AXIS, a rotary or (CEC outputs) "
        "a linear axis (MD10000; default C1, B1, A1, X1, Y1, Z1)",
    )
    q.add_argument(
        "--max-points",
        type=number("--max-points", 2, 100000, integer=True),
        help="--tables: the most points a table may hold (default: linuxcnc 256, siemens 200, "
        "MD38000 as configured; isg 1500, kw_nr_max)",
    )
    q.add_argument(
        "--isg-axis",
        action="append",
        metavar="AXIS=N",
        help="--tables, isg: the logical axis number of AXIS (default X 1, Y 2, Z 3, A 4, B 5, C 6)",
    )
    q.add_argument(
        "--max-cross-points",
        type=number("--max-cross-points", 2, 100000, integer=True),
        help="--tables: the most points a cross table may hold (default: siemens 200, "
        "MD18342 as configured; isg 1000, kw.crosscomp)",
    )
    q.add_argument(
        "--tables-dir",
        type=path("--tables-dir"),
        help="--tables: the folder of the tables (default: that of -o, else the current one)",
    )
    fanuc = q.add_argument_group("--tables with --controller fanuc (pitch error compensation)")
    for option, lo, hi, whole, what in (
        ("--fanuc-unit", 1e-6, 1.0, False, "the rotary axes' detection unit, deg (default 0.001)"),
        ("--fanuc-first-number", 0, 1e5, True, "the first data number of the first table (0)"),
        ("--fanuc-last-number", 0, 1e5, True, "the control's highest data number (1023, a 0i's)"),
        ("--fanuc-max-value", 1, 1e6, True, "the largest absolute value of one data number (127)"),
        ("--fanuc-magnification", 1, 100, True, "parameter 3623 (default: the smallest that fits)"),
    ):
        fanuc.add_argument(option, type=number(option, lo, hi, integer=whole), help=what)


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
        "--controller",
        required=True,
        choices=["linuxcnc", "siemens", "isg", "heidenhain", "fanuc", "realtime"],
        help="realtime: the whole model (location errors and every effect) as the blob of the "
        "real-time evaluation (docs/realtime.md)",
    )
    q.add_argument(
        "--current",
        type=path("--current"),
        help="the controller's values active during the test: its HAL file (linuxcnc), MPF (siemens) "
        'or JSON {"controller": ..., "parameters": {...}}; default: zero offsets',
    )
    from .thermal import duration

    q.add_argument(
        "--at",
        type=duration("--at"),
        help="a thermal model (docs/thermal.md): the errors after this time of the test's duty "
        "from its first row, e.g. 2h",
    )
    q.add_argument(
        "--state",
        type=number_list("--state", 0.0, 1000.0, most=2),
        help="a thermal model: the errors at these lag states y1[,y2] (0: cold; 3: steady "
        "state at 300 rev/min)",
    )
    from . import export_chain

    export_chain.add_options(q)
    export_chain.add_predictor_options(q)
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
        help="linuxcnc: the axis' positioning error as a [JOINT_n]COMP_FILE (type 1, as --tables "
        "writes it) over --comp-range every --comp-step, written to FILE; may be repeated",
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
    _add_table_args(q)
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
