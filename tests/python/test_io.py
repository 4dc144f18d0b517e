# SPDX-License-Identifier: BSD-3-Clause
"""Session files from Python: both formats, exact round trips, sessions built from arrays and validated."""

import numpy as np
import pytest

import rotacal


def test_load_both_formats(shared_data):
    s = rotacal.load(shared_data / "ballbar_ac_table2.csv")
    assert isinstance(s, rotacal.BallbarSession)
    assert len(s) == 1804 and s.xyz.shape == (1804, 3) and s.angles_deg.shape == (1804, 2)
    assert s.test_names == [
        "sphere_xy",
        "sphere_yz",
        "sphere_zx",
        "radial_A",
        "axial_C",
        "radial_C",
        "axial_A",
    ]
    assert s.length[0] == 100.0146021
    r = rotacal.load(shared_data / "rtest_bc_oyama.csv")
    assert isinstance(r, rotacal.RtestSession)
    assert r.d.shape == (168, 3)
    np.testing.assert_array_equal(r.nests["2"], [0.0, -120.0, 140.0])


def test_round_trip_is_exact(shared_data, tmp_path):
    s = rotacal.load(shared_data / "ballbar_ac_random.csv")
    rng = np.random.default_rng(4)
    s2 = s.with_lengths(s.length + rng.normal(0, 1e-4, len(s)))
    rotacal.save(s2, tmp_path / "x.csv")
    back = rotacal.load(tmp_path / "x.csv")
    np.testing.assert_array_equal(back.length, s2.length)
    np.testing.assert_array_equal(back.xyz, s2.xyz)
    np.testing.assert_array_equal(back.angles_deg, s2.angles_deg)


def test_session_from_arrays_is_validated():
    n = 4
    args = dict(
        machine=rotacal.MachineType.AC_trt,
        ballbar_length=100.0,
        pivot=np.array([120.0, 0, 60]),
        tests=["t"] * n,
        time=np.arange(n, dtype=float),
        xyz=np.zeros((n, 3)),
        angles_deg=np.zeros((n, 2)),
        length=np.full(n, 100.0),
    )
    s = rotacal.BallbarSession(**args)
    assert len(s) == n
    with pytest.raises(rotacal.InvalidArgument, match="length"):
        rotacal.BallbarSession(**{**args, "length": np.full(n - 1, 100.0)})
    with pytest.raises(rotacal.InvalidArgument, match="time decreases"):
        rotacal.BallbarSession(**{**args, "time": np.array([0.0, 2.0, 1.0, 3.0])})
    with pytest.raises(rotacal.InvalidArgument, match="xyz"):
        rotacal.BallbarSession(**{**args, "xyz": np.full((n, 3), np.nan)})


def test_malformed_file_names_the_line(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text(
        "# format: rotacal-ballbar/1\n# machine: AC-trt\n# ballbar_length: 100\n# pivot: 1, 2, 3\n"
        "test,time,X,Y,Z,A,C,length\nt,0,1,2,3,0,0,100\nt,1,1,2,oops,0,0,100\n"
    )
    with pytest.raises(rotacal.ParseError, match=r"bad\.csv:7:\d+: .*'oops' is not a number"):
        rotacal.load(p)
    with pytest.raises(rotacal.IoError, match="nowhere.csv"):
        rotacal.load(tmp_path / "nowhere.csv")
