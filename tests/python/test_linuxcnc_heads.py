# SPDX-License-Identifier: BSD-3-Clause
"""`rotacal export --controller linuxcnc` of the head machines LinuxCNC 2.9 ships a module for:
maxkins (B-head-C-table) and 5axiskins (BC-head), and the refusals of every other controller.

The model holds all eight location errors non-zero. The modules hold only pivot-length (and the
table's C line through the X/Y joints' HOME_OFFSET); the export reports every other error NOT
HELD. The held part is checked twice against rotacal's model of the held errors alone, written
out below from formats.md ("Any 5-axis machine"): by the modules' inverse kinematics written
here from LinuxCNC 2.9's maxkins.c / 5axiskins.c (fed only with the exported file), and by the
real modules in a headless LinuxCNC (tests/linuxcnc/maxkins-sim.ini, 5axiskins-sim.ini: MDI G0
in world coordinates, the joints read back; one start per module, as a LinuxCNC runs one
kinematics).
"""

import json
import re

import numpy as np
import pytest

from linuxcnc_session import hal_commands, requires_linuxcnc, shared
from rotacal import _core

from conftest import run_cli

LINUXCNC_STARTS = {"maxkins", "5axiskins"}  # linuxcnc_session.shared

EXIT_INPUT = 3
TOL = 1e-4  # mm: 0.1 um
P = 250.0  # mm: the built-ins' pivot_length + tool_length (150 + 100)
# E_X0C E_Y0C E_A0C E_B0C E_X0B E_Z0B E_A0B E_C0B (both machines, chain order), mm and rad
ERRORS = np.array([0.021, -0.034, 40e-6, -25e-6, 0.017, -0.045, 30e-6, -55e-6])
HELD = {"maxkins": [0, 1, 5], "5axiskins": [5]}
MACHINE = {"maxkins": "B-head-C-table", "5axiskins": "BC-head"}
# a model field that tries to add a pin and an INI line to the file
HOSTILE = "s <m> $(rm -rf)\nsetp maxkins.pivot-length 0\n# [JOINT_0]HOME_OFFSET = 5\r\n"


