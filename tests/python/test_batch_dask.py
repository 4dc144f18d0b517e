# SPDX-License-Identifier: BSD-3-Clause
"""rotacal.batch on a real Dask cluster, started here on 127.0.0.1: one scheduler for every test
of this file and two workers (processes without a nanny, so that a SIGKILL is a death). A grid
slice there gives the local run's bits; a worker killed mid-run leaves every item exactly once;
the scheduler killed gives a clear error, the results so far kept, and a resume that completes.
Skipped, with the reason, only where dask[distributed] is not installed (rotacal[dask])."""

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip(
    "distributed", reason="Dask distributed is not installed: pip install rotacal[dask]"
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
import batch_grid  # noqa: E402

import rotacal  # noqa: E402
from rotacal.batch import BatchError, run, stream  # noqa: E402

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
BALLBAR = ("ballbar_ac_random.csv", "ballbar_ac_table2.csv")
# The workers import rotacal where this process does, batch_grid from this folder, and the
# confusion grid's modules from bench/ and tests/reference/.
PATHS = [str(Path(rotacal.__file__).resolve().parents[1]), str(HERE)]
PATHS += [str(REPO / "bench"), str(REPO / "tests" / "reference")]
ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join(PATHS),
    OMP_NUM_THREADS="1",
    DASK_DISTRIBUTED__WORKER__DAEMON="False",
)
ENV.pop("DASK_SCHEDULER_ADDRESS", None)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    """A scheduler and its workers, as processes of this test session."""

    def __init__(self) -> None:
        self.address = f"tcp://127.0.0.1:{_free_port()}"
        port = self.address.rsplit(":", 1)[1]
        self.scheduler = self._start(
            "dask_scheduler", "--host", "127.0.0.1", "--port", port, "--no-dashboard"
        )
        self.workers = [self.start_worker(f"w{i}") for i in (1, 2)]
        self.wait_for(2)

    def _start(self, cli: str, *args: str) -> subprocess.Popen:
        return subprocess.Popen(
            [sys.executable, "-m", f"distributed.cli.{cli}", *args],
            env=ENV,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )

    def start_worker(self, name: str) -> subprocess.Popen:
        return self._start(
            "dask_worker",
            self.address,
            "--name",
            name,
            "--nthreads",
            "1",
            "--no-nanny",
            "--no-dashboard",
            "--death-timeout",
            "30",
        )

    def wait_for(self, n: int) -> None:
        from distributed import Client

        with Client(self.address, timeout="60s", set_as_default=False) as c:
            c.wait_for_workers(n, timeout=120)

    def stop(self) -> None:
        for p in [*self.workers, self.scheduler]:
            if p.poll() is None:
                p.kill()
            p.wait()


@pytest.fixture(scope="session")
def cluster():
    c = Cluster()
    yield c
    c.stop()


@pytest.fixture(scope="module")
def grid(shared_data):
    return batch_grid.grid([shared_data / f for f in BALLBAR], 24)


@pytest.fixture(scope="module")
def local(grid):
    out = run(batch_grid.noisy_identification, grid, seed=3, jobs=1)
    assert all(ok for ok, _ in out), out
    return out


def test_a_grid_slice_on_dask_gives_the_local_results(cluster, grid, local):
    assert run(batch_grid.noisy_identification, grid, seed=3, executor=cluster.address) == local


def test_dask_scheduler_address_in_the_environment_is_the_default(cluster, monkeypatch):
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", cluster.address)
    pids = {pid for _, pid in run(batch_grid.process_id, list(range(8)), chunk=1)}
    assert os.getpid() not in pids and pids <= {w.pid for w in cluster.workers}, pids


