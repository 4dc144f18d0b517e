# SPDX-License-Identifier: BSD-3-Clause
"""``rotacal batch identify|diagnose FILES...``: every session of a fleet identified or diagnosed
alone, on local threads (--jobs) or a Dask cluster (--scheduler), one record per file streamed
to a results file that a rerun resumes (docs/batch.md); with --store, the history written as the
results arrive."""

from __future__ import annotations

import argparse
import time
from functools import partial
from pathlib import Path

from .options import EPILOG, EXIT_OK, OptionError, budget_sizes, number, path, say
from .setups import add_db_arg, add_plausibility_arg

# Some items failed (each recorded with its error); the others' results are in the file.
EXIT_SOME_FAILED = 6
BATCH_EPILOG = (
    EPILOG + f", {EXIT_SOME_FAILED} some items failed (their errors are in the results file)"
)


def _machine_id(file: str, how: str) -> str:
    """The history's machine id of a fleet file: its name without suffix, or its folder's name."""
    p = Path(file)
    return p.stem if how == "stem" else p.resolve().parent.name


def _options(a: argparse.Namespace) -> dict:
    """What every item is computed with, as the results file's header records it: a rerun with
    other options is refused rather than mixed into the same file."""
    o = {
        "noise": a.noise,
        "no_budget": a.no_budget,
        "sizes": budget_sizes(a.budget_sizes),
        "max_deviation": a.max_deviation,
        "store": a.store,
    }
    if a.kind == "diagnose":
        o["max_harmonic"] = a.max_harmonic
    return o


def _progress(a: argparse.Namespace, total: int):
    from ..progress import ProgressBar

    return None if a.no_progress else ProgressBar(f"batch {a.kind}", total, " items")


def _store(h, a: argparse.Namespace, file: str, value: dict) -> int:
    """The history entry of one item's result: the identification, with the diagnosis beside it."""
    d = value["identification"] if a.kind == "identify" else value["diagnosis"]
    return h.add_identification(
        _machine_id(file, a.machine_id_from),
        value["model"],
        note=a.note,
        details={"diagnosis" if a.kind == "diagnose" else "identification": d},
        where=file,
    )


def cmd_batch(a: argparse.Namespace) -> int:
    from ..batch import BatchError, ResultsFile, items

    if len(set(a.file)) != len(a.file):
        dup = sorted({f for f in a.file if a.file.count(f) > 1})
        raise OptionError(f"FILE: {', '.join(dup[:3])} given twice (one result per file)")
    if a.jobs is not None and a.scheduler is not None:
        raise OptionError(
            "--jobs and --scheduler: one or the other (a cluster has its own workers)"
        )
    if (a.note is not None or a.db is not None) and not a.store:
        raise OptionError("--note and --db go with --store")
    options = _options(a)  # --budget-sizes refused before any work
    h = None
    if a.store:
        from ..history import open_history

        h = open_history(a.db)  # a store that cannot be opened is refused before any work
    work = partial(items.WORK[a.kind], options=options)
    try:
        with ResultsFile(a.results, {"command": a.kind, "options": options}) as out:
            done = {i for i, f in enumerate(a.file) if f in out.records}
            if done:
                say(f"rotacal: {a.results}: {len(done)} of {len(a.file)} items recorded, resuming")
            try:
                n_new, failed = _run(a, work, out, done, h)
            except BatchError as e:  # the cluster lost: what is recorded stays, a rerun resumes
                raise BatchError(
                    f"{e}; {len(out.records)} of {len(a.file)} items are recorded in "
                    f"{a.results}: run the same command again to resume"
                ) from None
    finally:
        if h is not None:
            h.close()
    failed_all = [r for r in (out.records[f] for f in a.file) if not r["ok"]]
    print(
        f"{len(a.file)} items: {len(a.file) - len(failed_all)} done, {len(failed_all)} failed "
        f"({n_new} computed in this run, {failed} of them failed); results in {a.results}"
    )
    for r in failed_all:
        say(f"rotacal: {r['item']}: {r['error']['type']}: {r['error']['message']}")
    return EXIT_SOME_FAILED if failed_all else EXIT_OK


