# SPDX-License-Identifier: BSD-3-Clause
"""R-test from Python: identification of the independent implementation's file against its truth."""

import json
import re

import numpy as np
import pytest

import rotacal
from conftest import run_cli as rotacal_cli
from conftest import split_by_c, truth


@pytest.fixture(scope="module")
def oyama(shared_data):
    path = shared_data / "rtest_bc_oyama.csv"
    return rotacal.load(path), truth(path)


def test_joint_identification_against_truth(oyama):
    s, t = oyama
    d = rotacal.identify(s).to_dict()
    assert d["method"] == "joint" and d["converged"] and d["n_samples"] == 168
    for n, v in d["location_errors"].items():
        assert abs(v["value"] - t["errors"][n]) <= 4 * v["std"], (n, v, t["errors"][n])
    assert abs(d["residual_rms_um"] - t["noise_um"]) < 0.15 * t["noise_um"]
    # The map shows what the paper reported: dz_BY grows towards B = +-90 (gravity sag,
    # -s (1 - cos B)) and alpha_BY varies linearly with B (coning, k B).
    by = {e["B"]: e for e in d["error_map"]["entries"] if e["C"] == 0}
    s_true, k_true = t["effects"]["gravity_sag_B"], t["effects"]["coning_B"]
    for b in (-90, 90):
        dz, dz_std = by[b]["BY"][2], by[b]["BY_std"][2]
        assert abs(dz - (-s_true)) <= 4 * dz_std, (b, dz, dz_std)
        alpha, alpha_std = by[b]["BY"][3], by[b]["BY_std"][3]
        assert abs(alpha - k_true * np.radians(b)) <= 4 * alpha_std, (b, alpha, alpha_std)


def test_paper_method_lists_its_assumptions(oyama):
    s, _ = oyama
    d = rotacal.identify(s, method="paper").to_dict()
    assert d["method"] == "paper" and len(d["error_map"]["entries"]) == 84
    assert any("B1 = C1 = 0" in n for n in d["notes"])
    with pytest.raises(rotacal.InvalidArgument, match="method"):
        rotacal.identify(s, method="other")


def test_cli_identify_rtest(shared_data, tmp_path):
    r = rotacal_cli("identify", shared_data / "rtest_bc_oyama.csv")
    assert r.returncode == 0, r.stderr
    assert set(json.loads(r.stdout)["location_errors"]) >= {"E_X0B", "E_Z0B", "E_X0C", "E_Y0C"}
    r = rotacal_cli(
        "identify",
        shared_data / "rtest_bc_oyama.csv",
        "--method",
        "paper",
        "--save-model",
        tmp_path / "m.json",
    )
    assert r.returncode == 3 and "--method joint" in r.stderr and not (tmp_path / "m.json").exists()


# ------------------------------------------------------------------------- simulate, model files, predict

EFFECTS = [
    "--effect",
    "gravity_sag_B=0.006",
    "--effect",
    "coning_B=0.000145",
    "--effect",
    "axial_motion_C_h2=0.002,-0.001",
]


@pytest.fixture(scope="module")
def held_out(tmp_path_factory):
    """Simulate C = 0, 15, ..., 345; fit on C = 0, 30, ...; predict C = 15, 45, ... through files."""
    tmp = tmp_path_factory.mktemp("heldout")
    r = rotacal_cli(
        "simulate", "rtest", "--c-step", "15", *EFFECTS, "--seed", "11", "-o", tmp / "s.csv"
    )
    assert r.returncode == 0, r.stderr
    fit, held = split_by_c(tmp / "s.csv", 30)
    r = rotacal_cli("identify", fit, "--save-model", tmp / "m.json")
    assert r.returncode == 0, r.stderr
    r = rotacal_cli(
        "predict", held, "--model", tmp / "m.json", "--probe-zeros", "fitted", "-o", tmp / "p.csv"
    )
    assert r.returncode == 0, r.stderr
    return tmp, fit, held, json.loads((tmp / "s.truth.json").read_text()), r.stderr


