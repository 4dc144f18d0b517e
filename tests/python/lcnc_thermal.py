# SPDX-License-Identifier: BSD-3-Clause
"""The check of a thermal HAL chain (`rotacal export --thermal-chain`) in a running LinuxCNC
start (test_linuxcnc_kins.py: xyzac-trt-kins' pins; test_linuxcnc_rotacal_kins.py: rotacal-kins'
y1).

The job loads the chain and, beside it, a realtime log: `sampler` takes every servo period the
joint's vel-cmd, the lag state and each fed pin (through `mult2` by 1e6: halsampler prints six
decimals), after the chain's functions in the same thread. tests/linuxcnc/thermal_display.py
turns C at 300 rev/min (u = 3), rests, and takes the chain out again. The reference is the
discrete lag driven by the logged speed, y_k = y_(k-1) + g (|v_k| / 600 - y_(k-1)), g = 1 -
exp(-T/tau) from the model's tau (not from the file under test): a lost log line (a gap in the
sample numbers) restarts it from the logged state, and a missed servo period is no period of
the chain either, so nothing depends on timing.
"""

import json
import math
from pathlib import Path

import numpy as np

from linuxcnc_session import hal_commands

SCALE = 1e6  # the log's factor
U_TEST = 3.0  # 300 rev/min
TURN = ["G1 C5400 F108000"]  # 5400 deg at 1800 deg/s: 3 s of u = 3, then at rest


def job_commands(chain_text: str, pins: list[str]) -> tuple[list, list]:
    """(the job's halcmd commands: the chain and its log, the commands that take both out)."""
    cmds = hal_commands(chain_text)
    logged = ["y1"] + [p.replace(".", "-") for p in pins]
    cmds += [
        ["loadrt", "sampler", "depth=30000", "cfg=" + "f" * (1 + len(logged))],
        ["loadrt", "mult2", "names=" + ",".join(f"rotacal-log-{n}" for n in logged)],
    ]
    cmds += [["addf", f"rotacal-log-{n}", "servo-thread"] for n in logged]
    cmds += [["net", "rotacal-th-vel", "sampler.0.pin.0"]]
    sources = ["rotacal-th-y1"] + [f"rotacal-th-{p.split('.', 1)[1]}" for p in pins]
    for k, (n, sig) in enumerate(zip(logged, sources)):
        cmds += [
            ["net", sig, f"rotacal-log-{n}.in0"],
            ["setp", f"rotacal-log-{n}.in1", str(SCALE)],
            ["net", f"rotacal-log-{n}", f"rotacal-log-{n}.out", "sampler.0.pin." + str(k + 1)],
        ]
    cmds += [["addf", "sampler.0", "servo-thread"]]  # last: it samples the log as set up
    signals = {c[1] for c in cmds if c[0] == "net"}
    comps = {c[1] for c in cmds if c[0] == "loadrt"}
    cleanup = [["unloadrt", c] for c in sorted(comps)] + [["delsig", s] for s in sorted(signals)]
    return cmds, cleanup


def run(start, job_dir: Path, chain_text: str, pins: list[str]) -> np.ndarray:
    """Run the chain in `start` while C turns; the log (N, 3 + len(pins)): sample number,
    vel-cmd (deg/s), y1, the pins (mm)."""
    cmds, cleanup = job_commands(chain_text, pins)
    plan = {"moves": TURN, "rest_s": 1.5, "move_timeout_s": 30, "cleanup": cleanup}
    r = start.job(
        "thermal_display", job_dir, {"plan.json": json.dumps(plan)}, "thermal.json", 60, cmds
    )
    assert r["halsampler_exit"] == 0, r
    log = np.loadtxt(job_dir / "samples.txt", ndmin=2)
    assert len(log) == r["lines"] > 1000, r
    log[:, 2:] /= SCALE
    print(
        f"thermal chain: {len(log)} servo periods logged, sampler overruns {r['overruns']}, "
        f"gaps {(np.diff(log[:, 0]) != 1).sum()}, job {r['elapsed']:.1f} s"
    )
    return log


def discrete_lag(log: np.ndarray, tau: float, period_s: float) -> np.ndarray:
    """y driven by the logged speed, restarted from the logged y after a gap in the log."""
    g = 1.0 - math.exp(-period_s / tau)
    u = np.abs(log[:, 1]) / 600.0
    y = np.empty(len(log))
    y[0] = log[0, 2]
    for k in range(1, len(log)):
        if log[k, 0] - log[k - 1, 0] == 1:
            y[k] = y[k - 1] + g * (u[k] - y[k - 1])
        else:
            y[k] = log[k, 2]
    return y


def check_lag(log: np.ndarray, tau: float, period_s: float) -> np.ndarray:
    """The logged state is the discrete lag's to 1 % of the tested steady state; it rose far
    enough for the check to fail when the chain does not run. Returns the reference y."""
    y = discrete_lag(log, tau, period_s)
    err = np.abs(log[:, 2] - y).max()
    print(f"  y1: max {log[:, 2].max():.4f}, |logged - discrete lag| max {err:.3g}")
    assert log[:, 2].max() > 0.3 * U_TEST, "the state hardly rose: C did not turn long enough"
    assert np.abs(log[:, 1]).max() > 1000.0  # deg/s: C turned
    assert err < 0.01 * U_TEST
    return y
