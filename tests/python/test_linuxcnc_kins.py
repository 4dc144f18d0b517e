# SPDX-License-Identifier: BSD-3-Clause
"""`rotacal export --controller linuxcnc` checked by LinuxCNC itself.

test_export.py re-implements xyzac-trt-kins (trtfuncs.c) in numpy; here the real module does
the inverse kinematics. A headless simulated machine (tests/linuxcnc/xyzac-trt-sim.ini: motion,
xyzac-trt-kins, pass-through joints as LinuxCNC's sim configs, no GUI) is started once with
`linuxcnc` (shared with the other checks of xyzac-trt-kins) and runs twice, once with the
machine's current pins (the --current file of the export) and once with the pins of rotacal's
exported HAL file, set with halcmd. Its display program
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
import pytest

import lcnc_thermal
from linuxcnc_session import hal_commands, requires_linuxcnc, shared
from rotacal import _core
from rotacal.exports import export_controller

from conftest import run_cli

pytestmark = requires_linuxcnc
LINUXCNC_STARTS = {"xyzac-trt"}  # linuxcnc_session.shared

RUN_TIMEOUT = 45  # s, the display's own bound (SIGALRM); the test waits 15 s longer
TOL = 1e-4  # mm: 0.1 um; LinuxCNC reports doubles, the exported pins carry 1 nm
P0 = np.array([250.0, -120.0, 80.0])  # joint position of the pivot (rotacal's origin)


def rotacal_cli(*args):
    r = run_cli(*args)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    return r


def xyzac_trt():
    """The shared start of xyzac-trt-sim.ini (linuxcnc_session.shared): its pins.hal is empty,
    each job sets the pins it uses."""
    return shared("xyzac-trt", "xyzac-trt-sim.ini", {"pins.hal": ""})


def run_linuxcnc(run_dir: Path, pins: Path, poses: np.ndarray) -> dict:
    """The joints at every pose, with the pins of `pins` set in the shared start."""
    return xyzac_trt().job(
        "tcp_display",
        run_dir,
        {"poses.json": json.dumps(poses.tolist())},
        "joints.json",
        RUN_TIMEOUT,
        hal_commands(pins.read_text()),
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


def test_thermal_chain_feeds_the_trt_pins_as_the_lag(fast_thermal_model, tmp_path):
    """Issue 53's HAL chain: the lag of a tau 3 s thermal model run by LinuxCNC's abs, scale,
    lowpass and sum2 while C turns, into xyzac-trt-kins' pins."""
    current = tmp_path / "machine.hal"
    current.write_text(
        "".join(f"setp xyzac-trt-kins.{k} {v}\n" for k, v in zip(
            ("x-rot-point", "y-rot-point", "z-rot-point", "y-offset", "z-offset"),
            (P0[0], P0[1], 0.0, 0.0, P0[2]),
        ))
    )  # fmt: skip
    chain = tmp_path / "chain.hal"
    r = rotacal_cli(
        "export", "--model", fast_thermal_model, "--controller", "linuxcnc",
        "--thermal-chain", "trt", "--current", current, "-o", chain, "--json",
    )  # fmt: skip
    info, text = json.loads(r.stdout), chain.read_text()
    doc = json.loads(fast_thermal_model.read_text())
    tau = doc["thermal"]["lags"][0]["tau"]["value"]
    assert info["lowpass_gains"] == [pytest.approx(-np.expm1(-1e-3 / tau), rel=1e-15)]
    # Not held by the trt pins: the tilts and the table-side point, each with its steady state
    for name in ("E_B0A", "E_C0A", "E_A0C", "E_B0C", "q_x", "q_y", "q_z"):
        assert re.search(rf"^#   {name}: [-+]\S+ (rad|mm)", text, re.M), name
    pins = [p["pin"] for p in info["pins"]]
    assert set(pins) == {f"xyzac-trt-kins.{k}" for k in
                         ("x-rot-point", "y-rot-point", "z-rot-point", "y-offset", "z-offset")}  # fmt: skip

    log = lcnc_thermal.run(xyzac_trt(), tmp_path / "run", text, pins)
    y = lcnc_thermal.check_lag(log, tau, 1e-3)
    # Each pin: what `rotacal export --state y` writes at the reference's state (C++ export),
    # at every logged period by the export's affinity in y, checked at 12 of them directly.
    cold = {
        v.name: v.corrected
        for v in export_controller(
            fast_thermal_model, "linuxcnc", current, thermal_state=[0.0]
        ).values
    }
    one = {
        v.name: v.corrected
        for v in export_controller(
            fast_thermal_model, "linuxcnc", current, thermal_state=[1.0]
        ).values
    }
    for k in np.linspace(0, len(log) - 1, 12).astype(int):
        at = {
            v.name: v.corrected
            for v in export_controller(
                fast_thermal_model, "linuxcnc", current, thermal_state=[float(y[k])]
            ).values
        }
        for i, p in enumerate(pins):
            assert (
                abs(log[k, 3 + i] - at[p])
                < 1e-9 + 0.01 * abs(one[p] - cold[p]) * lcnc_thermal.U_TEST
            ), (p, k)
    for i, p in enumerate(pins):
        steady = abs(one[p] - cold[p]) * lcnc_thermal.U_TEST
        err = np.abs(log[:, 3 + i] - (cold[p] + (one[p] - cold[p]) * y)).max()
        print(
            f"  {p}: steady-state change {steady * 1e3:.3f} um, |pin - model| max {err * 1e6:.3g} nm"
        )
        assert err < max(0.01 * steady, 1e-6)
    assert max(abs(one[p] - cold[p]) for p in pins) * lcnc_thermal.U_TEST > 1e-3  # mm: pins move
