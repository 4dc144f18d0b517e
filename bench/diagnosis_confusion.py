# SPDX-License-Identifier: BSD-3-Clause
"""Confusion-matrix benchmark of rotacal's diagnosis on data from the independent reference
simulator tests/reference/refsim (issue 29, item 2). rotacal never simulates here: refsim makes
the readings, refsim.writers the file rotacal reads, refsim.noise the noise; rotacal only
diagnoses (rotacal.diagnose with its default DiagnosisOptions), in this process.

Cells: machine (AC-trt, BC-trt, B-head-C-table by default) x instrument (ballbar single set-up,
R-test 2-nest grid; refsim.poses; with --instruments ...,probe also the touch probe, 24 poses x 5
touches of plan probe's default layout: confusion/probe.py) x every entry of refsim's catalogue that applies x noise
(white, AR(1) rho 0.5 and 0.9, 1/f-like "pink", one stream per ballbar test / per R-test set-up
and channel) x amplitude (1x, 3x, 10x the entry's half-detection amplitude); N draws per cell,
M null sessions (no effect) per noise kind, spread over the machines and instruments. Motion-only
entries (backlash_*, servo_lag_*, reversal_spike_*) are skipped: refsim models static poses only.

Truth of every session of a machine x instrument: location errors drawn once (uniform +-30 um,
+-80 urad, seeded by the machine's name), the ballbar pivot off by (12, -8, 15) um, R-test probe
zeros uniform +-5 um per nest and channel, the probe's sphere off by (21, -17, 12) um; noise
1-sigma (marginal) 0.5 um ballbar, 0.3 um R-test, 0.5 um probe (along each touch's approach, one
stream per session), declared in the file (noise_um). thermal_warmup's tau is fixed at a third of the session.

Half-detection amplitude of an entry (machine, instrument): J0 is the baseline Jacobian (the 8
location errors, and the ballbar pivot, the R-test probe zeros of each nest and channel or the
probe's sphere position and, on a head, tool_offset_Z), Je the
entry's (its parameters; thermal_warmup: d only), both by central differences of refsim at the
truth. P = (I - Q0 Q0^T) with Q0 an orthonormal basis of J0; the least-absorbable direction u is
the first right singular vector of P Je (unit norm in the entry's native units), s its singular
value, k the number of singular values of P Je above 1e-3 of Je's largest (the rest is absorbed:
what is left of it is second order). Under white noise sigma an oracle fitting J0 and the k
visible directions of Je detects
when the chi-square drop D exceeds max(k F_crit(k, n - p - k; alpha / C), 10 + k ln n) (the F-test
at alpha = 0.01 Bonferroni over the C entries of the catalogue, and delta BIC < -10; n readings,
p = rank J0). D ~ noncentral chi2(k, lambda), lambda = (a s / sigma)^2: a_half is the a at which
P(detect) = 0.5 (lambda by Monte Carlo). A session's effect is sign * amp * a_half * u, the sign
random. Entries with s = 0 (absorbed) or needing more than a plausible size (1 mm, 1 mrad, 1 um/s,
1e-3) at 10x get no cell and are listed.

Per session: rotacal's first finding is right (named alone, the truth), ambiguous (not named, the
truth in its group, the best's posterior weight < 0.9: DiagnosisOptions.min_weight, the smaller
of its BIC and AIC weights), nothing (no finding) or wrong (named alone and wrong, or a group
without the truth). The oracle: the same session's readings minus the truth's
baseline readings, GLS with the true noise covariance on J0 against J0 + Je (its k visible
directions), the same two thresholds (BIC with the covariance known: chi2 + parameters x ln n). Coverage: |estimate - truth| <= 2 std for each determined parameter of right findings
(rotacal's units: thermal_warmup tau as ln(tau / 300 s)); beside it, on the parameters of those
findings that GLS under the true noise covariance determines (every entry whose parameters the
baseline does not absorb, thermal_warmup aside), rotacal's coverage and that GLS's on the same
readings: one draw per cell gives some 290 parameters in 130 sessions, whose coverage moves by
2-3 points from seed to seed with any estimator (AR(1) 0.9, 10x, seed 211: rotacal 223, the
true-covariance GLS 224 of 246).

  PYTHONPATH=build/dev/python python3 bench/diagnosis_confusion.py --smoke
  ... --machines AC-trt,BC-trt --noise white,ar1_0.9 --amplitudes 3,10 --draws 3 --null 30 --json out.json
  ... --tables-from out.json        (re-make the tables of a run)
  ... --results run.jsonl           (each session as it finishes; a rerun resumes)
  ... --jobs 2 | --scheduler tcp://host:8786   (local threads, default one per core; a Dask
      cluster whose workers import rotacal, tests/reference and bench: docs/batch.md)
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests" / "reference"))
sys.path.insert(0, str(HERE))

from confusion import report  # noqa: E402
from confusion import outcome  # noqa: E402
from confusion.setup import motion_only_entries, tempdir  # noqa: E402
from confusion.stats import NOISE_KINDS  # noqa: E402

SMOKE = {
    "machines": ["BC-trt"],
    "instruments": ["ballbar", "rtest", "probe"],
    "entries": ["gravity_sag", "tilt_motion_C_h1", "thermal_warmup_Z"],
    "noise": ["white", "ar1_0.9"],
    "amplitudes": [3.0],
    "draws": 2,
    "null": 4,
}


def parse_args(argv) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--smoke", action="store_true", help="a few cells, a few draws (< 60 s)")
    p.add_argument("--draws", type=int, default=10, help="draws per cell (default 10)")
    p.add_argument(
        "--null", type=int, default=100, help="null sessions per noise kind (default 100)"
    )
    p.add_argument(
        "--noise", default="white,ar1_0.5,ar1_0.9,pink", help=f"of {','.join(NOISE_KINDS)}"
    )
    p.add_argument("--machines", default="AC-trt,BC-trt,B-head-C-table")
    p.add_argument(
        "--instruments",
        default="ballbar,rtest",
        help="of ballbar,rtest,probe (default ballbar,rtest)",
    )
    p.add_argument(
        "--amplitudes", default="1,3,10", help="multiples of the half-detection amplitude"
    )
    p.add_argument(
        "--entries", default="", help="comma-separated substrings of catalogue ids (default: all)"
    )
    p.add_argument("--seed", type=int, default=29)
    p.add_argument("--json", help="write every session's outcome (and the amplitudes) to this file")
    p.add_argument(
        "--jobs", type=int, help="local worker threads (rotacal.batch; default one per core)"
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="a Dask scheduler (default $DASK_SCHEDULER_ADDRESS, else local threads)",
    )
    p.add_argument(
        "--results",
        metavar="RUN.jsonl",
        help="stream each session's record to this file as it finishes; a rerun of the same "
        "plan computes only the sessions not in it yet (the whole grid in several runs)",
    )
    p.add_argument("--no-cells", action="store_true", help="leave out the per-cell table")
    p.add_argument("--tables-from", help="print the tables of a --json file and stop")
    a = p.parse_args(argv)
    cfg = {
        "machines": a.machines.split(","),
        "instruments": a.instruments.split(","),
        "entries": [s for s in a.entries.split(",") if s],
        "noise": a.noise.split(","),
        "amplitudes": [float(x) for x in a.amplitudes.split(",")],
        "draws": a.draws,
        "null": a.null,
    }
    if a.smoke:
        cfg.update(SMOKE)
    for nz in cfg["noise"]:
        if nz not in NOISE_KINDS:
            p.error(f"--noise: unknown kind {nz!r} (known: {', '.join(NOISE_KINDS)})")
    for inst in cfg["instruments"]:
        if inst not in ("ballbar", "rtest", "probe"):
            p.error(f"--instruments: {inst!r} is none of ballbar, rtest, probe")
    cfg["seed"] = a.seed
    a.cfg = cfg
    return a


def plan(cache: outcome.CellCache, cfg: dict) -> tuple[list, list]:
    """(entries with their amplitudes, tasks): the hidden-effect cells' draws, then the nulls."""
    entries, tasks = [], []
    combos = [(m, i) for m in cfg["machines"] for i in cfg["instruments"]]
    for m, inst in combos:
        st = cache.setup(m, inst)
        for eid in st.catalogue:
            if cfg["entries"] and not any(s in eid for s in cfg["entries"]):
                continue
            ent = cache.entry(st, eid)
            entries.append(
                {
                    "machine": m,
                    "instrument": inst,
                    **{k: v for k, v in ent.items() if k not in ("je", "je_visible")},
                }
            )
            if ent["a_half"] is None:
                continue
            for nz in cfg["noise"]:
                for amp in cfg["amplitudes"]:
                    tasks += [
                        {
                            "machine": m,
                            "instrument": inst,
                            "entry": eid,
                            "noise": nz,
                            "amp": amp,
                            "draw": d,
                            "seed": cfg["seed"],
                        }
                        for d in range(cfg["draws"])
                    ]
    for nz in cfg["noise"]:
        for d in range(cfg["null"]):
            m, inst = combos[d % len(combos)]
            tasks.append(
                {
                    "machine": m,
                    "instrument": inst,
                    "entry": None,
                    "noise": nz,
                    "amp": 0.0,
                    "draw": d,
                    "seed": cfg["seed"],
                }
            )
    return entries, tasks


