# SPDX-License-Identifier: BSD-3-Clause
"""The thermal model as a PLC's state-space predictor (issue 53 item 5, other controllers):
`export --controller X --thermal-predictor --cycle T` for every controller. The test runs the
document as its format says a PLC runs it, over a duty of its own (300 rev/min for 80 min, then
40 min at rest, a cycle of 1 s), and checks the lag state against the lag's exact solution
written here, and every rewritten parameter against what `export --state y` writes at that
state: what the PLC computes is what rotacal would export at that moment."""

import json
import math

import pytest

from conftest import run_cli as run

CONTROLLERS = ["linuxcnc", "siemens", "isg", "heidenhain", "fanuc"]


@pytest.fixture(scope="module")
def thermal_model(shared_data, tmp_path_factory):
    out = tmp_path_factory.mktemp("predictor") / "thermal.json"
    r = run("identify", shared_data / "thermal_probe_ac.csv", "--save-model", out)
    assert r.returncode == 0, r.stderr
    return out


def exact_state(tau: float, t: float, heat_s: float, u: float) -> float:
    """tau dy/dt = u - y from 0: heating for heat_s, then at rest."""
    if t <= heat_s:
        return u * (1.0 - math.exp(-t / tau))
    return u * (1.0 - math.exp(-heat_s / tau)) * math.exp(-(t - heat_s) / tau)


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_the_plc_computes_what_export_writes_at_each_state(thermal_model, tmp_path, controller):
    doc_path = tmp_path / "predictor.json"
    r = run(
        "export", "--model", thermal_model, "--controller", controller,
        "--thermal-predictor", "--cycle", "1s", "-o", doc_path,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    doc = json.loads(doc_path.read_text())
    assert doc["format"] == "rotacal-thermal-predictor/1" and doc["cycle_s"] == 1.0
    (lag,) = doc["lags"]
    assert doc["rewrites"], "a thermal model moves some parameter of every controller"
    for p in doc["rewrites"]:  # linear in the state to well below a nanometre or nanoradian
        assert abs(p["nonlinearity_at_steady_state"]) < 1e-9, p
    heat_s, u = 4800, 3.0  # 300 rev/min
    y = 0.0
    for n in range(1, 7201):  # the PLC: one update per cycle
        y = lag["a"] * y + lag["b"] * (u if n <= heat_s else 0.0)
        if n not in (600, 4800, 7200):
            continue
        assert y == pytest.approx(exact_state(lag["tau_s"], n, heat_s, u), rel=1e-9)
        e = run(
            "export", "--model", thermal_model, "--controller", controller,
            "--state", f"{y:.17g}", "--json",
        )  # fmt: skip
        assert e.returncode == 0, e.stderr
        want = {p["name"]: p["corrected"] for p in json.loads(e.stdout)["parameters"]}
        for p in doc["rewrites"]:
            got = p["cold"] + sum(g * y for g in p["gains"])
            # Exact for the affine parameters; a direction's cosine departs from the line by
            # at most what the document states at the steady state (quadratic in the state).
            bound = abs(p["nonlinearity_at_steady_state"]) + 1e-12
            assert abs(got - want[p["name"]]) <= bound, (p["name"], n, got - want[p["name"]])
        for p in doc["constant"]:
            assert p["cold"] == pytest.approx(want[p["name"]], abs=1e-12), p["name"]


def test_predictor_refusals(thermal_model, shared_data):
    r = run(
        "export", "--model", thermal_model, "--controller", "siemens",
        "--thermal-predictor", "--cycle", "2min",
    )  # fmt: skip
    assert r.returncode == 3 and "--cycle 120 s: not 0.1 ms to 60 s" in r.stderr
    r = run(
        "export", "--model", thermal_model, "--controller", "siemens",
        "--thermal-predictor", "--state", "1",
    )  # fmt: skip
    assert r.returncode == 3 and "--thermal-predictor: not with --at/--state" in r.stderr
    cold = shared_data / "ballbar_ac_table2.csv"
    m = thermal_model.parent / "cold.json"
    assert run("identify", cold, "--save-model", m).returncode == 0
    r = run("export", "--model", m, "--controller", "isg", "--thermal-predictor")
    assert r.returncode == 3 and "needs a thermal model" in r.stderr