def test_held_out_poses_are_predicted_to_the_noise(held_out):
    tmp, fit, held, truth, stderr = held_out
    s_held = rotacal.load(held)
    pred = rotacal.load(tmp / "p.csv")
    assert len(s_held) == len(pred) == 168 and set(np.asarray(pred.angles_deg)[:, 1] % 30) == {15.0}
    # Truth: the noise-free readings of the simulated machine with each set-up's probe zero.
    d_true = rotacal.rtest.truth_readings(truth, s_held)
    err = np.asarray(pred.d) - d_true
    noise = truth["noise_um"] * 1e-3
    rms = np.sqrt(np.mean(err**2))
    # The model's own error: noise * sqrt(p / n) ~ 0.3 * sqrt(70 / 504) um; the bound is 2x noise.
    assert rms < 2 * noise, rms
    assert rms < 0.5 * noise, rms  # what the estimate above says it should be
    # The 1-sigma columns account for it (probe-zero uncertainty noise / sqrt(84) added).
    std = np.array(
        [
            [float(v) for v in row.split(",")[-3:]]
            for row in (tmp / "p.csv").read_text().splitlines()
            if row[:1].isdigit()
        ]
    )
    assert std.shape == err.shape and np.all(std > 0)
    z = err / np.hypot(std, noise / np.sqrt(84))
    assert 0.3 < np.sqrt(np.mean(z**2)) < 2.0
    # The CLI's measured - predicted RMS (one offset per set-up removed) is the noise.
    rms_cli = float(re.search(r"RMS ([0-9.]+) um", stderr).group(1))
    assert abs(rms_cli - truth["noise_um"]) < 0.15 * truth["noise_um"]


def test_model_file_round_trip_predicts_as_in_memory(held_out):
    tmp, fit, held, truth, _ = held_out
    ident = rotacal.identify_rtest(rotacal.load(fit))
    s_held = rotacal.load(held)
    in_memory = rotacal.rtest.predict_rtest(ident.model_dict(), s_held, probe_zeros="fitted")
    saved = rotacal.load_model(tmp / "m.json")
    assert saved["kind"] == "rtest-joint" and saved["nests"] == {
        "1": [100.0, 0.0, 60.0],
        "2": [0.0, -120.0, 140.0],
    }
    from_file = rotacal.rtest.predict_rtest(saved, s_held, probe_zeros="fitted")
    assert np.array_equal(np.asarray(in_memory.d), np.asarray(from_file.d))
    assert rotacal._core.format_rtest(in_memory) == rotacal._core.format_rtest(from_file)
    assert rotacal._core.format_rtest(from_file) == (tmp / "p.csv").read_text()
    # Without the fitted zeros the prediction is the table's error alone: it differs by the zeros.
    bare = np.asarray(rotacal.rtest.predict_rtest(saved, s_held).d)
    zeros = np.array([ident.raw.probe_zeros[k] for k in s_held.setups])
    assert np.allclose(bare + zeros, np.asarray(from_file.d), atol=1e-15)
    # The location errors in the file are the fit's, within their uncertainty of the truth.
    for n, p in saved["location_errors"].items():
        assert abs(p["value"] - truth["errors"][n]) < 4 * p["std"], n


def test_model_file_errors_name_file_and_key(held_out, tmp_path, shared_data):
    tmp, fit, held, _, _ = held_out
    good = json.loads((tmp / "m.json").read_text())
    s = rotacal.load(held)

    def broken(change, match):
        d = json.loads(json.dumps(good))
        change(d)
        path = tmp_path / "bad.json"
        path.write_text(json.dumps(d))
        with pytest.raises(rotacal.InvalidArgument, match=match):
            rotacal.rtest.predict_rtest(rotacal.load_model(path), s, source=str(path))

    broken(lambda d: d.update(kind="ballbar"), "bad.json: kind 'ballbar'")
    broken(lambda d: d["map_coefficients"].pop("dz_BY.b2"), "missing: dz_BY.b2")
    broken(lambda d: d["basis"].update(c_harmonics=3), "do not match basis")
    broken(lambda d: d["covariance"]["matrix"].pop(), r"covariance.matrix: shape")
    broken(
        lambda d: d["location_errors"]["E_X0B"].update(value="x"),
        "E_X0B: 'value' must be a finite number",
    )
    # Fitted probe zeros belong to the fitted set-up: a moved nest is refused.
    (tmp_path / "moved.csv").write_text(
        held.read_text().replace("# nest.2: 0, -120, 140", "# nest.2: 0, -120, 150")
    )
    r = rotacal_cli(
        "predict",
        tmp_path / "moved.csv",
        "--model",
        tmp / "m.json",
        "--probe-zeros",
        "fitted",
        "-o",
        tmp_path / "x.csv",
    )
    assert r.returncode == 3 and "nest.2" in r.stderr  # the plausibility check sees it first
    r = rotacal_cli(
        "predict",
        tmp_path / "moved.csv",
        "--model",
        tmp / "m.json",
        "--probe-zeros",
        "fitted",
        "--max-deviation",
        "20",
        "-o",
        tmp_path / "x.csv",
    )
    assert r.returncode == 3 and "set-up '2'" in r.stderr
    # An R-test session with a ballbar model, and the other way round.
    (tmp_path / "ballbar.json").write_text(json.dumps(dict(good, kind="ballbar")))
    r = rotacal_cli("predict", held, "--model", tmp_path / "ballbar.json", "-o", tmp_path / "x.csv")
    assert r.returncode == 3 and "not an R-test joint model" in r.stderr
    r = rotacal_cli(
        "predict",
        shared_data / "ballbar_ac_table2.csv",
        "--model",
        tmp / "m.json",
        "-o",
        tmp_path / "x.csv",
    )
    assert r.returncode == 3 and "not a ballbar model" in r.stderr


