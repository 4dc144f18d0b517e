# SPDX-License-Identifier: BSD-3-Clause
"""The diagnosis is never confidently wrong (issue 29): the cases it named wrongly, on data from
the independent reference simulator (tests/reference/refsim), with set-ups and seeds other
than the issue's, in coloured noise where it applies. A session is judged as a calibration
engineer reads it: a cause named alone must be the hidden one; "one of these" must hold it;
nothing is an allowed answer where the data cannot decide."""

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
import refsim  # noqa: E402
from refsim import noise, poses, writers  # noqa: E402

import rotacal  # noqa: E402


def location_errors(machine, rng) -> dict:
    """Location errors of a few tens of um and urad, as a machine after assembly has them."""
    m = refsim.builtin(machine)
    return {
        n: (
            rng.normal(0, 20e-3) if n[-3] in "XYZUV" and "D" not in n[2:4] else rng.normal(0, 40e-6)
        )
        for n in m.error_names()
    }


def rtest_session(
    tmp_path,
    effects,
    seed,
    nests=((100.0, 0.0, 60.0), (0.0, -120.0, 140.0)),
    noise_um=0.3,
    rho=0.0,
    machine="BC-trt",
):
    rng = np.random.default_rng(seed)
    m = refsim.builtin(machine)
    s = poses.rtest_grid(m, nests=nests)
    model = refsim.Model(m, location_errors(machine, rng), effects)
    d = refsim.rtest_displacements(
        model, s["nests"], s["setup"], s["xyz"], np.radians(s["angles_deg"]), s["time"]
    )
    zeros = {k: rng.normal(0, 5e-3, 3) for k in s["nests"]}  # each set-up's unknown probe zero
    d = d + np.array([zeros[k] for k in s["setup"]])
    for a in range(3):
        d[:, a] += (
            noise.ar1(s["setup"], rho, noise_um * 1e-3, rng)
            if rho
            else noise.white(len(d), noise_um * 1e-3, rng)
        )
    path = writers.write_rtest(tmp_path / f"rtest_{seed}.csv", m, s, d, noise_um=noise_um)
    return rotacal.load(path)


def ballbar_session(
    tmp_path,
    effects,
    seed,
    pivot=(120.0, 0.0, 60.0),
    noise_um=0.5,
    rho=0.0,
    machine="AC-trt",
    declare_noise=True,
):
    rng = np.random.default_rng(seed)
    m = refsim.builtin(machine)
    s = poses.ballbar_single_setup(m, pivot=pivot)
    model = refsim.Model(m, location_errors(machine, rng), effects)
    actual_pivot = np.asarray(pivot) + rng.normal(0, 10e-3, 3)  # the set-up error
    length = refsim.ballbar_lengths(
        model, actual_pivot, s["xyz"], np.radians(s["angles_deg"]), s["time"]
    )
    length = length + (
        noise.ar1(s["test"], rho, noise_um * 1e-3, rng)
        if rho
        else noise.white(len(length), noise_um * 1e-3, rng)
    )
    path = writers.write_ballbar(
        tmp_path / f"ballbar_{seed}.csv", m, s, length, noise_um=noise_um if declare_noise else None
    )
    return rotacal.load(path)


def verdict(d: dict, truth: str) -> str:
    """right / ambiguous (the truth in the group) / nothing / wrong, for the first finding."""
    if not d["findings"]:
        return "nothing"
    f = d["findings"][0]
    if f["named"]:
        return "right" if f["effect"] == truth else "wrong"
    return "ambiguous" if truth in [g["effect"] for g in f["group"]] else "wrong"


def assert_determined(d: dict) -> None:
    """Issue 29 item 6: every finding has a parameter of at least 3 sigma."""
    for f in d["findings"]:
        ps = [p for p in f["parameters"].values() if p["value"] is not None]
        assert any(abs(p["value"]) >= 3 * p["std"] for p in ps), f


