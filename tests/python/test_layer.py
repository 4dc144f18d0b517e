"""The Python layer's seams: one dispatch on the session kind, options laid over the C++
defaults, no import cycle between the instruments, and a CLI that draws only when asked."""
import ast
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rotacal
from rotacal import _core, machines, sessions
from rotacal.diagnosis import diagnosis_options

PACKAGE = Path(rotacal.__file__).parent


def _imports(module: str) -> set[str]:
    tree = ast.parse((PACKAGE / f"{module}.py").read_text())
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            out |= {node.module} if node.module else {a.name for a in node.names}
    return out


def test_ballbar_and_rtest_do_not_import_each_other():
    assert "rtest" not in _imports("ballbar")
    assert "ballbar" not in _imports("rtest")


def test_the_session_kind_is_told_in_one_place():
    for path in PACKAGE.glob("*.py"):
        assert not re.search(r"isinstance\([^)]*Session", path.read_text()), path.name


def test_by_kind(shared_data):
    b = rotacal.load(shared_data / "ballbar_ac_table2.csv")
    r = rotacal.load(shared_data / "rtest_bc_oyama.csv")
    assert sessions.kind(b) == "ballbar" and sessions.kind(r) == "rtest"
    with pytest.raises(rotacal.InvalidArgument, match="needs a rotacal-ballbar/1 session, this is rotacal-rtest/1"):
        sessions.by_kind(r, {"ballbar": 1}, "report")
    with pytest.raises(rotacal.InvalidArgument, match="not a session: str"):
        rotacal.diagnose("ballbar_ac_table2.csv")
    with pytest.raises(rotacal.InvalidArgument, match="takes only `method`"):
        rotacal.identify(r, effects=["gravity_sag_B"])


def test_diagnosis_options_lie_over_the_cpp_defaults():
    cpp = _core.DiagnosisOptions()
    o = diagnosis_options(max_findings=2, alpha=None)
    assert o.max_findings == 2 and o.alpha == cpp.alpha and o.max_harmonic == cpp.max_harmonic
    with pytest.raises(rotacal.InvalidArgument, match="unknown option 'max_harmonics'"):
        diagnosis_options(max_harmonics=3)
    for bad in (0, -1, 100000, 2.5):
        with pytest.raises(rotacal.InvalidArgument, match="max_harmonic"):
            diagnosis_options(max_harmonic=bad)


def test_cli_setup_defaults_are_the_cpp_ones():
    from rotacal.cli import _setup, build_parser
    a = build_parser().parse_args(["plan", "ballbar", "-o", "x.ngc"])
    s, cpp = _setup(a), _core.BallbarSetup()
    assert s.ballbar_length == cpp.ballbar_length and np.allclose(s.pivot, cpp.pivot)
    assert s.step_deg == cpp.step_deg and list(s.tilt_range_deg) == list(cpp.tilt_range_deg)
    assert list(s.rot_range_deg) == [0.0, 359.0]  # the CLI's own C range (one step short of the turn)


def test_truth_draws_random_errors_then_the_pivot_error():
    a = machines.ballbar_truth(rotacal.MachineType.AC_trt, "random", seed=5)
    b = machines.ballbar_truth(rotacal.MachineType.AC_trt, "zero", seed=5)
    rng = np.random.default_rng(5)
    errors = machines.random_location_errors(rotacal.MachineType.AC_trt, rng)
    assert np.allclose(list(a["errors"].values()), errors)
    assert np.allclose(a["pivot_error"], rng.normal(0.0, machines.PIVOT_ERROR_MM, 3))
    assert b["pivot_error"] == np.random.default_rng(5).normal(0.0, machines.PIVOT_ERROR_MM, 3).tolist()
    t2 = machines.ballbar_truth(rotacal.MachineType.AC_trt, "table2")
    assert t2["errors"] == machines.TABLE2_ERRORS
    with pytest.raises(rotacal.InvalidArgument, match="table2 is the paper's AC-trt"):
        machines.ballbar_truth(rotacal.MachineType.BC_trt, "table2")
    with pytest.raises(rotacal.InvalidArgument, match="E_Y0A"):
        machines.ballbar_truth(rotacal.MachineType.BC_trt, {"E_Y0A": 0.1})


def test_identify_does_not_load_matplotlib(shared_data):
    r = subprocess.run([sys.executable, "-X", "importtime", "-m", "rotacal", "identify",
                        str(shared_data / "ballbar_ac_table2.csv")], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "rotacal.cli" in r.stderr
    assert "matplotlib" not in r.stderr