def test_simulate_rtest_pattern_truth_and_identification(tmp_path):
    out = tmp_path / "sim.csv"
    r = rotacal_cli(
        "simulate",
        "rtest",
        "--b-range",
        "-90,90",
        "--b-step",
        "45",
        "--c-range",
        "0,360",
        "--c-step",
        "45",
        "--nest",
        "100,0,60",
        "--nest",
        "0,-120,140",
        "--nest",
        "-80,60,100",
        "--errors",
        "E_X0B=0.02,E_B0C=-4e-5",
        *EFFECTS[:4],
        "--noise",
        "0.5",
        "--seed",
        "4",
        "-o",
        out,
    )
    assert r.returncode == 0, r.stderr
    s = rotacal.load(out)
    assert len(s) == 5 * 8 * 3 and sorted(s.nests) == ["1", "2", "3"] and s.noise_um == 0.5
    a = np.asarray(s.angles_deg)
    assert sorted(set(a[:, 0])) == [-90, -45, 0, 45, 90] and sorted(set(a[:, 1])) == list(
        range(0, 360, 45)
    )
    # Beside it, the truth in the shape of ../shared/data/rtest_bc_oyama.truth.json.
    truth = json.loads(out.with_suffix(".truth.json").read_text())
    assert {"errors", "effects", "nests", "noise_um"} <= set(truth)
    assert truth["errors"]["E_X0B"] == 0.02 and truth["errors"]["E_Z0B"] == 0.0
    assert truth["effects"] == {"gravity_sag_B": 0.006, "coning_B": 0.000145}
    assert len(truth["probe_zeros"]) == 3
    # The readings are the truth plus noise of the stated size.
    res = np.asarray(s.d) - rotacal.rtest.truth_readings(truth, s)
    assert abs(np.sqrt(np.mean(res**2)) - 0.5e-3) < 0.15 * 0.5e-3
    d = rotacal.identify(s).to_dict()
    for n, p in d["location_errors"].items():
        assert abs(p["value"] - truth["errors"][n]) < 4 * p["std"], n
    # Random errors are seeded; the ballbar simulator still answers as before.
    r1 = rotacal_cli("simulate", "rtest", "--seed", "9", "-o", tmp_path / "a.csv")
    r2 = rotacal_cli(
        "simulate", "rtest", "--seed", "9", "-o", tmp_path / "b.csv", "--truth", tmp_path / "t.json"
    )
    assert r1.returncode == r2.returncode == 0
    assert (tmp_path / "a.csv").read_text() == (tmp_path / "b.csv").read_text()
    assert json.loads((tmp_path / "t.json").read_text())["errors"]["E_X0B"] != 0.0
    for bad, what in (
        (["--b-step", "0"], "--b-range/--b-step"),
        (["--effect", "coning_B=1,2"], "coning_B"),
        (["--errors", "E_Y0A=1"], "E_Y0A"),
        (["--probe-dir", "1,0,0"], "--probe-dir"),
        (["--nest", "1,2"], "--nest"),
    ):
        r = rotacal_cli("simulate", "rtest", *bad, "-o", tmp_path / "x.csv")
        assert r.returncode == 3 and what in r.stderr, (bad, r.stderr)


# ------------------------------------------------------------------------- device calibration

# Three probes roughly along the diagonals of a nest, as on commercial R-test heads.
DIRS = np.array([[0.8, 0.05, -0.6], [-0.4, 0.7, -0.6], [-0.4, -0.72, -0.55]])
DIRS = DIRS / np.linalg.norm(DIRS, axis=1, keepdims=True)


