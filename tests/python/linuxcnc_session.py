# SPDX-License-Identifier: BSD-3-Clause
"""Running a headless LinuxCNC of tests/linuxcnc from a test.

A start costs seconds (rtapi_app, motion, task, io): the checks that use one kinematics module
share one (`shared`, `Start`: its display, serve_display.py, runs the tests' display programs as
jobs): xyzac-trt-kins (test_linuxcnc_kins.py, test_linuxcnc_probe.py through its identity
type), maxkins and 5axiskins (test_linuxcnc_heads.py), rotacal-kins (test_linuxcnc_rotacal_kins
.py). `run_linuxcnc` is one start for one display: the COMP_FILE check (test_comp_tables.py),
whose compensation table motion can only append to (command.c, EMCMOT_SET_JOINT_COMP), never
clear, so it would stay in every later check of a shared start.

Running LinuxCNC as root (as this project's CI does) needs RTAPI_UID, a non-root uid that
rtapi_app falls back to (it refuses otherwise), and RTAPI_FIFO_PATH in a directory that uid
may write. Only one LinuxCNC can run on a machine (/tmp/linuxcnc.lock; a new one shuts the
old one down), so a run refuses to start while another is running. Whatever the run started
is ended by pid (its process group, then the processes that carry the run's marker in their
environment), never by name.
"""

import json
import os
import re
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