def task_key(t: dict) -> str:
    """A session's key in a --results file: its cell and draw."""
    return "/".join(str(t[k]) for k in ("machine", "instrument", "entry", "noise", "amp", "draw"))


def run(tasks: list, executor, jobs: int | None, results=None) -> list:
    """Every task, in order of completion (rotacal.batch: local threads, a Dask cluster), with a
    progress line on stderr; with ``results`` (a rotacal.batch.ResultsFile) the sessions it
    holds are taken from it and the others added to it as they finish. A session that fails
    stops the bench: it is a bug, not data."""
    from rotacal.batch import stream

    keys = [task_key(t) for t in tasks]
    held = results.records if results is not None else {}
    done = {i for i, k in enumerate(keys) if k in held}
    if done:
        print(f"[confusion] {len(done)} sessions from {results.path}", file=sys.stderr)
    out, t0, last = [held[keys[i]]["result"] for i in sorted(done)], time.time(), 0.0
    for i, ok, rec in stream(outcome.work, tasks, seed=0, executor=executor, jobs=jobs, skip=done):
        if not ok:
            raise RuntimeError(f"a session failed: {rec}")
        if results is not None:
            results.add(keys[i], True, rec)
        out.append(rec)
        now = time.time()
        if now - last > 5.0 or len(out) == len(tasks):
            last = now
            el = now - t0
            eta = el / max(1, len(out) - len(done)) * (len(tasks) - len(out))
            wrong = sum(r["outcome"] in ("wrong", "bad_group") for r in out)
            print(
                f"[confusion] {len(out)}/{len(tasks)} sessions, {el:.0f} s, eta {eta:.0f} s, wrong {wrong}",
                file=sys.stderr,
                flush=True,
            )
    return out


