"""`rotacal export --controller linuxcnc` checked by LinuxCNC itself.

test_export.py re-implements xyzac-trt-kins (trtfuncs.c) in numpy; here the real module does
the inverse kinematics. A headless simulated machine (tests/linuxcnc/xyzac-trt-sim.ini: motion,
xyzac-trt-kins, pass-through joints as LinuxCNC's sim configs, no GUI) is started twice with
`linuxcnc`, once with the machine's current pins (the --current file of the export) and once
with rotacal's exported HAL file loaded as a [HAL]HALFILE. Its display program
(tests/linuxcnc/tcp_display.py, run by Debian's /usr/bin/python3, which has the `linuxcnc`
module) homes the machine, moves in world coordinates (TCP: coordinated mode through the
kinematics) with MDI G0 to table points q at tilt A and rotation C, and reads back the joint
positions. With the exported pins those must be where rotacal's identified model puts the
table point (P0 + forward(position errors, A, C, q)); with the current pins they must not.

Running LinuxCNC as root (as this project's CI does) needs RTAPI_UID, a non-root uid that
rtapi_app falls back to (it refuses otherwise), and RTAPI_FIFO_PATH in a directory that uid
may write. Only one LinuxCNC can run on a machine (/tmp/linuxcnc.lock; a new one shuts the
old one down), so the test refuses to start while another is running.
"""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from rotacal import _core

LINUXCNC = shutil.which("linuxcnc")
LCNC_PYTHON = "/usr/bin/python3"  # the display's shebang: Debian's python3 has the linuxcnc module
CONFIG = Path(__file__).resolve().parents[1] / "linuxcnc"


def _linuxcnc_module():
    if not os.access(LCNC_PYTHON, os.X_OK):
        return False
    r = subprocess.run([LCNC_PYTHON, "-c", "import linuxcnc"], capture_output=True, timeout=60,
                       env={"PATH": "/usr/bin:/bin"})
    return r.returncode == 0


pytestmark = pytest.mark.skipif(
    LINUXCNC is None or not _linuxcnc_module(),
    reason="LinuxCNC not installed (linuxcnc on PATH and the linuxcnc module of /usr/bin/python3): "
    "apt-get install linuxcnc-uspace")

RTAPI_UID = 65534  # nobody: rtapi_app's fallback uid when started by root
LOCK = Path("/tmp/linuxcnc.lock")
LCNC_PROCESSES = {"linuxcncsvr", "milltask", "rtapi_app", "io"}
RUN_TIMEOUT = 45  # s, the display's own bound (SIGALRM); the test waits 15 s longer
TOL = 1e-4  # mm: 0.1 um; LinuxCNC reports doubles, the exported pins carry 1 nm
P0 = np.array([250.0, -120.0, 80.0])  # joint position of the pivot (rotacal's origin)


