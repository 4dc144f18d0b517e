# SPDX-License-Identifier: BSD-3-Clause
"""Figures of the calibration history (docs/history.md): `history add` of 10,000
identifications (each its own transaction, as the command stores it) and `history show` of a
machine with 1,000 entries, in process; prints the times and the store's size. The target:
show <= 200 ms on SQLite.

    PYTHONPATH=... python bench/history_bench.py            # 10,000 adds, 10 machines x 1,000
    PYTHONPATH=... python bench/history_bench.py --smoke    # 300 adds, a quick check that it runs
    PYTHONPATH=... python bench/history_bench.py --db postgresql://...   # an empty PostgreSQL database

The identifications are one real joint fit of the shared Table 2 session (model with covariance,
noise model: the size of a stored entry) with its values shifted a little each time.
"""

from __future__ import annotations

import argparse
import copy
import datetime
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import rotacal
from rotacal.history import open_history
from rotacal.models import source_dict

SESSION = Path(__file__).resolve().parents[2] / "shared" / "data" / "ballbar_ac_table2.csv"


def identification() -> tuple[dict, dict]:
    """(model dict, identify --json dict) of the shared session, as identify --store stores them."""
    s = rotacal.load(str(SESSION))
    r = rotacal.identify(s, "joint")
    return r.model_dict() | {"source": source_dict(SESSION)}, r.to_dict()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--smoke", action="store_true", help="300 adds, machines of 100 entries")
    ap.add_argument(
        "--db", help="an empty store to fill (default: a SQLite file in a temporary folder)"
    )
    ap.add_argument(
        "--runs", type=int, default=7, help="show is timed this many times; the median is printed"
    )
    a = ap.parse_args()
    n_add, per_machine = (300, 100) if a.smoke else (10_000, 1_000)
    model, details = identification()
    tmp = tempfile.TemporaryDirectory(prefix="rotacal-history-bench-")
    db = a.db or os.path.join(tmp.name, "history.sqlite")
    t0 = datetime.datetime(2020, 1, 1, tzinfo=datetime.timezone.utc)
    models = []
    for i in range(n_add):  # made before the clock starts: only the store is timed
        m = copy.deepcopy(model)
        m["source"]["session_sha256"] = format(i, "064x")
        m["source"]["session"] = f"machine{i // per_machine}/session{i % per_machine}.csv"
        for k, est in enumerate(m["location_errors"].values()):
            if est["value"] is not None:
                est["value"] += 1e-7 * ((i * (k + 3)) % 11 - 5)
        models.append(m)
    with open_history(db) as h:
        start = time.perf_counter()
        for i, m in enumerate(models):
            when = (t0 + datetime.timedelta(days=i % per_machine)).strftime("%Y-%m-%dT%H:%M:%SZ")
            h.add_identification(
                f"SN-{i // per_machine:04d}",
                m,
                measured_at=when,
                details={"identification": details},
                note="bench",
            )
        add_s = time.perf_counter() - start
        times = []
        for _ in range(a.runs):
            s0 = time.perf_counter()
            summary = h.show("SN-0000")
            times.append(time.perf_counter() - s0)
        s0 = time.perf_counter()
    with open_history(db) as h2:  # open (schema check) and show, as a command does after start-up
        h2.show("SN-0000")
    open_show = time.perf_counter() - s0
    assert summary["identifications"] == per_machine
    size = (
        sum(p.stat().st_size for p in Path(db).parent.glob(Path(db).name + "*"))
        if "://" not in db
        else None
    )
    print(
        f"store: {'PostgreSQL' if '://' in db else 'SQLite'}, {n_add} identifications of "
        f"{n_add // per_machine} machines"
    )
    print(
        f"history add: {n_add} in {add_s:.2f} s = {add_s / n_add * 1e3:.2f} ms each "
        f"({n_add / add_s:.0f}/s), one transaction each"
    )
    if size is not None:
        print(
            f"store size: {size / 1e6:.1f} MB ({size / n_add / 1e3:.1f} kB per identification, model with "
            "covariance and the identify --json details)"
        )
    med = statistics.median(times)
    print(
        f"history show of a machine with {per_machine} entries: median {med * 1e3:.1f} ms of {a.runs} "
        f"(min {min(times) * 1e3:.1f}, max {max(times) * 1e3:.1f}); open + show {open_show * 1e3:.1f} ms"
        + (
            ""
            if a.smoke or "://" in db
            else f"; target <= 200 ms: {'met' if med <= 0.2 else 'NOT met'}"
        )
    )
    tmp.cleanup()
    return 0


if __name__ == "__main__":
    sys.exit(main())
