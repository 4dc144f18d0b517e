# SPDX-License-Identifier: BSD-3-Clause
"""The LinuxCNC (machine-axis) program of every built-in machine through LinuxCNC's own
interpreter, rs274: it runs to M2 without an error, every block ends on the planned machine
axes (the machine's own rotary letters in their a, b, c slots), the ballbar keeps L0 at every
block end and along every arc by the kinematics written out from the description in
test_linuxcnc.Chain, and each block takes the planned time (test_linuxcnc.check_program)."""

import re

import numpy as np
import pytest

import rotacal
from rotacal import _core
from test_linuxcnc import RS274, Chain, check_program

pytestmark = pytest.mark.skipif(
    RS274 is None,
    reason="rs274 (LinuxCNC stand-alone G-code interpreter) not on PATH: apt-get install linuxcnc-uspace",
)

BUILTINS = list(_core.builtin_machine_names())


def plan_of(name, **kw):
    m = _core.parse_machine_type(name)
    return rotacal.plan_ballbar_test(rotacal.BallbarSetup(m, **kw))


@pytest.mark.parametrize("name", BUILTINS)
def test_every_builtin_program_runs_the_plan(name, tmp_path):
    plan = plan_of(name)
    m = plan.setup.machine
    text = rotacal.write_nc_program(plan, "linuxcnc")
    n_lines, n_arcs = check_program(plan, text, tmp_path)
    assert n_lines > 1000  # every sample of every test is a block
    # Only the machine's two rotary axes move; the third rs274 slot stays at 0.
    moved = {L for L in "ABC" if re.search(rf"\b{L}-?[0-9]*[1-9]", text.split("G93", 1)[1])}
    assert moved == set(m.axis_names)


@pytest.mark.parametrize("name", ["B-head-C-table", "AC-head"])
def test_head_programs_at_another_layout(name, tmp_path):
    """A head machine with another pivot, bar, step and the radial test inside."""
    plan = plan_of(
        name,
        pivot=np.array([80.0, -40.0, 90.0]),
        ballbar_length=150.0,
        step_deg=2.5,
        radial_c_side=rotacal.RadialSide.inside,
    )
    assert check_program(plan, rotacal.write_nc_program(plan, "linuxcnc"), tmp_path)[0] > 0


def test_the_chain_check_catches_a_head_program_off_the_ball(tmp_path):
    """The check is not blind on a head machine: the program of a machine with a tool 1 mm
    longer than the plan's keeps the poses, so only the ballbar length (the independent chain)
    can tell, and it does."""
    plan = plan_of("B-head-C-table")
    text = rotacal.write_nc_program(plan, "linuxcnc")
    chain = Chain(plan.setup.machine)
    chain.t = chain.t + np.array([0.0, 0.0, -1e-3])  # 1 um longer tool
    import test_linuxcnc

    original = test_linuxcnc.Chain
    try:
        test_linuxcnc.Chain = lambda machine: chain
        with pytest.raises(AssertionError) as e:
            check_program(plan, text, tmp_path)
        assert "ballbar_length" in str(e.value) or "L0" in str(e.value)
    finally:
        test_linuxcnc.Chain = original