def rot(axis, a):
    """Right-handed rotation by a about a unit axis (Rodrigues), written out here."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K


def lines(e, table_c):
    """formats.md: the C and B lines' points and directions (C: dp (E_X0C, E_Y0C, 0), dn (E_B0C,
    -E_A0C, 0); B: dp (E_X0B, 0, E_Z0B), dn (-E_C0B, 0, E_A0B)), nominal C along +Z, B along +Y
    through the machine origin (table C) or the controlled point (head axes)."""
    pc, nc = np.array([e[0], e[1], 0.0]), np.array([e[3], -e[2], 1.0])
    pb, nb = np.array([e[4], 0.0, e[5]]), np.array([-e[7], 1.0, e[6]])
    return pc, nc, pb, nb


def rotacal_point(kins, e, q, b, c):
    """The controlled point X, Y, Z that puts the tool ball on workpiece point q at rotacal's
    angles b, c: B-head-C-table: ball = X + Rot(B line, b) t equal to Rot(C line, c) q;
    BC-head: ball = X + Rot(C line, c) Rot(B line, b) t equal to q; t = (0, 0, -P)."""
    t = np.array([0.0, 0.0, -P])
    pc, nc, pb, nb = lines(e, kins == "maxkins")
    about = lambda p, n, a, x: p + rot(n, a) @ (x - p)  # noqa: E731
    if kins == "maxkins":
        return about(pc, nc, c, q) - about(pb, nb, b, t)
    return q - about(pc, nc, c, about(pb, nb, b, t))


def module_inverse(kins, pins, w, B, C):
    """LinuxCNC 2.9's kinematicsInverse: maxkins.c (world = table frame, C turning it the other
    way) and 5axiskins.c (s2r(L, C, 180 - B)); W = 0; degrees."""
    L = pins[f"{kins}.pivot-length"]
    Br, Cr = np.radians(B), np.radians(C)
    if kins == "maxkins":
        r, th = np.hypot(w[0], w[1]), np.arctan2(w[1], w[0]) - Cr
        return np.array(
            [r * np.cos(th) - L * np.sin(Br), r * np.sin(th), w[2] + L * np.cos(Br) - L]
        )
    p = np.radians(180.0 - B)
    s2r = L * np.array([np.sin(p) * np.cos(Cr), np.sin(p) * np.sin(Cr), np.cos(p)])
    return np.array([w[0] - s2r[0], w[1] - s2r[1], w[2] - L - s2r[2]])


def write_model(path, kins, e=ERRORS):
    m = _core.parse_machine_type(MACHINE[kins])
    names = list(_core.location_error_names(m))
    unit = lambda i: "rad" if i in (2, 3, 6, 7) else "mm"  # noqa: E731
    doc = {
        "format": "rotacal-model/1",
        "kind": "ballbar",
        "machine": MACHINE[kins],
        "machine_description": json.loads(m.description_json),
        "location_errors": {
            n: {"value": float(e[i]), "std": 1e-4 if unit(i) == "mm" else 1e-6, "unit": unit(i)}
            for i, n in enumerate(names)
        },
        "pivot": {k: {"value": 0.0, "unit": "mm"} for k in "xyz"},
        "source": {"session": HOSTILE},
    }
    path.write_text(json.dumps(doc))
    return names


def export(tmp_path, kins):
    model, out = tmp_path / f"{kins}.json", tmp_path / f"{kins}.hal"
    names = write_model(model, kins)
    r = run_cli("export", "--model", model, "--controller", "linuxcnc", "-o", out, "--json")
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    text = out.read_text()
    pins = {m.group(1): float(m.group(2)) for m in re.finditer(r"^setp (\S+) (\S+)$", text, re.M)}
    home = {
        int(m.group(1)): float(m.group(2))
        for m in re.finditer(r"^# \[JOINT_(\d)\]HOME_OFFSET = (\S+)$", text, re.M)
    }
    return names, pins, home, text, json.loads(r.stdout)


def poses(kins, n=12, seed=3):
    """Workpiece points q and rotacal angles b, c over the travel (B within +-110 deg, C beyond
    a turn both ways), rounded as a G0 word carries them."""
    rng = np.random.default_rng(seed)
    q = np.round(rng.uniform(-200, 200, (n, 3)), 3)
    b = np.round(np.concatenate([[0, 90, -90, 110], rng.uniform(-110, 110, n - 4)]), 3)
    c = np.round(np.concatenate([[0, 0, 180, -270], rng.uniform(-400, 400, n - 4)]), 3)
    return q, b, c


def expected(kins, q, b, c):
    """Per pose: LinuxCNC's world position and angles (B, C) to command, and the joints rotacal's
    model of the held errors puts there. maxkins' joint origin is on the C line (HOME_OFFSET), so
    its world is q - C line; both modules' joints are the controlled point less P along Z."""
    held = np.zeros(8)
    held[HELD[kins]] = ERRORS[HELD[kins]]
    shift = np.array([held[0], held[1], 0.0]) if kins == "maxkins" else np.zeros(3)
    world, joints = [], []
    for qi, bi, ci in zip(q, b, c):
        X = rotacal_point(kins, held, qi, np.radians(bi), np.radians(ci))
        world.append(qi - shift)
        joints.append(X - [0.0, 0.0, P] - shift)
    angles = np.column_stack([-b, -c if kins == "maxkins" else c])
    return np.array(world), angles, np.array(joints)


