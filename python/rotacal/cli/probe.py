# SPDX-License-Identifier: BSD-3-Clause
"""The touch probe on a sphere on the command line (issue 31): ``rotacal simulate probe``, and
what ``rotacal identify`` does with a rotacal-probe/1 session (``rotacal diagnose`` takes it as
it is). C++ computes (include/rotacal/probe, rotacal.probe); this module only composes."""

from __future__ import annotations

import argparse

import numpy as np

from .. import _core, probe, units
from ..machines import PIVOT_ERROR_MM, location_errors, load_machine
from ..sessions import save
from .options import EPILOG, EXIT_OK, SEED, OptionError, number, numbers, path, say
from .options import effects_option, errors_option
from .probe_poses import design_file, poses_option
from .setups import write_truth

# The sphere and stylus of the simulator's default pattern (probe/simulate.hpp, rotacal.simulate_probe).
DEFAULT_SPHERE = (150.0, 0.0, 80.0)
DEFAULT_SPHERE_DIAMETER = 25.0
DEFAULT_STYLUS_DIAMETER = 6.0
DEFAULT_NOISE_UM = 0.5
DEFAULT_LOG_FILE = "rotacal_probe.log"
DEFAULT_APPROACH_MM = 5.0  # probe/nc_program.hpp ProbeProgramOptions
DEFAULT_PROBE_FEED = 50.0  # mm/min, likewise
DEFAULT_POSITIONING_FEED = 1000.0  # mm/min, likewise

# What a touch-probe identification cannot do, refused before the fit.
NO_CYCLES_MODEL = (
    "--save-model/--store: the model file holds a fit with its uncertainties and covariance; the "
    "cycles' method gives none (identify with --method joint, the default)"
)


# ------------------------------------------------------------------------- simulate probe


def _truth(a: argparse.Namespace) -> tuple[dict, dict]:
    """(simulation inputs, truth document) of `simulate probe`: one generator from --seed draws
    random errors first, then the sphere's set-up error, as the ballbar's truth does."""
    from ..machines import effect_parameters

    mtype = load_machine(a.machine)
    rng = np.random.default_rng(a.seed)
    e = location_errors(errors_option(a.errors), mtype, rng)
    offset = rng.normal(0.0, a.sphere_error, 3)
    ids, params, values = effect_parameters(effects_option(a.effect))
    sphere = np.asarray(a.sphere if a.sphere is not None else DEFAULT_SPHERE, float)
    inputs = {
        "machine": mtype,
        "errors": e,
        "ids": ids,
        "params": params,
        "offset": offset,
        "sphere": sphere,
    }
    truth = {
        "machine": _core.machine_name(mtype),
        "errors": dict(zip(_core.location_error_names(mtype), e.tolist())),
        "effects": {k: (v[0] if len(v) == 1 else v) for k, v in values.items()},
        "sphere_nominal": sphere.tolist(),
        "sphere_error": offset.tolist(),
        "sphere_diameter": a.sphere_diameter,
        "stylus_diameter": a.stylus_diameter,
        "noise_um": a.noise,
        "rho": a.rho,
        "seed": a.seed,
    }
    return inputs, truth


def cmd_simulate_probe(a: argparse.Namespace) -> int:
    x, truth = _truth(a)
    mtype = x["machine"]
    session, actual = _core.simulate_probe(
        mtype,
        x["errors"],
        x["ids"],
        x["params"],
        x["offset"],
        a.noise,
        a.rho,
        a.seed,
        None,
        None,
        x["sphere"],
        a.sphere_diameter,
        a.stylus_diameter,
    )
    truth["sphere_actual"] = np.asarray(actual, float).ravel().tolist()
    save(session, a.output, other_outputs=[a.truth])
    if a.truth:
        write_truth(truth, a.truth, [a.output])
    say(
        f"wrote {a.output}: {len(session)} touches at {len(session.pose_names)} poses on a simulated "
        f"{_core.machine_name(mtype)}" + (f", truth in {a.truth}" if a.truth else "")
    )
    return EXIT_OK


