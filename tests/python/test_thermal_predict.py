# SPDX-License-Identifier: BSD-3-Clause
"""A thermal model applied (issue 53 item 5): `rotacal identify THERMAL.csv --save-model`, then
`rotacal predict --model M --duty FILE` (the location errors over time for a duty) and
`rotacal export --model M --at/--state` (the errors at a lag state written for a controller).

Judged by independent data: the shared thermal_probe_ac.csv's truth (its epochs' errors), the
reference simulator's lag (tests/reference/refsim/thermal.py), and the lag formula written out
here from the model file's numbers."""

import json
import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
from refsim import thermal  # noqa: E402

from conftest import run_cli as run  # noqa: E402
from conftest import truth  # noqa: E402


@pytest.fixture(scope="module")
def model(shared_data, tmp_path_factory):
    """The thermal model of the shared session, saved by the command line."""
    path = tmp_path_factory.mktemp("thermal") / "thermal_model.json"
    r = run("identify", shared_data / "thermal_probe_ac.csv", "--save-model", path)
    assert r.returncode == 0, r.stderr
    return path, json.loads(path.read_text())


def test_model_file_holds_cold_gains_tau(model, shared_data):
    path, m = model
    assert m["kind"] == "thermal" and m["machine"] == "AC-trt"
    assert m["source"]["session"].endswith("thermal_probe_ac.csv")
    th = m["thermal"]
    assert th["axis"] == "C" and th["tested_speed_rpm"] == 300
    assert len(th["lags"]) == 1 and th["lags"][0]["tau"]["unit"] == "s"
    t = truth(shared_data / "thermal_probe_ac.csv")
    tau = th["lags"][0]["tau"]
    assert abs(tau["value"] - t["thermal"][0]["tau_s"]) <= 3 * tau["std"]
    for name, g in th["lags"][0]["gains"].items():
        assert abs(g["value"] - t["thermal"][0]["gains"][name]) <= 3 * g["std"], name
    for name, e in m["location_errors"].items():
        assert abs(e["value"] - t["errors"][name]) <= 3 * e["std"], name
    n = 8 + 9 * len(th["lags"])
    assert len(m["covariance"]["parameters"]) == n and len(m["covariance"]["matrix"]) == n
    # What reads a model without a lag state refuses it, naming what to use instead.
    r = run("export", "--model", path, "--controller", "linuxcnc")
    assert r.returncode == 3 and "a thermal model" in r.stderr and "--at" in r.stderr


def test_predict_own_duty_matches_truth_epochs(model, shared_data):
    """The session as the duty (its duty and its epochs' pauses): the prediction at each epoch's
    middle against the truth's errors there (independent data), within 3 sigma."""
    path, _ = model
    f = shared_data / "thermal_probe_ac.csv"
    epochs = truth(f)["epochs"]
    times = ",".join(f"{e['t_mid']:.6f}" for e in epochs)
    r = run("predict", "--model", path, "--duty", f, "--times", times, "--json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["axis"] == "C" and len(d["times_s"]) == len(epochs)
    worst = 0.0
    for e in d["errors"]:
        assert e["observable"], e
        for i, ep in enumerate(epochs):
            z = abs(e["value"][i] - ep["errors"][e["name"]]) / e["std"][i]
            worst = max(worst, z)
    assert worst <= 3.0, worst
    # The drift is really predicted: E_X0C moves by ~-20 um over the heat-up.
    x = next(e for e in d["errors"] if e["name"] == "E_X0C")
    assert max(x["value"]) - min(x["value"]) > 0.015


def test_predict_other_duty_as_the_reference_lag(model, tmp_path):
    """Half the speed for 3 h, then at rest: a duty file from cold at 0 s. The prediction is
    refsim's drift of the model's own numbers (the same cold values, tau and gains)."""
    path, m = model
    duty = tmp_path / "half_speed.duty"
    duty.write_text("# duty.1: 0, C=150\n# duty.2: 10800, C=0\n", encoding="utf-8")
    times = [0.0, 60.0, 1800.0, 5400.0, 10800.0, 10860.0, 14400.0, 21600.0]
    r = run(
        "predict", "--model", path, "--duty", duty, "--times", ",".join(map(str, times)), "--json"
    )
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    lag = m["thermal"]["lags"][0]
    ref, _ = thermal.drifted(
        {n: e["value"] for n, e in m["location_errors"].items()},
        [0.0, 0.0, 0.0],
        [
            {
                "axis": "C",
                "tau_s": lag["tau"]["value"],
                "gains": {n: g["value"] for n, g in lag["gains"].items()},
            }
        ],
        thermal.parse_duty({"duty.1": "0, C=150", "duty.2": "10800, C=0"}),
        times,
        list(range(1, len(times) + 1)),  # every time its own instant: no epoch pauses
    )
    for e in d["errors"]:
        for i in range(len(times)):
            assert e["value"][i] == pytest.approx(ref[e["name"]][i], rel=1e-9, abs=1e-12)
    # At 150 rev/min the steady state is half the tested one: after 3 h (4.5 tau) 99 % of it.
    y = [s[0] for s in d["states"]]
    assert y[0] == 0.0 and y[4] == pytest.approx(1.5 * (1 - math.exp(-10800 / lag["tau"]["value"])))
    # The CSV form: a header, one row per time.
    r = run("predict", "--model", path, "--duty", duty, "--step", "1h")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].startswith("time_s,y1,E_Y0A,E_Y0A_std")
    assert len(lines) > 6 and lines[1].startswith("0.000,0.000000000,")


