# SPDX-License-Identifier: BSD-3-Clause
"""rotacal.batch on one computer: results that do not depend on the backend, the chunking or the
order; the C++ calls of a batch item release the GIL; `rotacal batch identify|diagnose` with a
malformed file, its results file resumed after a cut, and the history written as it goes."""

import concurrent.futures as cf
import functools
import json
import multiprocessing
import shutil
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import batch_grid  # noqa: E402
from conftest import run_cli  # noqa: E402

from rotacal import _core  # noqa: E402
from rotacal.batch import BatchError, ResultsFile, executor, items, run, seeds  # noqa: E402

BALLBAR = ("ballbar_ac_random.csv", "ballbar_ac_table2.csv")


@pytest.fixture(scope="module")
def grid(shared_data):
    return batch_grid.grid([shared_data / f for f in BALLBAR], 12)


def test_results_identical_whatever_backend_chunking_and_order(grid):
    """The same bits on one thread, two threads item by item, a pool given as it is (forked
    processes), and a run that skips the first half (each item's stream is chosen by its index)."""
    one = run(batch_grid.noisy_identification, grid, seed=7, jobs=1, chunk=len(grid))
    assert all(ok for ok, _ in one), one
    two = run(batch_grid.noisy_identification, grid, seed=7, jobs=2, chunk=1)
    with cf.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork")) as pool:
        procs = run(batch_grid.noisy_identification, grid, seed=7, executor=pool, chunk=5)
    half = run(batch_grid.noisy_identification, grid, seed=7, jobs=2, skip=range(6))
    assert two == one
    assert procs == one
    assert half[6:] == one[6:] and half[:6] == [None] * 6
    # The noise matters (the same file, two seeds, two results), so the equality above is not vacuous.
    other = run(batch_grid.noisy_identification, grid[:1], seed=8, jobs=1)
    assert other[0][1] != one[0][1]


def test_item_streams_are_the_seed_sequence_children():
    kids = seeds(5, 3)
    assert [k.spawn_key for k in kids] == [(0,), (1,), (2,)]
    assert (
        np.random.default_rng(kids[2]).random()
        == np.random.default_rng(np.random.SeedSequence(5).spawn(3)[2]).random()
    )


def test_chunks_are_tens_of_items_and_balance_the_workers():
    assert executor.chunk_size(34_000, 2) == executor.MAX_CHUNK
    assert executor.chunk_size(40, 2) == 5  # 8 chunks: 4 a worker
    assert executor.chunk_size(3, 8) == 1


def test_a_failing_item_is_recorded_and_the_rest_goes_on(shared_data, tmp_path):
    bad = tmp_path / "bad.csv"
    lines = (shared_data / BALLBAR[0]).read_text().splitlines()
    lines[8] = lines[8].replace(",", ",x", 1)  # line 9 of the file
    bad.write_text("\n".join(lines) + "\n")
    work = functools.partial(items.identify_file, options={"no_budget": True})
    (ok0, err), (ok1, good) = run(work, [str(bad), str(shared_data / BALLBAR[0])], jobs=1)
    assert not ok0 and ok1
    assert err["type"] == "ParseError" and "bad.csv" in err["message"] and ":9" in err["message"]
    assert good["identification"]["location_errors"]


def _longest_core_call_released(work, module: str = "rotacal._core") -> tuple[bool, str, dict]:
    """Run ``work()`` on a thread whose profile hook notes the rotacal._core function it is in;
    this thread, polling, sees which ones it could run during (only a call that releases the GIL
    lets it: a C function holding the GIL is never interrupted). (seen in the longest call, its
    name, {name: seconds})."""
    import time

    state = {"in": None, "t": 0.0}
    spent: dict = {}
    seen: set = set()
    done = threading.Event()

    def hook(frame, event, arg):
        if event == "c_call" and getattr(arg, "__module__", None) == module:
            state["in"], state["t"] = arg.__name__, time.perf_counter()
        elif event in ("c_return", "c_exception") and state["in"] is not None:
            if getattr(arg, "__module__", None) == module:
                name = state["in"]
                spent[name] = max(spent.get(name, 0.0), time.perf_counter() - state["t"])
                state["in"] = None

    def target():
        sys.setprofile(hook)
        try:
            work()
        finally:
            sys.setprofile(None)
            done.set()

    # No thread is made to hand over the GIL while it runs bytecode (the hook's included): this
    # one runs only where the other blocks or releases the GIL itself.
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    try:
        t = threading.Thread(target=target)
        t.start()
        while not done.is_set():
            now = state["in"]
            if now is not None:
                seen.add(now)
            time.sleep(0.0002)
        t.join()
    finally:
        sys.setswitchinterval(interval)
    longest = max(spent, key=spent.get)
    return longest in seen, longest, spent


def test_the_gil_probe_tells_a_call_that_holds_it_from_one_that_releases_it():
    """The check below can fail: builtins.sum over a long range holds the GIL for its whole
    call, time.sleep releases it."""
    import time

    held, name, spent = _longest_core_call_released(lambda: sum(range(10**7)), "builtins")
    assert name == "sum" and not held, spent
    released, name, _ = _longest_core_call_released(lambda: time.sleep(0.05), "time")
    assert name == "sleep" and released