def add_sphere_args(g) -> None:
    """The artefact: nominal sphere centre, sphere and stylus diameters (simulate and plan probe)."""
    g.add_argument(
        "--sphere",
        type=numbers("--sphere", 3, 1e4, "mm"),
        metavar="X,Y,Z",
        help=f"nominal sphere centre, table frame, mm (default {','.join(f'{v:g}' for v in DEFAULT_SPHERE)})",
    )
    g.add_argument(
        "--sphere-diameter",
        type=number("--sphere-diameter", 1.0, 500.0, "mm"),
        default=DEFAULT_SPHERE_DIAMETER,
        help="calibrated sphere diameter D, mm",
    )
    g.add_argument(
        "--stylus-diameter",
        type=number("--stylus-diameter", 0.1, 100.0, "mm"),
        default=DEFAULT_STYLUS_DIAMETER,
        help="calibrated stylus ball diameter d, mm",
    )


def add_simulate_probe(kinds: argparse._SubParsersAction) -> None:
    k = kinds.add_parser(
        "probe",
        help="touches of a spindle probe on a calibration sphere (the controller cycles' "
        "test; ../shared/spec/formats.md rotacal-probe/1)",
        epilog=EPILOG,
    )
    g = k.add_argument_group("set-up (the default poses and touch directions of the simulator)")
    g.add_argument(
        "--machine",
        default="AC-trt",
        type=path("--machine"),
        metavar="NAME|FILE",
        help="a built-in (`rotacal machines`) or a rotacal-machine/1 description file (default AC-trt)",
    )
    add_sphere_args(g)
    g = k.add_argument_group("simulated machine")
    g.add_argument(
        "--errors",
        default="random",
        help="location errors: random (seeded), table2 (Flynn et al.), zero, or NAME=VALUE,... (mm, rad)",
    )
    g.add_argument(
        "--effect",
        action="append",
        metavar="ID=P1,P2",
        help="a catalogue effect, e.g. gravity_sag_A=0.004, stylus_radius_offset=0.0015 or "
        "probe_lobing=0.001,0 (repeatable)",
    )
    g.add_argument(
        "--sphere-error",
        type=number("--sphere-error", 0.0, 10.0, "mm"),
        default=PIVOT_ERROR_MM,
        help="1-sigma set-up error of the sphere centre per axis, mm",
    )
    g.add_argument(
        "--noise",
        type=number("--noise", 0.0, 1000.0, "um"),
        default=DEFAULT_NOISE_UM,
        help="1-sigma noise per latched coordinate, um",
    )
    g.add_argument(
        "--rho",
        type=number("--rho", 0.0, 0.999),
        default=0.0,
        help="AR(1) coefficient of the noise from touch to touch (0: white)",
    )
    g.add_argument("--seed", type=SEED, default=1)
    k.add_argument(
        "--truth", metavar="JSON", type=path("--truth"), help="write the simulated machine here"
    )
    k.add_argument("-o", "--output", required=True, type=path("--output"))
    k.set_defaults(func=cmd_simulate_probe)


# ------------------------------------------------------------------------- identify a probe session


def print_probe_identification(d: dict) -> None:
    """The lines of a touch-probe fit (`rotacal identify` adds its noise model and budget)."""

    def value(v: float, unit: str) -> str:
        factor, shown = units.shown(unit)
        return f"{v * factor:+9.3f} {shown:4s}"

    print(
        f"{d['method']} identification, {d['machine']}, {d['n_samples']} touches, "
        f"residual RMS {d['residual_rms_um']:.3f} um"
    )
    others = {k: v for k, v in d.get("other_parameters", {}).items() if not k.startswith("sphere.")}
    for name, p in {**d["location_errors"], **others}.items():
        if p["value"] is None:
            print(f"  {name:20s} unobservable")
            continue
        std = "" if p["std"] is None else f" +- {p['std'] * units.shown(p['unit'])[0]:.3f}"
        print(f"  {name:20s} {value(p['value'], p['unit'])}{std}")
    stds = [d.get("other_parameters", {}).get("sphere." + c, {}).get("std") for c in "xyz"]
    print(
        "  sphere centre (table frame): "
        + ", ".join(f"{v:.4f}" for v in d["sphere"])
        + " mm"
        + ("" if None in stds else " +- " + ", ".join(f"{v * 1e3:.3f}" for v in stds) + " um")
    )
    if "dispersion_um" in d:
        print(
            f"  dispersion of the sphere centres: {d['dispersion_um']:.3f} um (the cycles' method gives no "
            "uncertainty per parameter)"
        )
    for u in d["unobservable"]:
        print(f"  not determined by these touches: {u}")
    for n in d["notes"]:
        print(f"  note: {n}")


