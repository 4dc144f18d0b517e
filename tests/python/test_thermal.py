# SPDX-License-Identifier: BSD-3-Clause
"""`rotacal identify` of a thermal session (issue 53): the shared thermal_probe_ac.csv judged
against its truth, a reference-simulator session without drift (no significant drift), and bad
input refused by file and line. The fit's own numbers are checked in tests/cpp/test_*_thermal.cpp;
here the command line and the binding around it."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
import refsim  # noqa: E402
from refsim import thermal, writers  # noqa: E402

from conftest import run_cli as run  # noqa: E402
from conftest import SHARED, truth  # noqa: E402


def test_shared_thermal_probe_identified(shared_data):
    f = shared_data / "thermal_probe_ac.csv"
    t = truth(f)["thermal"][0]
    r = run("identify", f, "--tolerance", "5um", "--tolerance", "10urad", "--json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    lag = d["identification"]["lags"][0]
    assert abs(lag["tau_s"] - t["tau_s"]) <= 3 * lag["tau_std_s"]
    for g in lag["gains"]:
        assert g["observable"], g
        assert abs(g["value"] - t["gains"][g["name"]]) <= 3 * g["std"], g
    s = d["summary"]
    assert s["axis"] == "C" and s["tested_speed_rpm"] == 300 and not s["no_significant_drift"]
    by_name = {e["name"]: e for e in s["drifts"]}
    x = by_name["E_X0C"]  # truth -7.7 um per 100 rev/min: -23 um at 300, over 5 um
    assert x["significant"] and x["tolerance"] == pytest.approx(0.005)
    assert 0 < x["exceeds_after_s"] < t["tau_s"]
    assert by_name["E_A0C"]["tolerance"] == pytest.approx(1e-5)
    text = run("identify", f, "--tolerance", "5um", "--peer")
    assert text.returncode == 0, text.stderr
    joint, peer = text.stdout.split("the per-epoch peer")
    assert "thermal test of axis C at 300 rev/min: 1480 rows in 37 epochs" in joint
    assert "lag 1: tau = " in joint and "never exceeds 5.000 um" in joint
    assert "lag 1: tau = " in peer and "note: per-epoch peer" in peer


def _refsim_session(path, lags, seed=1, interval_s=1200.0, effects=None, rho=0.0):
    """AC-trt probe, C at 300 rev/min for 4 h then at rest to 6 h, an epoch of 8 poses x 5
    touches every `interval_s`; the shared file's cold errors and set-up, the drift of `lags`
    (refsim.thermal: the truth's "thermal" list), catalogue `effects` beside it, 0.5 um noise
    along each approach: white, or AR(1) with `rho` from touch to touch."""
    t = truth(SHARED / "thermal_probe_ac.csv")
    dirs = refsim.poses.probe_directions()
    poses = [(0.0, c) for c in (0, 90, 180, 270)] + [(a, 0.0) for a in (-60, -30, 30, 60)]
    pose, time, ang, n, epoch = [], [], [], [], []
    for e in range(int(6 * 3600 / interval_s) + 1):
        for k, (a, c) in enumerate(poses):
            for j, d in enumerate(dirs):
                pose.append(len(poses) * e + k + 1)
                time.append(interval_s * e + 16.0 * k + 2.0 * j)
                ang.append((a, c))
                n.append(d)
                epoch.append(e + 1)
    s = {"pose": pose, "time": np.array(time), "angles_deg": np.array(ang), "n": np.array(n)}
    s["sphere"] = np.array([150.0, 0.0, 80.0])
    duty = [(0.0, {"C": 300.0}), (14400.0, {"C": 0.0})]
    errors, sphere = thermal.drifted(t["errors"], t["sphere_actual"], lags, duty, time, epoch)
    latched = refsim.probe_touches(
        refsim.Model("AC-trt", errors, effects),
        sphere,
        s["sphere"],
        25.0,
        6.0,
        s["n"],
        np.radians(s["angles_deg"]),
        s["time"],
    )
    rng = np.random.default_rng(seed)
    e = refsim.noise.ar1(["touches"] * len(time), rho, 5e-4, rng)
    latched = latched + s["n"] * e[:, None]
    writers.write_probe(path, refsim.builtin("AC-trt"), s, latched, 25.0, 6.0, noise_um=0.5)
    thermal.add_thermal_columns(path, duty, epoch)
    return path


def test_no_drift_gives_no_significant_drift(tmp_path):
    r = run("identify", _refsim_session(tmp_path / "null.csv", []), "--tolerance", "5um", "--json")
    assert r.returncode == 0, r.stderr
    summary = json.loads(r.stdout)["summary"]
    assert summary["no_significant_drift"]
    drifts = summary["drifts"]
    assert len(drifts) == 11
    for e in drifts:
        assert e["observable"], e
        assert not e["significant"], e
        assert abs(e["steady_change"]) <= 3 * e["steady_std"]
        if e["unit"] == "mm":  # 0 +- sub-um: never 5 um
            assert e["exceeds_after_s"] is None, e
        else:  # no tolerance given for the orientations: no time either
            assert "tolerance" not in e and "exceeds_after_s" not in e


def _drift_test(path):
    from rotacal import _core

    return _core.identify_thermal(str(path))


def _joint_at_least_each_gain(d):
    """W = z^T R^-1 z >= z_k^2 for every gain k (Cauchy-Schwarz): the joint statistic is never
    below the largest single gain's (value / sigma)^2 of the same covariance."""
    t = d["summary"]["drift_test"]
    gains = d["identification"]["lags"][0]["gains"]
    z2 = max((g["value"] / g["std"]) ** 2 for g in gains if g["observable"])
    assert t["statistic"] >= z2 * (1 - 1e-9), (t, z2)
    assert t["gains"] == sum(g["observable"] for g in gains)


def test_joint_drift_test_decides_whether_the_session_drifts(tmp_path):
    """One test of all gains against 0 (summary's drift_test, F at 1 %): a reference-simulator
    session without drift passes, white and AR(1) 0.9 (where the noise model's effective
    samples, 53 of 760 here, give the dof: 31); the shared session and one whose gains are 1/20
    of its truth (E_X0C's steady change 1.2 um) are found drifting.
    The false-alarm rate itself is bench/thermal_bench.py's (500 null sessions)."""
    white = _drift_test(_refsim_session(tmp_path / "null.csv", []))
    t = white["summary"]["drift_test"]
    assert not t["drift_found"] and white["summary"]["no_significant_drift"], t
    assert t["level"] == 0.01 and t["gains"] == 11 and 0.01 <= t["p_value"] <= 1
    assert t["residual_dof"] == white["identification"]["n_samples"] - 23
    _joint_at_least_each_gain(white)
    ar = _drift_test(_refsim_session(tmp_path / "ar.csv", [], seed=3, rho=0.9))
    t = ar["summary"]["drift_test"]
    assert ar["identification"]["noise_model"], ar["identification"]
    assert not t["drift_found"] and t["residual_dof"] < ar["identification"]["n_samples"] / 2, t
    _joint_at_least_each_gain(ar)
    lags = truth(SHARED / "thermal_probe_ac.csv")["thermal"]
    small = [lags[0] | {"gains": {k: v / 20 for k, v in lags[0]["gains"].items()}}]
    d = _drift_test(_refsim_session(tmp_path / "small.csv", small, seed=5, interval_s=600.0))
    t = d["summary"]["drift_test"]
    assert t["drift_found"] and not d["summary"]["no_significant_drift"], t
    _joint_at_least_each_gain(d)
    full = _drift_test(SHARED / "thermal_probe_ac.csv")["summary"]["drift_test"]
    assert full["drift_found"] and full["p_value"] < 1e-12, full


def test_two_lags_identified(tmp_path):
    """tau2 = 4 tau1, K2 = 0.7 K1 (the issue's two-lag case) in a 6 h test, epochs every 10 min:
    both taus and all 22 gains within 3 sigma; one lag leaves a lack of fit."""
    k1 = truth(SHARED / "thermal_probe_ac.csv")["thermal"][0]["gains"]
    lags = [
        {"axis": "C", "tau_s": 1200.0, "gains": k1},
        {"axis": "C", "tau_s": 4800.0, "gains": {k: 0.7 * v for k, v in k1.items()}},
    ]
    f = _refsim_session(tmp_path / "two.csv", lags, interval_s=600.0)
    r = run("identify", f, "--lags", "2", "--noise", "white", "--json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)["identification"]
    assert d["converged"] and len(d["lags"]) == 2
    for got, want in zip(d["lags"], lags):
        assert abs(got["tau_s"] - want["tau_s"]) <= 3 * got["tau_std_s"], got["tau_s"]
        for g in got["gains"]:
            assert g["observable"], g
            assert abs(g["value"] - want["gains"][g["name"]]) <= 3 * g["std"], g
    assert d["residual_rms_um"] < 0.55  # noise 0.5 um
    one = json.loads(run("identify", f, "--noise", "white", "--json").stdout)["identification"]
    assert one["residual_rms_um"] > 0.65  # 0.71 um: one lag cannot follow both


def _within_3_sigma(d, lags):
    for got, want in zip(d["lags"], lags):
        assert abs(got["tau_s"] - want["tau_s"]) <= 3 * got["tau_std_s"], got["tau_s"]
        for g in got["gains"]:
            assert g["observable"], g
            assert abs(g["value"] - want["gains"][g["name"]]) <= 3 * g["std"], g


def test_coloured_noise_identified_with_the_noise_model(tmp_path):
    """AR(1) 0.8 noise from touch to touch: the noise model finds it (and its GLS fit is the
    sharper one here: tau +- 5.3 s against white's 10.9) and the drift stays within 3 sigma of
    the truth."""
    lags = truth(SHARED / "thermal_probe_ac.csv")["thermal"]
    f = _refsim_session(tmp_path / "ar.csv", lags, seed=7, interval_s=600.0, rho=0.8)
    d = json.loads(run("identify", f, "--json").stdout)["identification"]
    assert d["noise_model"], d["noise_model"]  # correlated noise named
    _within_3_sigma(d, lags)


def test_a_static_effect_beside_the_drift_stays_out_of_it(tmp_path):
    """An oval C bearing track (radial_motion_C_h2, 3 um, not in the thermal model) the same in
    every epoch: the gains come from what changes with the lag state, so they stay within 3
    sigma of the truth; the effect shows as lack of fit, not as drift."""
    lags = truth(SHARED / "thermal_probe_ac.csv")["thermal"]
    fx = {"radial_motion_C_h2": [0.003, 0.0, 0.0, 0.003]}
    f = _refsim_session(tmp_path / "oval.csv", lags, seed=8, interval_s=600.0, effects=fx)
    d = json.loads(run("identify", f, "--noise", "white", "--json").stdout)["identification"]
    _within_3_sigma(d, lags)
    assert d["residual_rms_um"] > 0.7  # noise 0.5 um: the oval is left over


HEAD = (
    "# format: rotacal-probe/1\n# machine: AC-trt\n# units: mm, deg, s\n"
    "# sphere: 150.0000, 0.0000, 80.0000\n# sphere_diameter: 25.0000\n# stylus_diameter: 6.0000\n"
)
ROW = "149.999348,0.000453,95.464574,0.0000,0.0000,0.000000,0.000000,-1.000000"


@pytest.mark.parametrize(
    "duty,columns,rows,line,says",
    [
        ("# duty.1: 0, B=300\n", ",epoch", ["1", "1"], 7, "names axis 'B'"),
        ("# duty.1: 0, C=300\n", ",epoch", ["2", "1"], 10, "epochs never decrease"),
        ("# duty.1: 0, C=300\n", "", ["", ""], 7, "need an 'epoch' column"),
    ],
)
def test_bad_thermal_input_refused_by_file_and_line(tmp_path, duty, columns, rows, line, says):
    body = "".join(f"{k + 1},{2.0 * k},{ROW}{',' + e if e else ''}\n" for k, e in enumerate(rows))
    f = tmp_path / "bad.csv"
    f.write_text(HEAD + duty + "pose,time,X,Y,Z,A,C,nx,ny,nz" + columns + "\n" + body)
    r = run("identify", f)
    assert r.returncode == 3, (r.stdout, r.stderr)
    assert f"{f}:{line}" in r.stderr and says in r.stderr, r.stderr


def test_thermal_options_refused_where_they_do_not_apply(shared_data):
    r = run("identify", shared_data / "probe_ac_table2.csv", "--tolerance", "5um")
    assert r.returncode == 3 and "for a thermal session" in r.stderr
    r = run("identify", shared_data / "thermal_probe_ac.csv", "--tolerance", "5 furlongs")
    assert r.returncode == 3 and "--tolerance" in r.stderr
    r = run("identify", shared_data / "thermal_probe_ac.csv", "--monte-carlo", "5")
    assert r.returncode == 3 and "--monte-carlo: not for a thermal session" in r.stderr


def test_diagnose_gives_a_thermal_finding_only_where_the_session_drifts(tmp_path, shared_data):
    """`rotacal diagnose` of a thermal session adds the joint drift test (issue 53 item 4: a
    session with no drift gives no thermal finding); its catalogue still pools the epochs."""
    null = _refsim_session(tmp_path / "null.csv", [])
    r = run("diagnose", null, "--no-budget", "--json")
    assert r.returncode == 0, r.stderr
    f = json.loads(r.stdout)["thermal"]
    assert not f["drift_found"] and f["drift_test"]["gains"] == 11 and not f["significant"], f
    assert "pooled" in f["baseline"]
    text = run("diagnose", shared_data / "thermal_probe_ac.csv", "--no-budget")
    assert text.returncode == 0, text.stderr
    assert "thermal, axis C: joint test of the 11 gains" in text.stdout
    assert "thermal drift found" in text.stdout and "E_X0C" in text.stdout
