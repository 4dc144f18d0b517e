# SPDX-License-Identifier: BSD-3-Clause
"""`rotacal export --tables` for LinuxCNC: the COMP_FILE of a rotary joint's positioning error,
checked by LinuxCNC's documented table semantics implemented here from its sources (read, not
copied: src/emc/motion/usrmotintf.cc usrmotLoadComp, command.c EMCMOT_SET_JOINT_COMP, control.c
compute_screw_comp, motion.c's table ends), fed only with the exported file. The machine's
error is written out from ../shared/spec/effects.md, not taken from rotacal."""

import json
import math
import re

import numpy as np
import pytest

from linuxcnc_session import CONFIG, requires_linuxcnc
from linuxcnc_session import run_linuxcnc as run_session

from conftest import run_cli

EXIT_OK, EXIT_INPUT = 0, 3

# A worm-gear C (effects.md): actual C = C + eps + a1 cos C + b1 sin C + b3 sin 3C (rad), and a
# radial run-out and a sagging A no joint table can hold.
EPS, A1, B1, B3 = 2e-5, 1e-4, -5e-5, 3e-5


def positioning_deg(c_deg):
    c = np.radians(c_deg)
    return np.degrees(EPS + A1 * np.cos(c) + B1 * np.sin(c) + B3 * np.sin(3 * c))


def est(v):
    return {"value": v}


def model_doc(effects=True, source="s.csv"):
    names = ("E_Y0A", "E_Z0A", "E_B0A", "E_C0A", "E_X0C", "E_Y0C", "E_A0C", "E_B0C")
    fx = [
        {"id": "gravity_sag_A", "params": {"s": est(0.004)}},
        {
            "id": "radial_motion_C_h2",
            "params": {k: est(v) for k, v in zip("abcd", (2e-3, 0, 0, 0))},
        },
    ]
    if effects:
        fx += [
            {"id": "rotary_zero_offset_C", "params": {"eps": est(EPS)}},
            {"id": "angular_positioning_C_h1", "params": {"a": est(A1), "b": est(B1)}},
            {"id": "angular_positioning_C_h3", "params": {"a": est(0.0), "b": est(B3)}},
        ]
    return {
        "format": "rotacal-model/1",
        "kind": "ballbar",
        "machine": "AC-trt",
        "location_errors": {n: est(0.0) for n in names},
        "pivot": {"x": est(0.0), "y": est(0.0), "z": est(100.0)},
        "effects": fx,
        "source": {"session": source},
    }


def load_comp(text, comp_file_type):
    """usrmotLoadComp + EMCMOT_SET_JOINT_COMP: lines of three numbers up to the first that is
    not; TYPE 0 holds actual positions (trim = nominal - actual), TYPE 1 the trims themselves;
    nominal strictly increasing; at most EMCMOT_COMP_SIZE (256) entries."""
    nominal, fwd, rev = [], [], []
    for line in text.splitlines():
        parts = line.split()
        try:
            nom, f, r = (float(p) for p in parts[:3])
        except ValueError:
            break
        if len(parts) < 3:
            break
        if comp_file_type == 0:
            f, r = nom - f, nom - r
        assert not nominal or nom > nominal[-1], "compensation values must increase"
        nominal.append(nom), fwd.append(f), rev.append(r)
    assert len(nominal) <= 256, "too many compensation entries"
    return np.array(nominal), np.array(fwd), np.array(rev)


def trim_at(table, pos, moving_up=True):
    """compute_screw_comp: the entry with nominal <= pos < next nominal, linear from it with
    the slope to the next; below the first entry the first trim (the -DBL_MAX sentinel, slope
    0), at or beyond the last the last trim (its slope is never set)."""
    nominal, fwd, rev = table
    trim = fwd if moving_up else rev
    i = np.searchsorted(nominal, pos, side="right") - 1
    out = np.empty_like(pos, dtype=float)
    below, above = i < 0, i >= len(nominal) - 1
    out[below], out[above] = trim[0], trim[-1]
    mid = ~(below | above)
    j = i[mid]
    slope = (trim[j + 1] - trim[j]) / (nominal[j + 1] - nominal[j])
    out[mid] = trim[j] + slope * (pos[mid] - nominal[j])
    return out


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    d = tmp_path_factory.mktemp("tables")
    m = d / "model.json"
    m.write_text(json.dumps(model_doc()))
    r = run_cli(
        "export",
        "--model",
        m,
        "--controller",
        "linuxcnc",
        "--tables",
        "--spacing",
        "5deg",
        "--tables-dir",
        d,
        "-o",
        d / "kins.hal",
    )
    assert r.returncode == EXIT_OK, r.stderr
    return d, r


