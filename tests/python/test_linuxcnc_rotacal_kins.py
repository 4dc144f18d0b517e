# SPDX-License-Identifier: BSD-3-Clause
"""rotacal-kins (linuxcnc/rotacal_kins.cpp), the identified model in LinuxCNC's servo thread,
checked in the real LinuxCNC.

The test installs the module built with the library (build/release/linuxcnc/rotacal-kins.so;
it builds it there if missing) into LinuxCNC's module directory, writes an AC-trt and a BC-trt
model (location errors, angular positioning and radial run-out harmonics, sag; the AC one with
thermal gains on two location errors) as blobs with `rotacal export --controller realtime`,
and the blob of a thermal model (its cold errors and gains, exported by the same command), and
starts one headless LinuxCNC (tests/linuxcnc/rotacal-kins-sim.ini) that loads the three and
switches between them with motion.switchkins-type (shared with the thermal HAL chain's check). Its display sets the tool-offset, y1 and y2
pins, jogs the joints to positions over the travel and moves in world coordinates with G0.

Reference: rotacal's Python evaluation of the model files (rotacal.realtime on the JSON, not on
the blob; tests/cpp/test_realtime.cpp holds it to the fits' own kinematics), with the thermal
states folded into the location errors by hand. The world position LinuxCNC computes from the
joints must be the model's tool tip within 0.01 um, the joints it moves to for a world pose the
model's inverse within 0.01 um, and the world position read back the commanded pose.
"""

import json
import os
import shutil
import struct
import subprocess
import tempfile
import zlib
from pathlib import Path

import numpy as np
import pytest

import rotacal
from rotacal import realtime

from conftest import run_cli
import lcnc_thermal
from linuxcnc_session import requires_linuxcnc, shared

pytestmark = requires_linuxcnc
LINUXCNC_STARTS = {"rotacal-kins"}  # linuxcnc_session.shared

ROOT = Path(__file__).resolve().parents[2]
MODULE_DIR = Path("/usr/lib/linuxcnc/modules")
RUN_TIMEOUT = 60  # s, the display's own bound
TOL = 1e-5  # mm: 0.01 um
NAMES = {
    "AC-trt": ["E_Y0A", "E_Z0A", "E_B0A", "E_C0A", "E_X0C", "E_Y0C", "E_A0C", "E_B0C"],
    "BC-trt": ["E_X0B", "E_Z0B", "E_A0B", "E_C0B", "E_X0C", "E_Y0C", "E_A0C", "E_B0C"],
}
ERRORS = [0.03, -0.02, 5e-5, -4e-5, 0.015, 0.025, -3e-5, 6e-5]  # mm, rad
# Thermal gains of the AC model (blob layout, realtime/blob.hpp): E_X0C moves 4 um per unit of
# y1, E_Y0C -3 um per unit of y2; the display sets y1, y2 to these.
GAINS = {(4, 0): 0.004, (5, 1): -0.003}
Y1, Y2 = 0.5, -0.8
Y_THERMAL = 1.5  # y1 of the thermal model's blob (steady state at 150 rev/min)
GAIN_OFFSET = 20 + 18 + 2 * 195 + 8 * 8  # header, machine..pivot, two axes, errors: bytes


def model_doc(machine, tilt, errors, effects=True):
    est = lambda v: {"value": v, "std": 1e-6}  # noqa: E731
    fx = [
        {"id": "angular_positioning_C_h1", "params": {"a": est(4e-5), "b": est(-2.5e-5)}},
        {"id": f"angular_positioning_{tilt}_h2", "params": {"a": est(-1.5e-5), "b": est(2e-5)}},
        {
            "id": "radial_motion_C_h2",
            "params": dict(zip("abcd", map(est, (3e-3, -1e-3, 2e-3, 5e-4)))),
        },
        {"id": f"gravity_sag_{tilt}", "params": {"s": est(0.004)}},
    ]
    return {
        "format": "rotacal-model/1",
        "kind": "ballbar",
        "machine": machine,
        "location_errors": {n: est(v) for n, v in zip(NAMES[machine], errors)},
        "pivot": {k: est(0.0) for k in "xyz"},
        "effects": fx if effects else [],
        "source": {"session": "test"},
    }


def with_thermal_gains(blob: bytes) -> bytes:
    """The blob with GAINS written into its thermal_gain field (column-major 8 x 2) and its
    CRC-32 renewed: the layout of realtime/blob.hpp's comment, written here independently."""
    b = bytearray(blob)
    for (i, col), g in GAINS.items():
        struct.pack_into("<d", b, GAIN_OFFSET + 8 * (8 * col + i), g)
    struct.pack_into("<I", b, 16, zlib.crc32(bytes(b[20:])))
    return bytes(b)


