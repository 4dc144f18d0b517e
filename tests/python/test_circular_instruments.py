# SPDX-License-Identifier: BSD-3-Clause
"""A virtual ballbar playing an ISO 230-4 circular program over a pseudo-terminal, recorded by
`rotacal circular record` and analysed by `rotacal circular analyze`, as a user runs them; the
recovered G and causes against the simulated machine."""

import json
import subprocess
import sys

import numpy as np
import pytest

import rotacal
import rotacal.circular as circular
from rotacal import _core

from conftest import run_cli

# One plane, one feed, both directions at 100 Hz: 46 s of program, played at 5x real time.
PLAN = ["--planes", "XY", "--feeds", "2000", "--rate", "100"]
MACHINE = [
    "--squareness",
    "XY=35",
    "--backlash",
    "X=4,Y=2.5",
    "--servo-lag",
    "X=1.5",
    "--cyclic",
    "X=1.2:-0.7",
]
# A recorder starved of CPU (both cores busy) can stall for seconds: not the instrument's silence.
PATIENT = ["--silence", "30"]


def rotacal_cli(*args, timeout=600):
    """A child: `record` and `virtual` run side by side, each with its own signal handling."""
    return subprocess.run(
        [sys.executable, "-m", "rotacal", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def parameters(result: dict) -> dict:
    return {p["name"]: p for f in result["diagnosis"]["findings"] for p in f["parameters"]}


def test_virtual_record_analyze_recovers_the_simulated_machine(tmp_path):
    virtual = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "rotacal",
            "circular",
            "virtual",
            *PLAN,
            *MACHINE,
            "--speed",
            "5",
            "--exit-when-done",
            "--truth",
            tmp_path / "truth.json",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        port = virtual.stdout.readline().strip()
        assert port.startswith("/dev/"), virtual.stderr.read()
        rec = rotacal_cli(
            "circular",
            "record",
            *PLAN,
            "--port",
            port,
            *PATIENT,
            "--no-progress",
            "--json",
            "-o",
            tmp_path / "rec.csv",
        )
        assert rec.returncode == 0, rec.stderr
        summary = json.loads(rec.stdout)
        assert (
            summary["reason"] == "end of program"
            and summary["lost"] == 0
            and summary["crc_errors"] == 0
        )
    finally:
        if virtual.poll() is None:
            virtual.terminate()
        virtual.communicate(timeout=60)

    # Rows on a data arc carry the run's label, the rest (run-in, overshoot, the move between
    # the runs) "transition"; a run has the plan's readings at the recorded rate (+-1 at the ends).
    session = rotacal.load(tmp_path / "rec.csv")
    assert set(session.tests) == {"circular_XY_ccw", "circular_XY_cw", "transition"}
    assert circular.is_circular(session)
    planned = circular.plan(["XY"], [2000.0], sample_rate_hz=100.0)
    for run in planned.runs:
        n = int(np.sum(np.asarray(session.tests) == run.label))
        assert abs(n - len(run.time)) <= 1, (run.label, n, len(run.time))

    r = run_cli("circular", "analyze", tmp_path / "rec.csv", "--json")
    assert r.returncode == 0, r.stderr
    result = json.loads(r.stdout)
    assert result["ignored_tests"] == ["transition"]

    # G against the same machine simulated without noise (the truth's centring error): the
    # reading noise (0.3 um, AR(1) rho 0.9) moves the largest and the smallest radial deviation
    # by at most ~3.3 sigma each over ~100 effective samples, so G by less than 2 um.
    truth = json.loads((tmp_path / "truth.json").read_text())
    e = circular.errors(
        squareness_urad={"XY": 35},
        backlash_um={"X": 4, "Y": 2.5},
        servo_lag_ms={"X": 1.5},
        cyclic_um={"X": (1.2, -0.7)},
    )
    exact = circular.simulate(planned, e, centring_error_mm=truth["centring_error"], noise_um=0.0)
    G_exact = {x.label: x.G_um for x in _core.analyze_circular(exact).runs}
    assert {x["label"] for x in result["runs"]} == set(G_exact)
    for x in result["runs"]:
        assert abs(x["G_um"] - G_exact[x["label"]]) < 2.0, (
            x["label"],
            x["G_um"],
            G_exact[x["label"]],
        )

    # Every hidden error named, and nothing else; each parameter within 4 of its 1-sigma of
    # the simulated value (servo mismatch: tau_X - tau_Y).
    found = {f["effect"] for f in result["diagnosis"]["findings"]}
    assert found == {
        "servo_mismatch_XY",
        "squareness_XY",
        "backlash_X",
        "backlash_Y",
        "cyclic_error_X",
    }
    p = parameters(result)
    expected = {
        "servo_mismatch_XY.dtau": truth["servo_tau"]["X"] - truth["servo_tau"]["Y"],
        "squareness_XY.s": truth["squareness"]["XY"],
        "backlash_X.b": truth["backlash"]["X"],
        "backlash_Y.b": truth["backlash"]["Y"],
        "cyclic_error_X.c": truth["cyclic_cos"]["X"],
        "cyclic_error_X.d": truth["cyclic_sin"]["X"],
    }
    for name, value in expected.items():
        assert abs(p[name]["value"] - value) < 4.0 * p[name]["std"], (name, p[name], value)


def test_python_api_plays_and_records_a_circular_program(tmp_path):
    planned = circular.plan(["ZX"], [3000.0], ["cw"], sample_rate_hz=50.0)
    options = circular.simulation_options(
        circular.errors(backlash_um={"Z": 3.0}), noise_um=0.2, seed=4
    )
    dev = circular.virtual_ballbar(planned, options, speed=5.0)
    try:
        summary = circular.record_ballbar(
            dev.port, planned, tmp_path / "s.csv", silence_timeout_s=30.0, progress=False
        )
    finally:
        dev.stop()
    assert summary.reason == "end of program" and summary.lost == 0
    session = rotacal.load(tmp_path / "s.csv")
    tests = np.asarray(session.tests)
    on_arc = tests == "circular_ZX_cw"
    assert (
        set(tests) == {"circular_ZX_cw", "transition"}
        and on_arc.sum() >= len(planned.runs[0].time) - 1
    )
    # The data arc's rows are one contiguous block, in time order, at the commanded points.
    idx = np.flatnonzero(on_arc)
    assert np.all(np.diff(idx) == 1) and np.all(np.diff(session.time[idx]) > 0)
    centre = np.array([120.0, 0.0, 60.0])
    radius = np.hypot(session.xyz[idx, 2] - centre[2], session.xyz[idx, 0] - centre[0])
    assert np.allclose(radius, 100.0, atol=1e-9) and np.allclose(session.xyz[idx, 1], 0.0)
    result = circular.analyze(session, diagnose=False)
    assert [r.label for r in result.analysis.runs] == ["circular_ZX_cw"]


def test_bad_simulation_options_are_refused_before_serving():
    planned = circular.plan(["XY"], [2000.0], sample_rate_hz=100.0)
    with pytest.raises(_core.InvalidArgument, match="noise_rho"):
        circular.virtual_ballbar(planned, circular.simulation_options(noise_rho=1.0))
    r = rotacal_cli("circular", "virtual", *PLAN, "--backlash", "Q=3")
    assert r.returncode == 3 and "--backlash" in r.stderr  # a bad value: exit 3, the option named