def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    if a.tables_from:
        print(report.tables(json.loads(Path(a.tables_from).read_text()), per_cell=not a.no_cells))
        return 0
    cfg = a.cfg
    t0 = time.time()
    cache = outcome.process_cache(tempdir())
    entries, tasks = plan(cache, cfg)
    print(
        f"[confusion] {len(tasks)} sessions planned ({len(entries)} entries) in {time.time() - t0:.1f} s",
        file=sys.stderr,
        flush=True,
    )
    if a.results:
        from rotacal.batch import ResultsFile

        with ResultsFile(a.results, {"command": "diagnosis_confusion", "options": cfg}) as held:
            records = run(tasks, a.scheduler, a.jobs, held)
    else:
        records = run(tasks, a.scheduler, a.jobs)

    def key(r):
        return (r["machine"], r["instrument"], r["entry"] or "", r["noise"], r["amp"], r["draw"])

    records.sort(key=key)
    motion = sorted({e for m in cfg["machines"] for e in motion_only_entries(m)})
    doc = {
        "config": cfg,
        "motion_only": motion,
        "entries": entries,
        "records": records,
        "wall_s": time.time() - t0,
        "jobs": a.jobs,
        "scheduler": a.scheduler,
        "cpu_count": os.cpu_count(),
    }
    if a.json:
        Path(a.json).write_text(json.dumps(doc, indent=1))
    print(report.tables(doc, per_cell=not a.no_cells))
    print(f"\n({len(records)} sessions in {time.time() - t0:.0f} s, --jobs {a.jobs})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
