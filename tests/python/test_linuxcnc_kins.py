# SPDX-License-Identifier: BSD-3-Clause
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

The run itself: linuxcnc_session.py.
"""

import json
import re
from pathlib import Path

import numpy as np

from linuxcnc_session import requires_linuxcnc
from linuxcnc_session import run_linuxcnc as run_session
from rotacal import _core

from conftest import run_cli

pytestmark = requires_linuxcnc

RUN_TIMEOUT = 45  # s, the display's own bound (SIGALRM); the test waits 15 s longer
TOL = 1e-4  # mm: 0.1 um; LinuxCNC reports doubles, the exported pins carry 1 nm
P0 = np.array([250.0, -120.0, 80.0])  # joint position of the pivot (rotacal's origin)


def rotacal_cli(*args):
    r = run_cli(*args)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    return r


def run_linuxcnc(run_dir: Path, pins: Path, poses: np.ndarray) -> dict:
    """One headless LinuxCNC session with the pins of `pins`; the joints at every pose."""
    return run_session(
        run_dir,
        "xyzac-trt-sim.ini",
        {"pins.hal": pins.read_text(), "poses.json": json.dumps(poses.tolist())},
        "joints.json",
        RUN_TIMEOUT,
    )


def _pins(path: Path) -> dict:
    return {
        m.group(1): float(m.group(2))
        for m in re.finditer(r"^setp xyzac-trt-kins\.(\S+) (\S+)$", path.read_text(), re.M)
    }


def test_xyzac_trt_kins_with_exported_pins_reproduces_the_model(shared_data, tmp_path):
    model = tmp_path / "model.json"
    rotacal_cli("identify", shared_data / "ballbar_ac_table2.csv", "--save-model", model)
    # The machine's kinematics while the ballbar test ran: the pivot at joint position P0.
    current = tmp_path / "machine.hal"
    current.write_text(
        f"setp xyzac-trt-kins.x-rot-point {P0[0]}\nsetp xyzac-trt-kins.y-rot-point {P0[1]}\n"
        f"setp xyzac-trt-kins.z-rot-point 0\nsetp xyzac-trt-kins.z-offset {P0[2]}\n"
        "setp xyzac-trt-kins.y-offset 0\n"
    )
    corrected = tmp_path / "corrected.hal"
    rotacal_cli(
        "export",
        "--model",
        model,
        "--controller",
        "linuxcnc",
        "--current",
        current,
        "-o",
        corrected,
    )
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
        print(
            f"{name}: LinuxCNC session {r['elapsed']:.1f} s, "
            f"|joints - model| max {np.abs(fb[:, :3] - expected).max():.2e} mm, "
            f"|joints - nominal| max {np.abs(fb[:, :3] - nominal).max():.2e} mm"
        )

    # The current pins are the nominal machine (the test can fail) ...
    assert np.abs(runs["current"] - nominal).max() < TOL
    assert np.abs(runs["current"] - expected).max() > 1e-3
    # ... the exported ones put the table point where the identified model does.
    assert np.abs(runs["corrected"] - expected).max() < TOL