def test_probe_calibration_recovers_directions_and_sphere_offset():
    noise_um = 0.3
    moves = rotacal._core.default_calibration_moves(0.5)
    zeros = np.array([0.11, -0.05, 0.3])
    readings = rotacal._core.simulate_probe_calibration(DIRS, zeros, moves, noise_um, 5)
    cal = rotacal.rtest.calibrate_probes(moves, readings)
    assert cal.sigma_um == pytest.approx(noise_um, rel=0.4)  # 30 dof: +-40% is > 3 sigma
    dirs = np.asarray(cal.dirs)
    for i in range(3):
        angle = np.arccos(min(1.0, float(dirs[i] @ DIRS[i])))
        assert 0 < cal.direction_std_rad[i] < 3e-3
        assert angle < 4 * cal.direction_std_rad[i], (i, angle)
        assert abs(cal.zeros[i] - zeros[i]) < 6 * noise_um * 1e-3 / np.sqrt(len(moves))
    with pytest.raises(rotacal.InvalidArgument):
        rotacal.rtest.calibrate_probes(moves[:4], readings[:4])
    flat = moves.copy()
    flat[:, 2] = 0
    with pytest.raises(rotacal.DegenerateGeometry):
        rotacal.rtest.calibrate_probes(flat, readings)

    spindle = np.arange(0, 360, 45.0)
    offset = np.array([0.004, -0.0025])
    r = rotacal._core.simulate_spindle_indexing(
        DIRS, zeros, offset, np.array([0.01, 0.02, -0.03]), np.radians(spindle), noise_um, 6
    )
    so = rotacal.rtest.calibrate_sphere_offset(dirs, spindle, r)
    assert np.all(np.abs(np.asarray(so.offset) - offset) < 4 * np.asarray(so.offset_std))
    assert np.all(np.asarray(so.offset_std) < 1e-3)


def test_raw_probe_session_is_converted(tmp_path):
    out = tmp_path / "raw.csv"
    dirs = [f"--probe-dir={','.join(map(str, d))}" for d in DIRS]
    r = rotacal_cli(
        "simulate", "rtest", *dirs, "--raw-only", *EFFECTS[:4], "--seed", "8", "-o", out
    )
    assert r.returncode == 0, r.stderr
    text = out.read_text()
    assert "probe.3.dir:" in text and "setup,time,B,C,X,Y,Z,d1,d2,d3\n" in text
    s = rotacal.load(out)
    with pytest.raises(rotacal.InvalidArgument, match="raw"):
        s.d
    truth = json.loads(out.with_suffix(".truth.json").read_text())
    converted, notes = rotacal.rtest.with_displacements(s)
    assert "probe.N.dir" in notes[0]
    # d = Dirs^-1 raw: its noise is the reading noise through Dirs^-1 (per component, RMS).
    err = np.asarray(converted.d) - rotacal.rtest.truth_readings(truth, s)
    inv = np.linalg.inv(DIRS)
    expected = truth["noise_um"] * 1e-3 * np.sqrt(np.mean(np.sum(inv**2, axis=1)))
    assert abs(np.sqrt(np.mean(err**2)) - expected) < 0.15 * expected
    # identify and report take the raw file as it is (the conversion is stated in the notes).
    d = rotacal.identify(s).to_dict()
    assert any("d1,d2,d3" in n for n in d["notes"])
    for n, p in d["location_errors"].items():
        assert abs(p["value"] - truth["errors"][n]) < 4 * p["std"], n
    r = rotacal_cli("report", out, "--no-diagnosis", "-o", tmp_path / "raw.html")
    assert r.returncode == 0, r.stderr
    assert 'id="error-map"' in (tmp_path / "raw.html").read_text()
    # With calibrated directions instead of the file's.
    moves = rotacal._core.default_calibration_moves(0.5)
    cal = rotacal.rtest.calibrate_probes(
        moves,
        rotacal._core.simulate_probe_calibration(DIRS, np.zeros(3), moves, truth["noise_um"], 2),
    )
    calibrated, notes = rotacal.rtest.with_displacements(s, cal.dirs)
    assert "calibrated" in notes[0]
    # Direction errors of ~1 mrad on readings of ~50 um add < 0.1 um: still the noise level.
    err = np.asarray(calibrated.d) - rotacal.rtest.truth_readings(truth, s)
    assert np.sqrt(np.mean(err**2)) < 1.5 * expected


