#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Two --json files of bench/diagnosis_confusion.py (the same plan: machines, noise, amplitudes,
draws, null, seed), compared session by session: whether a change of the diagnosis changed any
decision (outcome, findings with their groups and BIC weights to full float, z and coverage of
a right finding), and the median CPU time of a diagnosis per instrument and noise kind in each.

  python3 bench/confusion_compare.py before.json after.json [--show 10] [--decisions]

--decisions compares what an engineer is told (outcome, each finding's name, whether it is named
alone, its group, and the coverage of a right finding) and leaves out the BIC weights and z,
floats that a change which reorders arithmetic moves in the last digits.

Exit status 1 where any session differs (or the plans do), 0 where every one is the same: a
speed-up that claims to change no outcome is checked so.
"""

import argparse
import json
import statistics
import sys
from pathlib import Path

# What a session decided (diagnosis_confusion's record, confusion/outcome.py); time_ms and
# cpu_ms are how long it took, the rest what the bench made.
DECIDED = ("outcome", "findings", "z", "coverage")


def decision(r: dict) -> tuple:
    """What a session told the engineer, without the floats (--decisions)."""
    return (
        r["outcome"],
        [(f["effect"], f["named"], sorted(f["group"])) for f in r["findings"]],
        r.get("coverage"),
    )


def shown(r: dict) -> list:
    """Each finding's name, with the size of its group where it is not named alone."""
    return [
        x["effect"] + ("" if x["named"] else f" (group of {len(x['group'])})")
        for x in r["findings"]
    ]


def key(r: dict) -> tuple:
    return (
        r["machine"],
        r["instrument"],
        r["entry"] or "",
        r["noise"],
        r["amp"],
        r["draw"],
        r["seed"],
    )


def kind(r: dict) -> str:
    return f"{r['instrument']:8s} {r['noise']:9s} {'null' if r['entry'] is None else 'effect'}"


def medians(records: list) -> dict:
    by = {}
    for r in records:
        by.setdefault(kind(r), []).append(r["cpu_ms"])
        by.setdefault(f"{r['instrument']:8s} {r['noise']:9s} all", []).append(r["cpu_ms"])
        by.setdefault(f"{r['instrument']:8s} {'every':9s} all", []).append(r["cpu_ms"])
    return {k: (statistics.median(v), len(v)) for k, v in by.items()}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("before")
    p.add_argument("after")
    p.add_argument("--show", type=int, default=10, help="differing sessions printed (default 10)")
    p.add_argument(
        "--decisions",
        action="store_true",
        help="compare outcome, names, groups and coverage only, not weights and z",
    )
    a = p.parse_args(argv)
    docs = [json.loads(Path(f).read_text()) for f in (a.before, a.after)]
    recs = [{key(r): r for r in d["records"]} for d in docs]
    only = [set(recs[0]) - set(recs[1]), set(recs[1]) - set(recs[0])]
    if only[0] or only[1]:
        print(
            f"plans differ: {len(only[0])} sessions only in {a.before}, {len(only[1])} only in {a.after}"
        )
    diffs = []
    for k in sorted(set(recs[0]) & set(recs[1]), key=str):
        b, f = recs[0][k], recs[1][k]
        if a.decisions:
            changed = ["outcome, names, groups or coverage"] if decision(b) != decision(f) else []
        else:
            changed = [field for field in DECIDED if b.get(field) != f.get(field)]
        if changed:
            diffs.append((k, changed, b, f))
    common = len(set(recs[0]) & set(recs[1]))
    print(f"{common} sessions in both, {len(diffs)} differ in what they decided")
    for k, changed, b, f in diffs[: a.show]:
        print(
            f"  {k}: {', '.join(changed)}: {b['outcome']} {shown(b)} -> {f['outcome']} {shown(f)}"
        )
    m = [medians(d["records"]) for d in docs]
    print(
        f"\nmedian CPU ms per diagnosis (thread time)\n  {'':29s} {'before':>8s} {'after':>8s} {'n':>5s}"
    )
    for k in sorted(set(m[0]) | set(m[1])):
        b, f = m[0].get(k, (float("nan"), 0)), m[1].get(k, (float("nan"), 0))
        print(f"  {k:29s} {b[0]:8.0f} {f[0]:8.0f} {max(b[1], f[1]):5d}")
    return 1 if diffs or only[0] or only[1] else 0


if __name__ == "__main__":
    sys.exit(main())
