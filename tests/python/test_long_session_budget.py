# SPDX-License-Identifier: BSD-3-Clause
"""The budget of a long ballbar session (issue 56): its diagnosis searched on every k-th reading,
what that search found then diagnosed on every reading (_core.budget_diagnosis_ballbar), gives
the expanded uncertainties of the budget on the whole session's diagnosis within 1 %. The
session comes from the independent reference simulator (tests/reference/refsim) with a left-in
effect the search must find on the reduced readings too."""

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
from refsim import instruments, poses, writers  # noqa: E402
from refsim.kinematics import Model  # noqa: E402
from refsim.machines import load_machine  # noqa: E402

rotacal = pytest.importorskip("rotacal")
_core = rotacal._core
from rotacal.diagnosis import diagnosis_options  # noqa: E402


@pytest.fixture(scope="module")
def long_session(tmp_path_factory):
    """AC-trt, the single set-up's seven tests at 0.1 deg (18,004 readings, more than twice the
    budget's 8,192 design rows), an X/Y squareness of 30 urad, white noise 0.5 um."""
    machine = load_machine("AC-trt")
    s = poses.ballbar_single_setup(machine, step_deg=0.1, dt=0.05)
    rng = np.random.default_rng(56)
    errors = [
        rng.uniform(-30e-3, 30e-3) if k % 4 < 2 else rng.uniform(-80e-6, 80e-6) for k in range(8)
    ]
    model = Model(machine, errors=errors, effects={"linear_squareness_XY": 30e-6})
    length = instruments.ballbar_lengths(
        model, s["pivot"], s["xyz"], np.radians(s["angles_deg"]), s["time"]
    )
    path = tmp_path_factory.mktemp("long") / "ballbar_long.csv"
    writers.write_ballbar(path, machine, s, length + rng.normal(0.0, 0.5e-3, len(length)), 0.5)
    return rotacal.load(path)


def test_the_budget_of_a_long_session_searched_on_a_reduced_design(long_session):
    s = long_session
    assert len(s) > 2 * 8192
    dense_diagnosis = rotacal.diagnose(s)
    reduced = _core.budget_diagnosis_ballbar(s, diagnosis_options())
    held = reduced.final_fit.effects
    assert held == dense_diagnosis.raw.final_fit.effects
    assert "linear_squareness_XY" in held
    assert len(reduced.final_fit.residuals) == len(s)  # fitted on every reading
    dense = rotacal.uncertainty_budget(s, dense_diagnosis)
    now = rotacal.uncertainty_budget(s)  # the reduced search
    compared = 0
    for d, r in zip(dense.errors, now.errors):
        assert (d.name, d.observable) == (r.name, r.observable)
        if d.observable:
            compared += 1
            assert abs(r.expanded - d.expanded) <= 0.01 * d.expanded, d.name
    assert compared >= 6


def test_a_short_session_is_diagnosed_as_it_is(shared_data):
    s = rotacal.load(shared_data / "ballbar_ac_table2.csv")
    assert len(s) <= 2 * 8192
    a, b = _core.budget_diagnosis_ballbar(s, diagnosis_options()), rotacal.diagnose(s).raw
    assert a.final_fit.effects == b.final_fit.effects
    assert np.array_equal(a.final_fit.residuals, b.final_fit.residuals)
    assert [f.effect for f in a.findings] == [f.effect for f in b.findings]
