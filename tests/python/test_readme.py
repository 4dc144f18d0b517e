# SPDX-License-Identifier: BSD-3-Clause
"""Every code block of the README, run as a new user runs it: from the root of a fresh clone,
with the installed `rotacal` command. The one block not run is the test command itself (this
test is part of it). Shell blocks run line by line in bash; the Python block with this
interpreter; the C++ block is compiled with the CMake block against the installed package
(ROTACAL_PREFIX, set by scripts/test.sh) and run."""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
TEST_COMMAND = "bash scripts/test.sh"
KINDS = ("sh", "python", "cpp", "cmake")


def blocks() -> list[tuple[str, str]]:
    return re.findall(r"^```(\w*)\n(.*?)^```", README.read_text(), re.S | re.M)


def test_readme_is_for_users():
    text = README.read_text()
    assert len(text.encode()) <= 30 * 1024, (
        f"README.md is {len(text.encode())} bytes (at most 30 KB)"
    )
    long = [i + 1 for i, line in enumerate(text.splitlines()) if len(line) > 400]
    assert not long, f"README.md lines over 400 characters: {long}"
    kinds = {k for k, _ in blocks()}
    assert kinds <= set(KINDS), (
        f"a README block of a kind this test cannot run: {kinds - set(KINDS)}"
    )
    assert {"sh", "python", "cpp"} <= kinds


@pytest.fixture(scope="module")
def clone(tmp_path_factory) -> Path:
    """A fresh clone of this checkout, with its uncommitted changes to tracked files, so that
    what is tested is the README as it stands (in CI the two are the same)."""
    dst = tmp_path_factory.mktemp("readme") / "rotacal"
    subprocess.run(["git", "clone", "-q", str(ROOT), str(dst)], check=True)
    changed = subprocess.run(
        ["git", "-C", str(ROOT), "diff", "--name-only", "HEAD"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    for name in changed:
        if (ROOT / name).exists():
            shutil.copy2(ROOT / name, dst / name)
        else:
            (dst / name).unlink(missing_ok=True)
    return dst


def _installed_command():
    exe = shutil.which("rotacal")
    if exe is None:
        pytest.fail("the `rotacal` command is not installed: the README's commands need it")
    return exe


def test_readme_shell_blocks_run(clone):
    _installed_command()
    ran = 0
    for kind, code in blocks():
        if kind != "sh":
            continue
        for line in code.splitlines():
            command = line.split("#", 1)[0].strip()
            if not command or command.startswith(TEST_COMMAND):
                continue
            r = subprocess.run(
                ["bash", "-euo", "pipefail", "-c", command],
                cwd=clone,
                capture_output=True,
                text=True,
                timeout=900,
            )
            assert r.returncode == 0, f"{command}\n{r.stdout[-2000:]}\n{r.stderr[-4000:]}"
            ran += 1
    assert ran >= 5
    assert (clone / "out" / "demo").is_dir(), "the main job wrote no out/demo"


def test_readme_python_block_runs(clone):
    for kind, code in blocks():
        if kind == "python":
            r = subprocess.run(
                [sys.executable, "-c", code], cwd=clone, capture_output=True, text=True, timeout=300
            )
            assert r.returncode == 0, r.stderr
            assert "E_Y0C" in r.stdout


def test_readme_cpp_block_builds_and_runs(clone, tmp_path):
    prefix = os.environ.get("ROTACAL_PREFIX")
    if not prefix:
        if os.environ.get("CI"):
            pytest.fail("ROTACAL_PREFIX (the installed package, set by scripts/test.sh) is not set")
        pytest.skip("ROTACAL_PREFIX is not set: run through scripts/test.sh")
    code = dict((k, c) for k, c in blocks() if k in ("cpp", "cmake"))
    (tmp_path / "main.cpp").write_text(code["cpp"])
    (tmp_path / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.18)\nproject(readme LANGUAGES CXX)\n"
        "add_executable(my_cnc_tool main.cpp)\n" + code["cmake"]
    )
    build = tmp_path / "build"
    for cmd in (
        [
            "cmake",
            "-S",
            str(tmp_path),
            "-B",
            str(build),
            "-G",
            "Ninja",
            f"-DCMAKE_PREFIX_PATH={prefix}",
        ],
        ["cmake", "--build", str(build)],
    ):
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-4000:]
    r = subprocess.run([str(build / "my_cnc_tool")], cwd=clone, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "E_Y0C = " in r.stdout