def module_so() -> Path:
    """rotacal-kins.so of the build tree, built there if missing (CMake target rotacal_kins)."""
    build = Path(os.environ.get("ROTACAL_BUILD_DIR", ROOT / "build/release"))
    so = build / "linuxcnc/rotacal-kins.so"
    if not so.exists():
        r = subprocess.run(
            ["cmake", "--build", str(build), "--target", "rotacal_kins"],
            capture_output=True,
            text=True,
        )
        assert r.returncode == 0, (
            f"building rotacal-kins in {build} failed (CMake makes the target where LinuxCNC's "
            f"headers are: apt-get install linuxcnc-uspace-dev, then configure again):\n"
            f"{r.stdout}\n{r.stderr}"
        )
    return so


@pytest.fixture(scope="module")
def installed_module():
    dest = MODULE_DIR / "rotacal-kins.so"
    tmp = MODULE_DIR / ".rotacal-kins.so.tmp"
    shutil.copyfile(module_so(), tmp)
    os.replace(tmp, dest)
    yield dest
    dest.unlink(missing_ok=True)


def travel(rng, n, tilt_col):
    """Joint positions (X Y Z A B C, mm and deg) over the travel; the tilt in its column."""
    j = np.zeros((n, 6))
    j[:, :3] = np.round(rng.uniform(-300, 300, (n, 3)), 6)
    j[:, tilt_col] = np.round(rng.uniform(-100, 100, n), 6)
    j[:, 5] = np.round(rng.uniform(-400, 400, n), 6)
    return j


@pytest.fixture(scope="module")
def rotacal_kins(installed_module, tmp_path_factory, fast_thermal_model):
    """The shared start of rotacal-kins-sim.ini with an AC-trt and a BC-trt model (switchkins
    types 0 and 1) and the blob `export --controller realtime` writes of a thermal model (type
    2, AC-trt): (start, plan, references)."""
    tmp_path = tmp_path_factory.mktemp("rotacal-kins")
    rng = np.random.default_rng(55)
    blob_dir = Path(tempfile.mkdtemp(prefix="rotacal-kins-"))  # rtapi_app reads it as RTAPI_UID
    os.chmod(blob_dir, 0o755)
    plan, refs, blobs = {"models": []}, [], []
    try:
        for machine, tilt, tilt_col, thermal, tool in (
            ("AC-trt", "A", 3, True, 35.0),
            ("BC-trt", "B", 4, False, 0.0),
        ):
            model = tmp_path / f"{machine}.json"
            rotacal.save_model(model_doc(machine, tilt, ERRORS), model)
            blob = blob_dir / f"{machine}.rtb"
            r = run_cli("export", "--model", model, "--controller", "realtime", "-o", blob)
            assert r.returncode == 0, r.stderr
            errors = list(ERRORS)
            if thermal:  # the reference: the gains' shift folded into the location errors
                blob.write_bytes(with_thermal_gains(blob.read_bytes()))
                errors[4] += GAINS[(4, 0)] * Y1
                errors[5] += GAINS[(5, 1)] * Y2
            os.chmod(blob, 0o644)
            blobs.append(str(blob))
            ref = tmp_path / f"{machine}.ref.json"
            rotacal.save_model(model_doc(machine, tilt, errors), ref)
            nominal = tmp_path / f"{machine}.nominal.json"
            rotacal.save_model(model_doc(machine, tilt, [0.0] * 8, effects=False), nominal)
            refs.append(
                (realtime.load_realtime(ref), realtime.load_realtime(nominal), tilt_col, tool)
            )
            joints = travel(rng, 6, tilt_col)
            world = travel(rng, 6, tilt_col)
            world[:, tilt_col] = np.where(np.abs(world[:, tilt_col]) < 2, 10, world[:, tilt_col])
            plan["models"].append(
                {
                    "tool-offset": tool,
                    "y1": Y1 if thermal else 0.0,
                    "y2": Y2 if thermal else 0.0,
                    "joints": joints.tolist(),
                    "world": world.tolist(),
                }
            )
        # Type 2: the thermal model's blob (its cold errors and gains) at y1 = Y_THERMAL; the
        # reference is the plain model of its errors at that state (effects.md
        # thermal_location_R: E0 + K y).
        blob = blob_dir / "thermal.rtb"
        r = run_cli(
            "export", "--model", fast_thermal_model, "--controller", "realtime", "-o", blob
        )  # fmt: skip
        assert r.returncode == 0, r.stderr
        os.chmod(blob, 0o644)
        blobs.append(str(blob))
        th = json.loads(fast_thermal_model.read_text())
        errors = [
            (th["location_errors"][n]["value"] or 0.0)
            + (th["thermal"]["lags"][0]["gains"][n]["value"] or 0.0) * Y_THERMAL
            for n in NAMES["AC-trt"]
        ]
        ref = tmp_path / "thermal.ref.json"
        rotacal.save_model(model_doc("AC-trt", "A", errors, effects=False), ref)
        refs.append(
            (realtime.load_realtime(ref), realtime.load_realtime(tmp_path / "AC-trt.nominal.json"), 3, 0.0)
        )  # fmt: skip
        joints, world = travel(rng, 4, 3), travel(rng, 4, 3)
        world[:, 3] = np.where(np.abs(world[:, 3]) < 2, 10, world[:, 3])
        plan["models"].append(
            {"tool-offset": 0.0, "y1": Y_THERMAL, "y2": 0.0, "joints": joints.tolist(), "world": world.tolist()}
        )  # fmt: skip
        ini = (ROOT / "tests/linuxcnc/rotacal-kins-sim.ini").read_text()
        start = shared(
            "rotacal-kins",
            "rotacal-kins-sim.ini",
            {"rotacal-kins-sim.ini": ini.replace("@MODELS@", ",".join(blobs))},
        )
        # rtapi_app reads the blobs when the module loads: the first job waits for that
        start.job("rotacal_kins_display", tmp_path / "up", {"plan.json": '{"models": []}'},
                  "rotacal_kins.json", RUN_TIMEOUT)  # fmt: skip
    finally:
        shutil.rmtree(blob_dir, ignore_errors=True)
    return start, plan, refs