def stated_error_deg(text):
    return float(re.search(r"worst interpolation error between points: (\S+) deg", text)[1])


def test_compensated_c_reaches_the_commanded_angle_over_the_table(exported):
    d, r = exported
    text = (d / "comp_C.txt").read_text()
    ini = (d / "comp_tables.ini").read_text()
    assert "[JOINT_4]" in ini and f"COMP_FILE = {d / 'comp_C.txt'}" in ini
    assert "COMP_FILE_TYPE = 1" in ini
    table = load_comp(text, 1)
    assert len(table[0]) == 145 and table[0][0] == -360.0 and table[0][-1] == 360.0
    stated = stated_error_deg(text)
    # Every angle LinuxCNC may be commanded to within the table, points and between them.
    pos = np.linspace(-360.0, 360.0, 14401)[:-1] + 0.0173
    for up in (True, False):
        motor = pos + trim_at(table, pos, up)
        actual = motor + positioning_deg(motor)  # the machine: effects.md's worm gear
        residual = np.abs(actual - pos)
        assert residual.max() <= stated * 1.001 + 1e-9, (residual.max(), stated)
    uncompensated = np.abs(positioning_deg(pos)).max()
    assert uncompensated > 100 * stated  # the table does the work, and can fail
    assert residual.max() >= 0.5 * stated  # the stated error is the table's, not a loose bound
    # At the points the table is exact, to its 9 decimals.
    motor = table[0] + table[1]
    assert np.abs(motor + positioning_deg(motor) - table[0]).max() < 2e-9
    assert not (d / "comp_A.txt").exists()  # A has no positioning error
    assert "E_ZA" in r.stderr and "E_XC" in r.stderr  # the sag and the run-out: not in a table
    assert "E_CC" not in r.stderr  # C's rotation about Z is its positioning: in the table


def test_the_header_says_what_the_table_holds_and_where_it_stops(exported):
    d, _ = exported
    text = (d / "comp_C.txt").read_text()
    data = [ln for ln in text.splitlines() if not ln.startswith("#")]
    trailer = text.splitlines()[len(data) :]
    assert len(data) == 145 and all(ln.startswith("#") for ln in trailer)
    body = "\n".join(trailer)
    for said in (
        "COMP_FILE_TYPE = 1",
        "positioning_C",
        "angular_positioning_C_h1",
        "rotary_zero_offset_C",
        "every 5.000000 deg",
        "correction stops outside -360.000000..360.000000 deg",
        "BACKLASH",
        "trim = nominal - actual",
    ):
        assert said in body, said
    # Beyond the table LinuxCNC holds the end value: the error comes back there.
    table = load_comp(text, 1)
    pos = np.array([400.0, 430.0])
    motor = pos + trim_at(table, pos)
    assert np.abs(motor + positioning_deg(motor) - pos).max() > 100 * stated_error_deg(text)


def test_a_range_for_a_continuously_turning_c(exported, tmp_path):
    d, _ = exported
    r = run_cli(
        "export",
        "--model",
        d / "model.json",
        "--controller",
        "linuxcnc",
        "--tables",
        "--spacing",
        "10",
        "--table-range",
        "C=-1080,1080",
        "--tables-dir",
        tmp_path,
    )
    assert r.returncode == EXIT_OK, r.stderr
    table = load_comp((tmp_path / "comp_C.txt").read_text(), 1)
    assert table[0][0] == -1080 and table[0][-1] == 1080 and len(table[0]) == 217