@pytest.mark.parametrize("kins", ["maxkins", "5axiskins"])
def test_head_export_holds_its_part_and_reports_the_rest(tmp_path, kins):
    names, pins, home, text, j = export(tmp_path, kins)
    assert set(pins) == {f"{kins}.pivot-length"}
    assert pins[f"{kins}.pivot-length"] == pytest.approx(P + ERRORS[5], abs=1e-6)
    assert home == ({0: -ERRORS[0], 1: -ERRORS[1]} if kins == "maxkins" else {})
    held = {e["name"]: e["held"] for e in j["location_errors"]}
    assert [held[n] for n in names] == [i in HELD[kins] for i in range(8)]
    flat = " ".join(ln[2:] for ln in text.splitlines() if ln.startswith("# "))
    where = {e["name"]: e["where"] for e in j["location_errors"]}
    for i, n in enumerate(names):
        if i not in HELD[kins]:
            scale = 1e6 if i in (2, 3, 6, 7) else 1e3
            said = flat.split(f"{n} = {ERRORS[i] * scale:.2f} +- ")[1][:40]
            assert "NOT HELD" in said, (n, said)
            assert "compensate" in where[n] and "--controller realtime" in where[n], where[n]
    # the model's source (any text) stays in comments: only comments and the one setp line
    assert all(ln.startswith("#") or ln.startswith("setp ") for ln in text.splitlines() if ln)
    assert sum(ln.startswith("setp") for ln in text.splitlines()) == 1

    q, b, c = poses(kins, n=400)
    world, ang, want = expected(kins, q, b, c)
    got = np.array([module_inverse(kins, pins, w, B, C) for w, (B, C) in zip(world, ang)])
    assert np.abs(got - want).max() < 1e-6  # mm: the pin is written to 1 nm
    # The unheld errors are real: the full model differs from the held part by microns.
    full = np.array(
        [
            rotacal_point(kins, ERRORS, qi, np.radians(bi), np.radians(ci))
            for qi, bi, ci in zip(q, b, c)
        ]
    ) - [0.0, 0.0, P]
    shift = [ERRORS[0], ERRORS[1], 0.0] if kins == "maxkins" else [0.0] * 3
    unheld = np.abs(full - shift - want).max()
    print(f"{kins}: unheld errors move the tool by up to {unheld * 1e3:.1f} um over the travel")
    assert unheld > 5e-3


def test_the_table_part_written_here_is_rotacals_forward():
    # the C table of B-head-C-table written out above against rotacal's own (_core.forward)
    m = _core.parse_machine_type("B-head-C-table")
    q, b, c = poses("maxkins", n=20)
    pc, nc, _, _ = lines(ERRORS, True)
    mine = np.array([pc + rot(nc, np.radians(ci)) @ (qi - pc) for qi, ci in zip(q, c)])
    ang = np.radians(np.column_stack([b, c]))
    assert np.abs(_core.forward(m, ERRORS, ang, q) - mine).max() < 1e-9


@pytest.mark.parametrize(
    "controller, lacks",
    [
        ("siemens", "$TC_CARR type P (table-table) only"),
        ("isg", "kinematic IDs of head or nutating machines"),
        ("heidenhain", "not the head or nutating axes' rows"),
        ("fanuc", "not the head or nutating machine types"),
    ],
)
def test_other_controllers_refuse_head_machines_naming_what_they_lack(tmp_path, controller, lacks):
    model = tmp_path / "m.json"
    write_model(model, "maxkins")
    r = run_cli("export", "--model", model, "--controller", controller)
    assert r.returncode == EXIT_INPUT and lacks in r.stderr, r.stderr
    assert "B-head-C-table" in r.stderr and "Traceback" not in r.stderr


@pytest.mark.parametrize("machine", ["AC-head", "B45C-trt"])
def test_linuxcnc_refuses_machines_it_has_no_module_for(tmp_path, machine):
    m = _core.parse_machine_type(machine)
    names = list(_core.location_error_names(m))
    model = tmp_path / "m.json"
    doc = {
        "format": "rotacal-model/1",
        "kind": "ballbar",
        "machine": machine,
        "machine_description": json.loads(m.description_json),
        "location_errors": {n: {"value": 0.0} for n in names},
        "pivot": {k: {"value": 0.0, "unit": "mm"} for k in "xyz"},
    }
    model.write_text(json.dumps(doc))
    r = run_cli("export", "--model", model, "--controller", "linuxcnc")
    assert r.returncode == EXIT_INPUT, r.stderr
    assert "LinuxCNC 2.9 ships no kinematics module" in r.stderr and machine in r.stderr