def rotacal_cli(*args):
    r = subprocess.run([sys.executable, "-m", "rotacal", *map(str, args)], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    return r


def _processes():
    """(pid, comm, state) of every process, read from /proc (nothing is sent to any)."""
    for p in Path("/proc").iterdir():
        if p.name.isdigit():
            try:
                stat = (p / "stat").read_text()
            except OSError:
                continue
            comm = stat[stat.index("(") + 1:stat.rindex(")")]
            yield int(p.name), comm, stat[stat.rindex(")") + 2:].split()[0]


def _running_linuxcnc():
    """LinuxCNC processes on this machine (zombies left for their parent to reap excepted)."""
    return [f"{comm} ({pid})" for pid, comm, state in _processes() if comm in LCNC_PROCESSES and state != "Z"]


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


def run_linuxcnc(run_dir: Path, pins: Path, poses: np.ndarray) -> dict:
    """One headless LinuxCNC session with the pins of `pins`; the joints at every pose."""
    shutil.copytree(CONFIG, run_dir)
    os.chmod(run_dir / "tcp_display.py", 0o755)
    shutil.copy(pins, run_dir / "pins.hal")
    (run_dir / "poses.json").write_text(json.dumps(poses.tolist()))
    other = _running_linuxcnc()
    if other:
        pytest.fail(f"another LinuxCNC is running ({', '.join(other)}); starting one would shut it down")
    fifo_dir = Path(tempfile.mkdtemp(prefix="rotacal-rtapi-"))  # /tmp: reachable by RTAPI_UID
    os.chown(fifo_dir, RTAPI_UID, -1)
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV", "DISPLAY", "WAYLAND_DISPLAY")}
    env.update(RTAPI_UID=str(RTAPI_UID), RTAPI_FIFO_PATH=str(fifo_dir / "rtapi_fifo"),
               HOME=str(run_dir),  # without a tty, linuxcnc leaves its logs in $HOME on an error
               ROTACAL_LCNC_RUN_TIMEOUT=str(RUN_TIMEOUT), ROTACAL_LCNC_RUN=str(run_dir))
    marker = f"ROTACAL_LCNC_RUN={run_dir}".encode()
    log = []
    t0 = time.monotonic()
    proc = subprocess.Popen([LINUXCNC, str(run_dir / "xyzac-trt-sim.ini")], cwd=run_dir, env=env,
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            start_new_session=True)
    try:
        try:
            out, _ = proc.communicate(timeout=RUN_TIMEOUT + 15)
        except subprocess.TimeoutExpired:
            out = b""
            log.append(f"linuxcnc still running after {RUN_TIMEOUT + 15} s")
        t_end = time.monotonic()
    finally:
        _stop(proc, log)
        _end_ours(marker, log)
        shutil.rmtree(fifo_dir, ignore_errors=True)
    elapsed = time.monotonic() - t0
    print(f"linuxcnc ran {t_end - t0:.1f} s, shut down in {elapsed - (t_end - t0):.1f} s more")

    def diagnostics():
        logs = "".join(f"\n--- {f.name}\n{f.read_text(errors='replace')[-3000:]}"
                       for f in (run_dir / "linuxcnc_print.txt", run_dir / "linuxcnc_debug.txt") if f.exists())
        return f"{'; '.join(log)}\nlinuxcnc exit {proc.returncode}, output:\n{out.decode(errors='replace')}{logs}"

    result = run_dir / "joints.json"
    assert result.exists(), f"the display wrote no joints.json\n{diagnostics()}"
    data = json.loads(result.read_text())
    assert "error" not in data, f"{data['error']}\n{diagnostics()}"
    assert proc.returncode == 0 and not log, diagnostics()
    assert not LOCK.exists(), f"LinuxCNC left {LOCK}\n{diagnostics()}"
    data["elapsed"] = elapsed
    return data


def _pins(path: Path) -> dict:
    return {m.group(1): float(m.group(2))
            for m in re.finditer(r"^setp xyzac-trt-kins\.(\S+) (\S+)$", path.read_text(), re.M)}


def test_xyzac_trt_kins_with_exported_pins_reproduces_the_model(shared_data, tmp_path):
    model = tmp_path / "model.json"
    rotacal_cli("identify", shared_data / "ballbar_ac_table2.csv", "--save-model", model)
    # The machine's kinematics while the ballbar test ran: the pivot at joint position P0.
    current = tmp_path / "machine.hal"
    current.write_text(f"setp xyzac-trt-kins.x-rot-point {P0[0]}\nsetp xyzac-trt-kins.y-rot-point {P0[1]}\n"
                       f"setp xyzac-trt-kins.z-rot-point 0\nsetp xyzac-trt-kins.z-offset {P0[2]}\n"
                       "setp xyzac-trt-kins.y-offset 0\n")
    corrected = tmp_path / "corrected.hal"
    rotacal_cli("export", "--model", model, "--controller", "linuxcnc", "--current", current, "-o", corrected)
    pins = _pins(corrected)
    assert set(pins) == {"x-rot-point", "y-rot-point", "z-rot-point", "y-offset", "z-offset"}

    # Table points q (table frame, mm) at tilt A and rotation C (deg): the tool tip in
    # workpiece coordinates is P0 + q. A over the axis' travel, C beyond one turn both ways.
    rng = np.random.default_rng(11)
    n = 10
    q = np.round(rng.uniform(-150, 150, (n, 3)), 3)  # as commanded: G0 words carry 6 decimals
    a_deg = np.array([0.0, 90.0, -90.0, 45.0, -30.0, 60.0, -75.0, 15.0, -5.0, 80.0])
    c_deg = np.array([0.0, 90.0, 180.0, 270.0, -45.0, 400.0, -135.0, 30.0, 720.5, -300.0])
    poses = np.column_stack([P0 + q, a_deg, c_deg])

    names = list(_core.location_error_names(_core.MachineType.AC_trt))
    d = json.loads(model.read_text())
    e = np.array([d["location_errors"][k]["value"] or 0.0 for k in names])
    e[[2, 3, 6, 7]] = 0.0  # the tilts: xyzac-trt-kins has no orientation terms
    assert np.abs(e).max() > 0.01  # mm: errors large enough for the test to fail
    ang = np.radians(np.column_stack([a_deg, c_deg]))
    expected = P0 + _core.forward(_core.MachineType.AC_trt, e, ang, q)
    nominal = P0 + _core.forward(_core.MachineType.AC_trt, np.zeros(8), ang, q)

    runs = {}
    for name, hal in (("current", current), ("corrected", corrected)):
        r = run_linuxcnc(tmp_path / name, hal, poses)
        assert r["motion_mode"] == 2, r  # TRAJ_MODE_COORD: moves through the kinematics
        assert len(r["moves"]) == n
        world = np.array([m["world"] for m in r["moves"]])[:, [0, 1, 2, 3, 5]]
        assert np.abs(world - poses).max() < 1e-6, "not in position at the commanded pose"
        fb = np.array([m["joints"] for m in r["moves"]])
        cmd = np.array([m["joints_cmd"] for m in r["moves"]])
        assert np.abs(fb - cmd).max() < 1e-9  # the simulated drives follow exactly
        assert np.abs(fb[:, 3:] - poses[:, 3:]).max() < 1e-9  # rotary joints = A, C
        runs[name] = fb[:, :3]
        print(f"{name}: LinuxCNC session {r['elapsed']:.1f} s, "
              f"|joints - model| max {np.abs(fb[:, :3] - expected).max():.2e} mm, "
              f"|joints - nominal| max {np.abs(fb[:, :3] - nominal).max():.2e} mm")

    # The current pins are the nominal machine (the test can fail) ...
    assert np.abs(runs["current"] - nominal).max() < TOL
    assert np.abs(runs["current"] - expected).max() > 1e-3
    # ... the exported ones put the table point where the identified model does.
    assert np.abs(runs["corrected"] - expected).max() < TOL