def test_diagnosis_json_says_which_harmonics_the_sampling_cannot_resolve(shared_data):
    # C every 30 deg resolves harmonics 1-5 only; 6-8 are left out with the reason, not numbers.
    d = rotacal.diagnose(rotacal.load(shared_data / "rtest_bc_oyama.csv")).to_dict()
    for g in d["residual_structure"]["before"]:
        assert len(g["harmonic_um"]) == 5 and g["harmonics_left_out"] == [6, 7, 8]
        assert all(0 <= a < 1.0 for a in g["harmonic_um"])  # um, finite
        assert "left out" in g["harmonic_note"] and "12 distinct angles" in g["harmonic_note"]


# ------------------------------------------------------------------------- any machine (issue 13)


@pytest.mark.parametrize("machine", ["AC-trt", "B45C-trt", "B-head-C-table", "AC-head", "BC-head"])
def test_simulate_and_identify_on_any_machine(machine):
    from rotacal import rtest

    mtype = rotacal._core.parse_machine_type(machine)
    effects = {"tool_offset_Z": 0.015} if mtype.has_head else None
    s, t = rtest.simulate_rtest("random", effects, machine=machine, noise_um=0.3, seed=7)
    pattern = rtest.default_pattern(machine)
    assert len(s) == len(pattern["b_deg"]) * len(pattern["c_deg"]) * len(pattern["nests"])
    d = rtest.identify_rtest(s).to_dict()
    assert d["machine"] == machine and d["converged"]
    assert abs(d["residual_rms_um"] - 0.3) < 0.1
    seen = 0
    for n, v in d["location_errors"].items():
        if v["value"] is None:
            continue
        seen += 1
        assert abs(v["value"] - t["errors"][n]) <= 3 * v["std"], (n, v, t["errors"][n])
    maps = rotacal._core.rtest_map_names(mtype)
    assert d["error_map"]["maps"] == maps
    if mtype.has_head:
        # One tool length: the head's tilt axis position along the spindle goes with the tool
        # length error, and the advice says which set-up separates them.
        assert seen >= 6 and "tool_offset_Z" in d
        assert any("tool_offset_Z" in u for u in d["unobservable"])
        assert any("second tool length" in n for n in d["notes"])
    else:
        assert seen == 8 and d["unobservable"] == []
    # Oyama's method stays on BC-trt and names the method that works here.
    with pytest.raises(rotacal.InvalidArgument, match="joint fit"):
        rtest.identify_rtest(s, method="paper")


def test_default_pattern_follows_the_limits():
    from rotacal import rtest

    p = rtest.default_pattern("B45C-trt")  # B turns 0..180
    assert p["b_deg"][0] == pytest.approx(0.0) and p["b_deg"][-1] == pytest.approx(180.0)
    assert rtest.default_pattern("BC-trt")["b_deg"] == rtest.B_GRID
    with pytest.raises(rotacal.InvalidArgument, match=r"beyond its limits \[0, 180\]"):
        rtest.simulate_rtest("zero", machine="B45C-trt", b_deg=[-90, 0, 90])


def test_cli_simulate_and_identify_head_machine(tmp_path):
    out = tmp_path / "head.csv"
    r = rotacal_cli("simulate", "rtest", "--machine", "B-head-C-table", "-o", out, "--seed", "4")
    assert r.returncode == 0, r.stderr
    assert "7 B x 12 C x 2 nests" in r.stderr + r.stdout
    text = out.read_text()
    assert "# machine: B-head-C-table" in text
    r = rotacal_cli("identify", out)
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["machine"] == "B-head-C-table" and set(d["location_errors"]) >= {"E_X0C", "E_X0B"}
    assert "tool_offset_Z" in d and d["error_map"]["maps"] == ["BZ", "CY"]
    truth_errors = json.loads((tmp_path / "head.truth.json").read_text())["errors"]
    for n, v in d["location_errors"].items():
        if v["value"] is not None:
            assert abs(v["value"] - truth_errors[n]) <= 3 * v["std"], n
    r = rotacal_cli("identify", out, "--method", "paper")
    assert r.returncode != 0 and "joint fit" in r.stderr
    # A grid the machine cannot turn to is refused, naming the axis and its limits.
    r = rotacal_cli(
        "simulate",
        "rtest",
        "--machine",
        "B45C-trt",
        "--b-range",
        "-90,90",
        "--b-step",
        "45",
        "-o",
        tmp_path / "nut.csv",
    )
    assert r.returncode != 0 and "beyond its limits [0, 180]" in r.stderr
