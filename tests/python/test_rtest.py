"""R-test from Python: identification of the independent implementation's file against its truth."""
import json
import subprocess
import sys

import numpy as np
import pytest

import rotacal
from conftest import truth


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
    run = lambda *a: subprocess.run([sys.executable, "-m", "rotacal", *map(str, a)], capture_output=True,
                                    text=True, timeout=300)
    r = run("identify", shared_data / "rtest_bc_oyama.csv")
    assert r.returncode == 0, r.stderr
    assert set(json.loads(r.stdout)["location_errors"]) >= {"E_X0B", "E_Z0B", "E_X0C", "E_Y0C"}
    r = run("identify", shared_data / "rtest_bc_oyama.csv", "--save-model", tmp_path / "m.json")
    assert r.returncode == 3 and "not available yet" in r.stderr
