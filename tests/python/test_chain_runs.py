# SPDX-License-Identifier: BSD-3-Clause
"""The runs of the measure -> compensate -> measure-again chain in batches (ballbar/chain_runs.hpp):
what a run records, that a batch equals its runs one at a time, and that compensating for the
identified errors of the shared Table 2 machine removes most of them."""

import json

import numpy as np
import pytest

from rotacal import _core

AC = _core.MachineType.AC_trt


@pytest.fixture(scope="module")
def setup():
    return _core.BallbarSetup()


@pytest.fixture(scope="module")
def nominal(setup):
    return _core.plan_ballbar_test(setup, None).commanded_session()


@pytest.fixture(scope="module")
def table2_machine(shared_data):
    t = json.loads((shared_data / "ballbar_ac_table2.truth.json").read_text())
    names = list(_core.location_error_names(AC))
    errors = np.array([t["errors"][n] for n in names])
    return errors, _core.BallbarMachineModel(
        AC, errors, np.array(t["pivot_actual"]), ["gravity_sag_A"], [0.003]
    )


def test_a_record_holds_the_nominal_commands_and_the_programs_angles_with_ar1_noise(
    setup, nominal, table2_machine
):
    errors, m = table2_machine
    program = _core.plan_ballbar_test(setup, errors).commanded_session()
    clean = _core.record_run(nominal, program, m, None, "paper", 0.5, 0.6)
    noisy = _core.record_run(nominal, program, m, 17, "paper", 0.5, 0.6)
    assert np.array_equal(noisy.xyz, nominal.xyz) and not np.allclose(program.xyz, nominal.xyz)
    assert np.array_equal(noisy.pivot, nominal.pivot)
    assert np.array_equal(noisy.angles_deg, program.angles_deg) and np.array_equal(
        noisy.time, program.time
    )
    assert list(noisy.tests) == list(program.tests)
    assert noisy.noise_um == 0.5 and clean.noise_um == 0.5
    # The clean reading is the simulator's; the noise is the core's AR(1) generator with this seed.
    assert np.array_equal(clean.length, _core.simulate_ballbar(program, m, 0.0, 1, False).length)
    expected = _core.noise_ar1(list(program.tests), list(program.time), 0.6, 0.5e-3, 17)
    assert np.allclose(noisy.length - clean.length, expected, rtol=0, atol=1e-12)


def test_a_batch_equals_its_runs_one_at_a_time(setup, nominal, table2_machine):
    errors, m = table2_machine
    other = _core.BallbarMachineModel(AC, errors * 0.5, np.array([120.0, 0.0, 60.0]), [], [])
    machines = [m, other, m, other]
    # Compensations in the order a, a, b, a: a program is reused only while the next run's
    # compensation is the same.
    a, b = errors, errors * 0.9
    comp = np.array([a, a, b, a])
    seeds = [3, 4, 5, 6]
    batch = _core.identify_runs(setup, machines, comp, seeds, "paper", 0.5, 0.0)
    for i in range(4):
        program = _core.plan_ballbar_test(setup, comp[i]).commanded_session()
        s = _core.record_run(nominal, program, machines[i], seeds[i], "paper", 0.5, 0.0)
        one = np.array([p.value for p in _core.identify_paper(s).parameters[:8]])
        assert np.array_equal(batch[i], one), i
    first = _core.identify_runs(setup, machines[:2], None, [], "paper", 0.5, 0.0)
    for i in range(2):
        s = _core.record_run(nominal, nominal, machines[i], None, "paper", 0.5, 0.0)
        assert np.array_equal(first[i], [p.value for p in _core.identify_paper(s).parameters[:8]])


def test_compensating_the_table2_machine_removes_most_of_its_errors(setup, table2_machine):
    errors, m = table2_machine
    before = _core.identify_runs(setup, [m], None, [], "paper", 0.5, 0.0)
    after = _core.identify_runs(setup, [m], before, [], "paper", 0.5, 0.0)
    scale = np.array([1e3, 1e3, 1e6, 1e6, 1e3, 1e3, 1e6, 1e6])  # um and urad
    # The paper's chain finds the errors to within its small-error approximations (and the sag).
    assert np.all(np.abs(before[0] - errors) * scale < 2.0), (before[0] - errors) * scale
    # Flynn et al. Table 2: compensation reduces every location error by about 90 % or more.
    assert np.all(np.abs(after[0]) < 0.1 * np.abs(errors)), after[0] * scale


def test_bad_batches_raise_typed_errors(setup, table2_machine):
    _, m = table2_machine
    with pytest.raises(_core.InvalidArgument, match="compensate_for"):
        _core.identify_runs(setup, [m, m], np.zeros((1, 8)), [], "paper", 0.5, 0.0)
    with pytest.raises(_core.InvalidArgument, match="seeds"):
        _core.identify_runs(setup, [m, m], None, [1], "paper", 0.5, 0.0)
    with pytest.raises(_core.InvalidArgument, match="method"):
        _core.identify_runs(setup, [m], None, [], "fast", 0.5, 0.0)
    with pytest.raises(_core.InvalidArgument, match="rho"):
        _core.identify_runs(setup, [m], None, [1], "paper", 0.5, 1.0)
