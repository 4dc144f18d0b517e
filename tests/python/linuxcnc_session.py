# SPDX-License-Identifier: BSD-3-Clause
"""Running a headless LinuxCNC of tests/linuxcnc from a test (test_linuxcnc_kins.py,
test_linuxcnc_probe.py).

Running LinuxCNC as root (as this project's CI does) needs RTAPI_UID, a non-root uid that
rtapi_app falls back to (it refuses otherwise), and RTAPI_FIFO_PATH in a directory that uid
may write. Only one LinuxCNC can run on a machine (/tmp/linuxcnc.lock; a new one shuts the
old one down), so a run refuses to start while another is running. Whatever the run started
is ended by pid (its process group, then the processes that carry the run's marker in their
environment), never by name.
"""

import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
from pathlib import Path

import pytest

LINUXCNC = shutil.which("linuxcnc")
LCNC_PYTHON = "/usr/bin/python3"  # the displays' shebang: Debian's python3 has the linuxcnc module
CONFIG = Path(__file__).resolve().parents[1] / "linuxcnc"
RTAPI_UID = 65534  # nobody: rtapi_app's fallback uid when started by root
LOCK = Path("/tmp/linuxcnc.lock")
LCNC_PROCESSES = {"linuxcncsvr", "milltask", "rtapi_app", "io"}


def _linuxcnc_module():
    if not os.access(LCNC_PYTHON, os.X_OK):
        return False
    r = subprocess.run(
        [LCNC_PYTHON, "-c", "import linuxcnc, hal"],
        capture_output=True,
        timeout=60,
        env={"PATH": "/usr/bin:/bin"},
    )
    return r.returncode == 0


requires_linuxcnc = pytest.mark.skipif(
    LINUXCNC is None or not _linuxcnc_module(),
    reason="LinuxCNC not installed (linuxcnc on PATH and the linuxcnc and hal modules of /usr/bin/python3): "
    "apt-get install linuxcnc-uspace",
)


def _processes():
    """(pid, comm, state) of every process, read from /proc (nothing is sent to any)."""
    for p in Path("/proc").iterdir():
        if p.name.isdigit():
            try:
                stat = (p / "stat").read_text()
            except OSError:
                continue
            comm = stat[stat.index("(") + 1 : stat.rindex(")")]
            yield int(p.name), comm, stat[stat.rindex(")") + 2 :].split()[0]


def _running_linuxcnc():
    """LinuxCNC processes on this machine (zombies left for their parent to reap excepted)."""
    return [
        f"{comm} ({pid})"
        for pid, comm, state in _processes()
        if comm in LCNC_PROCESSES and state != "Z"
    ]


def _ours(marker):
    """Live processes started by our linuxcnc run, known by a variable in their environment:
    linuxcncsvr and rtapi_app leave our process group (setsid)."""
    left = []
    for pid, comm, state in _processes():
        try:
            env = Path(f"/proc/{pid}/environ").read_bytes()
        except OSError:
            continue
        if marker in env.split(b"\0") and state != "Z":
            left.append((pid, comm))
    return left


def _end_ours(marker, log):
    """Wait for what our run started to exit; end by pid (SIGTERM, then SIGKILL) what does not."""
    for sig, grace in ((None, 20), (signal.SIGTERM, 5), (signal.SIGKILL, 5)):
        left = _ours(marker)
        if not left:
            return
        if sig is not None:
            log.append(f"{sig.name} to {', '.join(f'{c} ({p})' for p, c in left)}")
            for pid, _ in left:
                try:
                    os.kill(pid, sig)
                except ProcessLookupError:
                    pass
        end = time.monotonic() + grace
        while _ours(marker) and time.monotonic() < end:
            time.sleep(0.1)
    left = _ours(marker)
    if left:
        log.append(f"still running: {left}")


def _stop(proc, log):
    """End the linuxcnc process group we started: SIGTERM lets the linuxcnc script's own Cleanup
    run (the display ends, then task, io, HAL and rtapi_app); SIGKILL only if that hangs."""
    if proc.poll() is not None:
        return
    for sig, grace in ((signal.SIGTERM, 20), (signal.SIGKILL, 10)):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=grace)
            log.append(f"linuxcnc ended by {sig.name}")
            return
        except subprocess.TimeoutExpired:
            continue
    log.append(f"linuxcnc (pid {proc.pid}) did not end after SIGKILL")


def run_linuxcnc(run_dir: Path, ini: str, files: dict, result: str, run_timeout: float) -> dict:
    """One headless LinuxCNC session of tests/linuxcnc/`ini` in a copy at `run_dir`, with
    `files` (name -> text) added there; returns the JSON its display wrote to `result`, with
    "elapsed" (s, start to shut-down) added. The display is bounded by `run_timeout` s."""
    shutil.copytree(CONFIG, run_dir)
    for name, text in files.items():
        (run_dir / name).write_text(text)
    for program in run_dir.glob("*.py"):  # the displays and the HAL component are run as programs
        os.chmod(program, 0o755)
    other = _running_linuxcnc()
    if other:
        pytest.fail(
            f"another LinuxCNC is running ({', '.join(other)}); starting one would shut it down"
        )
    fifo_dir = Path(tempfile.mkdtemp(prefix="rotacal-rtapi-"))  # /tmp: reachable by RTAPI_UID
    os.chown(fifo_dir, RTAPI_UID, -1)
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV", "DISPLAY", "WAYLAND_DISPLAY")
    }
    env.update(
        RTAPI_UID=str(RTAPI_UID),
        RTAPI_FIFO_PATH=str(fifo_dir / "rtapi_fifo"),
        HOME=str(run_dir),  # without a tty, linuxcnc leaves its logs in $HOME on an error
        ROTACAL_LCNC_RUN_TIMEOUT=str(run_timeout),
        ROTACAL_LCNC_RUN=str(run_dir),
    )
    marker = f"ROTACAL_LCNC_RUN={run_dir}".encode()
    log = []
    t0 = time.monotonic()
    proc = subprocess.Popen(
        [LINUXCNC, str(run_dir / ini)],
        cwd=run_dir,
        env=env,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    try:
        try:
            out, _ = proc.communicate(timeout=run_timeout + 15)
        except subprocess.TimeoutExpired:
            out = b""
            log.append(f"linuxcnc still running after {run_timeout + 15} s")
        t_end = time.monotonic()
    finally:
        _stop(proc, log)
        _end_ours(marker, log)
        shutil.rmtree(fifo_dir, ignore_errors=True)
    elapsed = time.monotonic() - t0
    print(f"linuxcnc ran {t_end - t0:.1f} s, shut down in {elapsed - (t_end - t0):.1f} s more")

    def diagnostics():
        logs = "".join(
            f"\n--- {f.name}\n{f.read_text(errors='replace')[-3000:]}"
            for f in (run_dir / "linuxcnc_print.txt", run_dir / "linuxcnc_debug.txt")
            if f.exists()
        )
        return f"{'; '.join(log)}\nlinuxcnc exit {proc.returncode}, output:\n{out.decode(errors='replace')}{logs}"

    path = run_dir / result
    assert path.exists(), f"the display wrote no {result}\n{diagnostics()}"
    data = json.loads(path.read_text())
    assert "error" not in data, f"{data['error']}\n{diagnostics()}"
    assert proc.returncode == 0 and not log, diagnostics()
    assert not LOCK.exists(), f"LinuxCNC left {LOCK}\n{diagnostics()}"
    data["elapsed"] = elapsed
    return data
