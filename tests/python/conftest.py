# SPDX-License-Identifier: BSD-3-Clause
"""Fixtures shared by the Python tests: the shared sessions beside the repository and their truth files,
and the command line run in this process."""

import contextlib
import io
import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

# The independent implementation's sessions, beside the repository (../shared/data).
SHARED = Path(__file__).resolve().parents[3] / "shared" / "data"


def _starts(item) -> set:
    """The LinuxCNC starts (linuxcnc_session.shared keys) a test module declares it uses."""
    return set(getattr(getattr(item, "module", None), "LINUXCNC_STARTS", ()))


def pytest_collection_modifyitems(session, config, items):
    """The modules that share a LinuxCNC start run one after the other (each module's tests in
    their order), so that the start serves them all and does not idle through other modules."""
    first, rank = {}, {}
    for it in items:
        m = getattr(it, "module", None)
        if m not in rank:
            key = min(_starts(it), default=None)
            i = len(rank)
            rank[m] = (first.setdefault(key, i) if key else i, i)
    items.sort(key=lambda it: rank[getattr(it, "module", None)])


def pytest_runtest_teardown(item, nextitem):
    """A shared start ends when the next test does not use it (its servo thread would run on
    through the other tests), and with the session."""
    session = sys.modules.get("linuxcnc_session")
    if session is None or session._current is None:
        return
    if nextitem is None or session._current.key not in _starts(nextitem):
        session.close_shared()


@pytest.fixture(scope="session")
def shared_data() -> Path:
    if not SHARED.is_dir():
        pytest.fail(f"shared data not found at {SHARED} (expected ../shared beside the repository)")
    return SHARED


@pytest.fixture(scope="session")
def fast_thermal_model(shared_data, tmp_path_factory) -> Path:
    """The thermal model of ../shared/data/thermal_probe_ac.csv (one lag, gains of every
    location error) with tau set to 3 s: a lag that settles within a LinuxCNC test."""
    import rotacal

    path = tmp_path_factory.mktemp("thermal") / "thermal.json"
    r = run_cli("identify", shared_data / "thermal_probe_ac.csv", "--save-model", path)
    assert r.returncode == 0, r.stderr
    doc = json.loads(path.read_text())
    doc["thermal"]["lags"][0]["tau"]["value"] = 3.0
    rotacal.save_model(doc, path)
    return path


def truth(path: Path) -> dict:
    return json.loads(path.with_suffix(".truth.json").read_text())


def split_by_c(path, step):
    """Two files from one session: rows with C on multiples of `step` deg, and the others."""
    lines = path.read_text().splitlines()
    meta = [ln for ln in lines if ln.startswith("#")]
    header, *rows = [ln for ln in lines if ln and not ln.startswith("#")]
    c_col = header.split(",").index("C")
    on = [r for r in rows if float(r.split(",")[c_col]) % step == 0]
    off = [r for r in rows if float(r.split(",")[c_col]) % step != 0]
    out = []
    for name, part in (("fit", on), ("held", off)):
        p = path.with_name(f"{path.stem}.{name}.csv")
        p.write_text("\n".join(meta + [header] + part) + "\n")
        out.append(p)
    return out


def run_cli(*args, cwd=None, env=None) -> subprocess.CompletedProcess:
    """`python -m rotacal ARGS` run in this process, as `subprocess.run(..., capture_output=True,
    text=True, cwd=cwd, env=dict(os.environ, **env))` returned it: `python -m rotacal` only calls
    cli.main, so its exit code (argparse's SystemExit included), stdout and stderr (encoded as the
    child's, read back with universal newlines) are the child's. A child interpreter cost about
    0.3 CPU-s per command (numpy and the extension imported again); tests whose point is the
    process itself (the entry point, signals, concurrent commands, memory limits) still start one."""
    from rotacal import cli

    argv = [str(a) for a in args]
    streams = [
        io.TextIOWrapper(io.BytesIO(), encoding=std.encoding, errors=std.errors)
        for std in (sys.__stdout__, sys.__stderr__)
    ]
    saved_env, saved_cwd = dict(os.environ), os.getcwd()
    # A pipe's width for help text, as the child saw; the environment the child had.
    os.environ.update({"COLUMNS": os.environ.get("COLUMNS", "80"), **(env or {})})
    try:
        if cwd is not None:
            os.chdir(cwd)
        with (
            warnings.catch_warnings(),
            contextlib.redirect_stdout(streams[0]),
            contextlib.redirect_stderr(streams[1]),
        ):
            warnings.resetwarnings()  # the interpreter's default filters: a warning shows on stderr
            for category in (
                DeprecationWarning,
                PendingDeprecationWarning,
                ImportWarning,
                ResourceWarning,
            ):
                warnings.simplefilter("ignore", category)
            try:
                code = cli.main(argv)
            except SystemExit as e:  # argparse: usage errors, --help, --version
                code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
                if e.code is not None and not isinstance(e.code, int):
                    print(e.code, file=sys.stderr)
    finally:
        os.chdir(saved_cwd)
        os.environ.clear()
        os.environ.update(saved_env)
    text = []
    for stream in streams:
        stream.flush()
        data = stream.buffer.getvalue().decode(stream.encoding, "replace")
        text.append(data.replace("\r\n", "\n").replace("\r", "\n"))
    return subprocess.CompletedProcess(["rotacal", *argv], code, text[0], text[1])
