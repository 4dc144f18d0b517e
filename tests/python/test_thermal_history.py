# SPDX-License-Identifier: BSD-3-Clause
"""The thermal model in the calibration history (issue 53, item 6): `identify THERMAL --store`
keeps a thermal test's cold errors beside the other calibrations and its lags' tau and gains,
and `history show` follows them over months. The sessions come from the independent reference
simulator (tests/reference/refsim, through test_thermal's helper): two tests three months apart,
the second with the C axis line's x drift 1.6x the first's (a bearing whose preload changed),
everything else as the shared file's truth."""

import copy
import json

from conftest import SHARED, truth
from conftest import run_cli as run
from test_thermal import _refsim_session


def test_thermal_tests_followed_over_months(tmp_path):
    lags = copy.deepcopy(truth(SHARED / "thermal_probe_ac.csv")["thermal"])
    worn = copy.deepcopy(lags)
    worn[0]["gains"]["E_X0C"] *= 1.6
    db = tmp_path / "history.db"
    for name, lag, seed, date in (("jan", lags, 11, "2026-01-12"), ("apr", worn, 12, "2026-04-13")):
        f = _refsim_session(tmp_path / f"{name}.csv", lag, seed=seed)
        r = run("identify", f, "--store", "--machine-id", "M7", "--db", db, "--date", date)
        assert r.returncode == 0, r.stderr
        assert "stored as entry" in r.stderr
    r = run("history", "show", "M7", "--db", db, "--json")
    assert r.returncode == 0, r.stderr
    h = json.loads(r.stdout)
    assert [c["test"] for c in h["calibrations"]] == ["thermal", "thermal"]
    # The cold errors join the location errors' history, the lags their own.
    assert len(h["location_errors"]["E_X0C"]["points"]) == 2
    th = h["thermal"]
    tau = th["lag1.tau"]
    assert tau["unit"] == "s" and len(tau["points"]) == 2
    for p in tau["points"]:
        assert abs(p["value"] - lags[0]["tau_s"]) <= 3 * p["std"], p
    x = th["lag1.E_X0C"]["points"]
    for p, truth_gain in zip(x, (lags[0]["gains"]["E_X0C"], worn[0]["gains"]["E_X0C"])):
        assert abs(p["value"] - truth_gain) <= 3 * p["std"], p
    assert x[1]["exceeds_uncertainty"]  # -7.7 -> -12.4 um per unit of heat input
    y = th["lag1.E_Y0C"]["points"]  # unchanged: within its expanded uncertainty
    assert not y[1]["exceeds_uncertainty"]
    assert th["lag1.E_X0C"]["drift_per_month"]["value"] < 0
    text = run("history", "show", "M7", "--db", db)
    assert text.returncode == 0, text.stderr
    assert "thermal tests: each lag's tau" in text.stdout
    row = next(line for line in text.stdout.splitlines() if line.strip().startswith("lag1.E_X0C"))
    assert row.split()[1] == "2" and row.split()[5] == "yes"
