# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal plan thermal`` (issue 53, item 1): the NC program of a thermal test and its session
template with the duty. The touch probe's program (probe/nc_program.hpp with a
ThermalProgramDuty) measures the epoch's poses at every interval and runs the duty between;
the template holds the commanded touches of every epoch, the `epoch` column and the
`# duty.N:` lines (formats.md "Thermal test of a rotary axis")."""

from __future__ import annotations

import argparse

import numpy as np

from .. import _core
from ..machines import load_machine
from ..outputs import write_outputs
from .options import EXIT_OK, OptionError, number, say
from .probe import _BALLBAR_ONLY, DEFAULT_SPHERE
from .probe_poses import poses_option
from .thermal_sim import epoch_poses, fill_test_defaults, test_plan, thermal_session_text


def add_plan_thermal_args(q: argparse.ArgumentParser) -> None:
    """plan thermal's own option beside the test's (thermal_sim.add_test_args)."""
    q.add_argument(
        "--max-speed", type=number("--max-speed", 0.0, 1e5, "rev/min"), default=None,
        help="plan thermal: the axis' speed limit, rev/min (default 500): a faster --speed is refused",
    )  # fmt: skip


def cmd_plan_thermal(a: argparse.Namespace) -> int:
    given = [
        f"--{d.replace('_', '-')}"
        for d in _BALLBAR_ONLY
        if getattr(a, d, None) not in (None, "", [])
    ]
    if given:
        raise OptionError(f"plan thermal: {', '.join(given)} belong to plan ballbar")
    fill_test_defaults(a)
    if a.instrument != "probe":
        raise OptionError(
            "plan thermal --instrument rtest: rotacal writes no R-test NC program yet (the R-test "
            "is run by `rotacal record rtest`); plan the probe's thermal test, or simulate the "
            "R-test's (rotacal simulate thermal --instrument rtest)"
        )
    if a.design:
        raise OptionError("plan thermal: --design belongs to plan probe (give --poses)")
    machine = load_machine(a.machine) if a.machine else _core.MachineType.AC_trt
    plan = test_plan(a, machine)
    poses = poses_option(a.poses) if a.poses else epoch_poses(machine)
    sphere = np.asarray(a.sphere if a.sphere is not None else DEFAULT_SPHERE, float)
    text = _core.write_probe_nc_program(
        machine, a.dialect, poses, sphere, a.sphere_diameter, a.stylus_diameter, a.log_file,
        approach_mm=a.approach, probe_feed=a.probe_feed, positioning_feed=a.positioning_feed,
        thermal=(plan.axis, plan.speed, plan.heat_s, plan.cool_s, plan.interval_s, a.max_speed),
    )  # fmt: skip
    # The template: the nominal machine's touches of every epoch (no errors, no drift, no noise).
    template, epoch, _ = _core.simulate_thermal(
        "probe", machine, np.zeros(8), [], [], plan.duty(), plan.epoch_starts(), plan.axis, [],
        poses, 0.0, 0.0, 1, sphere[None, :], np.zeros(3), 0.0, 6.0,
    )  # fmt: skip
    outputs = [(a.output, text)]
    if a.session:
        outputs.append((a.session, thermal_session_text(template, plan, epoch)))
    write_outputs(outputs)
    say(
        f"wrote {a.output}: {a.dialect} thermal test program, {max(epoch)} epochs of "
        f"{len(poses)} poses, {plan.axis} at {plan.speed:g} rev/min for {plan.heat_s / 3600:g} h "
        f"then at rest for {plan.cool_s / 3600:g} h; latched positions logged to {a.log_file}"
    )
    if a.session:
        say(f"wrote {a.session}: the commanded touches of every epoch with the duty (template)")
    return EXIT_OK