def identify_probe_session(
    a: argparse.Namespace, s: _core.ProbeSession, sizes: dict | None
) -> tuple[probe.ProbeIdentification, dict]:
    """The identification and the document `rotacal identify` prints of a rotacal-probe/1
    session: --method joint (the default; with the uncertainty budget unless --no-budget),
    cycles or cycles-free-radius (the controller cycles' method, radius known or fitted per
    pose). What the cycles' method cannot do (a model file, the Monte Carlo check: it reports no
    uncertainty) is refused before the fit."""
    if a.method == "paper":
        raise OptionError(
            "identify: --method paper is the ballbar's and the R-test's; a touch-probe session "
            "takes joint, cycles or cycles-free-radius"
        )
    if a.length_offset:
        raise OptionError("identify: --length-offset is for ballbar sessions")
    if (a.save_model or a.store) and a.method != "joint":
        raise OptionError(NO_CYCLES_MODEL)
    if a.monte_carlo and a.method != "joint":
        raise OptionError(
            "identify: --monte-carlo checks a reported 1-sigma; the cycles' method reports none"
        )
    result = probe.identify_probe(s, a.method, noise=a.noise)
    d = result.to_dict()
    if not d["converged"]:  # an error, not a note: its values are no identification
        why = "; ".join(n for n in d.get("notes", []) if "converge" in n) or "did not converge"
        raise _core.DegenerateGeometry(
            f"identify: {a.file}: the {a.method} fit did not converge ({why}): check the session "
            "for an outlier touch or a wrong sphere position; nothing is reported or saved"
        )
    if a.method == "joint" and not a.no_budget:
        from ..diagnosis import uncertainty_budget
        from ..results import budget_dict

        d["uncertainty_budget"] = budget_dict(uncertainty_budget(s, sizes=sizes))
    if a.monte_carlo:
        d["monte_carlo"] = probe.monte_carlo_probe(
            s, result, a.monte_carlo, seed=a.seed, noise=a.noise
        )
    return result, d


# ------------------------------------------------------------------------- plan probe, import probe

# `plan`'s ballbar set-up options: refused with `plan probe`, which has its own.
_BALLBAR_ONLY = (
    "length",
    "pivot",
    "tilt_range",
    "axial_c_tilt",
    "step",
    "feed",
    "rotary_feed",
    "tests",
    "radial_c",
    "directions",
    "feed_factors",
    "compensate",
)


def _plan_template(a: argparse.Namespace, mtype, poses, pose_directions=()) -> _core.ProbeSession:
    """The commanded rows of `plan probe` as a session template: the nominal machine's touches
    (no errors, no noise), in the program's order."""
    sphere = np.asarray(a.sphere if a.sphere is not None else DEFAULT_SPHERE, float)
    session, _ = _core.simulate_probe(
        mtype,
        np.zeros(8),
        [],
        [],
        np.zeros(3),
        0.0,
        0.0,
        1,
        poses,
        None,
        sphere,
        a.sphere_diameter,
        a.stylus_diameter,
        list(pose_directions),
    )
    return session


def cmd_plan_probe(a: argparse.Namespace) -> int:
    from ..outputs import write_outputs
    from ..sessions import session_text

    given = [
        f"--{d.replace('_', '-')}"
        for d in _BALLBAR_ONLY
        if getattr(a, d, None) not in (None, "", [])
    ]
    if given:
        raise OptionError(f"plan probe: {', '.join(given)} belong to plan ballbar")
    mtype = load_machine(a.machine) if a.machine else _core.MachineType.AC_trt
    poses, dirs = design_file(a) if a.design else (poses_option(a.poses), [])
    sphere = np.asarray(a.sphere if a.sphere is not None else DEFAULT_SPHERE, float)
    text = _core.write_probe_nc_program(
        mtype,
        a.dialect,
        poses,
        sphere,
        a.sphere_diameter,
        a.stylus_diameter,
        a.log_file,
        approach_mm=a.approach,
        probe_feed=a.probe_feed,
        positioning_feed=a.positioning_feed,
        pose_directions=dirs,
    )
    # Every output only once all can be written: the template is made and checked (a file
    # load reads back) before either is written (rotacal.outputs.write_outputs).
    template = _plan_template(a, mtype, poses, dirs)
    outputs = [(a.output, text)]
    if a.session:
        outputs.append((a.session, session_text(template, "plan probe --session")))
    write_outputs(outputs, [a.design] if a.design else [])
    say(
        f"wrote {a.output}: {a.dialect} probing program, {len(template)} touches at {len(template.pose_names)} poses, "
        f"latched positions logged to {a.log_file} on the controller"
    )
    if a.session:
        say(
            f"wrote {a.session}: the commanded touches as a session template (rotacal import probe --plan)"
        )
    return EXIT_OK