def test_a_confusion_grid_slice_on_dask_gives_the_local_results(cluster):
    """bench/diagnosis_confusion.py's sessions (refsim's readings, rotacal's diagnosis): the
    same decisions, weights and z to the last bit, wherever they ran (the timings aside)."""
    sys.path[:0] = PATHS[2:]
    import diagnosis_confusion as bench
    from confusion import outcome
    from confusion.setup import tempdir

    cfg = {
        **bench.SMOKE,
        "instruments": ["ballbar"],
        "entries": ["gravity_sag"],
        "draws": 3,
        "null": 2,
        "seed": 29,
    }
    _, tasks = bench.plan(outcome.process_cache(tempdir()), cfg)
    assert len(tasks) == 10

    def untimed(results):
        assert all(ok for ok, _ in results), results
        return [{k: v for k, v in r.items() if k not in ("time_ms", "cpu_ms")} for _, r in results]

    local = untimed(run(outcome.work, tasks, jobs=1))
    assert untimed(run(outcome.work, tasks, executor=cluster.address, chunk=2)) == local
    assert any(r["findings"] for r in local)  # a real diagnosis, not empty records


def test_a_worker_killed_mid_run_leaves_every_item_exactly_once(cluster, grid, local):
    third = cluster.start_worker("w3")
    cluster.workers.append(third)
    cluster.wait_for(3)
    got = []
    for i, ok, value in stream(
        batch_grid.noisy_identification, grid, seed=3, executor=cluster.address, chunk=1
    ):
        if not got:
            third.send_signal(signal.SIGKILL)  # mid-run: the first item is in, 23 are not
            third.wait()
        got.append((i, ok, value))
    assert sorted(i for i, _, _ in got) == list(range(len(grid)))
    assert [(ok, v) for _, ok, v in sorted(got, key=lambda g: g[0])] == local


def test_the_scheduler_killed_a_clear_error_then_a_resume(cluster, shared_data, tmp_path):
    """Last in this file: the scheduler dies, and the resume runs on local threads."""
    files = []
    for i in range(12):
        f = tmp_path / f"m{i:02d}.csv"
        f.write_bytes((shared_data / BALLBAR[i % 2]).read_bytes())
        files.append(str(f))
    res = tmp_path / "res.jsonl"
    args = [sys.executable, "-m", "rotacal", "batch", "identify", *files, "-o", str(res)]
    child = subprocess.Popen(
        [*args, "--scheduler", cluster.address, "--chunk", "1", "--no-progress"],
        env=ENV,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 300
    while child.poll() is None and time.monotonic() < deadline:
        if res.exists() and res.read_text().count("\n") >= 3:  # the header and two items
            break
        time.sleep(0.05)
    cluster.scheduler.kill()
    cluster.scheduler.wait()
    out, err = child.communicate(timeout=300)
    assert child.returncode == 5, (out, err)
    kept = res.read_text()
    n_kept = kept.count("\n") - 1
    assert 2 <= n_kept < len(files), err
    assert "scheduler" in err and "run the same command again to resume" in err, err
    assert f"{n_kept} of {len(files)} items are recorded in {res}" in err, err
    again = subprocess.run(args + ["--no-progress"], env=ENV, capture_output=True, text=True)
    assert again.returncode == 0, again.stderr
    assert f"({len(files) - n_kept} computed in this run" in again.stdout
    assert res.read_text().startswith(kept)
    lines = res.read_text().splitlines()[1:]
    import json

    assert sorted(json.loads(x)["item"] for x in lines) == sorted(files)


def test_without_dask_an_address_is_refused_clearly(monkeypatch):
    """What a user without the extra is told (distributed hidden from the import)."""
    import builtins

    real = builtins.__import__

    def no_dask(name, *a, **k):
        if name == "distributed" or name.startswith("distributed."):
            raise ImportError(name)
        return real(name, *a, **k)

    monkeypatch.setattr(builtins, "__import__", no_dask)
    with pytest.raises(BatchError, match=r"pip install rotacal\[dask\]"):
        run(batch_grid.noisy_identification, [("x", 1.0)], executor="tcp://127.0.0.1:1")
