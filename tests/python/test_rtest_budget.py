# SPDX-License-Identifier: BSD-3-Clause
"""The uncertainty budget of an R-test joint identification is the budget of the identification's
own model, the location errors with the smooth error maps (diagnose/rtest_budget.hpp): one value
per quantity. Sessions from the independent reference simulator (tests/reference/refsim):
- the budget's values and type A are the identification's (the budget of the diagnosis'
  baseline, without maps, showed other values and a third of its sigma as type A);
- a left-out squareness's budget line is the shift it really puts on the identified location
  errors (a nonlinear refit of refsim sessions with and without it), maps included (the
  baseline's line for E_C0B is 7.3 urad where the maps leave 0.19 urad);
- an identification of another session is refused by name."""

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
import refsim  # noqa: E402
from refsim import noise, poses, writers  # noqa: E402

import rotacal  # noqa: E402
from rotacal import _core  # noqa: E402
from rotacal.analysis import identification_budget, identify  # noqa: E402

MACHINE = "BC-trt"
ERRORS = [0.021, -0.014, 3.1e-5, -2.2e-5, 0.017, -0.025, 1.4e-5, 2.6e-5]


def session_file(tmp_path, name: str, effects: dict, ar_sigma_mm: float, seed: int = 5) -> Path:
    m = refsim.builtin(MACHINE)
    s = poses.rtest_grid(m, tilt_step=15.0, rot_step=30.0)
    errors = dict(zip(m.error_names(), ERRORS))
    d = refsim.rtest_displacements(
        refsim.Model(m, errors, effects),
        s["nests"],
        s["setup"],
        s["xyz"],
        np.radians(s["angles_deg"]),
        s["time"],
    )
    if ar_sigma_mm > 0:  # 6 s per pose: probe drift between poses, one AR(1) stream per channel
        rng = np.random.default_rng(seed)
        d = d + np.stack([noise.ar1(s["setup"], 0.6, ar_sigma_mm, rng) for _ in range(3)], axis=1)
    d = d + np.array([0.12, -0.05, 0.03])  # probe zeros
    return writers.write_rtest(tmp_path / f"{name}.csv", m, s, d, noise_um=0.5)


def by_name(budget) -> dict:
    return {e.name: e for e in budget.errors}


def test_the_budget_is_of_the_identifications_model(tmp_path):
    s = rotacal.load(
        session_file(tmp_path, "ar", {"angular_positioning_C_h3": [8e-6, -5e-6]}, 5e-4)
    )
    result = identify(s, "joint", noise="auto")
    reported = result.to_dict()["location_errors"]
    budget = by_name(identification_budget(s, None, result))
    assert set(budget) == set(reported)
    for name, p in reported.items():
        b = budget[name]
        assert b.observable
        assert b.value == pytest.approx(p["value"], rel=1e-12, abs=1e-15), name
        assert b.u_a == pytest.approx(p["std"], rel=1e-9), name
        assert b.u_c >= b.u_a and b.expanded >= 1.9 * b.u_c


def test_a_left_out_squareness_line_is_the_shift_it_puts_on_the_identification(tmp_path):
    size = 20e-6  # rad
    clean = rotacal.load(session_file(tmp_path, "clean", {}, 0.0))
    skewed = rotacal.load(session_file(tmp_path, "skewed", {"linear_squareness_XY": size}, 0.0))
    a = identify(clean, "joint", noise="white")
    b = identify(skewed, "joint", noise="white")
    va, vb = a.to_dict()["location_errors"], b.to_dict()["location_errors"]
    sizes = {"use_session_bounds": False, "overrides": {"linear_squareness_XY": size}}
    budget = by_name(identification_budget(clean, sizes, a))
    moved = 0
    for name in va:
        shift = abs(vb[name]["value"] - va[name]["value"])
        line = next(L for L in budget[name].type_b if L.effect == "linear_squareness_XY")
        scale = 1e-6 if budget[name].unit == "rad" else 1e-3  # 1 urad, 1 um
        assert line.bias_at_size == pytest.approx(shift, rel=0.05, abs=0.01 * scale), name
        assert line.u == pytest.approx(line.bias_at_size / np.sqrt(3.0))
        moved += shift > 0.1 * scale
    assert moved >= 1  # the squareness does move a location error through the map model


def test_another_sessions_identification_is_refused(tmp_path):
    one = rotacal.load(session_file(tmp_path, "one", {}, 5e-4, seed=1))
    two = rotacal.load(session_file(tmp_path, "two", {}, 5e-4, seed=2))
    result = identify(one, "joint", noise="white")
    with pytest.raises(_core.InvalidArgument, match="another session"):
        identification_budget(two, None, result)
