# SPDX-License-Identifier: BSD-3-Clause
"""Joint fits on correlated noise from Python and the CLI: the white fit's 1-sigma is several
times too small on AR(0.95) ballbar sessions, the noise-model fit's holds; the Monte Carlo
check re-simulates the fitted noise model (issue 11 items 1 and 3)."""

import json

import numpy as np
import pytest

import rotacal
from rotacal import _core
from rotacal.ballbar import identify, monte_carlo

from conftest import run_cli


@pytest.fixture(scope="module")
def clean(shared_data):
    """A noise-free session on the poses of the shared file, and the machine that made it."""
    s = rotacal.load(shared_data / "ballbar_ac_table2.csv")
    model = identify(s, noise="white").raw.model
    return _core.simulate_ballbar(s, model, 0.0, 1), model


def ar_session(clean, rho, seed):
    s, _ = clean
    e = _core.noise_ar1(list(s.tests), list(s.time), rho, 0.5e-3, seed)
    # declared 0.5 um, the marginal sigma, as a user who measured the noise at rest would
    return rotacal.BallbarSession(
        s.machine,
        s.ballbar_length,
        s.pivot,
        s.tests,
        s.time,
        s.xyz,
        s.angles_deg,
        np.asarray(s.length) + e,
        noise_um=0.5,
    )


def test_ar095_white_sigmas_too_small_noise_model_right(clean):
    _, model = clean
    truth = np.asarray(model.errors)
    names = list(_core.location_error_names(model.machine))
    z = {"white": [], "auto": []}
    for seed in range(5):
        s = ar_session(clean, 0.95, 300 + seed)
        for mode in z:
            d = identify(s, noise=mode).to_dict()
            for j, n in enumerate(names):
                e = d["location_errors"][n]
                z[mode].append((e["value"] - truth[j]) / e["std"])
            if mode == "auto":
                nm = d["noise_model"]
                assert nm["gls_refit"] and not nm["white"] and nm["max_order"] >= 1
                assert 15 < nm["correlation_samples"] < 100  # AR(0.95): tau = 39 readings
                assert nm["covariance_factor"] >= 1.0
    rms = {k: float(np.sqrt(np.mean(np.square(v)))) for k, v in z.items()}
    assert rms["white"] > 3.0, rms  # the issue measured 6.5
    assert 0.6 < rms["auto"] < 1.5, rms  # 40 z-scores: RMS 1 +- 0.11 for independent ones


def test_white_session_is_fitted_once(shared_data):
    d = identify(rotacal.load(shared_data / "ballbar_ac_table2.csv")).to_dict()
    assert d["noise_model"]["white"] and not d["noise_model"]["gls_refit"]
    assert d["noise_model"]["covariance_factor"] == 1.0


def test_monte_carlo_uses_the_fitted_noise_model(clean):
    s = ar_session(clean, 0.9, 11)
    r = identify(s)
    mc = monte_carlo(s, r, 60, seed=5, progress=False)
    assert mc["noise"].startswith("the fitted noise model: AR(")
    ratios = [p["ratio"] for n, p in mc["parameters"].items() if n.startswith("E_")]
    assert len(ratios) == 8
    # 60 draws: the sample sd is within +-30 % of the truth at 3 sigma; the reported sigma
    # carries the bias factor the draws also see.
    assert all(0.6 < x < 1.5 for x in ratios), ratios


def test_cli_noise_option_and_json(clean, tmp_path):
    s = ar_session(clean, 0.95, 7)
    f = tmp_path / "ar.csv"
    rotacal.save(s, f)

    def run(*a):
        return run_cli("identify", f, "--json", "--no-budget", *a)

    auto, white = json.loads(run().stdout), json.loads(run("--noise", "white").stdout)
    assert auto["noise_model"]["gls_refit"] and not white["noise_model"]["gls_refit"]
    ratio = [
        auto["location_errors"][n]["std"] / white["location_errors"][n]["std"]
        for n in auto["location_errors"]
    ]
    assert min(ratio) > 2.0, ratio  # correlated noise: the honest sigma is several times larger
    bad = run_cli("identify", f, "--noise", "pink")
    assert bad.returncode == 2 and "--noise" in bad.stderr
