# SPDX-License-Identifier: BSD-3-Clause
"""Where a batch runs: one executor argument for every batch API.

- ``None`` (the default): local threads, one per core. The C++ core releases the GIL during
  its loads, fits and diagnoses, so threads need no pickling and no extra dependency.
- An address (``tcp://host:8786``), given, or else the ``DASK_SCHEDULER_ADDRESS`` environment
  variable: a Dask distributed cluster (``pip install rotacal[dask]``). Its workers must
  import rotacal and read the batch's files at the same paths.
- Any ``concurrent.futures.Executor`` (a Dask client's ``get_executor()``, a process pool,
  mpi4py's): used as it is, and left open.

Work goes out to a cluster or a process pool in chunks (tens of items a task; to threads one by
one, as cheap and streaming each result as it is done), and every item draws its random numbers from
its own child of ``numpy.random.SeedSequence(root).spawn(n)``, chosen by the item's index in
the whole batch: results are bit-identical whatever the backend, the chunking and the order.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import os
import traceback
from typing import Any, Callable, Iterable, Iterator, Sequence

import numpy as np

from .. import _core

ENV_SCHEDULER = "DASK_SCHEDULER_ADDRESS"
MAX_CHUNK = 32  # items a task: enough to hide a cluster's per-task cost, few to lose to a kill
CHUNKS_PER_WORKER = 4  # at least this many chunks a worker, so that the last ones balance


class BatchError(_core.Error):
    """The batch itself cannot go on (its cluster lost, its results file unusable); the
    message says what was kept and how to resume."""


def local_workers() -> int:
    """The cores this process may run on (its affinity, not the machine's count)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _dask_client(address: str) -> Any:
    try:
        from distributed import Client
    except ImportError:
        raise BatchError(
            f"the scheduler {address} is a Dask cluster: install the extra, "
            "`pip install rotacal[dask]` (dask[distributed])"
        ) from None
    try:
        return Client(address, timeout="20s", set_as_default=False)
    except (OSError, TimeoutError) as e:
        raise BatchError(f"cannot reach the Dask scheduler at {address}: {e}") from None


@contextlib.contextmanager
def opened(executor: Any = None, jobs: int | None = None) -> Iterator[tuple[cf.Executor, int]]:
    """(the executor, its number of workers) for ``executor`` (None, an address or an
    Executor; module docstring) and ``jobs`` (local threads; default one per core). An
    executor made here is shut down on leaving; one given is left as it is."""
    if jobs is not None and jobs < 1:
        raise _core.InvalidArgument(f"jobs: {jobs} is not a number of workers (1 or more)")
    if isinstance(executor, cf.Executor):
        yield executor, jobs or _workers_of(executor)
        return
    if executor is not None and not isinstance(executor, str):
        raise _core.InvalidArgument(
            f"executor: {type(executor).__name__} is neither a scheduler address nor a "
            "concurrent.futures.Executor"
        )
    address = executor or os.environ.get(ENV_SCHEDULER) or None
    if address is None:
        n = jobs or local_workers()
        with cf.ThreadPoolExecutor(n, thread_name_prefix="rotacal-batch") as pool:
            yield pool, n
        return
    client = _dask_client(address)
    try:
        n = jobs or max(1, sum(w["nthreads"] for w in client.scheduler_info()["workers"].values()))
        # pure=False: a chunk run again after a worker's death is sent again, not deduplicated.
        yield client.get_executor(pure=False), n
    finally:
        with contextlib.suppress(Exception):
            client.close(timeout=5)


def _workers_of(executor: cf.Executor) -> int:
    n = getattr(executor, "_max_workers", None)  # thread and process pools
    if isinstance(n, int) and n > 0:
        return n
    client = getattr(executor, "_client", None)  # a Dask ClientExecutor
    if client is not None:
        with contextlib.suppress(Exception):
            return max(1, sum(w["nthreads"] for w in client.scheduler_info()["workers"].values()))
    return local_workers()


def chunk_size(n_items: int, workers: int) -> int:
    """Items a task off this process: tens where the batch is large, fewer where it would leave
    workers idle."""
    return max(1, min(MAX_CHUNK, n_items // (CHUNKS_PER_WORKER * max(1, workers))))


def seeds(root: int | None, n: int) -> list[np.random.SeedSequence]:
    """Item i's random stream: the i-th child of SeedSequence(root) (root None: fresh entropy)."""
    return np.random.SeedSequence(root).spawn(n)


def error_record(e: BaseException) -> dict:
    """What a failed item records: the exception's type and message (a reader's names the file
    and line), and where in the code it was raised."""
    tb = traceback.extract_tb(e.__traceback__)
    where = f"{os.path.basename(tb[-1].filename)}:{tb[-1].lineno}" if tb else ""
    return {"type": type(e).__name__, "message": str(e), "raised_at": where}


def run_chunk(fn: Callable[[Any, np.random.SeedSequence], Any], chunk: Sequence[tuple]) -> list:
    """One task: fn(item, seed) for each (index, item, seed); an item's failure is recorded as
    (index, False, error_record) and the chunk goes on."""
    out = []
    for i, item, seed in chunk:
        try:
            out.append((i, True, fn(item, seed)))
        except Exception as e:  # noqa: BLE001 - the item's error is its result
            out.append((i, False, error_record(e)))
    return out


def stream(
    fn: Callable[[Any, np.random.SeedSequence], Any],
    items: Sequence[Any],
    *,
    seed: int | None = 0,
    executor: Any = None,
    jobs: int | None = None,
    chunk: int | None = None,
    skip: Iterable[int] = (),
) -> Iterator[tuple[int, bool, Any]]:
    """fn(item, seed_sequence) of every item not in ``skip`` (indices), as
    (index, ok, result or error_record) in the order they finish. ``fn`` must be importable by
    name where the executor runs it (a module's function, not a lambda, for Dask or processes).
    A cluster lost mid-run raises BatchError after the results already yielded."""
    skipped = set(skip)
    children = seeds(seed, len(items))
    todo = [(i, items[i], children[i]) for i in range(len(items)) if i not in skipped]
    if not todo:
        return
    with opened(executor, jobs) as (ex, workers):
        # Threads share the process: a task costs some 18 us, not worth a chunk, and an item
        # alone streams its result (and its resume point) as soon as it is done.
        local = isinstance(ex, cf.ThreadPoolExecutor)
        size = chunk or (1 if local else chunk_size(len(todo), workers))
        futures = [ex.submit(run_chunk, fn, todo[k : k + size]) for k in range(0, len(todo), size)]
        try:
            for f in cf.as_completed(futures):
                try:
                    part = f.result()
                except (cf.CancelledError, OSError, TimeoutError) as e:
                    raise BatchError(f"{_lost(executor)} ({type(e).__name__}: {e})") from e
                yield from part
        finally:
            for f in futures:
                f.cancel()


def _lost(executor: Any) -> str:
    """What was lost when a task's future failed without a result of its own."""
    address = executor if isinstance(executor, str) else None
    if executor is None:
        address = os.environ.get(ENV_SCHEDULER)
    if address:
        return f"the Dask scheduler at {address} was lost, or its workers"
    return f"the executor ({type(executor).__name__}) lost the batch"


def run(
    fn: Callable[[Any, np.random.SeedSequence], Any], items: Sequence[Any], **kwargs: Any
) -> list[tuple[bool, Any]]:
    """Every item's (ok, result or error_record), in the items' order (stream's arguments)."""
    out: list = [None] * len(items)
    for i, ok, value in stream(fn, items, **kwargs):
        out[i] = (ok, value)
    return out