def test_duty_file_refused_by_line(model, tmp_path):
    path, _ = model
    bad = tmp_path / "bad.duty"
    bad.write_text("# duty.1: 0, C=150\nC=300 from here\n", encoding="utf-8")
    r = run("predict", "--model", path, "--duty", bad)
    assert r.returncode == 3 and "bad.duty" in r.stderr and "bad.duty:2:" in r.stderr, r.stderr
    other = tmp_path / "b_axis.duty"
    other.write_text("# duty.1: 0, B=100\n", encoding="utf-8")
    r = run("predict", "--model", path, "--duty", other)
    assert r.returncode == 3 and "lacks" in r.stderr, r.stderr
    tilt = tmp_path / "a_axis.duty"
    tilt.write_text("# duty.1: 0, A=10\n", encoding="utf-8")
    r = run("predict", "--model", path, "--duty", tilt)
    assert r.returncode == 3 and "drift of axis C only" in r.stderr, r.stderr


def _lag_of_test_duty(m: dict, t: float) -> float:
    """y(t) of the model's one lag over the test's heat input written in the file: on each piece
    of constant u, y(a + h) = u + (y(a) - u) exp(-h / tau)."""
    heat = m["thermal"]["test_heat_input"]
    tau = m["thermal"]["lags"][0]["tau"]["value"]
    start, u, y = heat["start_s"], heat["u"], 0.0
    t += start[0]
    for i, a in enumerate(start):
        if a >= t:
            break
        b = min(t, start[i + 1]) if i + 1 < len(start) else t
        y = u[i] + (y - u[i]) * math.exp(-(b - a) / tau)
    return y


@pytest.mark.parametrize("controller", ["linuxcnc", "siemens"])
def test_export_at_a_state_is_cold_plus_gain_times_lag(model, tmp_path, controller):
    path, m = model
    lag = m["thermal"]["lags"][0]
    for option, value, y in (
        ("--at", "2h", _lag_of_test_duty(m, 7200.0)),
        ("--state", "1.7", 1.7),
    ):
        r = run("export", "--model", path, "--controller", controller, option, value, "--json")
        assert r.returncode == 0, r.stderr
        got = json.loads(r.stdout)
        want = {
            n: e["value"] + lag["gains"][n]["value"] * y for n, e in m["location_errors"].items()
        }
        for e in got["location_errors"]:
            assert e["value"] == pytest.approx(want[e["name"]], rel=1e-9, abs=1e-12), e
        # The controller's parameters are those of an ordinary model with these errors.
        plain = tmp_path / f"plain_{controller}_{option[2:]}.json"
        plain.write_text(
            json.dumps(
                {
                    "format": "rotacal-model/1",
                    "kind": "ballbar",
                    "machine": "AC-trt",
                    "location_errors": {
                        n: {"value": v, "std": 0.0, "unit": m["location_errors"][n]["unit"]}
                        for n, v in want.items()
                    },
                    "pivot": {k: {"value": 0.0, "unit": "mm"} for k in "xyz"},
                }
            ),
            encoding="utf-8",
        )
        r2 = run("export", "--model", plain, "--controller", controller, "--json")
        assert r2.returncode == 0, r2.stderr
        ref = {p["name"]: p["corrected"] for p in json.loads(r2.stdout)["parameters"]}
        assert {p["name"] for p in got["parameters"]} == set(ref)
        for p in got["parameters"]:
            assert p["corrected"] == pytest.approx(ref[p["name"]], rel=1e-9, abs=1e-12), p
            assert p["std"] >= 0.0
        text = run("export", "--model", path, "--controller", controller, option, value)
        assert text.returncode == 0 and "thermal state y1 = " in text.stdout, text.stdout[:400]
    r = run("export", "--model", path, "--controller", controller, "--state", "1,2")
    assert r.returncode == 3 and "1 lag(s), 2 state(s)" in r.stderr, r.stderr