def _spawn(run_dir: Path, ini: str, files: dict, run_timeout: float, out):
    """Start `linuxcnc` on a copy of tests/linuxcnc at `run_dir` with `files` added there:
    (process, marker of its processes, rtapi fifo directory)."""
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
    proc = subprocess.Popen(
        [LINUXCNC, str(run_dir / ini)],
        cwd=run_dir,
        env=env,
        stdin=subprocess.DEVNULL,
        stdout=out,
        stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    return proc, f"ROTACAL_LCNC_RUN={run_dir}".encode(), fifo_dir


def _diagnostics(run_dir: Path, log: list, proc, out: str) -> str:
    logs = "".join(
        f"\n--- {f.name}\n{f.read_text(errors='replace')[-3000:]}"
        for f in (run_dir / "linuxcnc_print.txt", run_dir / "linuxcnc_debug.txt")
        if f.exists()
    )
    return f"{'; '.join(log)}\nlinuxcnc exit {proc.returncode}, output:\n{out}{logs}"


def run_linuxcnc(run_dir: Path, ini: str, files: dict, result: str, run_timeout: float) -> dict:
    """One headless LinuxCNC session of tests/linuxcnc/`ini` in a copy at `run_dir`, with
    `files` (name -> text) added there; returns the JSON its display wrote to `result`, with
    "elapsed" (s, start to shut-down) added. The display is bounded by `run_timeout` s."""
    close_shared()  # only one LinuxCNC runs on a machine
    log = []
    t0 = time.monotonic()
    proc, marker, fifo_dir = _spawn(run_dir, ini, files, run_timeout, subprocess.PIPE)
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
        return _diagnostics(run_dir, log, proc, out.decode(errors="replace"))

    path = run_dir / result
    assert path.exists(), f"the display wrote no {result}\n{diagnostics()}"
    data = json.loads(path.read_text())
    assert "error" not in data, f"{data['error']}\n{diagnostics()}"
    assert proc.returncode == 0 and not log, diagnostics()
    assert not LOCK.exists(), f"LinuxCNC left {LOCK}\n{diagnostics()}"
    data["elapsed"] = elapsed
    return data


class Start:
    """One headless LinuxCNC start of tests/linuxcnc/`ini` whose display, serve_display.py,
    runs jobs: the checks of several tests share it (see `shared`). `files` are written into
    the run directory before the start (the INI's HAL files among them)."""

    def __init__(self, key: str, ini: str, files: dict):
        self.key = key
        self.run_dir = Path(tempfile.mkdtemp(prefix=f"rotacal-lcnc-{key}-")) / "run"
        self.log, self.jobs = [], 0
        text = (CONFIG / ini).read_text() if ini not in files else files[ini]
        files = dict(
            files, **{ini: re.sub(r"(?m)^DISPLAY = .*$", "DISPLAY = ./serve_display.py", text)}
        )
        self.t0 = time.monotonic()
        self.out_path = self.run_dir.parent / "linuxcnc.out"
        self._out = open(self.out_path, "wb")  # a file, not a pipe: a long start fills no buffer
        self.proc, self.marker, self.fifo_dir = _spawn(self.run_dir, ini, files, 60, self._out)
        (self.run_dir / "jobs").mkdir()

    def diagnostics(self) -> str:
        out = self.out_path.read_text(errors="replace")[-6000:]
        return _diagnostics(self.run_dir, self.log, self.proc, out)

    def job(
        self, display: str, job_dir: Path, files: dict, result: str, timeout: float, hal=()
    ) -> dict:
        """Run tests/linuxcnc/`display`.py's main() in `job_dir` (with `files` written there)
        after the halcmd commands `hal` (argument lists); its result, with "elapsed" (s)."""
        job_dir.mkdir(parents=True, exist_ok=True)
        os.chmod(job_dir, 0o755)
        for name, text in files.items():
            (job_dir / name).write_text(text)
        n, t0 = self.jobs, time.monotonic()
        self.jobs += 1
        spec = {"display": display, "dir": str(job_dir), "result": result, "timeout": timeout,
                "hal": [list(map(str, a)) for a in hal]}  # fmt: skip
        tmp = self.run_dir / "jobs" / f".{n}.json"
        tmp.write_text(json.dumps(spec))
        os.replace(tmp, self.run_dir / "jobs" / f"{n}.json")
        done = self.run_dir / "jobs" / f"{n}.done"
        end = t0 + timeout + 15
        while not done.exists():
            if self.proc.poll() is not None:
                pytest.fail(f"LinuxCNC ({self.key}) ended during job {n}\n{self.diagnostics()}")
            if time.monotonic() > end:
                pytest.fail(
                    f"job {n} ({display}) not done after {timeout + 15} s\n{self.diagnostics()}"
                )
            time.sleep(0.05)
        data = json.loads((job_dir / result).read_text())
        assert "error" not in data, f"{data['error']}\n{self.diagnostics()}"
        data["elapsed"] = time.monotonic() - t0
        return data

    def cpu_seconds(self) -> float:
        """CPU seconds the start's processes (rtapi_app, task, io, ...) have used so far."""
        total = 0.0
        for pid, _ in _ours(self.marker):
            try:
                stat = Path(f"/proc/{pid}/stat").read_text()
            except OSError:
                continue
            fields = stat[stat.rindex(")") + 2 :].split()
            total += (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
        return total

    def close(self):
        """Stop the display (and with it LinuxCNC); the checks a one-shot run makes."""
        cpu = self.cpu_seconds()
        tmp = self.run_dir / "jobs" / f".{self.jobs}.json"
        tmp.write_text(json.dumps({"stop": True}))
        os.replace(tmp, self.run_dir / "jobs" / f"{self.jobs}.json")
        try:
            self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.log.append("linuxcnc still running 30 s after the stop job")
        finally:
            _stop(self.proc, self.log)
            _end_ours(self.marker, self.log)
            shutil.rmtree(self.fifo_dir, ignore_errors=True)
            self._out.close()
        print(
            f"LinuxCNC start {self.key}: {self.jobs} jobs, {time.monotonic() - self.t0:.1f} s, "
            f"{cpu:.1f} CPU-s in its processes before the stop"
        )
        assert self.proc.returncode == 0 and not self.log, self.diagnostics()
        assert not LOCK.exists(), f"LinuxCNC left {LOCK}\n{self.diagnostics()}"
        shutil.rmtree(self.run_dir.parent, ignore_errors=True)


def hal_commands(text: str) -> list:
    """The halcmd commands of a HAL file for a running start: its `setp`, `net`, `loadrt`,
    `addf` lines (comments and blank lines skipped; anything else refused: a job must not
    change what the start loaded)."""
    cmds = []
    for k, line in enumerate(text.splitlines(), 1):
        words = line.split("#", 1)[0].split()
        if not words:
            continue
        if words[0] not in ("setp", "net", "loadrt", "addf"):
            raise ValueError(f"line {k}: {line!r}: not a command a running start takes")
        cmds.append(words)
    return cmds


_current: Start | None = None


def shared(key: str, ini: str, files: dict | None = None) -> Start:
    """The running start `key`, or a new one (of `ini`, with `files`) after the running start
    of another key is closed: only one LinuxCNC runs on a machine. A kinematics module is
    loaded once per start (motmod binds kinematicsForward/Inverse at its load: rtapi_app
    dlopens modules RTLD_GLOBAL), so every key is one module (and its switchkins types). The
    last start is closed at the end of the test session (conftest.py)."""
    global _current
    if _current is not None and _current.key == key and _current.proc.poll() is None:
        return _current
    close_shared()
    _current = Start(key, ini, files or {})
    return _current


def close_shared():
    global _current
    if _current is not None:
        start, _current = _current, None
        start.close()