def test_rotacal_kins_in_linuxcnc_is_the_model(tmp_path, rotacal_kins):
    start, plan, refs = rotacal_kins
    out = start.job(
        "rotacal_kins_display",
        tmp_path / "run",
        {"plan.json": json.dumps(plan)},
        "rotacal_kins.json",
        RUN_TIMEOUT,
    )
    print(
        f"LinuxCNC job {out['elapsed']:.1f} s, {out['lcnc_cpu_s']:.1f} CPU-s in its processes so far"
    )

    for (ref, nominal_ref, tilt_col, tool), p, got in zip(refs, plan["models"], out["models"]):
        cols = [0, 1, 2, tilt_col, 5]  # the model's joints: X Y Z tilt C
        # Joints commanded: the world position LinuxCNC computes is the model's tool tip.
        fb = np.array([m["joints"] for m in got["joint_moves"]])
        # The free-mode planner ends a jog near its target (0.15 um, 12-07); the joints read are
        # the ones the forward kinematics ran on.
        assert np.abs(fb - np.array(p["joints"])).max() < 1e-3
        lw = np.array([m["world"] for m in got["joint_moves"]])
        tip, _ = realtime.forward(ref, fb[:, cols], tool_length=tool)
        nominal, _ = realtime.forward(nominal_ref, fb[:, cols], tool)
        fwd_err = np.abs(lw[:, :3] - tip).max()
        # World poses commanded: the joints are the model's inverse, and forward gives the pose.
        world = np.array(p["world"])
        fb = np.array([m["joints"] for m in got["world_moves"]])
        q, residual = realtime.inverse(ref, world[:, cols], tool_length=tool)
        inv_err = np.abs(fb[:, cols] - q)
        inv_err[:, 3:] *= np.pi / 180 * 200  # deg -> mm at a 200 mm radius
        lw = np.array([m["world"] for m in got["world_moves"]])
        back = np.abs(lw - world)
        print(
            f"{'AC' if tilt_col == 3 else 'BC'}-trt{' thermal' if p['y1'] == Y_THERMAL else ''}: forward {fwd_err * 1e6:.3g} nm (model - nominal "
            f"{np.abs(tip - nominal).max() * 1e3:.3g} um), inverse {inv_err.max() * 1e6:.3g} nm, "
            f"world read back {back[:, :3].max() * 1e6:.3g} nm, {back[:, 3:].max():.3g} deg"
        )
        assert np.abs(tip - nominal).max() > 0.01  # mm: the model's terms move the tip
        assert fwd_err < TOL
        assert residual[:, 0].max() < TOL
        assert inv_err.max() < TOL
        assert back[:, :3].max() < TOL and back[:, 3:].max() < 1e-6  # deg


def test_thermal_chain_feeds_y1_as_the_lag(fast_thermal_model, tmp_path, rotacal_kins):
    """Issue 53's HAL chain into rotacal-kins: the lag state itself on its pin y1 (the gains are
    the blob's), from C's vel-cmd (joint 5 of coordinates=XYZABC)."""
    start = rotacal_kins[0]
    r = run_cli(
        "export", "--model", fast_thermal_model, "--controller", "linuxcnc",
        "--thermal-chain", "rotacal-kins", "--json",
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    assert info["joint"] == 5 and info["pins"] == []
    text = run_cli(
        "export", "--model", fast_thermal_model, "--controller", "linuxcnc",
        "--thermal-chain", "rotacal-kins",
    ).stdout  # fmt: skip
    assert "net rotacal-th-y1 rotacal-th-lag1.out => rotacal-kins.y1" in text
    tau = json.loads(fast_thermal_model.read_text())["thermal"]["lags"][0]["tau"]["value"]
    log = lcnc_thermal.run(start, tmp_path / "run", text, [])
    lcnc_thermal.check_lag(log, tau, 1e-3)
