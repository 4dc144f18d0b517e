# SPDX-License-Identifier: BSD-3-Clause
"""Instruments over serial: virtual instruments on pseudo-terminals and recorders that write
session files as they read (docs/protocols.md has the byte-level protocols).

A recording appends and flushes every row, marks lost or corrupt data with ``#`` lines in the
file, and ends with a ``# summary:`` line; whatever stops it (the end of the program, Ctrl-C,
an unplugged device, silence) leaves a valid file with everything read so far.
"""

from __future__ import annotations

import signal
import threading
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from . import _core, rtest
from .progress import ProgressBar
from .models import machine_members

# A tripod of probes, each 45 deg off the vertical, as R-test nests are commonly built.
DEFAULT_PROBE_DIRS = np.array([[1.0, 0.0, -1.0], [0.0, 1.0, -1.0], [-1.0, -1.0, -1.0]])
DEFAULT_PROBE_DIRS /= np.linalg.norm(DEFAULT_PROBE_DIRS, axis=1, keepdims=True)

Progress = Callable[[int, int, int, float, float], bool]


class RecordingProgress:
    """Recorder callback: a bar over the program's duration."""

    def __init__(self, label: str = "recording"):
        self.label, self.bar = label, None

    def __call__(self, rows: int, lost: int, corrupt: int, t: float, duration: float) -> bool:
        if self.bar is None:
            self.bar = ProgressBar(self.label, duration, " s")
        self.bar.update(t, f"rows {rows}  lost {lost}  corrupt {corrupt}")
        return True

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _record(
    run: Callable[[Any], _core.RecordSummary], progress: Progress | bool
) -> _core.RecordSummary:
    """Run a recorder with Ctrl-C turned into a clean stop: while it records, SIGINT only sets a
    flag that the progress callback returns, so the recorder closes the file and reports."""
    user = RecordingProgress() if progress is True else (progress or None)
    stop = {"requested": False}

    def callback(*p: Any) -> bool:
        return not stop["requested"] and (user is None or bool(user(*p)))

    in_main = threading.current_thread() is threading.main_thread()
    previous = (
        signal.signal(signal.SIGINT, lambda *_: stop.update(requested=True)) if in_main else None
    )
    try:
        return run(callback)
    finally:
        if in_main:
            signal.signal(signal.SIGINT, previous)
        if isinstance(user, RecordingProgress):
            user.close()


def virtual_ballbar(
    plan: Any,
    truth: Any,
    *,
    noise_um: float = 0.5,
    seed: int = 1,
    rate_hz: float = 1000.0,
    speed: float = 1.0,
    baud: int = 115200,
    faults: _core.FaultInjection | None = None,
) -> _core.VirtualBallbar:
    """Start a virtual ballbar that measures the machine ``truth`` (a BallbarMachineModel) while
    it runs ``plan`` (a BallbarPlan). ``speed`` > 1 runs faster than real time. Returns the
    running instrument: open ``.port`` like a serial port; ``.stop()`` ends it."""
    dev = _core.VirtualBallbar(
        plan, truth, noise_um, seed, rate_hz, speed, baud, faults or _core.FaultInjection()
    )
    dev.start()
    return dev


def record_ballbar(
    port: str,
    plan: Any,
    path: str,
    *,
    baud: int = 115200,
    rate_hz: float = 1000.0,
    zero: bool = False,
    silence_timeout_s: float = 3.0,
    progress: Progress | bool = True,
) -> _core.RecordSummary:
    """Record a ballbar test from ``port`` into ``path`` (rotacal-ballbar/1); each sample gets the
    commanded pose of ``plan`` at its time. ``progress``: True draws a bar on stderr, False
    nothing, or a callable(rows, lost, corrupt, t_s, duration_s) -> bool (False stops)."""
    return _record(
        lambda cb: _core.record_ballbar(
            port, plan, str(path), baud, rate_hz, zero, silence_timeout_s, cb
        ),
        progress,
    )


def rtest_program(
    machine: str = "BC-trt",
    b_deg: Sequence[float] = rtest.B_GRID,
    c_deg: Sequence[float] = rtest.C_GRID,
    nests: Sequence[Sequence[float]] = rtest.DEFAULT_NESTS,
    dwell_s: float = rtest.DEFAULT_DWELL_S,
) -> _core.RtestSession:
    """The commanded R-test program (set-up, time, B, C, X, Y, Z per pose, nests): the pattern
    on the nominal machine, which is what the NC program commands."""
    session, _ = rtest.simulate_rtest(
        "zero",
        {},
        machine=machine,
        b_deg=b_deg,
        c_deg=c_deg,
        nests=nests,
        noise_um=0.0,
        probe_zero_um=0.0,
        dwell_s=dwell_s,
        seed=1,
    )
    return session


