# SPDX-License-Identifier: BSD-3-Clause
"""Ballbar test planning from Python: arrays, the reference session's commands, L0 along the
whole toolpath, compensation, NC program text, typed errors."""

import numpy as np
import pytest

import rotacal
from conftest import truth


def rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def read_commands(path):
    """Minimal reader of a rotacal-ballbar/1 file: labels and X,Y,Z,A,C columns."""
    rows = [l.split(",") for l in path.read_text().splitlines() if l and not l.startswith("#")]
    header, body = rows[0], rows[1:]
    cols = [header.index(c) for c in ("X", "Y", "Z", "A", "C")]
    labels = np.array([r[0] for r in body])
    values = np.array([[float(r[i]) for i in cols] for r in body])
    return labels, values


def test_default_plan_arrays_and_reference_commands(shared_data):
    plan = rotacal.plan_ballbar_test()
    n = plan.num_samples
    labels = np.array(plan.labels)
    assert labels.shape == (n,)
    assert plan.p_table.shape == (n, 3)
    assert plan.angles_deg.shape == (n, 2)
    assert plan.machine_axes.shape == (n, 5)
    assert plan.time.shape == (n,)
    assert np.all(np.diff(plan.time) > 0)
    assert plan.compensation is None

    ref_labels, ref = read_commands(shared_data / "ballbar_ac_table2.csv")
    tests = [l for l in dict.fromkeys(labels) if l != "transition"]
    assert tests == list(dict.fromkeys(ref_labels))
    for t in tests:
        got = plan.machine_axes[labels == t]
        want = ref[ref_labels == t]
        assert got.shape == want.shape, t
        np.testing.assert_allclose(got, want, rtol=0, atol=5.0000001e-7, err_msg=t)


@pytest.mark.parametrize("machine", [rotacal.MachineType.AC_trt, rotacal.MachineType.BC_trt])
def test_ballbar_stays_at_l0_everywhere(machine):
    pivot = np.array([95.0, 40.0, 75.0])
    setup = rotacal.BallbarSetup(
        machine=machine,
        ballbar_length=125.0,
        pivot=pivot,
        step_deg=3.0,
        radial_c_side=rotacal.RadialSide.inside,
    )
    plan = rotacal.plan_ballbar_test(setup)
    # Table frame: every sample, tests and transitions.
    np.testing.assert_allclose(np.linalg.norm(plan.p_table - pivot, axis=1), 125.0, atol=1e-9)
    # Machine frame, with the pivot moved by the nominal table (formats.md rotations).
    tilt = rx if machine == rotacal.MachineType.AC_trt else ry
    ang = np.radians(plan.angles_deg)
    pivot_m = np.array([tilt(a) @ rz(c) @ pivot for a, c in ang])
    np.testing.assert_allclose(
        np.linalg.norm(plan.machine_axes[:, :3] - pivot_m, axis=1), 125.0, atol=1e-9
    )
    letter = "A" if machine == rotacal.MachineType.AC_trt else "B"
    assert f"radial_{letter}" in plan.labels and f"axial_{letter}" in plan.labels


def test_compensated_plan_hits_targets_on_the_actual_machine(shared_data):
    t = truth(shared_data / "ballbar_ac_table2.csv")
    machine = rotacal.MachineType.AC_trt
    errors = np.array([t["errors"][n] for n in rotacal.location_error_names(machine)])
    nominal = rotacal.plan_ballbar_test()
    comp = rotacal.plan_ballbar_test(identified=errors)
    np.testing.assert_array_equal(comp.compensation, errors)
    np.testing.assert_array_equal(comp.p_table, nominal.p_table)
    np.testing.assert_array_equal(comp.angles_deg, nominal.angles_deg)
    on_actual = rotacal.forward(machine, errors, np.radians(comp.angles_deg), comp.p_table)
    miss_comp = np.abs(on_actual - comp.machine_axes[:, :3]).max()
    miss_nominal = np.abs(on_actual - nominal.machine_axes[:, :3]).max()
    assert miss_comp < 1e-9
    assert miss_nominal > 0.05
    with pytest.raises(rotacal.InvalidArgument, match="identified"):
        rotacal.plan_ballbar_test(identified=np.zeros(7))


def test_setup_options_round_trip_and_validation():
    s = rotacal.BallbarSetup(
        tilt_range_deg=(-60, 60),
        step_deg=2.0,
        tests=[rotacal.BallbarTest.radial_tilt, rotacal.BallbarTest.axial_c],
    )
    assert s.tilt_range_deg == [-60.0, 60.0]
    plan = rotacal.plan_ballbar_test(s)
    labels = np.array(plan.labels)
    assert (labels == "radial_A").sum() == 61
    assert (labels == "axial_C").sum() == 180
    np.testing.assert_array_equal(
        plan.angles_deg[labels == "radial_A"][:, 0], np.arange(-60, 61, 2)
    )
    s.ballbar_length = -1
    with pytest.raises(rotacal.InvalidArgument, match="ballbar_length"):
        rotacal.plan_ballbar_test(s)
    s = rotacal.BallbarSetup(pivot=np.array([0.0, 0.0, 50.0]))
    with pytest.raises(rotacal.InvalidArgument, match="radial_C"):
        rotacal.plan_ballbar_test(s)
    assert (
        rotacal.parse_ballbar_test("axial_B", rotacal.MachineType.BC_trt)
        == rotacal.BallbarTest.axial_tilt
    )
    with pytest.raises(rotacal.InvalidArgument, match="axial_B"):
        rotacal.parse_ballbar_test("axial_B", rotacal.MachineType.AC_trt)


def test_commanded_session_feeds_the_simulator(shared_data):
    """The plan's commands, measured on the Table 2 machine, read like the reference file."""
    t = truth(shared_data / "ballbar_ac_table2.csv")
    machine = rotacal.MachineType.AC_trt
    errors = np.array([t["errors"][n] for n in rotacal.location_error_names(machine)])
    session = rotacal.plan_ballbar_test().commanded_session()
    assert len(session) == 1804
    model = rotacal.BallbarMachineModel(machine, errors, np.array(t["pivot_actual"]))
    sim = rotacal.simulate_ballbar(session, model, noise_um=0.0)
    ref = rotacal.load(shared_data / "ballbar_ac_table2.csv")
    diff_um = (sim.length - ref.length) * 1e3
    # Only the file's noise separates them (0.5 um, 1-sigma).
    assert np.sqrt(np.mean(diff_um**2)) < 1.2 * t["noise_um"]


def test_nc_program_text():
    plan = rotacal.plan_ballbar_test()
    by_name = rotacal.write_nc_program(plan, "linuxcnc")
    assert by_name == rotacal.write_nc_program(plan, rotacal.NcDialect.linuxcnc)
    assert "G93" in by_name and "G21" in by_name
    assert "FUNCTION TCPM" in rotacal.write_nc_program(plan, "heidenhain")
    assert "TRAORI" in rotacal.write_nc_program(plan, "siemens")
    assert "G43.4 H7" in rotacal.write_nc_program(plan, "fanuc", rotacal.NcProgramOptions(tool=7))
    with pytest.raises(rotacal.InvalidArgument, match="mazak"):
        rotacal.write_nc_program(plan, "mazak")