def add_plan_probe_args(q: argparse.ArgumentParser) -> None:
    g = q.add_argument_group("touch probe (plan probe; --machine and --dialect as above)")
    add_sphere_args(g)
    g.add_argument(
        "--poses",
        metavar="T,R;T,R;...",
        help="tilt,rotary pairs, deg (default: the pattern of the controller cycles, rotacal simulate probe's)",
    )
    g.add_argument(
        "--design",
        type=path("--design"),
        metavar="DESIGN.json",
        help="the poses, each touch's direction and the sphere of `rotacal design probe --json`",
    )
    g.add_argument(
        "--log-file",
        default=DEFAULT_LOG_FILE,
        help="the file on the controller that (LOGOPEN,...) writes the latched positions to",
    )
    g.add_argument(
        "--approach",
        type=number("--approach", 0.01, 100.0, "mm"),
        default=DEFAULT_APPROACH_MM,
        help="each G38.2 starts this far outside the trigger sphere, mm (more than the sphere's "
        "set-up error and the machine's location errors move it)",
    )
    g.add_argument(
        "--probe-feed",
        type=number("--probe-feed", 0.1, 10000.0, "mm/min"),
        default=DEFAULT_PROBE_FEED,
        help="feed of the G38.2 moves, mm/min: the latch is quantised by the servo period, so the "
        "pretravel is up to feed x period (docs/probe.md)",
    )
    g.add_argument(
        "--positioning-feed",
        type=number("--positioning-feed", 1.0, 100000.0, "mm/min"),
        default=DEFAULT_POSITIONING_FEED,
        help="feed of the G1 moves down to each G38.2's start and back, mm/min",
    )


def refuse_probe_options(a: argparse.Namespace) -> None:
    """`plan ballbar` with an option of `plan probe`: refused, not ignored."""
    given = [
        o
        for o, v in (("--sphere", a.sphere), ("--poses", a.poses), ("--design", a.design))
        if v is not None
    ]
    given += [
        o
        for o, v, d in (
            ("--sphere-diameter", a.sphere_diameter, DEFAULT_SPHERE_DIAMETER),
            ("--stylus-diameter", a.stylus_diameter, DEFAULT_STYLUS_DIAMETER),
            ("--log-file", a.log_file, DEFAULT_LOG_FILE),
            ("--approach", a.approach, DEFAULT_APPROACH_MM),
            ("--probe-feed", a.probe_feed, DEFAULT_PROBE_FEED),
            ("--positioning-feed", a.positioning_feed, DEFAULT_POSITIONING_FEED),
        )
        if v != d
    ]
    if given:
        raise OptionError(f"plan ballbar: {', '.join(given)} belong to plan probe")


def cmd_import_probe(a: argparse.Namespace) -> int:
    from ..sessions import load

    plan = load(a.plan, format="probe")
    session = _core.read_linuxcnc_probe_log(a.log, plan)
    save(session, a.output, [a.log, a.plan])
    say(f"wrote {a.output}: {len(session)} touches at {len(session.pose_names)} poses from {a.log}")
    return EXIT_OK


def add_import(sub: argparse._SubParsersAction) -> argparse._SubParsersAction:
    q = sub.add_parser("import", help="a session from what a controller logged", epilog=EPILOG)
    kinds = q.add_subparsers(dest="kind", required=True)
    k = kinds.add_parser(
        "probe",
        help="the LinuxCNC log of `rotacal plan probe`'s program (lines: pose touch X Y Z)",
        epilog=EPILOG,
    )
    k.add_argument("log", metavar="LOG", type=path("LOG"))
    k.add_argument(
        "--plan",
        required=True,
        metavar="TEMPLATE.csv",
        type=path("--plan"),
        help="the session template `plan probe --session` wrote with the program",
    )
    k.add_argument("-o", "--output", required=True, type=path("--output"))
    k.set_defaults(func=cmd_import_probe)
    return kinds


COMMANDS = {"import": add_import}
KINDS = {"simulate": add_simulate_probe}