@pytest.mark.parametrize("amplitude", [1.2e-5, 2.5e-5])
@pytest.mark.parametrize(
    "nests",
    [((100.0, 0.0, 60.0), (0.0, -120.0, 140.0)), ((130.0, 40.0, 40.0), (-30.0, -100.0, 170.0))],
    ids=["default", "other"],
)
def test_rtest_wobble_of_c_is_named_as_wobble_not_face_runout(tmp_path, nests, amplitude):
    """The C table's first-order wobble moves two nests at different heights differently, a face
    runout moves both alike: with two nests the diagnosis names the wobble (it named axial_motion_C_h1
    in every session: its parameters were all held as trading off against E_A0C/E_B0C). Its
    forward-turning half is an axis tilt; the half it reports is the one turning against C."""
    a = d = amplitude
    s = rtest_session(tmp_path, {"tilt_motion_C_h1": [a, 0.0, 0.0, d]}, seed=int(amplitude * 1e7))
    r = rotacal.diagnose(s).to_dict()
    assert verdict(r, "tilt_motion_C_h1") == "right", r["findings"][:1]
    f = r["findings"][0]
    for name, true in zip("abcd", (a, 0.0, 0.0, d)):
        p = f["parameters"][f"tilt_motion_C_h1.{name}"]
        assert p["value"] is not None and abs(p["value"] - true) <= 4 * p["std"] + 1e-7, (name, p)
    assert f["gain"]["rms_after_um"] < 1.25 * 0.3  # nothing of the wobble left


def test_rtest_wobble_in_correlated_noise(tmp_path):
    s = rtest_session(tmp_path, {"tilt_motion_C_h1": [2e-5, 0.0, 0.0, 2e-5]}, seed=5, rho=0.5)
    r = rotacal.diagnose(s).to_dict()
    assert verdict(r, "tilt_motion_C_h1") == "right", r["findings"][:1]
    assert_determined(r)


@pytest.mark.parametrize("seed", [21, 22, 23, 24])
def test_rtest_drift_is_not_a_warmup_with_nothing_determined(tmp_path, seed):
    """A linear drift (4e-6 mm/s) was named thermal_warmup_Z with d = -1.4e-5 +- 2.6e-4 mm and an
    unobservable time constant: a finding with no number. Now every finding has a parameter of
    3 sigma, and a warm-up is never named alone over the drift it imitates."""
    s = rtest_session(tmp_path, {"thermal_drift_Z": [4e-6]}, seed=seed)
    r = rotacal.diagnose(s).to_dict()
    assert_determined(r)
    assert verdict(r, "thermal_drift_Z") in ("right", "ambiguous"), r["findings"][:1]


@pytest.mark.parametrize("seed", [31, 32, 33, 34, 35, 36])
def test_ballbar_sag_in_strongly_correlated_noise_is_never_named_wrong(tmp_path, seed):
    """AR(1) rho 0.9, 0.5 um at the instrument's sample rate, a 5 um sag of A and another pivot:
    the sag is at the edge of what such noise lets an oracle see (docs/noise_model.md), so
    "nothing" is an answer; a wrong name (radial_motion_A_h3, tilt_motion_A_h3 at 14 sigma)
    is not."""
    s = ballbar_session(
        tmp_path,
        {"gravity_sag_A": [5e-3]},
        seed=seed,
        pivot=(100.0, 20.0, 70.0),
        rho=0.9,
        declare_noise=False,
    )
    r = rotacal.diagnose(s).to_dict()
    assert verdict(r, "gravity_sag_A") != "wrong", r["findings"][:1]
    assert_determined(r)


