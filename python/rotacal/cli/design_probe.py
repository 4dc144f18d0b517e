# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal design probe``: the touch probe's poses with the smallest predicted uncertainty at a
number of touches, against ``plan probe``'s default poses, or the poses to add to a probe
session to separate two effects (docs/design.md). C++ computes (include/rotacal/probe/design.hpp,
rotacal.design); this module only composes."""

from __future__ import annotations

import argparse
import math
from typing import Any

import numpy as np

from .. import _core, jsontext
from ..probe_design import (
    SPHERE_CANDIDATES,
    design_probe,
    design_probe_separation,
    poses_text,
    probe_design_dict,
    probe_separation_dict,
)
from ..design import parameter_units
from ..machines import load_machine
from ..outputs import write_output
from ..sessions import PROBE, save
from .design import _print_separation, _session_after, add_separation_group
from .options import EPILOG, EXIT_OK, OptionError, number, numbers, path, say, shell_word
from .probe import DEFAULT_LOG_FILE, DEFAULT_SPHERE, _plan_template, add_sphere_args


def _write_program(
    a: argparse.Namespace,
    mtype: Any,
    poses: np.ndarray,
    directions: np.ndarray,
    inputs: list[str],
    pose_directions: list | None = None,
) -> None:
    """-o (the LinuxCNC probing program of `plan probe` at these poses, each along its own
    directions when given) and --session (its template), with the sphere at a.sphere."""
    pose_directions = [np.asarray(d, float) for d in pose_directions or []]
    default_dirs = np.asarray(_core.default_probe_poses_deg(mtype)[1], float)
    if not pose_directions and (
        directions.shape != default_dirs.shape or not np.allclose(directions, default_dirs)
    ):
        raise OptionError(
            "-o/--session: plan probe touches the default directions; these poses are touched along "
            "the session's own (see --json for them)"
        )
    sphere = np.asarray(a.sphere if a.sphere is not None else DEFAULT_SPHERE, float)
    if a.output:
        text = _core.write_probe_nc_program(
            mtype,
            "linuxcnc",
            poses,
            sphere,
            a.sphere_diameter,
            a.stylus_diameter,
            a.log_file,
            pose_directions=pose_directions,
        )
        write_output(a.output, text, inputs, [a.session] if a.session else [])
        say(f"wrote {a.output}: linuxcnc probing program, {len(poses)} poses")
    if a.session:
        save(
            _plan_template(a, mtype, poses, pose_directions),
            a.session,
            inputs,
            [a.output] if a.output else [],
        )
        say(
            f"wrote {a.session}: the commanded touches as a session template (rotacal import probe --plan)"
        )


def cmd_design_probe_separation(a: argparse.Namespace) -> int:
    from ..command_files import separation_template_path

    session = _session_after(a, PROBE)
    a.session = separation_template_path(a)  # -o alone: the template beside it (import --plan)
    d = design_probe_separation(
        session,
        [e.strip() for e in a.separate.split(",")],
        tilt_step=a.tilt_step,
        rot_step=a.rot_step,
        pose_time_s=a.pose_time or 0.0,
        max_time_s=a.max_time,
        max_correlation=a.max_correlation,
        noise_um=a.noise or 0.0,
    )
    if (a.output or a.session) and d.found:
        a.sphere, a.sphere_diameter, a.stylus_diameter = (
            session.sphere,
            session.sphere_diameter,
            session.stylus_diameter,
        )
        _write_program(
            a,
            session.machine,
            np.asarray(d.chosen.poses_deg),
            np.asarray(d.chosen.directions),
            [a.after],
        )
    elif a.output or a.session:
        say("rotacal: -o/--session not written: no added poses separate them")
    if a.json:
        print(jsontext.dumps(probe_separation_dict(d)))
        return EXIT_OK
    _print_separation(d, a.after, parameter_units(d.names))
    if d.found:
        print(
            f"run it with: rotacal plan probe --machine {shell_word(_core.machine_name(session.machine))} --poses "
            f'"{poses_text(d.chosen.poses_deg)}"'
            + (f" ({d.chosen.repeats:g} times)" if d.chosen.repeats > 1 else "")
        )
    return EXIT_OK


def cmd_design_probe(a: argparse.Namespace) -> int:
    if a.separate:
        return cmd_design_probe_separation(a)
    if a.after:
        raise OptionError("--after: goes with --separate EFFECT,EFFECT")
    mtype = load_machine(a.machine)
    noise = 0.5 if a.noise is None else a.noise
    sphere = a.sphere if a.sphere is not None else DEFAULT_SPHERE
    d = design_probe(
        mtype,
        sphere=sphere,
        sphere_diameter=a.sphere_diameter,
        stylus_diameter=a.stylus_diameter,
        touches=a.touches,
        tilt_step=a.tilt_step,
        rot_step=a.rot_step,
        noise_um=noise,
        touch_directions=not a.same_directions,
        max_contact_angle=a.max_contact_angle,
        sphere_candidates=_sphere_candidates(a.sphere_candidates),
    )
    a.sphere = np.asarray(d.sphere)
    _write_program(
        a,
        mtype,
        np.asarray(d.best.poses_deg),
        np.asarray(d.best.directions),
        [],
        list(d.best.pose_directions),
    )
    if a.json:
        print(jsontext.dumps(probe_design_dict(d)))
        return EXIT_OK
    tried = f" ({d.touches_tried} candidate touches)" if not a.same_directions else ""
    print(
        f"{d.poses_tried} candidate poses within the limits{tried}; {d.touches} touches, "
        f"noise {noise:g} um per touch"
    )
    for t in d.spheres:
        where = ", ".join(f"{v:g}" for v in t.sphere)
        print(
            f"  sphere at {where} mm: "
            + (
                f"designed largest U {t.worst_expanded_um:.3f} um"
                if t.plannable
                else f"not used: {t.why_not}"
            )
        )
    print(f"place the sphere at {', '.join(f'{v:g}' for v in d.sphere)} mm (table frame)")
    for label, c in (("designed", d.best), ("default", d.baseline)):
        where = (
            f"{len(c.poses_deg)} poses x {len(c.directions)} touches"
            if not len(c.pose_directions)
            else f"{len(c.poses_deg)} poses, {c.touches} touches along their own directions"
        )
        if not c.feasible:
            print(f"{label:9s} {where}: {c.why_not}")
            continue
        print(
            f"{label:9s} {where}: largest expanded uncertainty (k=2) {c.worst_expanded_um:.3f} um ({c.worst_error})"
        )
    if d.baseline.feasible:
        print(f"ratio designed / default: {d.ratio:.3f}")
    for name in d.best.undetermined:
        print(
            f"  {name}: no probe pose determines it (left out of the largest expanded uncertainty)"
        )
    print("predicted 1-sigma of the designed poses (inf: not determined):")
    for n, s_, (unit, k) in zip(d.best.names, d.best.sigma, parameter_units(d.best.names)):
        print(f"  {n:16s} {s_ * k if math.isfinite(s_) else math.inf:10.4f} {unit}")
    if len(d.best.pose_directions):
        print(
            f"run it with: rotacal design probe ... --json > design.json; rotacal plan probe --machine {shell_word(a.machine)} "
            "--design design.json (or -o/--session here)"
        )
    else:
        print(
            f"run it with: rotacal plan probe --machine {shell_word(a.machine)} --sphere {','.join(f'{v:g}' for v in d.sphere)} "
            f'--poses "{poses_text(d.best.poses_deg)}"'
        )
    return EXIT_OK


def _sphere_candidates(text: str) -> np.ndarray:
    """--sphere-candidates auto | none | X,Y,Z;X,Y,Z;... (mm, table frame)."""
    if text == "auto":
        return np.asarray(SPHERE_CANDIDATES, float)
    if text == "none":
        return np.zeros((0, 3))
    rows = [
        numbers("--sphere-candidates", 3, 1e4, "mm")(item)
        for item in text.split(";")
        if item.strip()
    ]
    if not rows:
        raise OptionError("--sphere-candidates: auto, none or X,Y,Z;X,Y,Z;... (mm)")
    return np.asarray(rows, float)


def add_design_probe(kinds: argparse._SubParsersAction) -> None:
    k = kinds.add_parser(
        "probe",
        help="the touch probe's poses with the smallest predicted uncertainty",
        epilog=EPILOG + "; docs/design.md",
    )
    k.add_argument(
        "--machine",
        default="AC-trt",
        type=path("--machine"),
        metavar="NAME|FILE",
        help="a built-in (`rotacal machines`) or a rotacal-machine/1 description file (default AC-trt)",
    )
    add_sphere_args(k)
    k.add_argument(
        "--touches",
        type=number("--touches", 0, 100000, integer=True),
        default=0,
        help="total touches to design for, a multiple of the 5 per pose (default 0: those of plan probe's "
        "default poses, 120)",
    )
    k.add_argument(
        "--same-directions",
        action="store_true",
        help="touch every pose along the default five directions (default: each touch its own direction)",
    )
    k.add_argument(
        "--max-contact-angle",
        type=number("--max-contact-angle", 0.0, 90.0, "deg", lo_open=True),
        default=80.0,
        help="candidate contact points within this angle of the stylus axis, deg (default 80)",
    )
    k.add_argument(
        "--sphere-candidates",
        default="auto",
        metavar="auto|none|X,Y,Z;...",
        help="other places of the sphere on the table to try, mm (default auto: "
        + "; ".join(",".join(f"{v:g}" for v in s) for s in SPHERE_CANDIDATES)
        + "); taken when the design there is 5 %% better",
    )
    k.add_argument(
        "--tilt-step",
        type=number("--tilt-step", 0.0, 180.0, "deg", lo_open=True),
        default=15.0,
        help="candidate tilt angles over the axis limits every this, deg (default 15)",
    )
    k.add_argument(
        "--rot-step",
        type=number("--rot-step", 1.0, 359.0, "deg"),
        default=30.0,
        help="candidate rotary angles over a full turn every this, deg (default 30)",
    )
    k.add_argument(
        "--noise",
        type=number("--noise", 0.0, 1000.0, "um", lo_open=True),
        help="1-sigma noise per latched coordinate, um (default 0.5; with --after: the session's)",
    )
    g = add_separation_group(k, "set of poses", "touch-probe session")
    g.add_argument(
        "--pose-time",
        type=number("--pose-time", 0.0, 3600.0, "s", lo_open=True),
        help="time per added pose, s (default: the session's)",
    )
    k.add_argument(
        "--log-file",
        default=DEFAULT_LOG_FILE,
        help="-o: the controller's file of the latched positions",
    )
    k.add_argument(
        "-o",
        "--output",
        type=path("--output"),
        help="write the LinuxCNC probing program of the designed (with --separate: the added) poses; "
        "with --separate, their session template beside it as .csv unless --session names one",
    )
    k.add_argument(
        "--session",
        type=path("--session"),
        metavar="TEMPLATE.csv",
        help="write its commanded touches as a session template (rotacal import probe --plan)",
    )
    k.add_argument("--json", action="store_true")
    k.set_defaults(func=cmd_design_probe)


COMMANDS: dict = {}
KINDS = {"design": add_design_probe}
