# SPDX-License-Identifier: BSD-3-Clause
"""examples/rtest_error_map.py, run as a user runs it (as test_cli.py runs the other examples)."""

import json
import subprocess
import sys
from pathlib import Path

from conftest import truth

ROOT = Path(__file__).resolve().parents[2]


def run_example(*args):
    return subprocess.run(
        [sys.executable, str(ROOT / "examples" / "rtest_error_map.py"), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_rtest_error_map_example_on_the_shared_file(shared_data, tmp_path):
    path = shared_data / "rtest_bc_oyama.csv"
    r = run_example(path, "-o", tmp_path / "out")
    assert r.returncode == 0, r.stderr
    assert "E_X0B" in r.stdout and "dz_BY" in r.stdout
    assert len((tmp_path / "out" / "error_map.csv").read_text().splitlines()) == 1 + 7 * 12
    assert json.loads((tmp_path / "out" / "model.json").read_text())["kind"] == "rtest-joint"
    # The saved map shows the paper's gravity sag at B = +-90 deg, against the truth file.
    t = truth(path)
    m = json.loads((tmp_path / "out" / "error_map.json").read_text())
    for e in m["entries"]:
        if e["C"] == 0 and abs(e["B"]) == 90:
            assert abs(e["BY"][2] + t["effects"]["gravity_sag_B"]) < 4 * e["BY_std"][2]


def test_rtest_error_map_example_simulates_without_a_session(tmp_path):
    r = run_example("-o", tmp_path)
    assert r.returncode == 0, r.stderr
    assert "simulated: gravity_sag_B = 0.006" in r.stdout
    assert (tmp_path / "error_map.json").exists() and (tmp_path / "model.json").exists()
