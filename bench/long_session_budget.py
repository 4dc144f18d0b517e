#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""What `rotacal identify` costs on a long ballbar session, with and without the uncertainty
budget (issue 56, item 4: at 90,000 samples, at most 1 s and 150 MB with the budget). The
session comes from the independent reference simulator (tests/reference/refsim): AC-trt, the
single set-up's seven tests at a step giving N samples, location errors drawn (+-30 um,
+-80 urad, seeded), white noise 0.5 um. Each command runs as its own process; its wall time and
peak resident memory (the kernel's, wait4) are printed. With --against DENSE.json (the --json
of an earlier run) it prints the largest relative change of an expanded uncertainty, which the
issue bounds at 1 %.

  PYTHONPATH=build/release/python python3 bench/long_session_budget.py [--samples 90000]
      [--json OUT.json] [--against DENSE.json]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "reference"))

from refsim import instruments, poses, writers  # noqa: E402
from refsim.kinematics import Model  # noqa: E402
from refsim.machines import load_machine  # noqa: E402


def session_file(folder: Path, samples: int, seed: int) -> Path:
    machine = load_machine("AC-trt")
    step = 0.02 * 90_000 / samples  # 1800 samples a degree of step: 90,000 at 0.02 deg
    s = poses.ballbar_single_setup(machine, step_deg=step, dt=0.01)
    rng = np.random.default_rng(seed)
    errors = [
        rng.uniform(-30e-3, 30e-3) if k % 4 < 2 else rng.uniform(-80e-6, 80e-6) for k in range(8)
    ]
    model = Model(machine, errors=errors)
    length = instruments.ballbar_lengths(
        model, s["pivot"], s["xyz"], np.radians(s["angles_deg"]), s["time"]
    )
    path = folder / f"ballbar_{len(length)}.csv"
    writers.write_ballbar(path, machine, s, length + rng.normal(0.0, 0.5e-3, len(length)), 0.5)
    return path


def measured(args: list) -> tuple[float, float, str]:
    """(wall s, peak RSS MB, stdout) of one command in its own process."""
    t0 = time.perf_counter()
    p = subprocess.Popen(args, stdout=subprocess.PIPE, env=dict(os.environ, ROTACAL_PROGRESS="0"))
    out = p.stdout.read().decode()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(args)}: exit {os.waitstatus_to_exitcode(status)}")
    return wall, usage.ru_maxrss / 1024.0, out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--samples", type=int, default=90_000)
    p.add_argument("--seed", type=int, default=56)
    p.add_argument("--json", help="write the identification with its budget here")
    p.add_argument(
        "--against", help="an earlier --json: the largest change of an expanded uncertainty"
    )
    a = p.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="long_budget_") as d:
        path = session_file(Path(d), a.samples, a.seed)
        base = [sys.executable, "-m", "rotacal", "identify", str(path), "--json"]
        wall_nb, rss_nb, _ = measured(base + ["--no-budget"])
        wall, rss, out = measured(base)
    doc = json.loads(out)
    print(f"{doc['n_samples']} samples, AC-trt, refsim, seed {a.seed}")
    print(f"  identify --no-budget  {wall_nb:7.2f} s wall  {rss_nb:7.0f} MB peak")
    print(
        f"  identify (budget)     {wall:7.2f} s wall  {rss:7.0f} MB peak   (issue 56: <= 1 s, 150 MB)"
    )
    if a.json:
        Path(a.json).write_text(json.dumps(doc, indent=1))
    if a.against:
        dense = json.loads(Path(a.against).read_text())["uncertainty_budget"]["location_errors"]
        now = doc["uncertainty_budget"]["location_errors"]
        rel = {
            n: abs(now[n]["expanded"] - e["expanded"]) / e["expanded"]
            for n, e in dense.items()
            if e["observable"] and e["expanded"]
        }
        worst = max(rel, key=rel.get)
        print(f"  largest change of an expanded uncertainty: {100 * rel[worst]:.3f} % ({worst})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
