# SPDX-License-Identifier: BSD-3-Clause
"""`rotacal export` as an engineer runs it: identify, export into the controller's parameters,
and check with the controller's own kinematics (written here from LinuxCNC's trtfuncs.c and
the SINUMERIK W1 manual, fed only with the exported file) that the corrected machine puts the
table where the identified model does. The errors a controller cannot hold go into a residual
model for NC compensation."""

import json
import re

import numpy as np
import pytest

import rotacal
from rotacal import _core

from conftest import run_cli

EXIT_INPUT, EXIT_IO = 3, 4


def rotacal_cli(*args):
    r = run_cli(*args)
    assert "Traceback" not in r.stderr, r.stderr
    return r


def rot(axis, a):
    """Right-handed rotation by a about a unit axis (Rodrigues), written out here."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K


@pytest.fixture(scope="module")
def model(shared_data, tmp_path_factory):
    d = tmp_path_factory.mktemp("export")
    m = d / "model.json"
    assert (
        rotacal_cli("identify", shared_data / "ballbar_ac_table2.csv", "--save-model", m).returncode
        == 0
    )
    return m


def _travel(n=400, seed=5):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-200, 200, (n, 3))
    ang = np.column_stack([np.radians(rng.uniform(-90, 90, n)), np.radians(rng.uniform(0, 360, n))])
    return q, ang


def _identified(model_path, only_positions):
    d = json.loads(model_path.read_text())
    names = list(_core.location_error_names(_core.MachineType.AC_trt))
    e = np.array([d["location_errors"][n]["value"] or 0.0 for n in names])
    if only_positions:
        e[[2, 3, 6, 7]] = 0.0
    return e


def test_linuxcnc_pins_reproduce_the_identified_model(model, tmp_path):
    # The kinematics active during the test: the pivot (rotacal's origin) at joint position P0.
    P0 = np.array([250.0, -120.0, 80.0])
    cur = tmp_path / "machine.hal"
    cur.write_text(
        "loadrt xyzac-trt-kins\n"
        f"setp xyzac-trt-kins.x-rot-point {P0[0]}\nsetp xyzac-trt-kins.y-rot-point {P0[1]}\n"
        f"setp xyzac-trt-kins.z-rot-point 0\nsetp xyzac-trt-kins.z-offset {P0[2]}\n"
        "setp xyzac-trt-kins.y-offset 0\nnet tool-offset motion.tooloffset.z xyzac-trt-kins.tool-offset\n"
    )
    out = tmp_path / "corrected.hal"
    r = rotacal_cli(
        "export", "--model", model, "--controller", "linuxcnc", "--current", cur, "-o", out
    )
    assert r.returncode == 0, r.stderr
    pins = {
        m.group(1): float(m.group(2))
        for m in re.finditer(r"^setp xyzac-trt-kins\.(\S+) (\S+)$", out.read_text(), re.M)
    }
    assert set(pins) == {"x-rot-point", "y-rot-point", "z-rot-point", "y-offset", "z-offset"}
    # trtfuncs.c, world -> joints with the module's default directions.
    rr = np.array([pins["x-rot-point"], pins["y-rot-point"], pins["z-rot-point"]])
    d = np.array([0.0, pins["y-offset"], pins["z-offset"]])
    q, ang = _travel()
    joints = np.array(
        [
            rr + d + rot([1, 0, 0], a) @ (rot([0, 0, 1], c) @ (P0 + p - rr) - d)
            for p, (a, c) in zip(q, ang)
        ]
    )
    e = _identified(model, only_positions=True)  # LinuxCNC holds no tilts
    expected = P0 + _core.forward(_core.MachineType.AC_trt, e, ang, q)
    assert np.abs(joints - expected).max() < 1e-4  # 0.1 um
    # ... and without the tilts the identified machine is not reproduced: the test can fail.
    full = P0 + _core.forward(_core.MachineType.AC_trt, _identified(model, False), ang, q)
    assert np.abs(joints - full).max() > 1e-3
    assert "E_B0A" in r.stderr and "not held" in r.stderr


def test_siemens_toolholder_reproduces_the_whole_model(model, tmp_path):
    out = tmp_path / "carr.mpf"
    r = rotacal_cli(
        "export",
        "--model",
        model,
        "--controller",
        "siemens",
        "--toolholder",
        "3",
        "-o",
        out,
        "--json",
    )
    assert r.returncode == 0, r.stderr
    assert "zero offsets assumed" in r.stderr
    v = {
        int(m.group(1)): float(m.group(2))
        for m in re.finditer(r"^\$TC_CARR(\d+)\[3\]=([-0-9.]+)$", out.read_text(), re.M)
    }
    vec = lambda n: np.array([v[n], v[n + 1], v[n + 2]])  # noqa: E731
    l2, v1, v2, l3, l4 = vec(4), vec(7), vec(10), vec(15), vec(18)
    q, ang = _travel()
    x = np.array([l2 + rot(v1, a) @ (l3 + rot(v2, c) @ (l4 + p)) for p, (a, c) in zip(q, ang)])
    expected = _core.forward(_core.MachineType.AC_trt, _identified(model, False), ang, q)
    assert np.abs(x - expected).max() < 1e-4
    j = json.loads(r.stdout)
    assert all(e["held"] for e in j["location_errors"])
    assert j["parameters"][0]["name"].startswith("$TC_CARR4[3]")


def test_residual_model_compensates_what_the_controller_cannot_hold(model, tmp_path):
    res = tmp_path / "residual.json"
    r = rotacal_cli(
        "export",
        "--model",
        model,
        "--controller",
        "linuxcnc",
        "-o",
        tmp_path / "k.hal",
        "--residual-model",
        res,
    )
    assert r.returncode == 0, r.stderr
    d = rotacal.load_model(res)
    full = json.loads(model.read_text())
    for name in ("E_Y0A", "E_Z0A", "E_X0C", "E_Y0C"):
        assert d["location_errors"][name]["value"] == 0.0
    for name in ("E_B0A", "E_C0A", "E_A0C", "E_B0C"):
        assert d["location_errors"][name]["value"] == full["location_errors"][name]["value"]
    assert "linuxcnc" in d["source"]["residual_after"]


@pytest.mark.parametrize("controller", ["isg", "heidenhain", "fanuc"])
def test_every_controller_says_what_it_holds(model, controller):
    r = rotacal_cli("export", "--model", model, "--controller", controller, "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    held = {e["name"]: e["held"] for e in j["location_errors"]}
    assert len(held) == 8
    # Positions reach every controller; tilts only those with axis vectors.
    assert held["E_Y0A"] and held["E_X0C"]
    assert held["E_B0A"] == (controller == "isg")


def test_export_refuses_bad_current_values_by_file_and_line(model, tmp_path):
    bad = tmp_path / "bad.hal"
    bad.write_text("setp xyzac-trt-kins.x-rot-point 1\nsetp xyzac-trt-kins.z-offset 1,5\n")
    r = rotacal_cli("export", "--model", model, "--controller", "linuxcnc", "--current", bad)
    assert r.returncode == EXIT_INPUT and f"{bad}:2" in r.stderr, r.stderr
    wrong = tmp_path / "c.json"
    wrong.write_text('{"controller": "siemens", "parameters": {}}')
    r = rotacal_cli("export", "--model", model, "--controller", "linuxcnc", "--current", wrong)
    assert r.returncode == EXIT_INPUT and "siemens" in r.stderr
    r = rotacal_cli("export", "--model", model, "--controller", "linuxcnc", "--current", tmp_path)
    assert r.returncode == EXIT_IO
    r = rotacal_cli("export", "--model", model, "--controller", "linuxcnc", "-o", model)
    assert r.returncode == EXIT_IO and json.loads(model.read_text())["format"] == "rotacal-model/1"


def test_linuxcnc_comp_file_of_an_rtest_map_holds_the_positioning_error(tmp_path):
    # An R-test of a B axis whose actual angle is B + 2e-4 sin(B) rad (worm error, effects.md).
    s, m = tmp_path / "ap.csv", tmp_path / "ap.json"
    assert (
        rotacal_cli(
            "simulate",
            "rtest",
            "--effect",
            "angular_positioning_B_h1=0,0.0002",
            "--seed",
            "3",
            "-o",
            s,
        ).returncode
        == 0
    )
    assert rotacal_cli("identify", s, "--save-model", m).returncode == 0
    comp = tmp_path / "b.comp"
    r = rotacal_cli(
        "export",
        "--model",
        m,
        "--controller",
        "linuxcnc",
        "--comp-file",
        f"B={comp}",
        "--comp-range",
        "-90,90",
        "--comp-step",
        "1",
    )
    assert r.returncode == 0, r.stderr
    # As LinuxCNC 2.9 reads it: three numbers a line up to the header, nominal strictly
    # increasing, <= 256 lines; COMP_FILE_TYPE 1 trims (nominal - actual), the same both ways.
    lines = comp.read_text().splitlines()
    rows = np.array([[float(x) for x in ln.split()] for ln in lines if not ln.startswith("#")])
    assert rows.shape == (181, 3) and np.all(np.diff(rows[:, 0]) > 0)
    assert all(ln.startswith("#") for ln in lines[181:])  # the header follows the numbers
    trim = np.radians(rows[:, 1])
    assert np.abs(trim + 2e-4 * np.sin(np.radians(rows[:, 0]))).max() < 3e-6  # rad
    assert np.array_equal(rows[:, 1], rows[:, 2])  # an R-test does not see reversal
    assert "[JOINT_3]" in r.stderr and f"COMP_FILE = {comp}" in r.stderr
    assert "COMP_FILE_TYPE = 1" in r.stderr and "[JOINT_4]" not in r.stderr
    # --tables (issue 54) from the same map: B's COMP_FILE (type 1) trims are -2e-4 sin B.
    r = rotacal_cli(
        "export",
        "--model",
        m,
        "--controller",
        "linuxcnc",
        "--tables",
        "--table-range",
        "B=-90,90",
        "--tables-dir",
        tmp_path,
    )
    assert r.returncode == 0, r.stderr
    rows = np.array(
        [
            [float(x) for x in line.split()]
            for line in (tmp_path / "comp_B.txt").read_text().splitlines()
            if line[0] != "#"
        ]
    )
    assert rows.shape == (37, 3) and np.array_equal(rows[:, 1], rows[:, 2])
    trim = np.radians(rows[:, 1])
    assert np.abs(trim + 2e-4 * np.sin(np.radians(rows[:, 0]))).max() < 3e-6  # rad
    assert "[JOINT_3]" in (tmp_path / "comp_tables.ini").read_text()
    assert not (tmp_path / "comp_C.txt").exists()  # the map has no gamma_CB: no C positioning
    # An axis without positioning error in the model is refused by name; so is another controller.
    assert (
        rotacal_cli(
            "export",
            "--model",
            m,
            "--controller",
            "linuxcnc",
            "--comp-file",
            f"C={tmp_path / 'c.comp'}",
        ).returncode
        == EXIT_INPUT
    )
    assert (
        rotacal_cli(
            "export",
            "--model",
            m,
            "--controller",
            "siemens",
            "--comp-file",
            f"B={tmp_path / 'x.comp'}",
        ).returncode
        == EXIT_INPUT
    )


def test_the_model_keeps_the_active_parameters_for_the_export(shared_data, tmp_path):
    cur = tmp_path / "machine.hal"
    cur.write_text("setp xyzac-trt-kins.x-rot-point 250\nsetp xyzac-trt-kins.z-offset 80\n")
    m = tmp_path / "m.json"
    r = rotacal_cli(
        "identify", shared_data / "ballbar_ac_table2.csv", "--save-model", m, "--controller", cur
    )
    assert r.returncode == 0, r.stderr
    assert "x-rot-point 250" in json.loads(m.read_text())["source"]["controller_parameters"]
    r = rotacal_cli("export", "--model", m, "--controller", "linuxcnc", "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert j["current_given"]
    x = next(p for p in j["parameters"] if p["name"].endswith("x-rot-point"))
    assert x["current"] == 250.0 and x["corrected"] == pytest.approx(
        250.0 + j["location_errors"][4]["value"]
    )


def test_isg_measured_sphere_centres_are_where_the_machine_put_the_nest(tmp_path):
    # An R-test of a machine with location errors; its nest centres, as the ISG kinematic
    # optimisation takes them, must be the actual machine's table point at each pose.
    s, m, truth = tmp_path / "r.csv", tmp_path / "r.json", tmp_path / "r.truth.json"
    assert (
        rotacal_cli(
            "simulate", "rtest", "--errors", "random", "--seed", "4", "-o", s, "--truth", truth
        ).returncode
        == 0
    )
    assert rotacal_cli("identify", s, "--save-model", m).returncode == 0
    prog = tmp_path / "centres.nc"
    r = rotacal_cli(
        "export",
        "--model",
        m,
        "--controller",
        "isg",
        "--centres",
        s,
        "--centres-output",
        prog,
        "--centres-setup",
        "2",
        "--isg-kinematic",
        "81,0",
        "--centres-origin",
        "500,-200,300",
    )
    assert r.returncode == 0, r.stderr
    text = prog.read_text()
    assert "V.L.KIN_TYP = 81" in text and 'NAME = "SysCalibFit.ecy"' in text
    recs = [
        [float(v) for v in re.findall(r"@P\d = ([-0-9.]+)", line)]
        for line in text.splitlines()
        if "SysCalibFitAddRecord" in line
    ]
    recs = np.array(recs)
    t = json.loads(truth.read_text())
    names = list(_core.location_error_names(_core.MachineType.BC_trt))
    e = np.array([t["errors"][n] for n in names])
    nest = np.array(t["nests"][1])
    ang = np.radians(recs[:, 4:6])
    expected = np.array([500.0, -200.0, 300.0]) + _core.forward(
        _core.MachineType.BC_trt, e, ang, np.tile(nest, (len(recs), 1))
    )
    assert len(recs) == 84
    assert np.abs(recs[:, :3] - expected).max() < 2e-3  # mm: 0.3 um noise, fitted probe zeros
    # Nominal positions would be tens of um away: the centres carry the errors.
    nominal = np.array([500.0, -200.0, 300.0]) + _core.forward(
        _core.MachineType.BC_trt, np.zeros(8), ang, np.tile(nest, (len(recs), 1))
    )
    assert np.abs(recs[:, :3] - nominal).max() > 5e-3
    assert (
        rotacal_cli(
            "export",
            "--model",
            m,
            "--controller",
            "linuxcnc",
            "--centres",
            s,
            "--centres-output",
            tmp_path / "x.nc",
        ).returncode
        == EXIT_INPUT
    )


def test_isg_centres_refuse_probe_zeros_of_another_session(tmp_path):
    # The probe zeros of one R-test do not hold for another: other nests, or the same nests
    # measured again (other bytes), are refused instead of written as centres.
    m = tmp_path / "r.json"
    sessions = {}
    for name, extra in (
        ("r", []),
        ("other_nests", ["--nest", "90,10,50", "--nest", "0,-100,120"]),
        ("again", ["--seed", "9"]),
    ):
        sessions[name] = tmp_path / f"{name}.csv"
        assert (
            rotacal_cli(
                "simulate",
                "rtest",
                "--errors",
                "random",
                "--seed",
                "4",
                *extra,
                "-o",
                sessions[name],
            ).returncode
            == 0
        )
    assert rotacal_cli("identify", sessions["r"], "--save-model", m).returncode == 0
    anonymous = tmp_path / "no_source.json"  # a model saved without its source: the nests decide
    doc = json.loads(m.read_text())
    del doc["source"]
    anonymous.write_text(json.dumps(doc))
    for name, model, words in (
        ("other_nests", anonymous, "has its nest at"),
        ("again", m, "fitted to another session"),
    ):
        prog = tmp_path / f"{name}.nc"
        r = rotacal_cli(
            "export",
            "--model",
            model,
            "--controller",
            "isg",
            "--centres",
            sessions[name],
            "--centres-output",
            prog,
        )
        assert r.returncode == EXIT_INPUT and words in r.stderr, r.stderr
        assert not prog.exists()


def test_heidenhain_and_fanuc_mappings(model, tmp_path):
    # Where the formulas are not public the export is a mapping: each parameter carries the
    # line-position changes of formats.md, from the values given as current.
    e = {n: v["value"] for n, v in json.loads(model.read_text())["location_errors"].items()}
    cur = tmp_path / "h.json"
    cur.write_text(
        json.dumps(
            {
                "controller": "heidenhain",
                "parameters": {
                    "Trans Y before MachAxis A": 5.0,
                    "Trans X before MachAxis C": -300.0,
                },
            }
        )
    )
    j = json.loads(
        rotacal_cli(
            "export", "--model", model, "--controller", "heidenhain", "--current", cur, "--json"
        ).stdout
    )
    v = {p["name"]: p for p in j["parameters"]}
    assert v["Trans Y before MachAxis A"]["corrected"] == pytest.approx(5.0 + e["E_Y0A"])
    assert v["Trans Z before MachAxis A"]["corrected"] == pytest.approx(e["E_Z0A"])
    assert v["Trans X before MachAxis C"]["corrected"] == pytest.approx(-300.0 + e["E_X0C"])
    assert v["Trans Y before MachAxis C"]["corrected"] == pytest.approx(e["E_Y0C"])
    j = json.loads(
        rotacal_cli("export", "--model", model, "--controller", "fanuc", "--json").stdout
    )
    v = {p["name"][:9]: p["corrected"] for p in j["parameters"]}
    assert [v[f"No. {19700 + k}"] for k in range(3)] == pytest.approx([0.0, e["E_Y0A"], e["E_Z0A"]])
    assert [v[f"No. {19703 + k}"] for k in range(3)] == pytest.approx(
        [e["E_X0C"], e["E_Y0C"] - e["E_Y0A"], -e["E_Z0A"]]
    )
