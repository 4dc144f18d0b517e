# SPDX-License-Identifier: BSD-3-Clause
"""The loop of an ambiguous diagnosis (issue 50, "Figures to reach: the loop";
docs/multi_diagnosis.md): a session of the independent reference simulator (tests/reference/refsim,
AR(1) 0.5 noise of 0.5 um, one hidden effect) diagnosed alone; where its first finding is a
group holding the truth, the deciding test is designed by the CLI (`rotacal design KIND
--separate X,Y --after S`, the pairs of python/rotacal/deciding_test.py in turn), its session
template read back, measured on the same machine by refsim and diagnosed with S by the CLI
(`rotacal diagnose S added.csv`). Counts per cell: draws; ambiguous (a group holding the truth);
nested (every pair of the group moves the table alike: no test can separate them); predicted
(the design separates a pair: predicted correlation below 0.5); of those, named first (the
truth alone, weight >= 0.9, for the machine) and wrong (a name or group without the truth).

    PYTHONPATH=build/release/python python3 bench/diagnosis_loop.py --draws 20
    PYTHONPATH=... python3 bench/diagnosis_loop.py --smoke        # one cell, 1 draw: that it runs

The cells are the groups the tests and docs/multi_diagnosis.md met (not yet the confusion
benchmark's list of every ambiguous entry at 3x its half-detection amplitude)."""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "python"))
import multi_diagnosis_data as md  # noqa: E402

import rotacal  # noqa: E402
from rotacal.deciding_test import deciding_pairs  # noqa: E402

# (instrument, machine, hidden effect and its parameters)
CELLS = [
    ("ballbar", "AC-trt", "gravity_sag_A", [4e-3]),
    ("ballbar", "AC-trt", "tilt_motion_A_h2", [3e-5, 0.0, 0.0, 0.0]),
    ("probe", "AC-trt", "gravity_sag_A", [5.5e-3]),
    ("rtest", "BC-trt", "coning_B", [2.5e-5]),
]


def cli(*args) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "rotacal", *map(str, args)], capture_output=True, text=True
    )


def session(kind, tmp, machine, errors, fx, seed, name, template=None):
    """The session of `kind` on the machine, or the added test of `template` (a path)."""
    if kind == "ballbar":
        if template is None:
            return md.ballbar(tmp, machine, errors, fx, seed)
        t = md.ballbar_template(template)
        return md.ballbar_from(tmp, machine, errors, fx, seed, t, name)
    if kind == "probe":
        actual = [140.004, -10.012, 75.021]  # the sphere, where both sessions find it
        poses = md.template_poses(template) if template else None
        return md.probe(tmp, machine, errors, fx, seed, poses_of=poses, actual=actual, name=name)
    pattern = md.rtest_template(template) if template else None
    return md.rtest(tmp, machine, errors, fx, seed, pattern=pattern, name=name)


def one_draw(kind, machine, truth, params, seed, tmp: Path) -> str:
    """not-ambiguous / ambiguous-nested / ambiguous-none, else the joint diagnosis' verdict:
    named / group / nothing / wrong / refused."""
    errors = md.machine_errors(machine, seed)
    fx = {truth: params}
    s, s_path = session(kind, tmp, machine, errors, fx, seed, f"S{seed}.csv")
    d = rotacal.diagnose(s).to_dict()
    f = d["findings"][0] if d["findings"] else None
    if f is None or f["named"] or truth not in [g["effect"] for g in f["group"]]:
        return "not-ambiguous"
    added = tmp / f"added{seed}.ngc"
    template = added.with_suffix(".csv")
    nested = True
    for pair in deciding_pairs(f):
        out = ["--session", template] if kind == "rtest" else ["-o", added]
        r = cli("design", kind, "--separate", ",".join(pair), "--after", s_path, "--json", *out)
        if r.returncode == 0:
            nested = nested and not json.loads(r.stdout)["separable"]
        if template.exists():
            break
    if not template.exists():
        return "ambiguous-nested" if nested else "ambiguous-none"
    _, a_path = session(kind, tmp, machine, errors, fx, seed + 1000, f"A{seed}.csv", template)
    r = cli("diagnose", s_path, a_path, "--json", "--no-progress")
    if r.returncode != 0:  # e.g. a one-pose probe test: identify_probe refuses it alone
        print(f"  seed {seed}: diagnose refused: {r.stderr.strip()}", file=sys.stderr)
        return "refused"
    j = json.loads(r.stdout)
    g = j["findings"][0] if j["findings"] else None
    if g is None:
        return "nothing"
    if g["named"]:
        ok = g["effect"] == truth and g["where"] == "machine" and g["weight"] >= 0.9
        return "named" if ok else "wrong"
    return "group" if truth in [m["effect"] for m in g["group"]] else "wrong"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--draws", type=int, default=20)
    p.add_argument("--first-seed", type=int, default=300)
    p.add_argument("--smoke", action="store_true", help="the first cell, 1 draw")
    p.add_argument("--cell", type=int, action="append", help="only these cells (0-based)")
    a = p.parse_args()
    cells = CELLS[:1] if a.smoke else [c for i, c in enumerate(CELLS) if not a.cell or i in a.cell]
    for kind, machine, truth, params in cells:
        counts: Counter = Counter()
        t0 = time.perf_counter()
        with tempfile.TemporaryDirectory() as tmp:
            for seed in range(a.first_seed, a.first_seed + (1 if a.smoke else a.draws)):
                counts[one_draw(kind, machine, truth, params, seed, Path(tmp))] += 1
        n = sum(counts.values())
        amb = n - counts["not-ambiguous"]
        predicted = amb - counts["ambiguous-nested"] - counts["ambiguous-none"]
        print(
            f"{kind} {machine} {truth} {params}: {n} draws, {amb} ambiguous, "
            f"{counts['ambiguous-nested']} nested, {predicted} predicted separable "
            f"({counts['ambiguous-none']} not), of those named {counts['named']}, "
            f"group {counts['group']}, nothing {counts['nothing']}, wrong {counts['wrong']}, "
            f"refused {counts['refused']} "
            f"({time.perf_counter() - t0:.1f} s)"
        )


if __name__ == "__main__":
    main()