def _run(a: argparse.Namespace, work, out, done: set, h) -> tuple[int, int]:
    """Every item not yet recorded, recorded as it arrives: (items computed, failed)."""
    from ..batch import executor
    from ..batch.executor import error_record

    bar, t0, n_new, failed = _progress(a, len(a.file)), time.monotonic(), 0, 0
    ex = a.scheduler  # None: DASK_SCHEDULER_ADDRESS, else local threads (executor.opened)
    try:
        for i, ok, value in executor.stream(
            work, a.file, seed=0, executor=ex, jobs=a.jobs, chunk=a.chunk, skip=done
        ):
            file = a.file[i]
            if ok and h is not None:
                try:
                    value["stored_entry"] = _store(h, a, file, value)
                except Exception as e:  # noqa: BLE001 - this item's failure, the batch goes on
                    ok, value = False, error_record(e)
                    value["message"] = f"store: {value['message']}"
            if ok:  # the model is the history's; the results line has the --json result
                value.pop("model", None)
            out.add(file, ok, value)
            failed += not ok
            n_new += 1
            if bar is not None:
                rate = n_new / max(time.monotonic() - t0, 1e-9)
                bar.update(len(done) + n_new, note=f"{rate:.2f} items/s, {failed} failed")
    finally:
        if bar is not None:
            bar.close()
    return n_new, failed


def add_batch(sub: argparse._SubParsersAction) -> argparse._SubParsersAction:
    q = sub.add_parser(
        "batch",
        help="identify or diagnose many sessions, each alone, on local cores or a Dask cluster",
        epilog=BATCH_EPILOG,
    )
    kinds = q.add_subparsers(dest="kind", required=True)
    for kind, what in (("identify", "identify"), ("diagnose", "diagnose")):
        k = kinds.add_parser(
            kind,
            help=f"{what} each session file alone (as `rotacal {kind} --json`)",
            epilog=BATCH_EPILOG,
        )
        k.add_argument("file", type=path("FILE"), nargs="+", help="the session files")
        k.add_argument(
            "-o",
            "--results",
            required=True,
            metavar="RESULTS.jsonl",
            type=path("--results"),
            help="one JSON line per file, written as each finishes; a rerun with the same "
            "options computes only the files not yet recorded",
        )
        k.add_argument(
            "--jobs",
            type=number("--jobs", 1, 4096, integer=True),
            help="local worker threads (default one per core)",
        )
        k.add_argument(
            "--scheduler",
            metavar="ADDRESS",
            help="a Dask scheduler, e.g. tcp://host:8786 (default $DASK_SCHEDULER_ADDRESS, else "
            "local threads; pip install rotacal[dask]); its workers read the files at these paths",
        )
        k.add_argument(
            "--chunk",
            type=number("--chunk", 1, 10_000, integer=True),
            help="files a task (default: up to 32, at least 4 tasks a worker)",
        )
        k.add_argument("--noise", default="auto", choices=["auto", "white"])
        k.add_argument("--budget-sizes", metavar="SIZES.json", type=path("--budget-sizes"))
        k.add_argument("--no-budget", action="store_true", help="skip the uncertainty budget")
        if kind == "diagnose":
            from ..diagnosis import MAX_HARMONIC

            k.add_argument(
                "--max-harmonic", type=number("--max-harmonic", 1, MAX_HARMONIC, integer=True)
            )
        k.add_argument("--no-progress", action="store_true", help="no progress line")
        add_plausibility_arg(k)
        g = k.add_argument_group("calibration history (docs/history.md)")
        g.add_argument(
            "--store",
            action="store_true",
            help="store each identification in the history as it arrives"
            + (" (with its diagnosis)" if kind == "diagnose" else ""),
        )
        g.add_argument(
            "--machine-id-from",
            choices=["stem", "folder"],
            default="stem",
            help="each file's machine id: its name without suffix (default) or its folder's name",
        )
        g.add_argument("--note", help="operator note stored with each entry")
        add_db_arg(g)
        k.set_defaults(func=cmd_batch)
    return kinds


COMMANDS = {"batch": add_batch}
