#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""What `rotacal identify` (and with --diagnose `rotacal diagnose`) costs on long ballbar sessions,
with and without the uncertainty budget (issue 56, item 4: at 90,000 samples identify with the
budget at most 1 s and 150 MB; at 1,000,000 samples, a 3 h recording at 100 Hz, identify at most
30 s, diagnose at most 10 min, peak memory at most 1 KB a sample above the baseline, which is the
peak of `python -c 'import rotacal'`, the interpreter and the package loaded). The
session comes from the independent reference simulator (tests/reference/refsim): AC-trt, the
single set-up's seven tests at a step giving N samples, location errors drawn (+-30 um,
+-80 urad, seeded), white noise 0.5 um. Each command runs as its own process; its wall time and
peak resident memory (the kernel's, wait4) are printed. With --against DENSE.json (the --json
of an earlier run of the first size) it prints the largest relative change of an expanded uncertainty, which the
issue bounds at 1 %.

  PYTHONPATH=build/release/python python3 bench/long_session_budget.py [--samples 90000[,N...]]
      [--diagnose] [--keep DIR] [--json OUT.json] [--against DENSE.json]
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
    path = folder / f"ballbar_{samples}_seed{seed}.csv"
    if path.exists():  # kept from an earlier run (--keep): the same size and seed, the same file
        return path
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
    writers.write_ballbar(path, machine, s, length + rng.normal(0.0, 0.5e-3, len(length)), 0.5)
    return path


def measured(args: list) -> tuple[float, float, float, str]:
    """(wall s, CPU s, peak RSS MB, stdout) of one command in its own process."""
    t0 = time.perf_counter()
    p = subprocess.Popen(args, stdout=subprocess.PIPE, env=dict(os.environ, ROTACAL_PROGRESS="0"))
    out = p.stdout.read().decode()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(args)}: exit {os.waitstatus_to_exitcode(status)}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0, out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--samples", default="90000", help="comma-separated session sizes")
    p.add_argument("--seed", type=int, default=56)
    p.add_argument(
        "--keep", help="keep the simulated sessions in this folder and reuse them (1e6: 10 min)"
    )
    p.add_argument("--diagnose", action="store_true", help="also time `rotacal diagnose`")
    p.add_argument("--json", help="write the first size's identification with its budget here")
    p.add_argument(
        "--against", help="an earlier --json: the largest change of an expanded uncertainty"
    )
    a = p.parse_args(argv)
    _, _, base_rss, _ = measured([sys.executable, "-c", "import rotacal"])
    load = os.getloadavg()[0]
    print(f"AC-trt, refsim, seed {a.seed}; baseline (import rotacal) {base_rss:.0f} MB peak")
    print(f"load average before: {load:.1f} (2 cores: wall times above 2 are a busy machine's)")
    for k, samples in enumerate(int(s) for s in a.samples.split(",")):
        with tempfile.TemporaryDirectory(prefix="long_budget_") as d:
            folder = Path(a.keep) if a.keep else Path(d)
            folder.mkdir(parents=True, exist_ok=True)
            path = session_file(folder, samples, a.seed)
            base = [sys.executable, "-m", "rotacal", "identify", str(path), "--json"]
            runs = [("identify --no-budget", base + ["--no-budget"]), ("identify (budget)", base)]
            if a.diagnose:
                runs.append(("diagnose", [sys.executable, "-m", "rotacal", "diagnose", str(path)]))
            figures = []
            for label, args in runs:
                wall, cpu, rss, out = measured(args)
                figures.append((label, wall, cpu, rss))
                if label == "identify (budget)":
                    doc = json.loads(out)
        n = doc["n_samples"]
        print(f"{n} samples ({n / 100 / 3600:.2f} h at 100 Hz)")
        for label, wall, cpu, rss in figures:
            per = (rss - base_rss) * 1024 * 1024 / n
            print(
                f"  {label:21s} {wall:8.2f} s wall {cpu:8.2f} s CPU {rss:7.0f} MB peak "
                f"{per:6.0f} B a sample"
            )
        if k == 0 and a.json:
            Path(a.json).write_text(json.dumps(doc, indent=1))
        if k == 0 and a.against:
            dense = json.loads(Path(a.against).read_text())["uncertainty_budget"]
            now = doc["uncertainty_budget"]["location_errors"]
            rel = {
                name: abs(now[name]["expanded"] - e["expanded"]) / e["expanded"]
                for name, e in dense["location_errors"].items()
                if e["observable"] and e["expanded"]
            }
            worst = max(rel, key=rel.get)
            print(
                f"  largest change of an expanded uncertainty: {100 * rel[worst]:.3f} % ({worst})"
            )
    print("issue 56: 90,000 samples identify (budget) <= 1 s, 150 MB; 1,000,000 samples identify")
    print("<= 30 s, diagnose <= 10 min, <= 1 KB a sample above the baseline")
    return 0


if __name__ == "__main__":
    sys.exit(main())