@requires_linuxcnc
@pytest.mark.parametrize("kins", ["maxkins", "5axiskins"])
def test_real_module_puts_the_tool_where_the_held_model_does(tmp_path, kins):
    _, pins, _, text, _ = export(tmp_path, kins)
    q, b, c = poses(kins)
    world, ang, want = expected(kins, q, b, c)
    commands = np.column_stack([np.round(world, 6), ang])
    # One start per module (linuxcnc_session.shared): motion binds one kinematics module
    r = shared(kins, f"{kins}-sim.ini", {"pins.hal": ""}).job(
        "heads_display",
        tmp_path / "run",
        {"poses.json": json.dumps(commands.tolist())},
        "joints.json",
        45,
        hal_commands(text),
    )
    assert r["motion_mode"] == 2, r  # TRAJ_MODE_COORD: moves through the kinematics
    fb = np.array([m["joints"] for m in r["moves"]])
    assert np.abs(fb - np.array([m["joints_cmd"] for m in r["moves"]])).max() < 1e-9
    rotary = [4, 5] if kins == "maxkins" else [3, 4]
    assert np.abs(fb[:, rotary] - ang).max() < 1e-9
    # world rounded to 1 nm as commanded: compare with the model at the commanded point
    _, _, want = expected(kins, q - world + commands[:, :3], b, c)
    residual = np.abs(fb[:, :3] - want).max()
    # the forward kinematics of the joints (what LinuxCNC displays): 5axiskins inverts its
    # inverse; maxkins 2.9 adds the head's offset unrotated by C, so only where B or C is 0
    fwd = np.array([m["world"] for m in r["moves"]])[:, :3]
    agree = np.ones(len(b), bool) if kins == "5axiskins" else (b == 0) | (c == 0)
    print(
        f"{kins}: LinuxCNC {r['elapsed']:.1f} s, |joints - held model| max {residual:.2e} mm, "
        f"|forward(joints) - world| max {np.abs(fwd - commands[:, :3]).max():.2e} mm "
        f"({np.abs(fwd - commands[:, :3])[agree].max():.2e} where the forward inverts)"
    )
    assert residual < TOL
    # the test can fail: the module with the nominal pin puts the joints elsewhere
    nominal = {f"{kins}.pivot-length": P}
    off = [module_inverse(kins, nominal, w, B, C) for w, (B, C) in zip(commands[:, :3], ang)]
    assert np.abs(np.array(off) - want).max() > 1e-3
    assert np.abs(fwd - commands[:, :3])[agree].max() < TOL
    if kins == "maxkins":  # elsewhere by (I - Rz(C)) (L sin B, 0, 0): the offset unrotated
        L, Br, Cr = pins["maxkins.pivot-length"], np.radians(ang[:, 0]), np.radians(ang[:, 1])
        xb = L * np.sin(Br)
        gap = np.column_stack([xb * (1 - np.cos(Cr)), -xb * np.sin(Cr), 0 * xb])
        assert np.abs(fwd - commands[:, :3] - gap).max() < TOL


def test_current_values_and_residual_model_of_a_head_export(tmp_path):
    model, out, res = tmp_path / "m.json", tmp_path / "k.hal", tmp_path / "residual.json"
    names = write_model(model, "maxkins")
    current = tmp_path / "machine.hal"  # the machine's HAL: other lines are skipped
    current.write_text("loadrt maxkins\nsetp maxkins.pivot-length 251.5\nsetp other.pin 3\n")
    r = run_cli(
        "export", "--model", model, "--controller", "linuxcnc", "--current", current, "-o", out,
        "--residual-model", res, "--json",
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    pins = dict(re.findall(r"^setp (\S+) (\S+)$", out.read_text(), re.M))
    assert float(pins["maxkins.pivot-length"]) == pytest.approx(251.5 + ERRORS[5], abs=1e-6)
    d = json.loads(res.read_text())
    for i, n in enumerate(names):  # the residual model keeps exactly what maxkins cannot hold
        want = 0.0 if i in HELD["maxkins"] else ERRORS[i]
        assert d["location_errors"][n]["value"] == pytest.approx(want, abs=1e-15), n
    # the HOME_OFFSETs from the JSON form of --current
    cj = tmp_path / "current.json"
    cj.write_text(json.dumps({"parameters": {"[JOINT_0]HOME_OFFSET": 12.5}}))
    r = run_cli("export", "--model", model, "--controller", "linuxcnc", "--current", cj)
    assert r.returncode == 0, r.stderr
    assert f"# [JOINT_0]HOME_OFFSET = {12.5 - ERRORS[0]:.6f}" in r.stdout
    assert f"# [JOINT_1]HOME_OFFSET = {-ERRORS[1]:.6f}" in r.stdout
