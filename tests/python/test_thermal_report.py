# SPDX-License-Identifier: BSD-3-Clause
"""The report of a thermal test (issue 53, item 6): each location error's epochs identified
alone (the per-epoch peer, +- 1 sigma) against the joint model over the test, with the duty
drawn above. The epochs' values are judged against the truth the independent implementation
wrote for every epoch of the shared thermal_probe_ac.csv (its `epochs`: t_mid and errors)."""

import re

import numpy as np

from rotacal import _core

from conftest import truth
from conftest import run_cli as run


def test_epochs_of_the_peer_agree_with_the_truth_of_every_epoch(shared_data):
    f = shared_data / "thermal_probe_ac.csv"
    epochs = _core.identify_thermal(str(f), peer=True)["peer"]["identification"]["epochs"]
    want = truth(f)["epochs"]
    assert len(epochs["t_mid_s"]) == len(want) == 37
    z2 = []
    for e, (t_mid, w) in enumerate(zip(epochs["t_mid_s"], want)):
        assert abs(t_mid - w["t_mid"]) <= 60.0, (e, t_mid, w["t_mid"])  # within the epoch
        for s in epochs["series"]:
            if s["name"] not in w["errors"]:
                continue  # the table-side point: no truth per epoch
            assert s["std"][e] is not None and s["std"][e] > 0, (e, s["name"])
            miss = s["value"][e] - w["errors"][s["name"]]
            # The machine drifts within an epoch (up to about 0.6 um of E_X0C in a minute at the
            # start of the cool-down), which the per-epoch method takes as static: its sigma
            # does not hold that, the slack does.
            slack = 0.5e-3 if s["unit"] == "mm" else 0.0
            assert abs(miss) <= 4.5 * s["std"][e] + slack, (e, s["name"], miss, s["std"][e])
            z2.append((miss / s["std"][e]) ** 2)
    assert len(z2) == 37 * 8
    assert 0.4 <= np.mean(z2) <= 2.5  # the epochs' sigmas describe their scatter


def test_report_draws_the_drift_under_the_duty(shared_data, tmp_path):
    out = tmp_path / "thermal.html"
    r = run("report", shared_data / "thermal_probe_ac.csv", "-o", out)
    assert r.returncode == 0, r.stderr
    page = out.read_text()
    assert "Thermal test of axis C (AC-trt)" in page
    assert page.count("data:image/png;base64,") == 1
    assert "each epoch identified alone" in page
    assert re.search(r"Lag 1: &tau; = 4\d\.\d &plusmn; 0\.\d min", page)  # truth 40 min
    drifts = page.count(">significant</td>") + page.count(">no significant drift</td>")
    assert drifts == 11  # 8 errors and the sphere's x, y, z
    rtest = tmp_path / "rtest.html"
    r = run("report", shared_data / "thermal_rtest_bc.csv", "-o", rtest)
    assert r.returncode == 0, r.stderr
    assert "an R-test session shows the model alone" in rtest.read_text()