@pytest.mark.parametrize("work", ["identify", "diagnose"])
def test_a_batch_items_cpp_calls_release_the_gil(shared_data, work):
    """The longest C++ call of a batch item (the fit, the diagnosis, the budget) let another
    Python thread run while it worked. Up to 5 tries: a thread the OS never scheduled during the
    call is not seen, but one that held the GIL can never be seen, so a pass is never luck."""
    path = str(shared_data / BALLBAR[0])
    seed = seeds(0, 1)[0]
    fn = items.WORK[work]
    for _ in range(5):
        released, longest, spent = _longest_core_call_released(
            lambda: fn(path, seed, {"no_budget": work == "diagnose"})
        )
        if released:
            break
    assert released, f"{longest} ({spent[longest]:.3f} s) held the GIL: {spent}"


# ------------------------------------------------------------------ rotacal batch identify|diagnose


@pytest.fixture
def fleet(shared_data, tmp_path):
    """Five machines' sessions (ballbar, R-test, touch probe), one of them malformed on line 9."""
    files = []
    for i, name in enumerate((*BALLBAR, "rtest_bc_oyama.csv", "probe_ac_table2.csv")):
        f = tmp_path / f"mill-{i + 1}.csv"
        shutil.copy(shared_data / name, f)
        files.append(f)
    bad = tmp_path / "mill-5.csv"
    lines = (shared_data / BALLBAR[1]).read_text().splitlines()
    lines[8] = lines[8].replace(",", ",x", 1)
    bad.write_text("\n".join(lines) + "\n")
    return files[:2] + [bad] + files[2:]


def _records(path: Path) -> tuple[dict, dict]:
    header, *lines = path.read_text().splitlines()
    recs = [json.loads(x) for x in lines]
    keys = [r["item"] for r in recs]
    assert len(keys) == len(set(keys)), f"an item recorded twice: {keys}"
    return json.loads(header), {r["item"]: r for r in recs}


def _untimed(recs: dict) -> dict:
    """The records without the diagnosis's "seconds" (how long it took, the one field that
    differs between two runs)."""
    for r in recs.values():
        if r["ok"]:
            r["result"]["diagnosis"].pop("seconds")
    return recs


def test_batch_identify_a_fleet_with_a_malformed_file(fleet, tmp_path):
    res = tmp_path / "res.jsonl"
    r = run_cli("batch", "identify", *fleet, "-o", res, "--jobs", "2", "--no-progress")
    assert r.returncode == 6, r.stderr
    header, recs = _records(res)
    assert header["command"] == "identify" and set(recs) == {str(f) for f in fleet}
    bad = recs[str(fleet[2])]
    assert not bad["ok"] and bad["error"]["type"] == "ParseError"
    assert "mill-5.csv" in bad["error"]["message"] and ":9" in bad["error"]["message"]
    assert f"{fleet[2]}: ParseError" in r.stderr and "5 items: 4 done, 1 failed" in r.stdout
    # Each result is what `rotacal identify --json` prints of that file alone.
    for f in (fleet[0], fleet[3], fleet[4]):
        alone = run_cli("identify", f, "--json")
        assert alone.returncode == 0, alone.stderr
        assert recs[str(f)]["result"]["identification"] == json.loads(alone.stdout), f


def test_batch_resumes_a_cut_run_and_computes_no_recorded_item_again(fleet, tmp_path):
    res = tmp_path / "res.jsonl"
    args = ("batch", "diagnose", *fleet[:4], "-o", res, "--no-budget", "--no-progress")
    assert run_cli(*args).returncode == 6
    full = res.read_text()
    _, recs = _records(res)
    # As a kill leaves it: the header, two records and half of the third.
    lines = full.splitlines(keepends=True)
    res.write_text("".join(lines[:3]) + lines[3][: len(lines[3]) // 2])
    kept = "".join(lines[:3])
    r = run_cli(*args)
    assert r.returncode == 6, r.stderr
    assert "2 of 4 items recorded, resuming" in r.stderr
    assert "(2 computed in this run" in r.stdout
    assert res.read_text().startswith(kept)
    _, again = _records(res)
    assert _untimed(again) == _untimed(recs)  # every item once, the same results
    r = run_cli(*args)  # nothing left: nothing computed
    assert "(0 computed in this run" in r.stdout and res.read_text().count("\n") == 5


def test_batch_refuses_the_results_of_other_options(fleet, tmp_path):
    res = tmp_path / "res.jsonl"
    run_cli("batch", "identify", fleet[0], "-o", res, "--no-budget", "--no-progress")
    r = run_cli("batch", "identify", fleet[0], "-o", res, "--no-progress")
    assert r.returncode == 5 and "the results of another batch" in r.stderr, r.stderr
    with pytest.raises(BatchError, match="not a rotacal batch results file"):
        (tmp_path / "x.jsonl").write_text("{}\n")
        ResultsFile(tmp_path / "x.jsonl", {"command": "identify"})


def test_batch_store_writes_the_history_as_results_arrive(fleet, tmp_path):
    from rotacal.history import open_history

    db = tmp_path / "h.sqlite"
    res = tmp_path / "res.jsonl"
    ok = [fleet[0], fleet[1], fleet[3]]
    r = run_cli("batch", "identify", *ok, "-o", res, "--store", "--db", db, "--no-progress")
    assert r.returncode == 0, r.stderr
    _, recs = _records(res)
    with open_history(str(db)) as h:
        machines = {m["machine_id"] for m in h.machines()}
        assert machines == {f.stem for f in ok} and len(machines) == 3
        for f in ok:
            entry = h.entry(recs[str(f)]["result"]["stored_entry"])
            assert entry["machine_id"] == f.stem


def test_batch_executor_argument_is_checked():
    with pytest.raises(_core.InvalidArgument, match="neither a scheduler address"):
        with executor.opened(3.5):
            pass
    with pytest.raises(_core.InvalidArgument, match="jobs"):
        with executor.opened(None, 0):
            pass