def test_report_gives_one_value_per_location_error(tmp_path):
    """A found sag extends the model: the report's location errors are the extended model's (the
    values to load), the baseline's stand beside them labelled as such, and no test the session
    already holds is offered as the one that would separate an ambiguity."""
    from rotacal import report

    s = ballbar_session(tmp_path, {"gravity_sag_A": [6e-3]}, seed=41)
    base = rotacal.identify(s)
    diag = rotacal.diagnose(s)
    d = diag.to_dict()
    assert d["findings"] and "gravity_sag_A" in [g["effect"] for g in d["findings"][0]["group"]]
    page = report.ballbar_report(tmp_path / "r.html", s, base, diag).read_text()
    assert "of the extended model" in page and "<th>Baseline</th><th>Shift</th>" in page
    ext = report.extended_identification(s, base, diag).to_dict()["location_errors"]
    for name, p in ext.items():  # the table shows the extended values
        if p["value"] is not None:
            scale = 1e3 if p["unit"] == "mm" else 1e6
            assert f"<td>{p['value'] * scale:+.2f}</td>" in page, name
    held = set(np.asarray(s.tests).tolist())
    for a in d["ambiguous"]:
        for t in held:
            assert f"a '{t}' test separates them" not in a["separating_test"], a


def test_ballbar_finding_uncertainty_holds_in_strongly_correlated_noise(tmp_path):
    """AR(1) rho 0.9 readings: a finding's sigma comes from the final model refitted by GLS under
    the noise model of what it leaves (REML). The white fit's sigma was about 4x too small here
    (RMS z 4.2, a third of the parameters within 2 sigma); an honest sigma gives RMS z near 1."""
    truth = [4e-3, -3e-3, 2e-3, 3e-3]
    z = []
    for seed in range(100, 116):
        s = ballbar_session(
            tmp_path, {"radial_motion_C_h2": truth}, seed=seed, rho=0.9, declare_noise=False
        )
        d = rotacal.diagnose(s).to_dict()
        assert verdict(d, "radial_motion_C_h2") != "wrong", d["findings"][:1]
        if d["findings"] and d["findings"][0]["effect"] == "radial_motion_C_h2":
            for p, t in zip(d["findings"][0]["parameters"].values(), truth):
                if p["value"] is not None and p["std"]:
                    z.append((p["value"] - t) / p["std"])
    z = np.asarray(z)
    assert len(z) >= 16
    assert 0.6 < np.sqrt(np.mean(z**2)) < 1.6, z
    assert np.mean(np.abs(z) <= 2.0) >= 0.75, z


@pytest.mark.parametrize(
    "machine,effect,params",
    [
        ("AC-trt", "tilt_motion_A_h2", [0.0, 5e-6, 0.0, 0.0]),
        ("BC-trt", "radial_motion_B_h2", [0.0, 3e-4, 0.0, 6e-4]),
        ("AC-trt", "straightness_ZX", [3e-5, -7e-5, 1.6e-4]),
    ],
    ids=["tilt_h2-vs-coning", "radial_h2-vs-sag", "straightness-vs-axial_h2"],
)
def test_ballbar_weak_effect_is_never_named_as_a_simpler_rival(tmp_path, machine, effect, params):
    """Near the detection limit (AR(1) rho 0.5, another pivot than the bench's), a simpler
    candidate that fits the readings as well, or nearly, was named alone at a weight of 0.95-1.0:
    coning for a tilt harmonic of A, the sag or the Z scale for a radial harmonic of B, another
    straightness for a straightness. Two reasons, both in the rival rule: the truth was left out
    of the rivals when it failed the round's F-test or BIC threshold by a little, and BIC's
    ln n per parameter outweighed a rival with one more parameter 40:1 by the count alone.
    Now the field is every observable candidate, and a name must hold at AIC's Occam term as at
    BIC's: the answer is "one of these" (holding the truth) or nothing, never a wrong name
    (main at 502354a: 6 wrong of these 36 sessions)."""
    for seed in range(200, 212):
        s = ballbar_session(
            tmp_path,
            {effect: params},
            seed=seed,
            machine=machine,
            rho=0.5,
            pivot=(100.0, 20.0, 70.0),
        )
        r = rotacal.diagnose(s).to_dict()
        assert verdict(r, effect) != "wrong", (seed, r["findings"][:1])


