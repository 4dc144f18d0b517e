# SPDX-License-Identifier: BSD-3-Clause
"""Plan the single set-up ballbar test, simulate a machine with a hidden effect, find it.

Usage: python examples/simulate_and_diagnose.py
"""

import numpy as np

import rotacal
from rotacal import _core

setup = _core.BallbarSetup()  # AC-trt, L0 = 100 mm, pivot (120, 0, 60), all seven tests
plan = _core.plan_ballbar_test(setup, None)
errors = rotacal.random_location_errors(setup.machine, np.random.default_rng(7))
machine = rotacal.BallbarMachineModel(
    setup.machine, errors, np.array([120.01, -0.02, 59.99]), ["ballbar_thermal_drift"], [2e-6]
)  # the bar grows 2 nm/s
session = rotacal.simulate_ballbar(plan.commanded_session(), machine, noise_um=0.5, seed=1)

d = rotacal.diagnose(session).to_dict()
f = d["findings"][0]
k = f["parameters"]["ballbar_thermal_drift"]
print(
    f"baseline chi2/dof {d['baseline']['chi2_per_dof']:.2f}; found {f['effect']}: "
    f"k = {k['value'] * 1e6:.3f} +- {k['std'] * 1e6:.3f} nm/s (truth 2.000)"
)
