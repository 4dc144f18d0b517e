#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Throughput of a diagnosis-confusion grid slice on the local executor (issue 56's figure:
on 2 cores, 2 workers at least 1.8x the sessions a second of 1, and the executor's overhead per
session at most 5 % against a plain loop). The first N sessions of the grid
(bench/diagnosis_confusion.py's plan, AC-trt ballbar, white and pink noise) are run three ways,
in this order, in one process: a plain loop over outcome.work, rotacal.batch.stream with 1
worker, and with 2 workers. The records (but their clocks) must be the same all three ways (the
sessions' seeds are their cells' and draws'). The figure needs an idle computer: the load
average is printed before each run, and a run on a busy computer measures the other processes.

  PYTHONPATH=build/release/python python3 bench/batch_throughput.py [--sessions 2000]
      [--workers 1,2]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import diagnosis_confusion as grid  # noqa: E402
from confusion import outcome  # noqa: E402


def timed(label: str, run) -> tuple[float, float, list]:
    """(wall s, CPU s of this process, records in task order) of one way of running."""
    load = os.getloadavg()[0]
    t0, c0 = time.perf_counter(), time.process_time()
    records = run()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"  {label:22s} {wall:8.1f} s wall {cpu:8.1f} s CPU   (load average before {load:.1f})")
    return wall, cpu, records


def without_clocks(record: dict) -> dict:
    """A session's record but its own time and CPU time, which differ run to run."""
    return {k: v for k, v in record.items() if k not in ("time_ms", "cpu_ms")}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sessions", type=int, default=2000, help="the grid's first N sessions")
    p.add_argument("--workers", default="1,2", help="comma-separated local worker counts")
    a = p.parse_args(argv)
    from rotacal.batch import stream

    cfg = grid.parse_args(
        ["--machines", "AC-trt", "--instruments", "ballbar", "--noise", "white,pink"]
    ).cfg
    cache = outcome.process_cache(grid.tempdir())
    _, tasks = grid.plan(cache, cfg)
    if len(tasks) < a.sessions:
        p.error(f"--sessions: the slice's grid has {len(tasks)} sessions")
    tasks = tasks[: a.sessions]
    outcome.work(tasks[0])  # the cells' cached set-ups made before any clock starts
    print(f"{len(tasks)} sessions of the confusion grid (AC-trt ballbar, white and pink noise)")

    def batch(jobs: int):
        def run():
            out = [None] * len(tasks)
            for i, ok, rec in stream(outcome.work, tasks, seed=0, jobs=jobs):
                if not ok:
                    raise RuntimeError(f"session {i} failed: {rec}")
                out[i] = rec
            return out

        return run

    loop_wall, _, reference = timed("plain loop", lambda: [outcome.work(t) for t in tasks])
    walls = {}
    for jobs in (int(w) for w in a.workers.split(",")):
        walls[jobs], _, records = timed(f"rotacal.batch, {jobs} worker(s)", batch(jobs))
        if [without_clocks(r) for r in records] != [without_clocks(r) for r in reference]:
            raise SystemExit(f"{jobs} worker(s): the records differ from the plain loop's")
    print(f"  plain loop {len(tasks) / loop_wall:.2f} sessions/s")
    for jobs, wall in walls.items():
        print(f"  {jobs} worker(s) {len(tasks) / wall:.2f} sessions/s")
    if 1 in walls:
        print(f"  overhead per session, 1 worker against the loop: {walls[1] / loop_wall - 1:+.1%}")
        for jobs, wall in walls.items():
            if jobs > 1:
                print(f"  speed-up, {jobs} workers against 1: {walls[1] / wall:.2f}x")
    print("issue 56: speed-up >= 1.8x on 2 cores, overhead <= 5 %, on an idle computer")
    return 0


if __name__ == "__main__":
    sys.exit(main())