def test_refusals_name_the_limit(exported, tmp_path):
    d, _ = exported
    m = d / "model.json"
    r = run_cli(
        "export",
        "--model",
        m,
        "--controller",
        "linuxcnc",
        "--tables",
        "--spacing",
        "1deg",
        "--tables-dir",
        tmp_path,
    )
    assert r.returncode == EXIT_INPUT and "at most 256" in r.stderr and "721" in r.stderr
    assert not (tmp_path / "comp_C.txt").exists()
    r = run_cli(
        "export", "--model", m, "--controller", "heidenhain", "--tables", "--tables-dir", tmp_path
    )
    assert r.returncode == EXIT_INPUT and "--tables" in r.stderr and "heidenhain" in r.stderr
    none = tmp_path / "none.json"
    none.write_text(json.dumps(model_doc(effects=False)))
    r = run_cli(
        "export", "--model", none, "--controller", "linuxcnc", "--tables", "--tables-dir", tmp_path
    )
    assert r.returncode == EXIT_INPUT and "no positioning error" in r.stderr
    r = run_cli(
        "export",
        "--model",
        m,
        "--controller",
        "linuxcnc",
        "--tables",
        "--spacing",
        "7",
        "--table-range",
        "C=0,360",
        "--tables-dir",
        tmp_path,
    )
    assert r.returncode == EXIT_OK, r.stderr  # 0..364, the first point past 360
    assert load_comp((tmp_path / "comp_C.txt").read_text(), 1)[0][-1] == 364.0
    assert math.isclose(stated_error_deg((tmp_path / "comp_C.txt").read_text()), 0, abs_tol=1e-3)


@requires_linuxcnc
def test_linuxcnc_loads_the_comp_file_and_adds_its_trims(exported, tmp_path):
    """The real motion controller with the exported COMP_FILE in [JOINT_4]: C turned up through
    a turn and back down (tests/linuxcnc/comp_display.py), at rest motor-pos-cmd - pos-cmd -
    motor-offset is the table's trim at pos-cmd (as read here from the file)."""
    d, _ = exported
    text = (d / "comp_C.txt").read_text()
    run_dir = tmp_path / "run"
    common = (CONFIG / "common.inc").read_text()  # ends in [JOINT_4]: the lines join it
    common += f"COMP_FILE = {run_dir / 'comp_C.txt'}\nCOMP_FILE_TYPE = 1\n"
    ini = (CONFIG / "xyzac-trt-sim.ini").read_text().replace("tcp_display.py", "comp_display.py")
    poses = [37.3, 95.0, 181.1, 263.9, 359.0, 300.7, 200.2, 111.1, 3.3, -90.4, -271.5, 400.0]
    files = {
        "common.inc": common,
        "xyzac-trt-comp.ini": ini,
        "comp_C.txt": text,
        "pins.hal": "# xyzac-trt-kins at its defaults\n",
        "poses.json": json.dumps(poses),
    }
    data = run_session(run_dir, "xyzac-trt-comp.ini", files, "comp.json", 45)
    table = load_comp(text, 1)
    got = np.array(
        [r["motor_pos_cmd"] - r["pos_cmd"] - r["motor_offset"] for r in data["readings"]]
    )
    pos = np.array([r["pos_cmd"] for r in data["readings"]])
    assert np.allclose(pos, poses, atol=1e-9, rtol=0)
    want = trim_at(table, pos)
    print("LinuxCNC trim - table trim (deg):", np.abs(got - want).max())
    # At rest control.c keeps the trim of the last moving servo cycle ("not moving, use whatever
    # was there before"), taken a fraction of a degree before the target: with this table's
    # slope (<= 4e-4 deg/deg) that is < 1e-6 deg (measured: 3.2e-7 deg); the trims are ~5e-3.
    assert np.abs(got - want).max() < 1e-6, (got, want)
    assert np.abs(want).max() > 1e-3  # the trims are far from 0: the check can fail


