# SPDX-License-Identifier: BSD-3-Clause
"""The touch probe on the command line (issue 31): `rotacal simulate probe`, and `identify` and
`diagnose` of a rotacal-probe/1 session. The truth of the fits comes from the independent
reference simulator (tests/reference/refsim), and the simulator's touches are checked against
refsim's touch model on the truth it wrote."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
import refsim  # noqa: E402

import rotacal  # noqa: E402
from conftest import run_cli as run  # noqa: E402
from test_probe import refsim_session  # noqa: E402


def outside_3_sigma(location_errors: dict, truth: dict) -> list[str]:
    bad = []
    for name, value in truth.items():
        p = location_errors[name]
        if p["value"] is None or abs(p["value"] - value) > 3 * p["std"]:
            bad.append(f"{name}: {p['value']} +- {p['std']}, truth {value}")
    return bad


def reference_errors(machine: str, seed: int) -> dict:
    rng = np.random.default_rng(seed)
    names = refsim.builtin(machine).error_names()
    return {
        n: (rng.normal(0, 0.03) if k % 4 < 2 else rng.normal(0, 4e-5)) for k, n in enumerate(names)
    }


@pytest.mark.parametrize("machine", ["AC-trt", "BC-trt"])
def test_simulate_probe_touches_where_the_reference_simulator_does(tmp_path, machine):
    out, truth_path = tmp_path / "s.csv", tmp_path / "s.truth.json"
    r = run(
        "simulate",
        "probe",
        "--machine",
        machine,
        "--effect",
        "stylus_radius_offset=0.002",
        "--sphere",
        "-40,30,90",
        "--noise",
        "0",
        "--seed",
        "5",
        "-o",
        out,
        "--truth",
        truth_path,
    )
    assert r.returncode == 0, r.stderr
    assert "wrote" in r.stderr and "120 touches at 24 poses" in r.stderr
    s = rotacal.load(out)
    assert isinstance(s, rotacal.ProbeSession) and len(s) == 120
    t = json.loads(truth_path.read_text())
    assert set(t["errors"]) == set(refsim.builtin(machine).error_names())
    assert t["sphere_nominal"] == [-40.0, 30.0, 90.0]
    assert (
        np.linalg.norm(np.subtract(t["sphere_actual"], t["sphere_nominal"])) > 1e-3
    )  # a set-up error
    # The same touches from refsim's own model of the truth (noise 0): within 1 nm.
    model = refsim.Model(machine, t["errors"], t["effects"])
    angles = np.radians(
        np.column_stack([np.asarray(s.angles_deg)[:, 0], np.asarray(s.angles_deg)[:, 1]])
    )
    ref = refsim.probe_touches(
        model,
        np.asarray(t["sphere_actual"]),
        np.asarray(t["sphere_nominal"]),
        25.0,
        6.0,
        np.asarray(s.n),
        angles,
        np.asarray(s.time),
    )
    assert np.abs(np.asarray(s.xyz) - ref).max() < 1e-6
    again = tmp_path / "again.csv"
    assert (
        run(
            "simulate",
            "probe",
            "--machine",
            machine,
            "--effect",
            "stylus_radius_offset=0.002",
            "--sphere",
            "-40,30,90",
            "--noise",
            "0",
            "--seed",
            "5",
            "-o",
            again,
        ).returncode
        == 0
    )
    assert again.read_text() == out.read_text()


def test_simulate_probe_refuses_bad_options(tmp_path):
    out = tmp_path / "s.csv"
    assert run("simulate", "probe", "--effect", "no_such_effect=1", "-o", out).returncode == 3
    r = run("simulate", "probe", "--rho", "1.5", "-o", out)
    assert r.returncode == 3 and "--rho" in r.stderr
    r = run("simulate", "probe", "-o", out, "--truth", out)
    assert r.returncode == 4 and "--truth" in r.stderr
    assert not out.exists()


@pytest.mark.parametrize("machine,seed", [("AC-trt", 21), ("BC-trt", 22)])
def test_identify_a_reference_session_within_3_sigma(tmp_path, machine, seed):
    errors = reference_errors(machine, seed)
    path, sphere_actual = refsim_session(tmp_path, machine, errors, {}, rho=0.5, seed=seed)
    r = run("identify", path, "--json", "--no-budget")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["method"] == "joint" and d["machine"] == machine and d["n_samples"] == 120
    assert not outside_3_sigma(d["location_errors"], errors), outside_3_sigma(
        d["location_errors"], errors
    )
    for k, c in enumerate("xyz"):
        p = d["other_parameters"]["sphere." + c]
        assert abs(p["value"] - sphere_actual[k]) <= 3 * p["std"]
    # The cycles' method on the same file: no uncertainty per parameter, a dispersion instead.
    r = run("identify", path, "--json", "--method", "cycles")
    assert r.returncode == 0, r.stderr
    c = json.loads(r.stdout)
    assert c["method"] == "cycles" and c["dispersion_um"] > 0
    for name, value in errors.items():
        p = c["location_errors"][name]
        assert p["std"] is None
        assert abs(p["value"] - value) < (50e-6 if p["unit"] == "rad" else 10e-3), name


def test_identify_prints_a_table_with_the_budget_and_refuses_what_a_probe_fit_lacks(tmp_path):
    path, _ = refsim_session(tmp_path, "AC-trt", reference_errors("AC-trt", 3), {}, rho=0.0, seed=3)
    r = run("identify", path)
    assert r.returncode == 0, r.stderr
    assert "joint identification, AC-trt, 120 touches" in r.stdout
    assert "sphere centre (table frame)" in r.stdout and "uncertainty budget" in r.stdout
    r = run("identify", path, "--method", "cycles-free-radius")
    assert r.returncode == 0 and "dispersion of the sphere centres" in r.stdout
    model = tmp_path / "m.json"
    r = run("identify", path, "--method", "cycles", "--save-model", model)
    assert r.returncode == 3 and "gives none" in r.stderr and not model.exists()
    for bad in (
        ["--method", "paper"],
        ["--length-offset"],
        ["--method", "cycles", "--monte-carlo", "10"],
    ):
        r = run("identify", path, *bad)
        assert r.returncode == 3 and r.stdout == "", bad
    # The cycles' method is the touch probe's: a ballbar session refuses it.
    ballbar = Path(__file__).resolve().parents[3] / "shared" / "data" / "ballbar_ac_table2.csv"
    assert run("identify", ballbar, "--method", "cycles").returncode == 3


def test_diagnose_finds_the_stylus_offset_of_a_reference_session(tmp_path):
    path, _ = refsim_session(
        tmp_path,
        "AC-trt",
        reference_errors("AC-trt", 7),
        {"stylus_radius_offset": 2e-3},
        rho=0.0,
        seed=7,
    )
    r = run("diagnose", path, "--json", "--no-progress")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    first = d["findings"][0]
    assert first["effect"] == "stylus_radius_offset"
    p = first["parameters"]["stylus_radius_offset"]
    assert abs(p["value"] - 2e-3) <= 3 * p["std"]
    r = run("diagnose", path, "--no-progress", "--no-budget")
    assert r.returncode == 0 and "stylus_radius_offset" in r.stdout
