# SPDX-License-Identifier: BSD-3-Clause
"""Hostile and careless input at the file layer (issue 17): every case ends in a typed
refusal naming file/line/column (or the path), never a crash, a traceback, unbounded memory
or a destroyed file. The command line maps them to exit 3 (content) and 4 (file system)."""

import os
import subprocess
import sys

import pytest

import rotacal
from rotacal import _core

from conftest import run_cli

HEAD = (
    "# format: rotacal-ballbar/1\n# machine: AC-trt\n# units: mm, deg, s\n"
    "# ballbar_length: 100\n# pivot: 120, 0, 60\ntest,time,X,Y,Z,A,C,length\n"
)
ROW = "sphere_xy,0.0,220,0,60,0,0,100.001\n"
ROW2 = "sphere_xy,0.1,219,1,60,0,1,100.002\n"
RHEAD = (
    "# format: rotacal-rtest/1\n# machine: BC-trt\n# units: mm, deg, s\n# nest.1: 100, 0, 60\n"
    "setup,time,B,C,X,Y,Z,dx,dy,dz\n"
)
RROW = "1,0.0,-90,0,-60,0,100,0.0058,-0.0301,-0.0129\n"


def _field(row, k, value):
    f = row.rstrip("\n").split(",")
    f[k] = value
    return ",".join(f) + "\n"


# (name, bytes of the file, exception, words the message must hold)
CASES = [
    (
        "non-UTF-8 byte in a number",
        (HEAD + "sphere_xy,0.0,22").encode() + b"\xff" + b"0,0,60,0,0,100\n",
        rotacal.ParseError,
        r":7:17: byte 0xFF is not UTF-8",
    ),
    ("UTF-16 file", (HEAD + ROW).encode("utf-16"), rotacal.ParseError, ":1:"),
    (
        "UTF-8 byte-order mark",
        b"\xef\xbb\xbf" + (HEAD + ROW).encode(),
        rotacal.ParseError,
        "byte-order mark",
    ),
    (
        "CR-only line ends",
        (HEAD + ROW).replace("\n", "\r").encode(),
        rotacal.ParseError,
        "carriage return",
    ),
    ("a 1 MB first line", b"x" * (1 << 20), rotacal.ParseError, "longer than 65536 bytes"),
    ("random bytes", bytes(range(256)) * 8, rotacal.ParseError, "bad.csv:1"),
    (
        "a length of 1e308",
        (HEAD + ROW + _field(ROW2, 7, "1e308")).encode(),
        rotacal.ParseError,
        ":8:",
    ),
    (
        "an X of 1e160",
        (HEAD + ROW + _field(ROW2, 2, "1e160")).encode(),
        rotacal.ParseError,
        "X 1e160 is outside",
    ),
    ("C of 1e300", (HEAD + _field(ROW, 6, "1e300")).encode(), rotacal.ParseError, "C 1e300"),
    ("length 4e-320", (HEAD + _field(ROW, 7, "4e-320")).encode(), rotacal.ParseError, "length"),
    (
        "a negative length",
        (HEAD + _field(ROW, 7, "-100")).encode(),
        rotacal.ParseError,
        "length must be > 0",
    ),
    (
        "ballbar_length 1e6",
        (HEAD.replace("length: 100", "length: 1e6") + ROW).encode(),
        rotacal.ParseError,
        "ballbar_length",
    ),
    (
        "a 1 MB test label",
        (HEAD + _field(ROW, 0, "L" * (1 << 20))).encode(),
        rotacal.ParseError,
        "longer than",
    ),
    (
        "a 300-byte test label",
        (HEAD + _field(ROW, 0, "L" * 300)).encode(),
        rotacal.ParseError,
        "256 bytes",
    ),
    (
        "R-test dx of 1e308",
        (RHEAD + _field(RROW, 7, "1e308")).encode(),
        rotacal.ParseError,
        "dx 1e308",
    ),
    (
        "R-test B of 1e308",
        (RHEAD + _field(RROW, 2, "1e308")).encode(),
        rotacal.ParseError,
        "B 1e308",
    ),
]


@pytest.mark.parametrize("name,data,exc,words", CASES, ids=[c[0] for c in CASES])
def test_hostile_session_files_are_refused(tmp_path, name, data, exc, words):
    p = tmp_path / "bad.csv"
    p.write_bytes(data)
    with pytest.raises(exc, match=words) as e:
        rotacal.load(p)
    assert len(str(e.value)) < 400, "the message echoes the offending text"


