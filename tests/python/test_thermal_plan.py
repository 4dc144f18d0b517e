# SPDX-License-Identifier: BSD-3-Clause
"""`rotacal simulate thermal` and `rotacal plan thermal` (issue 53, items 1 and 2).

- rotacal's own simulators with a thermal drift (two lags, another catalogue effect beside them)
  against the reference simulator's thermal extension (tests/reference/refsim/thermal.py) on
  the same truth, noise 0: the probe's latched touches and the R-test's readings agree;
- the simulated file is read back by the identify path;
- the plan's program runs the duty between the epochs and LinuxCNC's interpreter (rs274)
  accepts it; its template is a thermal session with the duty; a speed above --max-speed and
  an interval shorter than an epoch are refused.
Identification accuracy is judged on reference-simulator sessions (test_thermal.py)."""

import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

import rotacal

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
import refsim  # noqa: E402
from refsim import thermal, writers  # noqa: E402

from conftest import run_cli as run  # noqa: E402

TWO_LAGS = [  # tau, then gains per lag (mm, rad per 100 rev/min)
    "--tau", "20min", "--tau", "80min",
    "--gain", "E_X0C=-0.004,-0.003", "--gain", "E_Y0C=0.002,0.0015",
    "--gain", "E_A0C=8e-6,5e-6", "--gain", "q_z=0.003,0.002",
]  # fmt: skip


def _columns(path):
    s = writers.read_session(path)
    return s["meta"], s["columns"]


