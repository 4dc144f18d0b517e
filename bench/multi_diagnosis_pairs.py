# SPDX-License-Identifier: BSD-3-Clause
"""Figures of the diagnosis of several sessions (issue 50 item 1; docs/multi_diagnosis.md): a
ballbar single set-up and a touch-probe session of one AC-trt table, made by the independent
reference simulator (tests/reference/refsim) with AR(1) 0.5 noise of 0.5 um, one hidden machine
effect (or none), diagnosed alone and together. Per draw, the first finding of each diagnosis:
named (the truth alone), group (the truth among a group), nothing, or wrong; the joint one also
wrong when it holds the cause for a session instead of the machine. Prints the counts of each
triple (ballbar, probe, joint), the wall time of the three kinds of diagnosis, and how often the
joint model's value of the truth (where it holds it) is within 2 sigma of it.

    PYTHONPATH=build/release/python python3 bench/multi_diagnosis_pairs.py \\
        --effect coning_A --amplitude 2.5e-5 --first-seed 100 --draws 20
    PYTHONPATH=... python3 bench/multi_diagnosis_pairs.py --effect none --draws 30   # null pairs
    PYTHONPATH=... python3 bench/multi_diagnosis_pairs.py --smoke                    # that it runs
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "python"))
import multi_diagnosis_data as md  # noqa: E402

import rotacal  # noqa: E402


def verdict(d: dict, truth: str | None, joint: bool = False) -> str:
    if not d["findings"]:
        return "nothing"
    f = d["findings"][0]
    if joint and truth and f.get("where") != "machine":
        return "wrong"
    if f["named"]:
        return "named" if f["effect"] == truth else "wrong"
    return "group" if truth in [g["effect"] for g in f["group"]] else "wrong"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--effect", default="coning_A", help="a one-parameter machine entry, or none")
    p.add_argument("--amplitude", type=float, default=2.5e-5)
    p.add_argument("--first-seed", type=int, default=100)
    p.add_argument("--draws", type=int, default=20)
    p.add_argument("--smoke", action="store_true", help="2 draws")
    a = p.parse_args()
    truth = None if a.effect == "none" else a.effect
    fx = {truth: [a.amplitude]} if truth else {}
    counts: Counter = Counter()
    seconds = [0.0, 0.0, 0.0]
    covered: list[bool] = []
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(a.first_seed, a.first_seed + (2 if a.smoke else a.draws)):
            errors = md.machine_errors("AC-trt", seed)
            bb, _ = md.ballbar(Path(tmp), "AC-trt", errors, fx, seed + 1)
            pr, _ = md.probe(Path(tmp), "AC-trt", errors, fx, seed + 2)
            row = []
            for i, s in enumerate((bb, pr, [bb, pr])):
                t = time.perf_counter()
                d = rotacal.diagnose(s).to_dict()
                seconds[i] += time.perf_counter() - t
                row.append(verdict(d, truth, joint=i == 2))
                if i == 2 and truth and row[-1] in ("named", "group"):
                    held = d["findings"][0]["parameters"].get(truth)
                    if held:  # the extended model holds the truth: its 2-sigma coverage
                        covered.append(abs(held["value"] - a.amplitude) <= 2 * held["std"])
            counts[tuple(row)] += 1
    print(f"{a.effect} {a.amplitude:g}, seeds from {a.first_seed}: (ballbar, probe, joint) counts")
    for row, n in sorted(counts.items(), key=lambda kv: -kv[1]):
        print(f"  {n:3d}  {', '.join(row)}")
    print("wall s: ballbar %.1f, probe %.1f, joint %.1f" % tuple(seconds))
    if covered:
        print(
            f"joint model holding {truth}: within 2 sigma of the truth {sum(covered)} of {len(covered)}"
        )


if __name__ == "__main__":
    main()
