# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal machines``: list the built-in machines, or show one (built-in or file)."""

from __future__ import annotations

import argparse

from .. import _core, jsontext
from .options import EPILOG, EXIT_OK, OptionError


def cmd_machines(a: argparse.Namespace) -> int:
    """List the built-in machines, or show one (built-in or file): drawing, error names, JSON."""
    from ..machines import load_machine, machine_dict, machine_drawing

    if a.action == "list":
        if a.machine is not None:
            raise OptionError(
                f"machines: 'list' takes no machine (got {a.machine[:60]!r}); "
                "rotacal machines show NAME|FILE"
            )
        rows = [machine_dict(n) for n in _core.builtin_machine_names()]
        if a.json:
            print(
                jsontext.dumps(
                    [
                        {
                            k: r[k]
                            for k in (
                                "name",
                                "configuration",
                                "axis_names",
                                "tilt_axis",
                                "rot_axis",
                                "axes",
                                "location_error_names",
                            )
                        }
                        for r in rows
                    ]
                )
            )
            return EXIT_OK
        print(
            f"{len(rows)} built-in machines (any other: a rotacal-machine/1 file, docs/machines.md):"
        )
        for r in rows:
            sides = ", ".join(f"{ax['name']} {ax['side']}" for ax in r["axes"])
            print(
                f"  {r['name']:16s} {r['configuration']:12s} axes {''.join(r['axis_names'])} ({sides})"
            )
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
    print(
        f"default test ranges: tilt {d['default_tilt_range_deg'][0]:g} .. {d['default_tilt_range_deg'][1]:g} deg, "
        f"tilt held during axial_{d['rot_axis']} {d['default_axial_c_tilt_deg']:g} deg"
    )
    print("description (rotacal-machine/1, as a session's '# machine_description:' carries it):")
    print(load_machine(a.machine).description_json)
    return EXIT_OK


def add_machines(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "machines",
        help="the built-in machines; show one (or a rotacal-machine/1 file) as text",
        epilog=EPILOG + "; docs/machines.md",
    )
    q.add_argument(
        "action",
        nargs="?",
        choices=["list", "show"],
        default="list",
        help="list (default): the built-ins; show NAME|FILE: drawing, location errors, description",
    )
    q.add_argument("machine", nargs="?", metavar="NAME|FILE")
    q.add_argument("--json", action="store_true")
    q.set_defaults(func=cmd_machines)


COMMANDS = {"machines": add_machines}