def test_simulated_probe_matches_the_reference_simulator(tmp_path):
    out, truth_path = tmp_path / "t.csv", tmp_path / "t.truth.json"
    r = run(
        "simulate", "thermal", "--machine", "AC-trt", "--errors", "random", "--seed", "3",
        "--effect", "stylus_radius_offset=0.002", *TWO_LAGS, "--heat", "2h", "--cool", "1h",
        "--interval", "30min", "--noise", "0", "-o", out, "--truth", truth_path,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "7 epochs" in r.stderr and "2 lag(s)" in r.stderr
    meta, c = _columns(out)
    t = json.loads(truth_path.read_text())
    duty = thermal.parse_duty(meta)
    assert duty == [(0.0, {"C": 300.0}), (7200.0, {"C": 0.0})]
    assert sorted(set(c["epoch"].astype(int))) == list(range(1, 8))
    errs, q = thermal.drifted(
        t["errors"], t["sphere_actual"], t["thermal"], duty, c["time"], c["epoch"]
    )
    latched = refsim.probe_touches(
        refsim.Model("AC-trt", errs, t["effects"]),
        q,
        writers.vector(meta["sphere"]),
        25.0,
        6.0,
        np.c_[c["nx"], c["ny"], c["nz"]],
        np.radians(np.c_[c["A"], c["C"]]),
        c["time"],
    )
    assert np.abs(np.c_[c["X"], c["Y"], c["Z"]] - latched).max() < 2e-6  # 6 decimals written
    # The drift is there: the cold model misses by far more.
    cold = refsim.probe_touches(
        refsim.Model("AC-trt", t["errors"], t["effects"]),
        np.asarray(t["sphere_actual"]),
        writers.vector(meta["sphere"]),
        25.0,
        6.0,
        np.c_[c["nx"], c["ny"], c["nz"]],
        np.radians(np.c_[c["A"], c["C"]]),
        c["time"],
    )
    assert np.abs(np.c_[c["X"], c["Y"], c["Z"]] - cold).max() > 3e-3


def test_simulated_rtest_matches_the_reference_simulator_and_is_identified(tmp_path):
    out, truth_path = tmp_path / "r.csv", tmp_path / "r.truth.json"
    r = run(
        "simulate", "thermal", "--instrument", "rtest", "--machine", "BC-trt", "--seed", "4",
        "--effect", "radial_motion_C_h2=0.002,0.001,-0.001,0.0015", *TWO_LAGS, "--heat", "3h",
        "--cool", "1h", "--noise", "0", "-o", out, "--truth", truth_path,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    meta, c = _columns(out)
    t = json.loads(truth_path.read_text())
    duty = thermal.parse_duty(meta)
    errs, q = thermal.drifted(t["errors"], t["nests"][0], t["thermal"], duty, c["time"], c["epoch"])
    d = refsim.rtest_displacements(
        refsim.Model("BC-trt", errs, t["effects"]),
        {"1": np.zeros(3)},  # the nest moves per row: subtracted below
        ["1"] * len(c["time"]),
        np.c_[c["X"], c["Y"], c["Z"]],
        np.radians(np.c_[c["B"], c["C"]]),
        c["time"],
    )
    got = np.c_[c["dx"], c["dy"], c["dz"]] - (d - q)
    assert np.abs(got - np.asarray(t["probe_zeros"][0])).max() < 2e-6
    # Read back by the identify path (one lag of two: a fit, not a judgement of its accuracy).
    r = run("identify", out, "--noise", "white", "--json")
    assert r.returncode == 0, r.stderr
    ident = json.loads(r.stdout)["identification"]
    assert ident["n_epochs"] == 25 and ident["n_samples"] == len(c["time"])


RS274 = shutil.which("rs274")


def _plan(tmp_path, *extra):
    ngc, tpl = tmp_path / "thermal.ngc", tmp_path / "thermal.csv"
    r = run(
        "plan", "thermal", "--machine", "AC-trt", "--axis", "C", "--speed", "300",
        "--heat", "1h", "--cool", "30min", "--interval", "10min", *extra,
        "-o", ngc, "--session", tpl,
    )  # fmt: skip
    return r, ngc, tpl


def test_plan_thermal_program_and_template(tmp_path):
    r, ngc, tpl = _plan(tmp_path)
    assert r.returncode == 0, r.stderr
    text = ngc.read_text()
    # 10 epochs; the heat-up's 6 intervals turn C (half the revolutions each way), then dwell.
    assert text.count("(epoch ") == 10
    turns = [ln for ln in text.splitlines() if ln.startswith("G1 C")]
    assert len(turns) == 12 and all("F108000.0" in ln for ln in turns)
    # 600 s - 128 s of epoch at 300 rev/min: 2360 revolutions, 1180 each way.
    assert turns[0].startswith("G1 C424800.0000") and turns[1].startswith("G1 C-424800.0000")
    assert text.count("G4 P472.0") == 3
    meta, c = _columns(tpl)
    assert thermal.parse_duty(meta) == [(0.0, {"C": 300.0}), (3600.0, {"C": 0.0})]
    assert int(c["epoch"].max()) == 10 and len(c["epoch"]) == 10 * 8 * 5
    assert text.count("(LOG,") == len(c["epoch"])  # one latched line per touch of the template
    assert rotacal._core.is_thermal_session(str(tpl))


def test_plan_thermal_refusals(tmp_path):
    r, _, _ = _plan(tmp_path, "--max-speed", "200")
    assert r.returncode == 3 and "--max-speed 200" in r.stderr
    r, _, _ = _plan(tmp_path, "--interval", "1min")
    assert r.returncode != 0 and "longer than an epoch" in r.stderr
    r = run("plan", "probe", "--heat", "1h", "-o", tmp_path / "p.ngc")
    assert r.returncode == 3 and "belong to plan thermal" in r.stderr


@pytest.mark.skipif(RS274 is None, reason="rs274 (LinuxCNC's interpreter) not on PATH")
def test_rs274_runs_the_thermal_programs(tmp_path):
    """The endless C and the tilting A as the heated axis: LinuxCNC's interpreter reaches M2, the
    C turns come back to where they started, the A swings between the epoch's tilts."""
    from test_linuxcnc import run_rs274

    r, ngc, _ = _plan(tmp_path)
    assert r.returncode == 0, r.stderr
    canon = run_rs274(ngc.read_text(), tmp_path)
    probes = [a for n, a in canon if n == "STRAIGHT_PROBE"]
    assert len(probes) == 10 * 8 * 5
    (tmp_path / "a").mkdir()
    r, ngc, _ = _plan(tmp_path / "a", "--axis", "A", "--speed", "20")
    assert r.returncode == 0, r.stderr
    canon = run_rs274(ngc.read_text(), tmp_path / "a")
    a_ends = [float(a.split(",")[3]) for n, a in canon if n == "STRAIGHT_FEED"]
    assert min(a_ends) == pytest.approx(-60.0) and max(a_ends) == pytest.approx(60.0)


def test_design_thermal_chooses_among_intervals_and_poses(tmp_path):
    """More epochs in the same test time bound the drift better: at every pose set the 10 min
    interval's largest U(k=2)/|prior| is below the 30 min one's; the best design's poses are a
    valid plan."""
    r = run("design", "thermal", "--intervals", "10,30", "--json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    by = {(c["interval_min"], c["poses"]): c for c in d["candidates"]}
    for poses in ("6 poses", "8 poses", "10 poses"):
        assert by[(10, poses)]["worst"] < by[(30, poses)]["worst"]
        assert by[(10, poses)]["epochs"] == 37 and by[(10, poses)]["unobservable"] == []
    best = d["best"]
    assert best["worst"] == min(c["worst"] for c in d["candidates"])
    assert best["state_change"] == pytest.approx(1 - np.exp(-best["epoch_s"] / 1800.0))
    r, _, _ = _plan(tmp_path, "--poses", best["poses_deg"])
    assert r.returncode == 0, r.stderr


def test_simulated_coloured_noise(tmp_path):
    """--rho makes the noise AR(1) from row to row, white without it: the difference from the
    same session without noise, touch after touch."""
    base = ["simulate", "thermal", "--errors", "zero", "--gain", "E_X0C=0.004", "--heat", "2h"]
    base += ["--cool", "1h", "--interval", "10min", "--seed", "9"]
    clean = tmp_path / "clean.csv"
    assert run(*base, "--noise", "0", "-o", clean).returncode == 0
    _, c0 = _columns(clean)
    x0 = np.c_[c0["X"], c0["Y"], c0["Z"]]
    lag1 = {}
    for rho in ("0", "0.8"):
        f = tmp_path / f"rho{rho}.csv"
        assert run(*base, "--noise", "1", "--rho", rho, "-o", f).returncode == 0
        _, c = _columns(f)
        e = (np.c_[c["X"], c["Y"], c["Z"]] - x0)[:, 0] * 1e3  # um, X of each touch
        assert 0.8 < e.std() < 1.2
        lag1[rho] = np.corrcoef(e[:-1], e[1:])[0, 1]
    assert abs(lag1["0"]) < 0.1 and 0.7 < lag1["0.8"] < 0.9, lag1  # measured 0.002, 0.81