def load_eec(text):
    """A SINUMERIK EEC program as K3 ("Interpolatory compensation") and the 808D manual ("LEC")
    describe it: $AA_ENC_COMP[e,N,AXi] values at MIN + N STEP up to MAX, with MODULO 0/1."""
    values, params = {}, {}
    for line in text.splitlines():
        m = re.fullmatch(r"\$AA_ENC_COMP\[0,(\d+),(\w+)\]=(-?\d+\.\d+)", line)
        if m:
            values[int(m[1])] = float(m[3])
            continue
        m = re.fullmatch(r"\$AA_ENC_COMP_(STEP|MIN|MAX|IS_MODULO)\[0,(\w+)\]=(-?[\d.]+)", line)
        if m:
            params[m[1]] = float(m[3])
    n = round((params["MAX"] - params["MIN"]) / params["STEP"])
    assert sorted(values) == list(range(n + 1)), "every interpolation point has its value"
    return params, np.array([values[i] for i in range(n + 1)])


def eec_value(params, values, x):
    """Linear between the points; beyond them the end values hold, or (modulo) the table repeats
    every MAX - MIN."""
    lo, step = params["MIN"], params["STEP"]
    if params["IS_MODULO"] == 1:
        x = lo + np.mod(x - lo, params["MAX"] - lo)
    grid = lo + step * np.arange(len(values))
    return np.interp(x, grid, values)  # np.interp holds the end values


def test_sinumerik_eec_moves_c_where_the_model_says(exported, tmp_path):
    d, _ = exported
    r = run_cli(
        "export",
        "--model",
        d / "model.json",
        "--controller",
        "siemens",
        "--tables",
        "--spacing",
        "5",
        "--siemens-axis",
        "C=C1",
        "--tables-dir",
        tmp_path,
    )
    assert r.returncode == EXIT_OK, r.stderr
    text = (tmp_path / "eec_C.mpf").read_text()
    lines = text.splitlines()
    assert lines[:2] == ["%_N_AX_EEC_INI", "CHANDATA(1)"] and lines[-1] == "M17"
    params, values = load_eec(text)
    assert params == {"STEP": 5.0, "MIN": 0.0, "MAX": 360.0, "IS_MODULO": 1.0}
    assert values[0] == values[-1]  # a modulo table: both ends entered, equal
    stated = stated_error_deg(text)
    # The control corrects the actual value by the table's value at the axis position x: the
    # loop settles where x + value(x) = commanded, and a positive value moves the axis negative.
    # The axis then stands at x + positioning(x) (effects.md), which must be the commanded angle.
    x = np.linspace(-720.0, 720.0, 28801)[:-1] + 0.0173
    commanded = x + eec_value(params, values, x)
    actual = x + positioning_deg(x)
    residual = np.abs(actual - commanded)
    assert residual.max() <= stated * 1.001 + 1e-9, (residual.max(), stated)
    assert residual.max() >= 0.5 * stated
    assert np.abs(positioning_deg(x)).max() > 100 * stated
    # Sign: where the axis runs ahead (positioning > 0) the value is positive.
    i = np.argmax(positioning_deg(np.arange(0, 360, 5.0)))
    assert values[i] > 0
    r = run_cli(
        "export",
        "--model",
        d / "model.json",
        "--controller",
        "siemens",
        "--tables",
        "--spacing",
        "1",
        "--max-cross-points",
        "400",  # the CEC tables of the run-out and the sag fit: the EEC limit is the one hit
        "--tables-dir",
        tmp_path,
    )
    assert r.returncode == EXIT_INPUT and "MD38000" in r.stderr and "361" in r.stderr


def test_the_residual_model_leaves_to_compensate_only_what_no_table_holds(exported, tmp_path):
    d, _ = exported
    res = tmp_path / "residual.json"
    r = run_cli(
        "export",
        "--model",
        d / "model.json",
        "--controller",
        "linuxcnc",
        "--tables",
        "--tables-dir",
        tmp_path,
        "--residual-model",
        res,
        "-o",
        tmp_path / "kins.hal",
    )
    assert r.returncode == EXIT_OK, r.stderr
    doc = json.loads(res.read_text())
    values = {f["id"]: [p["value"] for p in f["params"].values()] for f in doc["effects"]}
    for held in ("rotary_zero_offset_C", "angular_positioning_C_h1", "angular_positioning_C_h3"):
        assert values[held] == [0.0] * len(values[held]), held  # in the COMP_FILE
    assert values["radial_motion_C_h2"][0] == 2e-3 and values["gravity_sag_A"] == [0.004]
    assert "tables" in doc["source"]["residual_after"]
