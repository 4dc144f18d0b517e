# SPDX-License-Identifier: BSD-3-Clause
"""`rotacal export --controller linuxcnc --thermal-chain` (rotacal/thermal_hal.py) without
LinuxCNC: the file's chain and numbers against `rotacal export --state`, and the refusals. The
chain running in LinuxCNC's servo thread: test_linuxcnc_kins.py, test_linuxcnc_rotacal_kins.py."""

import json
import math
import re

import pytest

from conftest import run_cli

EXIT_INPUT = 3
PINS = {
    "xyzac-trt-kins": ("x-rot-point", "y-rot-point", "z-rot-point", "y-offset", "z-offset"),
    "xyzbc-trt-kins": ("x-rot-point", "y-rot-point", "z-rot-point", "x-offset", "z-offset"),
}


def export(*args):
    r = run_cli("export", "--controller", "linuxcnc", *args)
    assert r.returncode == 0, r.stderr
    return r.stdout


def setp(text):
    return {m[0]: float(m[1]) for m in re.findall(r"^setp (\S+) (\S+)$", text, re.M)}


@pytest.fixture(scope="module")
def bc_thermal_model(shared_data, tmp_path_factory):
    """The thermal model of ../shared/data/thermal_rtest_bc.csv (BC-trt, R-test)."""
    path = tmp_path_factory.mktemp("bc") / "thermal.json"
    r = run_cli("identify", shared_data / "thermal_rtest_bc.csv", "--save-model", path)
    assert r.returncode == 0, r.stderr
    return path


@pytest.mark.parametrize(
    "which, kins, tilt",
    [("fast_thermal_model", "xyzac-trt-kins", "E_B0A"), ("bc_thermal_model", "xyzbc-trt-kins", "E_A0B")],
)  # fmt: skip
def test_the_chain_is_the_export_at_each_state(request, which, kins, tilt):
    m = request.getfixturevalue(which)
    text = export("--model", m, "--thermal-chain", "trt", "--servo-period", "500000")
    doc = json.loads(m.read_text())
    tau = doc["thermal"]["lags"][0]["tau"]["value"]
    v = setp(text)
    # speed -> u -> lowpass, in the servo thread in that order, then the gains and the sums
    assert "net rotacal-th-vel joint.4.vel-cmd => rotacal-th-speed.in" in text
    assert v["rotacal-th-u.gain"] == 1 / 600
    assert v["rotacal-th-lag1.gain"] == pytest.approx(1 - math.exp(-5e-4 / tau), rel=1e-15)
    funcs = re.findall(r"^addf (\S+) servo-thread$", text, re.M)
    assert funcs[:3] == ["rotacal-th-speed", "rotacal-th-u", "rotacal-th-lag1"]
    assert funcs[-len(PINS[kins]) :] == [f"rotacal-th-{p}" for p in PINS[kins]]
    # cold value and gain of each pin: the export at state 0 and the change to state 2 (the
    # export's text carries 1 nm)
    cold, warm = (setp(export("--model", m, "--state", s)) for s in ("0", "2"))
    for p in PINS[kins]:
        pin = f"{kins}.{p}"
        assert v[f"rotacal-th-{p}.offset"] == pytest.approx(cold[pin], abs=1e-6)
        assert 2 * v[f"rotacal-th-k1-{p}.gain"] == pytest.approx(warm[pin] - cold[pin], abs=2e-6)
        assert f"net rotacal-th-{p} rotacal-th-{p}.out => {pin}" in text
    # the gains the pins do not hold, with their steady state at the tested speed
    rpm = doc["thermal"]["tested_speed_rpm"]
    for name, unit in ((tilt, "rad"), ("E_A0C", "rad"), ("q_z", "mm")):
        k = doc["thermal"]["lags"][0]["gains"][name]["value"]
        got = re.search(rf"^#   {name}: (\S+) {unit}", text, re.M)
        assert got and float(got[1]) == pytest.approx(k * rpm / 100, rel=1e-5), name


def test_refusals_name_the_option(fast_thermal_model, tmp_path):
    m = fast_thermal_model
    for args, what in (
        (["--controller", "siemens", "--thermal-chain", "trt"], "--controller linuxcnc"),
        (["--controller", "linuxcnc", "--thermal-chain", "trt", "--state", "1"], "--at/--state"),
        (["--controller", "realtime", "--thermal-chain", "trt", "-o", tmp_path / "b"], "--thermal-chain"),
        (["--controller", "linuxcnc", "--thermal-chain", "trt", "--servo-period", "10"], "--servo-period"),
        (["--controller", "linuxcnc", "--thermal-chain", "trt", "--heat-joint", "16"], "--heat-joint"),
    ):  # fmt: skip
        r = run_cli("export", "--model", m, *args)
        assert r.returncode == EXIT_INPUT and what in r.stderr, (args, r.stderr)
    plain = tmp_path / "plain.json"
    d = json.loads(m.read_text())
    plain_doc = {
        "format": d["format"],
        "kind": "ballbar",
        "machine": d["machine"],
        "location_errors": {k: {"value": 0.0, "std": 1e-6} for k in d["location_errors"]},
        "pivot": {k: {"value": 0.0, "std": 0.0, "unit": "mm"} for k in "xyz"},
    }
    import rotacal

    rotacal.save_model(plain_doc, plain)
    r = run_cli("export", "--model", plain, "--controller", "linuxcnc", "--thermal-chain", "trt")
    assert r.returncode == EXIT_INPUT and "needs a thermal model" in r.stderr, r.stderr
