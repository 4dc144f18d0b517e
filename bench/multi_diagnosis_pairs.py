# SPDX-License-Identifier: BSD-3-Clause
"""Figures of the diagnosis of several sessions (issue 50; docs/multi_diagnosis.md): two
sessions of one table made by the independent reference simulator (tests/reference/refsim) with
AR(1) 0.5 noise of 0.5 um, a ballbar single set-up and a touch-probe session of an AC-trt
(`--pair ballbar-probe`) or an R-test and a touch-probe session of a BC-trt (`--pair
rtest-probe`), one hidden machine effect (or none), or an instrument effect in one session only
(`--session-effect probe:stylus_radius_offset`), diagnosed alone and together. Per draw, the
first finding of each diagnosis: named (the truth alone), group (the truth among a group),
nothing, or wrong; the joint one also wrong when it holds a machine effect for a session, or a
session's effect for the machine or the other session. Prints the counts of each triple
(first session, probe, joint), where both alone gave a group how often the joint named the
cause alone, the wall time of the three kinds of diagnosis, and how often the joint model's
value of the truth (where it holds it) is within 2 sigma of it.

    PYTHONPATH=build/release/python python3 bench/multi_diagnosis_pairs.py \\
        --effect coning_A --amplitude 2.5e-5 --first-seed 100 --draws 20
    PYTHONPATH=... python3 bench/multi_diagnosis_pairs.py --pair rtest-probe --effect coning_B
    PYTHONPATH=... python3 bench/multi_diagnosis_pairs.py --effect none \\
        --session-effect probe:stylus_radius_offset --amplitude 2.5e-3
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


def verdict(d: dict, truth: str | None, where: str = "") -> str:
    """named, group, nothing or wrong; `where`: the joint diagnosis' place of the truth (machine,
    or the session's name), a finding elsewhere is wrong."""
    if not d["findings"]:
        return "nothing"
    f = d["findings"][0]
    if where and truth and f.get("where") != where:
        return "wrong"
    if f["named"]:
        return "named" if f["effect"] == truth else "wrong"
    return "group" if truth in [g["effect"] for g in f["group"]] else "wrong"


# The two sessions of each pair: (machine, first session's maker).
PAIRS = {"ballbar-probe": ("AC-trt", md.ballbar), "rtest-probe": ("BC-trt", md.rtest)}


# The figure set of `--figures` (BENCHMARKS.md): (pair, machine effect, session effect, amplitude).
FIGURES = [
    ("ballbar-probe", "coning_A", None, 2.5e-5),
    ("ballbar-probe", "gravity_sag_A", None, 4.5e-3),
    ("rtest-probe", "coning_B", None, 2.5e-5),
    ("rtest-probe", "gravity_sag_B", None, 4.5e-3),
    ("ballbar-probe", "none", "probe:stylus_radius_offset", 2.5e-3),
    ("ballbar-probe", "none", "first:ballbar_length_offset", 2.5e-3),
    ("rtest-probe", "none", "probe:stylus_radius_offset", 2.5e-3),
    ("ballbar-probe", "none", None, 0.0),
    ("rtest-probe", "none", None, 0.0),
]


def run_cell(pair: str, effect: str, session_effect: str | None, amplitude: float, seeds) -> None:
    """Diagnose each draw's two sessions alone and together; print the counts."""
    machine, first = PAIRS[pair]
    own, entry = (session_effect or ":").split(":")
    truth = entry or (None if effect == "none" else effect)
    fx = {effect: [amplitude]} if effect != "none" else {}
    counts: Counter = Counter()
    seconds = [0.0, 0.0, 0.0]
    covered: list[bool] = []
    with tempfile.TemporaryDirectory() as tmp:
        for seed in seeds:
            errors = md.machine_errors(machine, seed)
            mine = {entry: [amplitude]} if entry else {}
            s1, _ = first(
                Path(tmp), machine, errors, fx | (mine if own == "first" else {}), seed + 1
            )
            pr, _ = md.probe(
                Path(tmp), machine, errors, fx | (mine if own == "probe" else {}), seed + 2
            )
            row = []
            for i, s in enumerate((s1, pr, {"first": s1, "probe": pr})):
                t = time.perf_counter()
                d = rotacal.diagnose(s).to_dict()
                seconds[i] += time.perf_counter() - t
                if i == 2:
                    joint_truth = f"{own}:{entry}" if entry else truth
                    row.append(verdict(d, joint_truth, own if entry else "machine"))
                    if joint_truth and row[-1] in ("named", "group"):
                        held = d["findings"][0]["parameters"].get(joint_truth)
                        if held:  # the extended model holds the truth: its 2-sigma coverage
                            covered.append(abs(held["value"] - amplitude) <= 2 * held["std"])
                else:
                    # With a session's own effect, the other session has nothing to find.
                    seen = (entry if ("first", "probe")[i] == own else None) if entry else truth
                    row.append(verdict(d, seen))
            counts[tuple(row)] += 1
    what = session_effect or effect
    print(f"{pair} ({machine}), {what} {amplitude:g}, seeds from {seeds[0]}:")
    print(f"  (first session, probe, joint) counts over {sum(counts.values())} draws")
    for row, n in sorted(counts.items(), key=lambda kv: -kv[1]):
        print(f"  {n:3d}  {', '.join(row)}")
    rows = list(counts.elements())
    tally = {k: [sum(r[i] == k for r in rows) for i in range(3)] for k in ("named", "wrong")}
    print(
        f"  named first: first alone {tally['named'][0]}, probe alone {tally['named'][1]}, "
        f"joint {tally['named'][2]} of {len(rows)}; wrong: {tally['wrong'][0]}, "
        f"{tally['wrong'][1]}, joint {tally['wrong'][2]}"
    )
    both_group = [r for r in rows if r[0] == "group" and r[1] == "group"]
    print(
        "  where both alone gave a group, named alone together: "
        f"{sum(r[2] == 'named' for r in both_group)} of {len(both_group)}"
    )
    print("  wall s: first %.1f, probe %.1f, joint %.1f" % tuple(seconds))
    if covered:
        print(f"  joint model holding the truth: within 2 sigma {sum(covered)} of {len(covered)}")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--pair", choices=sorted(PAIRS), default="ballbar-probe")
    p.add_argument("--effect", default="coning_A", help="a one-parameter machine entry, or none")
    p.add_argument(
        "--session-effect",
        metavar="SESSION:ENTRY",
        help="an instrument effect in one session only (first or probe), e.g. "
        "probe:stylus_radius_offset; with --effect none the truth",
    )
    p.add_argument("--amplitude", type=float, default=2.5e-5)
    p.add_argument("--first-seed", type=int, default=100)
    p.add_argument("--draws", type=int, default=20)
    p.add_argument("--figures", action="store_true", help="every cell of FIGURES, --draws each")
    p.add_argument("--smoke", action="store_true", help="2 draws")
    a = p.parse_args()
    own = (a.session_effect or ":").split(":")[0]
    if a.session_effect and (own not in ("first", "probe") or a.effect != "none"):
        p.error("--session-effect first:ENTRY or probe:ENTRY, with --effect none")
    seeds = list(range(a.first_seed, a.first_seed + (2 if a.smoke else a.draws)))
    cells = FIGURES if a.figures else [(a.pair, a.effect, a.session_effect, a.amplitude)]
    for cell in cells:
        run_cell(*cell, seeds)


if __name__ == "__main__":
    main()
