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
truth alone, weight >= 0.9, for the machine), left with only members nested with the truth
(the model rule decides: holding the truth or not) and wrong (a name or group without the
truth). Where no test of the cell's instrument decides (none predicted, or a group left with a
non-nested pair), the machine's other instrument, as the main job does: the touch probe's
standard poses on the same machine, diagnosed with the sessions (counts on a second line).

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
    all_nested = True
    for pair in deciding_pairs(f):
        out = ["--session", template] if kind == "rtest" else ["-o", added]
        r = cli("design", kind, "--separate", ",".join(pair), "--after", s_path, "--json", *out)
        if r.returncode != 0:  # a failed design is no verdict on the pair: counted apart
            print(f"  seed {seed}: design failed: {r.stderr.strip()}", file=sys.stderr)
            return "design-failed"
        all_nested = all_nested and not json.loads(r.stdout)["separable"]
        if template.exists():
            break
    if not template.exists():
        if not all_nested and kind != "probe":
            other(kind, machine, truth, errors, fx, seed, tmp, s_path, [s_path])
        return "ambiguous-nested" if all_nested else "ambiguous-none"
    _, a_path = session(kind, tmp, machine, errors, fx, seed + 1000, f"A{seed}.csv", template)
    verdict = joint_verdict(kind, truth, s_path, [s_path, a_path], seed)
    if verdict == "group" and kind != "probe":
        other(kind, machine, truth, errors, fx, seed, tmp, s_path, [s_path, a_path])
    return verdict


def other(kind, machine, truth, errors, fx, seed, tmp, s_path, paths) -> None:
    """Where no added test of this instrument decided: the machine's other instrument, the touch
    probe's standard poses on the same machine (as the main job does), diagnosed with `paths`."""
    _, p_path = md.probe(tmp, machine, errors, fx, seed + 2000, name=f"P{seed}.csv")
    v = joint_verdict(kind, truth, s_path, [*paths, p_path], seed)
    OTHER[(kind, machine, truth)][v] += 1


# The verdicts of the step to the touch probe's standard poses, per cell.
OTHER: dict = {}
_NESTED: dict = {}


def nested(kind, a, b, s_path) -> bool:
    """The design's word: a and b move the table alike (no test can separate them)."""
    key = (kind, frozenset((a, b)))
    if key not in _NESTED:
        r = cli("design", kind, "--separate", f"{a},{b}", "--after", s_path, "--json")
        if r.returncode != 0:
            raise SystemExit(f"design {kind} --separate {a},{b} failed: {r.stderr.strip()}")
        _NESTED[key] = not json.loads(r.stdout)["separable"]
    return _NESTED[key]


def joint_verdict(kind, truth, s_path, paths, seed) -> str:
    """named / nested-held / nested-other (the truth with only members nested with it; the model
    holds the truth, or not) / group / nothing / wrong / refused."""
    r = cli("diagnose", *paths, "--json", "--no-progress")
    if r.returncode != 0:
        print(f"  seed {seed}: diagnose refused: {r.stderr.strip()}", file=sys.stderr)
        return "refused"
    j = json.loads(r.stdout)
    g = j["findings"][0] if j["findings"] else None
    if g is None:
        return "nothing"
    if g["named"]:
        ok = g["effect"] == truth and g["where"] == "machine" and g["weight"] >= 0.9
        return "named" if ok else "wrong"
    members = [m["effect"] for m in g["group"]]
    if truth not in members:
        return "wrong"
    if all(m == truth or nested(kind, truth, m, s_path) for m in members):
        return "nested-held" if g["effect"] == truth else "nested-other"
    return "group"


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
        OTHER[(kind, machine, truth)] = Counter()
        t0 = time.perf_counter()
        with tempfile.TemporaryDirectory() as tmp:
            for seed in range(a.first_seed, a.first_seed + (1 if a.smoke else a.draws)):
                counts[one_draw(kind, machine, truth, params, seed, Path(tmp))] += 1
        n = sum(counts.values())
        amb = n - counts["not-ambiguous"]
        predicted = (
            amb - counts["ambiguous-nested"] - counts["ambiguous-none"] - counts["design-failed"]
        )
        print(
            f"{kind} {machine} {truth} {params}: {n} draws, {amb} ambiguous, "
            f"{counts['ambiguous-nested']} nested, {predicted} predicted separable "
            f"({counts['ambiguous-none']} not), of those named {counts['named']}, "
            f"left with only members nested with the truth {counts['nested-held']} (the model "
            f"holding the truth) + {counts['nested-other']} (another), "
            f"group {counts['group']}, nothing {counts['nothing']}, wrong {counts['wrong']}, "
            f"refused {counts['refused']}, design failed {counts['design-failed']} "
            f"({time.perf_counter() - t0:.1f} s)"
        )
        o = OTHER[(kind, machine, truth)]
        if o:
            print(
                f"  then the probe's standard poses too, in {sum(o.values())}: named "
                f"{o['named']}, only nested members left {o['nested-held']} (held) + "
                f"{o['nested-other']}, group {o['group']}, nothing {o['nothing']}, "
                f"wrong {o['wrong']}, refused {o['refused']}"
            )


if __name__ == "__main__":
    main()