def ballbar_pink_session(
    tmp_path, effects, seed, machine="AC-trt", pivot=(120.0, 0.0, 60.0), noise_um=0.5
):
    """A ballbar session in refsim's 1/f-like noise (equal-variance AR(1)s of 1 to 1000 samples),
    one stream per test, its 1-sigma declared in the file."""
    rng = np.random.default_rng(seed)
    m = refsim.builtin(machine)
    s = poses.ballbar_single_setup(m, pivot=pivot)
    model = refsim.Model(m, location_errors(machine, rng), effects)
    actual_pivot = np.asarray(pivot) + rng.normal(0, 10e-3, 3)
    length = refsim.ballbar_lengths(
        model, actual_pivot, s["xyz"], np.radians(s["angles_deg"]), s["time"]
    )
    length = length + noise.pink(s["test"], noise_um * 1e-3, rng)
    path = writers.write_ballbar(
        tmp_path / f"ballbar_pink_{seed}.csv", m, s, length, noise_um=noise_um
    )
    return rotacal.load(path)


def found_in_pink_sessions(tmp_path, effect, params, seeds, null_seeds, **setup) -> int:
    """Sessions of `seeds` in 1/f-like noise (ballbar_pink_session, `setup` its machine and pivot)
    whose first finding holds `effect`, asserting that none names a wrong cause, every finding
    has a determined parameter, and the null sessions of `null_seeds` stay clean."""
    found = 0
    for seed in seeds:
        r = rotacal.diagnose(
            ballbar_pink_session(tmp_path, {effect: params}, seed, **setup)
        ).to_dict()
        v = verdict(r, effect)
        assert v != "wrong", (seed, r["findings"][:1])
        assert_determined(r)
        found += v in ("right", "ambiguous")
    for seed in null_seeds:
        null = rotacal.diagnose(ballbar_pink_session(tmp_path, {}, seed, **setup)).to_dict()
        assert not null["findings"], (seed, null["findings"][:1])
    return found


def test_ballbar_drift_in_one_over_f_noise_is_not_taken_for_the_noise(tmp_path):
    """A thermal drift of X (1.9e-5 mm/s, some 15x its half-detection amplitude in white noise)
    is, on the ballbar, 98 % a level and a slope per test: what the 1/f-like treatment's stream
    levels and random walk take. The levels' variance was the declared noise's missing variance
    plus the walk's mean variance, unbounded in the stream's length, so a drift an oracle sees
    was noise: found in 3 of these 12 sessions on main at 75b25a6, 'nothing' in 9. A stream's
    level now varies at most as one reading does (noise_um^2). Null sessions of the same set-up
    stay clean."""
    found = 0
    for seed in range(300, 312):
        r = rotacal.diagnose(
            ballbar_pink_session(tmp_path, {"thermal_drift_X": [1.9e-5]}, seed)
        ).to_dict()
        v = verdict(r, "thermal_drift_X")
        assert v != "wrong", (seed, r["findings"][:1])
        assert_determined(r)
        found += v in ("right", "ambiguous")
        null = rotacal.diagnose(ballbar_pink_session(tmp_path, {}, seed + 100)).to_dict()
        assert not null["findings"], (seed + 100, null["findings"][:1])
    assert found >= 9, found


def test_ballbar_slow_shape_in_one_over_f_noise_is_found(tmp_path):
    """A fourth-order tilt of C (4.5e-6 rad, some 4x its half-detection amplitude in white noise)
    on the BC-trt ballbar in 1/f-like noise, another pivot than the bench's: slow along the
    tests, so the 1/f-like treatment's random walk took it for noise. REML's walk of such
    readings let a test of 360 readings vary 0.32 um^2 about its level where a stationary noise
    of the declared 0.5 um varies at most 0.25 um^2; the walk is now bounded by the declared
    noise (only on streams whose readings that noise can hold: a stream varying beyond it holds a
    shape the model lacks and keeps REML's walk): found (in the group) in 9 of these 10
    sessions, 1 on main at a544ad8. Null sessions of the same set-up stay clean and no session
    names a wrong cause."""
    found = 0
    for seed in range(400, 410):
        r = rotacal.diagnose(
            ballbar_pink_session(
                tmp_path,
                {"tilt_motion_C_h4": [0.0, 0.0, 4.5e-6, 0.0]},
                seed,
                machine="BC-trt",
                pivot=(100.0, 20.0, 70.0),
            )
        ).to_dict()
        v = verdict(r, "tilt_motion_C_h4")
        assert v != "wrong", (seed, r["findings"][:1])
        assert_determined(r)
        found += v in ("right", "ambiguous")
        null = rotacal.diagnose(
            ballbar_pink_session(
                tmp_path, {}, seed + 100, machine="BC-trt", pivot=(100.0, 20.0, 70.0)
            )
        ).to_dict()
        assert not null["findings"], (seed + 100, null["findings"][:1])
    assert found >= 8, found