def virtual_rtest(
    errors: Any = "random",
    effects: Mapping[str, Any] | None = None,
    *,
    machine: str = "BC-trt",
    b_deg: Sequence[float] = rtest.B_GRID,
    c_deg: Sequence[float] = rtest.C_GRID,
    nests: Sequence[Sequence[float]] = rtest.DEFAULT_NESTS,
    dwell_s: float = rtest.DEFAULT_DWELL_S,
    noise_um: float = rtest.DEFAULT_NOISE_UM,
    probe_zero_um: float = rtest.DEFAULT_PROBE_ZERO_UM,
    probe_dirs: np.ndarray | None = None,
    seed: int = 1,
    mode: str = "keyence",
    rate_hz: float = 100.0,
    speed: float = 1.0,
    baud: int = 115200,
    faults: _core.FaultInjection | None = None,
) -> tuple[_core.VirtualRtest, dict]:
    """Start a virtual R-test (sylvac, keyence or stream mode) on a machine with location errors
    and catalogue effects, running the Sec. 3.3 pattern. Returns (instrument, truth) where the
    truth has the shape of rtest.simulate_rtest's."""
    mtype, e, ids, params, effects_out = rtest.machine_truth(errors, effects, machine, seed)
    dirs = DEFAULT_PROBE_DIRS if probe_dirs is None else np.asarray(probe_dirs, dtype=float)
    nest_arr = np.asarray(nests, dtype=float).reshape(-1, 3)
    dev = _core.VirtualRtest(
        mtype,
        e,
        ids,
        params,
        list(map(float, b_deg)),
        list(map(float, c_deg)),
        nest_arr,
        float(dwell_s),
        float(noise_um),
        float(probe_zero_um),
        dirs,
        int(seed) % 2**32,
        mode,
        rate_hz,
        speed,
        baud,
        faults or _core.FaultInjection(),
    )
    dev.start()
    truth = {
        "errors": dict(zip(_core.location_error_names(mtype), e.tolist())),
        "effects": effects_out,
        "nests": nest_arr.tolist(),
        "noise_um": float(noise_um),
        "probe_zeros": dev.probe_zeros.tolist(),
        "probe_zero_um": float(probe_zero_um),
        **machine_members(mtype),
        "pattern": {
            "b_deg": list(map(float, b_deg)),
            "c_deg": list(map(float, c_deg)),
            "dwell_s": float(dwell_s),
        },
        "probe_dirs": dirs.tolist(),
        "mode": mode,
        "seed": int(seed),
    }
    return dev, truth


def record_rtest(
    port: str,
    program: _core.RtestSession,
    path: str,
    *,
    mode: str = "keyence",
    dwell_s: float = rtest.DEFAULT_DWELL_S,
    probe_dirs: np.ndarray | None = None,
    baud: int = 115200,
    rate_hz: float = 100.0,
    speed: float = 1.0,
    silence_timeout_s: float = 3.0,
    progress: Progress | bool = True,
) -> _core.RecordSummary:
    """Record an R-test from ``port`` into ``path`` (rotacal-rtest/1 with raw d1,d2,d3 and the
    probe directions, so readers convert them to dx,dy,dz). One row per pose: the mean of the
    readings taken inside its read window (the middle 80 % of its dwell, when the program holds
    the table at rest; docs/protocols.md), with their count ``n``, spread ``std_um``, mean
    program time ``t_s`` and smallest margin to the window's edges ``margin_s``. A polled reading
    not surely inside its window is counted (``summary.outside_window``), marked and not used; a
    pose without a reading inside its window is counted lost and marked."""
    dirs = DEFAULT_PROBE_DIRS if probe_dirs is None else np.asarray(probe_dirs, dtype=float)
    return _record(
        lambda cb: _core.record_rtest(
            port,
            mode,
            program,
            dwell_s,
            dirs,
            str(path),
            baud,
            rate_hz,
            speed,
            silence_timeout_s,
            cb,
        ),
        progress,
    )
