# SPDX-License-Identifier: BSD-3-Clause
"""The format step of the test command (scripts/format.sh --check) fails on a file the tools
would write otherwise, and passes on one they would leave as it is."""

import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

CASES = {
    "bad.cpp": ("int  f( int x ){return x+1;}\n", 1),
    "good.cpp": ("int f(int x) { return x + 1; }\n", 0),
    "bad.py": ("def f( x ):\n  return x+1\n", 1),
    "unused.py": ("import os\n", 1),  # formatted, but ruff's lint finds an unused import
    "good.py": ("def f(x):\n    return x + 1\n", 0),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_format_check(tmp_path, name):
    text, expected = CASES[name]
    f = tmp_path / name
    f.write_text(text)
    r = subprocess.run(
        ["bash", "scripts/format.sh", "--check", str(f)], cwd=ROOT, capture_output=True, text=True
    )
    assert r.returncode == expected, r.stdout + r.stderr
    assert f.read_text() == text  # --check never rewrites