def ballbar_gls_sigma(machine, effect, k, rho, noise_um, pivot=(120.0, 0.0, 60.0)):
    """1-sigma of `effect`'s k parameters by GLS under the true noise covariance (AR(1) rho per
    test, noise_um marginal), on refsim's Jacobian of the ballbar lengths by central differences:
    the location errors, the pivot and the effect (the model rotacal's final refit fits)."""
    m = refsim.builtin(machine)
    s = poses.ballbar_single_setup(m, pivot=pivot)
    angles = np.radians(s["angles_deg"])
    names = m.error_names()

    def lengths(errors, shift=np.zeros(3), p=np.zeros(k)):
        model = refsim.Model(m, dict(zip(names, errors)), {effect: p})
        return refsim.ballbar_lengths(model, np.asarray(pivot) + shift, s["xyz"], angles, s["time"])

    cols = []
    for i, name in enumerate(names):
        h = np.zeros(len(names))
        h[i] = 1e-3 if name[-3] in "XYZUV" and "D" not in name[2:4] else 1e-6
        cols.append((lengths(h) - lengths(-h)) / (2 * h[i]))
    for i in range(3):
        h = np.zeros(3)
        h[i] = 1e-3
        cols.append((lengths(np.zeros(len(names)), h) - lengths(np.zeros(len(names)), -h)) / 2e-3)
    for i in range(k):
        h = np.zeros(k)
        h[i] = 1e-6
        cols.append(
            (lengths(np.zeros(len(names)), p=h) - lengths(np.zeros(len(names)), p=-h)) / 2e-6
        )
    X = np.column_stack(cols)
    tests = np.asarray(s["test"])
    whitened = np.empty_like(X)
    for t in dict.fromkeys(s["test"]):
        idx = np.flatnonzero(tests == t)
        lag = np.abs(np.subtract.outer(np.arange(len(idx)), np.arange(len(idx))))
        chol = np.linalg.cholesky((noise_um * 1e-3) ** 2 * rho**lag)
        whitened[idx] = np.linalg.solve(chol, X[idx])
    return np.sqrt(np.diag(np.linalg.inv(whitened.T @ whitened))[-k:])


def test_ballbar_finding_sigma_in_ar1_noise_is_the_true_covariance_one(tmp_path):
    """AR(1) rho 0.9 readings on AC-trt, a Y scale error at 10x its half-detection size (the
    benchmark's): a right finding's sigma is that of GLS under the true noise covariance
    (refsim's Jacobian, not rotacal's), and the estimates spread as it says. The final refit
    gave REML's noise model Burg's small-sample correction of rho on top (+(1 + 3 rho) / n),
    which REML's restricted likelihood does not need: these sigmas were 1.02-1.28x the
    true-covariance one (median 1.15), now 1.02-1.15x (median 1.04)."""
    effect, params = "linear_scale_Y", [9e-6]
    oracle = ballbar_gls_sigma("AC-trt", effect, len(params), 0.9, 0.5)
    ratio, z = [], []
    for seed in range(700, 706):
        s = ballbar_session(tmp_path, {effect: params}, seed=seed, rho=0.9)
        d = rotacal.diagnose(s).to_dict()
        assert verdict(d, effect) != "wrong", d["findings"][:1]
        if not d["findings"] or d["findings"][0]["effect"] != effect:
            continue
        for p, t, o in zip(d["findings"][0]["parameters"].values(), params, oracle):
            if p["value"] is not None and p["std"] and o < 10 * p["std"]:
                ratio.append(p["std"] / o)
                z.append((p["value"] - t) / p["std"])
    assert len(ratio) >= 4, ratio
    assert 0.9 < np.median(ratio) < 1.08, ratio
    assert np.sqrt(np.mean(np.square(z))) < 1.8, z


