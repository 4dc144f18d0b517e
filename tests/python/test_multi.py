# SPDX-License-Identifier: BSD-3-Clause
"""One identification from several sessions of one machine (issue 31, item 5) from Python:
sessions made by the independent reference simulator (tests/reference/refsim, AR(1) noise, one
machine with several location errors) -- ballbar + probe, and ballbar + R-test -- are identified
jointly by rotacal.identify([...]) within 3 sigma of the truth, each session with its own
nuisances; sessions of two machine types are refused by name. The truth comes from refsim."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
import refsim  # noqa: E402
from refsim import noise, poses, writers  # noqa: E402

import rotacal  # noqa: E402
from conftest import run_cli  # noqa: E402
from test_json_schema import check, schemas  # noqa: E402

MACHINE = "AC-trt"


def truth_errors(machine: str) -> dict:
    names = refsim.builtin(machine).error_names()
    values = [0.028, -0.019, 2.4e-5, -3.1e-5, 0.012, 0.035, -1.6e-5, 2.2e-5]
    return dict(zip(names, values))


def ballbar_file(tmp_path, machine: str, errors: dict, seed: int) -> Path:
    m = refsim.builtin(machine)
    s = poses.ballbar_single_setup(m)
    model = refsim.Model(m, errors)
    length = refsim.ballbar_lengths(
        model,
        s["pivot"] + np.array([0.012, -0.008, 0.015]),
        s["xyz"],
        np.radians(s["angles_deg"]),
        s["time"],
    )
    length = length + noise.ar1(s["test"], 0.5, 5e-4, np.random.default_rng(seed))
    return writers.write_ballbar(tmp_path / f"bb_{machine}_{seed}.csv", m, s, length, noise_um=0.5)


def probe_file(tmp_path, machine: str, errors: dict, seed: int) -> Path:
    m = refsim.builtin(machine)
    ses = poses.probe_poses(m)
    sphere_actual = ses["sphere"] + np.array([0.031, -0.024, 0.017])
    latched = refsim.probe_touches(
        refsim.Model(m, errors),
        sphere_actual,
        ses["sphere"],
        25.0,
        6.0,
        ses["n"],
        np.radians(ses["angles_deg"]),
        ses["time"],
    )
    rng = np.random.default_rng(seed)
    one = ["touches"] * len(latched)
    latched = latched + np.column_stack([noise.ar1(one, 0.6, 5e-4, rng) for _ in range(3)])
    return writers.write_probe(
        tmp_path / f"probe_{machine}_{seed}.csv", m, ses, latched, 25.0, 6.0, noise_um=0.5
    )


def rtest_file(tmp_path, machine: str, errors: dict, seed: int) -> Path:
    m = refsim.builtin(machine)
    s = poses.rtest_grid(m)
    d = refsim.rtest_displacements(
        refsim.Model(m, errors),
        s["nests"],
        s["setup"],
        s["xyz"],
        np.radians(s["angles_deg"]),
        s["time"],
    )
    rng = np.random.default_rng(seed)
    d = d + np.stack([noise.ar1(s["setup"], 0.5, 5e-4, rng) for _ in range(3)], axis=1)
    d = d + np.array([0.2, -0.1, 0.05])  # the probe zeros: the sessions' own nuisances
    return writers.write_rtest(tmp_path / f"rt_{machine}_{seed}.csv", m, s, d, noise_um=0.5)


def off_by_more_than_3_sigma(result: dict, errors: dict) -> list:
    out = []
    for name, truth in errors.items():
        e = result["location_errors"][name]
        if e.get("observable", True) and abs(e["value"] - truth) > 3 * e["std"]:
            out.append((name, e["value"], e["std"], truth))
    return out


@pytest.mark.parametrize("second", ["probe", "rtest"])
def test_joint_identification_within_3_sigma(tmp_path, second):
    errors = truth_errors(MACHINE)
    make = probe_file if second == "probe" else rtest_file
    sessions = [
        rotacal.load(ballbar_file(tmp_path, MACHINE, errors, 5)),
        rotacal.load(make(tmp_path, MACHINE, errors, 6)),
    ]
    r = rotacal.identify(sessions)
    d = r.to_dict()
    assert d["converged"]
    assert [s["instrument"] for s in d["sessions"]] == ["ballbar", second]
    assert not off_by_more_than_3_sigma(d, errors), off_by_more_than_3_sigma(d, errors)
    observable = [n for n, e in d["location_errors"].items() if e.get("observable", True)]
    assert len(observable) >= 6, d["unobservable"]
    assert set(d["sessions"][0]["nuisances"]) == {"pivot_x", "pivot_y", "pivot_z"}
    assert len(d["sessions"][1]["nuisances"]) >= 3  # the sphere, or the probe zeros
    assert not d["disagreements"], d["disagreements"]
    for name in observable:  # the joint sigma is no larger than either session's alone
        for s in d["sessions"]:
            alone = s["alone"][name]
            if alone.get("observable", True):
                assert d["location_errors"][name]["std"] <= alone["std"] * 1.0001, (name, s["name"])


def test_sessions_of_two_machine_types_are_refused(tmp_path):
    a = rotacal.load(ballbar_file(tmp_path, "AC-trt", truth_errors("AC-trt"), 1))
    b = rotacal.load(probe_file(tmp_path, "BC-trt", truth_errors("BC-trt"), 2))
    with pytest.raises(rotacal.InvalidArgument, match="session 2"):
        rotacal.identify([a, b])


def test_cli_joint_identification_reports_a_planted_disagreement(tmp_path):
    errors = truth_errors(MACHINE)
    moved = dict(
        errors, E_X0C=errors["E_X0C"] + 0.030
    )  # the probe's machine, 30 um off in one error
    bb, pr = ballbar_file(tmp_path, MACHINE, errors, 7), probe_file(tmp_path, MACHINE, moved, 8)
    r = run_cli("identify", bb, pr, "--json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    named = schemas()  # the documented JSON (docs/json_schema.md), its noise model by name
    schema = named["joint_identification"]
    schema["sessions"][0]["noise_model"] = named["noise_model"]
    check(d, schema, "joint", named)
    assert [s["name"] for s in d["sessions"]] == [str(bb), str(pr)]
    found = [g for g in d["disagreements"] if g["parameter"] == "E_X0C"]
    assert found and found[0]["sessions"] == [str(bb), str(pr)], d["disagreements"]
    assert abs(found[0]["difference"] + 0.030) <= 3 * found[0]["sigma"]
    assert abs(found[0]["z"]) > 3
    text = run_cli("identify", bb, pr, cwd=tmp_path)
    assert text.returncode == 0 and "DISAGREE E_X0C" in text.stdout, text.stdout + text.stderr
    refused = run_cli("identify", bb, pr, "--monte-carlo", "10", cwd=tmp_path)
    assert refused.returncode != 0 and "--monte-carlo" in refused.stderr


def test_shared_effect_within_3_sigma(tmp_path):
    """A gravity sag of A on the machine, fitted once for both sessions (refsim truth)."""
    errors = truth_errors(MACHINE)
    sag = {"gravity_sag_A": 0.004}
    m = refsim.builtin(MACHINE)
    s = poses.ballbar_single_setup(m)
    length = refsim.ballbar_lengths(
        refsim.Model(m, errors, sag), s["pivot"], s["xyz"], np.radians(s["angles_deg"]), s["time"]
    ) + noise.ar1(s["test"], 0.5, 5e-4, np.random.default_rng(11))
    bb = writers.write_ballbar(tmp_path / "bb_sag.csv", m, s, length, noise_um=0.5)
    ses = poses.probe_poses(m)
    latched = refsim.probe_touches(
        refsim.Model(m, errors, sag),
        ses["sphere"],
        ses["sphere"],
        25.0,
        6.0,
        ses["n"],
        np.radians(ses["angles_deg"]),
        ses["time"],
    )
    latched = latched + np.random.default_rng(12).normal(0.0, 5e-4, latched.shape)
    pr = writers.write_probe(tmp_path / "probe_sag.csv", m, ses, latched, 25.0, 6.0, noise_um=0.5)
    d = rotacal.identify([rotacal.load(bb), rotacal.load(pr)], effects=["gravity_sag_A"]).to_dict()
    e = d["effects"]["gravity_sag_A"]
    assert e["std"] < 0.001 and abs(e["value"] - 0.004) <= 3 * e["std"], e
    assert not off_by_more_than_3_sigma(d, errors), off_by_more_than_3_sigma(d, errors)
    assert all("gravity_sag_A" not in s["nuisances"] for s in d["sessions"])
