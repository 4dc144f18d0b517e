# SPDX-License-Identifier: BSD-3-Clause
"""Convention check against the independent implementation: with the truth's location errors,
pivot and effects, the library's exact forward model reproduces the recorded readings to
within the stated noise (residual RMS within 15 % of noise_um)."""

import numpy as np
import pytest

import rotacal
from conftest import truth

BALLBAR_FILES = ["ballbar_ac_table2.csv", "ballbar_ac_random.csv"]


@pytest.mark.parametrize("name", BALLBAR_FILES)
def test_ballbar_truth_reproduces_lengths(shared_data, name):
    path = shared_data / name
    t = truth(path)
    s = rotacal.load(path)
    names = rotacal.location_error_names(s.machine)
    errors = np.array([t["errors"][n] for n in names])
    ids = list(t["effects"].keys())
    model = rotacal.BallbarMachineModel(
        s.machine, errors, np.array(t["pivot_actual"]), ids, [float(t["effects"][i]) for i in ids]
    )
    predicted = rotacal.predict(model, s).length
    rms_um = np.sqrt(np.mean((s.length - predicted) ** 2)) * 1e3
    assert abs(rms_um - t["noise_um"]) <= 0.15 * t["noise_um"], rms_um
    # The nominal model (no errors) must NOT fit: the check has teeth.
    nominal = rotacal.BallbarMachineModel(s.machine, np.zeros(8), np.array(t["pivot_actual"]))
    rms_nominal = np.sqrt(np.mean((s.length - rotacal.predict(nominal, s).length) ** 2)) * 1e3
    assert rms_nominal > 5 * t["noise_um"]