def test_ballbar_weak_shape_in_one_over_f_noise_is_not_taken_for_the_walk(tmp_path):
    """A third-order axial motion of C (0.5 um, some 3x its half-detection amplitude) on the BC-trt
    ballbar in 1/f-like noise, another pivot than the bench's. The search's 1/f-like treatment
    estimated its random walk (REML) with the effect still in the residuals, took part of the
    effect for the walk and whitened it away: delta BIC -2 to -10 where an oracle under the true
    covariance gives -12 to -28. The round's best few candidates are now judged under the walk
    estimated with their own columns: found (in the group) in 8 of these 10 sessions, 5 on main
    at 0da6be6. Null sessions of the same set-up stay clean and no session names a wrong cause."""
    found = found_in_pink_sessions(
        tmp_path,
        "axial_motion_C_h3",
        [5.0e-4, 0.0],
        range(600, 610),
        range(700, 704),
        machine="BC-trt",
        pivot=(110.0, -10.0, 65.0),
    )
    assert found >= 7, found


def test_ballbar_length_offset_in_one_over_f_noise_is_not_taken_for_the_levels(tmp_path):
    """A ballbar length offset (0.9 um, AC-trt, another pivot than the bench's) in 1/f-like noise
    is all a level per test. The 1/f-like treatment's walk, bounded only in its variation within
    a test, and the hidden levels gave a test's mean some 6x the variance refsim's noise has, and
    took the offset for noise: 'nothing' in all of these 6 sessions on main at 3cd9f30. With the
    round's slow candidates rescored with the readings' variance held to the declared one
    (search_round.cpp, h-pink10): found in 3. No session names a wrong cause."""
    found = 0
    for seed in range(800, 806):
        r = rotacal.diagnose(
            ballbar_pink_session(
                tmp_path, {"ballbar_length_offset": [9.0e-4]}, seed, pivot=(110.0, 15.0, 70.0)
            )
        ).to_dict()
        v = verdict(r, "ballbar_length_offset")
        assert v != "wrong", (seed, r["findings"][:1])
        found += v in ("right", "ambiguous")
    assert found >= 3, found


@pytest.mark.parametrize(
    "effect,params",
    [
        ("linear_squareness_ZX", [1.2e-5]),  # some 3.5x its half-detection amplitude in white noise
        ("tilt_motion_B_h4", [4.5e-6, 0.0, -2.2e-6, 0.0]),  # some 3.6x
    ],
)
def test_ballbar_middle_speed_shape_in_one_over_f_noise_is_found(tmp_path, effect, params):
    """A squareness and a fourth-order tilt of B on the BC-trt ballbar in 1/f-like noise, another
    pivot than the bench's: shapes only partly a level and a slope per test, which the round
    judged under the walk bounded within each test, where
    the noise's power at those orders is too high: found (in the group) in 3 of these 10
    sessions each on main at 4e0a475. Such a kept candidate now sends the round's kept few to
    the rescoring under one walk bounded by the readings' declared variance, its step three
    quarters of the way from the within-stream bound (search_round.cpp, hidden_levels.cpp):
    found in 6 of 10 each. No session names a wrong cause, and null sessions of the same set-up
    stay clean."""
    found = found_in_pink_sessions(
        tmp_path,
        effect,
        params,
        range(900, 910),
        range(1000, 1004),
        machine="BC-trt",
        pivot=(100.0, -15.0, 70.0),
    )
    assert found >= 5, found