def test_dev_zero_bounded_memory_and_time():
    code = (
        "import resource, rotacal\n"
        "resource.setrlimit(resource.RLIMIT_AS, (1 << 31, 1 << 31))\n"
        "try:\n    rotacal.load('/dev/zero')\nexcept rotacal.ParseError as e:\n    print(str(e))\n"
    )
    r = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=60,
        env=dict(os.environ),
    )
    assert r.returncode == 0, r.stderr[-500:]
    assert "/dev/zero:1: line longer than 65536 bytes" in r.stdout
    assert len(r.stdout) < 300


def test_directory_and_bad_paths_are_file_system_errors(tmp_path):
    with pytest.raises(rotacal.IoError, match="is a directory"):
        rotacal.load(tmp_path)
    with pytest.raises(rotacal.IoError, match="NUL"):
        _core.read_session(str(tmp_path / "f.csv") + "\x00junk")
    with pytest.raises(rotacal.IoError):
        rotacal.load(tmp_path / "missing.csv")


def test_duplicated_rows_are_reported(tmp_path):
    p = tmp_path / "dup.csv"
    p.write_text(HEAD + ROW + ROW2 + ROW2)
    s = rotacal.load(p)
    assert len(s) == 3
    assert s.warnings and "repeat" in s.warnings[0] and "line 9 repeats line 8" in s.warnings[0]


def test_session_from_arrays_is_one_the_reader_accepts():
    import numpy as np

    args = dict(
        machine=_core.parse_machine_type("AC-trt"),
        ballbar_length=100.0,
        pivot=np.array([120.0, 0, 60]),
        tests=["a", "a"],
        time=np.array([0.0, 1.0]),
        xyz=np.array([[220.0, 0, 60], [219, 1, 60]]),
        angles_deg=np.zeros((2, 2)),
    )
    for bad in (np.array([100.0, 0.0]), np.array([100.0, -1.0]), np.array([100.0, 1e308])):
        with pytest.raises(rotacal.InvalidArgument, match="length"):
            rotacal.BallbarSession(length=bad, **args)


@pytest.mark.parametrize(
    "args,code,words",
    [
        (["identify", "/dev/zero"], 3, "longer than 65536"),
        (["identify", "{tmp}"], 4, "is a directory"),
        (["identify", "{tmp}/bad.csv"], 3, "X 1e160 is outside"),
    ],
)
def test_cli_exit_codes(tmp_path, args, code, words):
    (tmp_path / "bad.csv").write_text(HEAD + ROW + _field(ROW2, 2, "1e160"))
    argv = [a.format(tmp=tmp_path) for a in args]
    r = run_cli(*argv)
    assert r.returncode == code, r.stderr[-500:]
    assert words in r.stderr
    assert "Traceback" not in r.stderr


def test_plausibility_names_the_cause(shared_data):
    """The check the entry points run before fitting (rotacal/session/plausibility.hpp)."""
    import numpy as np

    s = rotacal.load(shared_data / "ballbar_ac_table2.csv")
    assert _core.check_plausible(s, "s.csv").max_deviation_mm < 0.5
    rad = s.__class__(
        s.machine,
        s.ballbar_length,
        s.pivot,
        s.tests,
        s.time,
        s.xyz,
        np.radians(s.angles_deg),
        s.length,
    )
    with pytest.raises(rotacal.InvalidArgument, match="angles look like radians"):
        _core.check_plausible(rad, "s.csv")
    still = s.__class__(
        s.machine,
        s.ballbar_length,
        s.pivot,
        s.tests,
        s.time,
        s.xyz,
        np.zeros_like(s.angles_deg),
        s.length,
    )
    with pytest.raises(
        rotacal.InvalidArgument, match="all rotary angles equal: the axes never move"
    ):
        _core.check_plausible(still, "s.csv")
    l150 = s.__class__(s.machine, 150.0, s.pivot, s.tests, s.time, s.xyz, s.angles_deg, s.length)
    with pytest.raises(rotacal.InvalidArgument, match="ballbar_length 150 but the data say ~100"):
        _core.check_plausible(l150, "s.csv")
    o = _core.PlausibilityOptions()
    o.max_length_deviation_mm = 0.01
    with pytest.raises(rotacal.InvalidArgument, match="max_length_deviation_mm"):
        _core.check_plausible(s, "s.csv", o)
    with pytest.raises(rotacal.InvalidArgument, match="session machine BC-trt, model AC-trt"):
        _core.check_model_machine(
            _core.parse_machine_type("AC-trt"), _core.parse_machine_type("BC-trt"), "m.json"
        )
