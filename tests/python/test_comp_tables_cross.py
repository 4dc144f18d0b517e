# SPDX-License-Identifier: BSD-3-Clause
"""`rotacal export --tables` for the translations of the table axes: SINUMERIK cross error
compensation ($AN_CEC, K3 "Sag compensation"). The tables' semantics are implemented here from
the K3 function manual's description (read, not copied): `$AN_CEC[t,N]` at input positions
`$AN_CEC_MIN[t] + N $AN_CEC_STEP[t]` up to `$AN_CEC_MAX[t]`, linear between them, the end values
held beyond them or (`$AN_CEC_IS_MODULO[t] = 1`) the table repeated, a table's value added to its
output axis, the tables of one output axis summed. They are fed only with the exported files. The
ISG compensation value lists (TF5200 axis compensation: kw.ssfk, kw.crosscomp) likewise. The
machine's errors are written out here from ../shared/spec/effects.md, not taken from
rotacal: a tilting A that sags, a C with a worm gear, an out-of-round bearing track and face
runout."""

import json
import re

import numpy as np
import pytest

from conftest import run_cli

EXIT_OK, EXIT_INPUT = 0, 3

SAG = 0.004  # gravity_sag_A: table += (0, 0, -s (1 - cos A)), machine frame (mm)
RAD = (2e-3, 0.0, 0.0, 1e-3)  # radial_motion_C_h2 (a, b, c, d) in C's turning frame (mm)
AX = (1e-3, 5e-4)  # axial_motion_C_h1 (a, b) along C (mm)
EPS = 2e-5  # rotary_zero_offset_C (rad): C also gets a positioning table
A1, B1, B3 = 1e-4, -5e-5, 3e-5  # angular_positioning_C_h1, _h3: a worm gear (rad)


def est(v):
    return {"value": v}


def model_doc(source="s.csv"):
    names = ("E_Y0A", "E_Z0A", "E_B0A", "E_C0A", "E_X0C", "E_Y0C", "E_A0C", "E_B0C")
    return {
        "format": "rotacal-model/1",
        "kind": "ballbar",
        "machine": "AC-trt",
        "location_errors": {n: est(0.0) for n in names},
        "pivot": {"x": est(0.0), "y": est(0.0), "z": est(100.0)},
        "effects": [
            {"id": "gravity_sag_A", "params": {"s": est(SAG)}},
            {"id": "radial_motion_C_h2", "params": {k: est(v) for k, v in zip("abcd", RAD)}},
            {"id": "axial_motion_C_h1", "params": {k: est(v) for k, v in zip("ab", AX)}},
            {"id": "rotary_zero_offset_C", "params": {"eps": est(EPS)}},
            {"id": "angular_positioning_C_h1", "params": {"a": est(A1), "b": est(B1)}},
            {"id": "angular_positioning_C_h3", "params": {"a": est(0.0), "b": est(B3)}},
            {"id": "tilt_motion_C_h1", "params": {k: est(v) for k, v in zip("abcd", (1e-5,) * 4)}},
        ],
        "source": {"session": source},
    }


def positioning_deg(c_deg):
    """effects.md: actual C = C + eps + a1 cos C + b1 sin C + b3 sin 3C."""
    c = np.radians(c_deg)
    return np.degrees(EPS + A1 * np.cos(c) + B1 * np.sin(c) + B3 * np.sin(3 * c))


def translation_c(c_deg):
    """C's translation in the machine frame at A = 0 (mm, rows X, Y, Z): the radial motion turns
    with C (a point q goes to Rot(C) (E(C) q)), the axial motion is along Z."""
    c = np.radians(c_deg)
    a, b, cc, d = RAD
    ex, ey = a * np.cos(2 * c) + b * np.sin(2 * c), cc * np.cos(2 * c) + d * np.sin(2 * c)
    ez = AX[0] * np.cos(c) + AX[1] * np.sin(c)
    return np.array([np.cos(c) * ex - np.sin(c) * ey, np.sin(c) * ex + np.cos(c) * ey, ez])


def translation_a(a_deg):
    a = np.radians(a_deg)
    return np.array([0 * a, 0 * a, -SAG * (1 - np.cos(a))])


def rot_x(a_deg, v):
    a = np.radians(a_deg)
    return np.array(
        [v[0], np.cos(a) * v[1] - np.sin(a) * v[2], np.sin(a) * v[1] + np.cos(a) * v[2]]
    )


def load_cec(text):
    """Tables by index: values, input and output axis, STEP, MIN, MAX, DIRECTION, MULT, MODULO."""
    tables = {}
    for line in text.splitlines():
        m = re.fullmatch(r"\$AN_CEC\[(\d+),(\d+)\]=(-?\d+\.\d+)", line)
        if m:
            tables.setdefault(int(m[1]), {}).setdefault("v", {})[int(m[2])] = float(m[3])
            continue
        m = re.fullmatch(r"\$AN_CEC_(INPUT_AXIS|OUTPUT_AXIS)\[(\d+)\]=\((\w+)\)", line)
        if m:
            tables.setdefault(int(m[2]), {})[m[1]] = m[3]
            continue
        m = re.fullmatch(
            r"\$AN_CEC_(STEP|MIN|MAX|DIRECTION|MULT_BY_TABLE|IS_MODULO)\[(\d+)\]=(-?[\d.]+)", line
        )
        if m:
            tables.setdefault(int(m[2]), {})[m[1]] = float(m[3])
            continue
        assert line.startswith((";", "%_N_", "CHANDATA", "M17")), line  # nothing else runs
    for t in tables.values():
        n = round((t["MAX"] - t["MIN"]) / t["STEP"])
        assert sorted(t["v"]) == list(range(n + 1)), "every interpolation point has its value"
        t["v"] = np.array([t["v"][i] for i in range(n + 1)])
        assert t["DIRECTION"] == 0 and t["MULT_BY_TABLE"] == 0
    return tables


def cec_value(t, x):
    lo, step = t["MIN"], t["STEP"]
    if t["IS_MODULO"] == 1:
        x = lo + np.mod(x - lo, t["MAX"] - lo)
    return np.interp(x, lo + step * np.arange(len(t["v"])), t["v"])


def correction(tables, position):
    """Each output axis' summed correction, tables fed with position[input axis]."""
    out = {"X1": 0.0, "Y1": 0.0, "Z1": 0.0}
    for t in tables.values():
        out[t["OUTPUT_AXIS"]] = out[t["OUTPUT_AXIS"]] + cec_value(t, position[t["INPUT_AXIS"]])
    return np.array([out["X1"], out["Y1"], out["Z1"]])


def stated_mm(text):
    return float(re.search(r"worst interpolation error between points: (\S+) mm", text)[1])


@pytest.fixture(scope="module")
def siemens(tmp_path_factory):
    d = tmp_path_factory.mktemp("cec")
    m = d / "model.json"
    m.write_text(json.dumps(model_doc()))
    r = run_cli(
        "export", "--model", m, "--controller", "siemens", "--tables", "--tables-dir", d,
        "--residual-model", d / "residual.json", "-o", d / "carr.mpf",
    )  # fmt: skip
    assert r.returncode == EXIT_OK, r.stderr
    return d, r


def test_cec_tables_move_the_tool_with_the_table_point(siemens):
    d, r = siemens
    text_c, text_a = (d / "cec_C.mpf").read_text(), (d / "cec_A.mpf").read_text()
    assert text_c.splitlines()[:2] == ["%_N_NC_CEC_INI", "CHANDATA(1)"]
    tables = load_cec(text_a) | load_cec(text_c)
    assert len(tables) == 4  # A -> Z; C -> X, Y, Z
    err_a, err_c = stated_mm(text_a), stated_mm(text_c)
    # C over two turns either way, points and between them, at A = 0.
    c = np.linspace(-720.0, 720.0, 28801)[:-1] + 0.0173
    res = correction(tables, {"A1": 0.0, "C1": c}) - translation_c(c)
    worst = np.abs(res).max()
    # rotacal's translation is the model's at the commanded angle, where the C positioning error
    # (up to 1.3e-4 rad) turns the 2.3 um run-out a little; with the EEC table loaded C stands at
    # the commanded angle, as translation_c has it: 1.3e-4 x 2.3e-3 mm = 3e-7 mm of slack.
    assert worst <= err_c * 1.001 + 3e-7, (worst, err_c)
    assert worst >= 0.5 * err_c  # the stated error is the table's, not a loose bound
    assert np.abs(translation_c(c)).max() > 20 * err_c  # the tables do the work
    # A over its range at C = 0: the sag is held exactly by A's table wherever C stands.
    a = np.linspace(-360.0, 360.0, 14401)[:-1] + 0.0173
    zero = np.zeros_like(a)
    got = correction(tables, {"A1": a, "C1": zero}) - correction(tables, {"A1": zero, "C1": zero})
    res_a = np.abs(got - translation_a(a)).max()
    assert res_a <= err_a * 1.001 + 1e-9 and SAG > 20 * err_a
    # Sign: at A = 90 the table sags down, so the Z correction moves the tool down too.
    down = correction(tables, {"A1": 90.0, "C1": 0.0}) - correction(tables, {"A1": 0.0, "C1": 0.0})
    assert down[2] < -0.9 * SAG


def test_c_tables_hold_at_tilt_zero_only_and_say_what_remains(siemens):
    d, r = siemens
    text_c, text_a = (d / "cec_C.mpf").read_text(), (d / "cec_A.mpf").read_text()
    tables = load_cec(text_a) | load_cec(text_c)
    said = re.search(r"held at A = 0 only.* up to (\S+) um remains", text_c)
    assert said, text_c
    # At tilt A the machine moves the point by E_A(A) + Rx(A) E_C(C); the tables give
    # E_A(A) + E_C(C). What remains is within the interpolation errors plus the stated remainder.
    aa, cc = np.meshgrid(np.arange(-360.0, 360.0, 7.3), np.arange(0.0, 360.0, 2.9))
    aa, cc = aa.ravel(), cc.ravel()
    want = translation_a(aa) + rot_x(aa, translation_c(cc))
    res = np.linalg.norm(correction(tables, {"A1": aa, "C1": cc}) - want, axis=0)
    bound = float(said[1]) * 1e-3 + stated_mm(text_c) + stated_mm(text_a) + 3e-7
    assert res.max() <= bound, (res.max(), bound)
    assert res.max() > 0.5 * float(said[1]) * 1e-3  # the remainder is real, and stated
    assert "away from A = 0" in r.stderr and "E_AC" in r.stderr  # the wobble: no table


def test_the_residual_model_keeps_only_what_no_siemens_table_holds(siemens):
    d, _ = siemens
    doc = json.loads((d / "residual.json").read_text())
    values = {f["id"]: [p["value"] for p in f["params"].values()] for f in doc["effects"]}
    for held in (
        "gravity_sag_A",
        "radial_motion_C_h2",
        "axial_motion_C_h1",
        "rotary_zero_offset_C",
    ):
        assert not any(values[held]), held
    assert values["tilt_motion_C_h1"] == [1e-5] * 4


def test_cec_refusals_name_md18342(siemens, tmp_path):
    d, _ = siemens
    r = run_cli(
        "export", "--model", d / "model.json", "--controller", "siemens", "--tables",
        "--spacing", "1", "--max-points", "400", "--tables-dir", tmp_path,
    )  # fmt: skip
    assert r.returncode == EXIT_INPUT and "MD18342" in r.stderr and "361" in r.stderr, r.stderr
    r = run_cli(
        "export", "--model", d / "model.json", "--controller", "siemens", "--tables",
        "--spacing", "1", "--max-points", "400", "--max-cross-points", "361",
        "--tables-dir", tmp_path,
    )  # fmt: skip
    assert r.returncode == EXIT_OK, r.stderr  # the limit as configured
    assert len(load_cec((tmp_path / "cec_C.mpf").read_text())[1]["v"]) == 361


def test_hostile_text_in_the_model_stays_a_comment(tmp_path):
    hostile = "s.csv\nM30\n$AN_CEC[0,0]=99\r%_N_X_MPF\u2028G0 X0"
    m = tmp_path / "model.json"
    m.write_text(json.dumps(model_doc(source=hostile)))
    r = run_cli(
        "export", "--model", m, "--controller", "siemens", "--tables", "--tables-dir", tmp_path
    )
    assert r.returncode == EXIT_OK, r.stderr
    for name in ("cec_A.mpf", "cec_C.mpf", "eec_C.mpf"):
        text = (tmp_path / name).read_text()
        lines = text.splitlines()
        assert "M30" not in lines and "G0 X0" not in lines
        assert sum(ln.startswith("%") for ln in lines) == 1
        if name.startswith("cec"):
            assert all(99.0 not in t["v"] for t in load_cec(text).values())


def load_isg(text, prefix):
    """`name value` lines of a compensation value list (# comments), by name."""
    out = {}
    for line in text.splitlines():
        if line.startswith("#") or not line.strip():
            continue
        name, value = line.split()
        assert name.startswith(prefix), line  # nothing but this list's own entries
        out[name[len(prefix) :]] = int(value)
    return out


def ssfk_error(kw, p_deg, direction):
    """kw.ssfk: entry i at kw_startpos + i interval (0.0001 deg), its pos / neg value the
    position error (actual - commanded, 0.0001 deg) moving up / down, linear between entries, the
    end values held or (modulo) the table repeated over its span."""
    n = kw["kw_nr_max"]
    grid = (kw["kw_startpos"] + kw["interval"] * np.arange(n)) * 1e-4
    values = np.array([kw[f"table[{i}].{direction}"] for i in range(n)]) * 1e-4
    if kw["modulo"]:
        p_deg = grid[0] + np.mod(p_deg - grid[0], grid[-1] - grid[0])
    return np.interp(p_deg, grid, values)


def crosscomp_correction(kw, master_deg):
    n = kw["last_index"] + 1
    grid = np.array([kw[f"table[{i}].sollw"] for i in range(n)]) * 1e-4
    values = np.array([kw[f"table[{i}].correction"] for i in range(n)]) * 1e-4  # 0.1 um
    assert np.all(np.diff(grid) > 0)  # ISG refuses unsorted positions (ID 70245)
    return np.interp(master_deg, grid, values)


@pytest.fixture(scope="module")
def isg(siemens):
    d, _ = siemens
    (d / "isg").mkdir()
    r = run_cli(
        "export", "--model", d / "model.json", "--controller", "isg", "--tables",
        "--tables-dir", d / "isg", "-o", d / "isg" / "kin.lis",
    )  # fmt: skip
    assert r.returncode == EXIT_OK, r.stderr
    return d / "isg", r


def test_hostile_text_stays_a_comment_in_the_isg_lists(tmp_path):
    m = tmp_path / "model.json"
    m.write_text(json.dumps(model_doc(source="s.csv\nkw.ssfk.table[0].pos 99\r\u2028kw.x 1")))
    r = run_cli("export", "--model", m, "--controller", "isg", "--tables", "--tables-dir", tmp_path)
    assert r.returncode == EXIT_OK, r.stderr
    for name, prefix in (("ssfk_C.lis", "kw.ssfk."), ("crosscomp_Z.lis", "kw.crosscomp.")):
        text = (tmp_path / name).read_text()
        load_isg(text, prefix)  # every line but the list's own entries is a comment
        entries = sum(ln.startswith("kw.ssfk.table[0].pos") for ln in text.splitlines())
        assert entries == (prefix == "kw.ssfk.")  # the hostile line is no second entry


def test_isg_ssfk_puts_c_where_it_is_commanded_both_ways(isg):
    d, _ = isg
    text = (d / "ssfk_C.lis").read_text()
    kw = load_isg(text, "kw.ssfk.")
    assert kw["modulo"] == 1 and kw["bilateral"] == 1 and kw["kw_nr_max"] == 73
    err = float(re.search(r"worst interpolation error between points: (\S+) deg", text)[1])
    p = np.linspace(-720.0, 720.0, 28801)[:-1] + 0.0173
    for direction in ("pos", "neg"):
        motor = p - ssfk_error(kw, p, direction)  # the control takes the error off the setpoint
        res = np.abs(motor + positioning_deg(motor) - p)
        assert res.max() <= err * 1.001 + 1e-9, (res.max(), err)
    assert res.max() >= 0.5 * err and np.abs(positioning_deg(p)).max() > 20 * err
    i = np.argmax(positioning_deg(np.arange(0.0, 360.0, 5.0)))
    assert kw[f"table[{i}].pos"] > 0  # where C runs ahead the error is positive
    r = run_cli(
        "export", "--model", d.parent / "model.json", "--controller", "isg", "--tables",
        "--spacing", "0.2", "--tables-dir", d,
    )  # fmt: skip
    assert r.returncode == EXIT_INPUT and "P-COMP-00060" in r.stderr and "3601" in r.stderr
    r = run_cli(
        "export", "--model", d.parent / "model.json", "--controller", "isg", "--tables",
        "--spacing", "0.2", "--max-cross-points", "3601", "--tables-dir", d,
    )  # fmt: skip
    assert r.returncode == EXIT_INPUT and "kw_nr_max" in r.stderr and "1801" in r.stderr
    r = run_cli(
        "export", "--model", d.parent / "model.json", "--controller", "isg", "--tables",
        "--max-points", "72", "--tables-dir", d,
    )  # fmt: skip
    # The limit as configured (P-COMP-00059): a control set to 72 entries refuses the 73.
    assert r.returncode == EXIT_INPUT and "at most 72" in r.stderr and "73" in r.stderr
    r = run_cli(
        "export", "--model", d.parent / "model.json", "--controller", "isg", "--tables",
        "--spacing", "0.00125", "--tables-dir", d,
    )  # fmt: skip
    assert r.returncode == EXIT_INPUT and "0.0001 deg" in r.stderr, r.stderr


def test_isg_crosscomp_moves_each_slave_with_one_master(isg):
    d, r = isg
    lists = {s: (d / f"crosscomp_{s}.lis").read_text() for s in "XYZ"}
    kws = {s: load_isg(t, "kw.crosscomp.") for s, t in lists.items()}
    assert kws["X"]["master_ax_nr"] == kws["Y"]["master_ax_nr"] == 6  # C
    assert kws["Z"]["master_ax_nr"] == 4  # A's sag is the larger along Z
    c = np.linspace(-360.0, 360.0, 14401)[:-1] + 0.0173
    want = translation_c(c)
    for j, s in enumerate("XY"):
        err = stated_mm(lists[s])
        res = np.abs(crosscomp_correction(kws[s], c) - want[j])
        assert res.max() <= err * 1.001 + 1e-9 and np.abs(want[j]).max() > 20 * err, s
    a = c
    res = np.abs(crosscomp_correction(kws["Z"], a) - translation_a(a)[2])
    assert res.max() <= stated_mm(lists["Z"]) * 1.001 + 1e-9
    assert "E_ZC" in lists["Z"] and "E_ZC" in r.stderr  # C's axial motion: not in a table
    assert "held at A = 0 only" in lists["X"]


def test_heidenhain_tables_are_mapping_only(siemens, tmp_path):
    d, _ = siemens
    r = run_cli(
        "export", "--model", d / "model.json", "--controller", "heidenhain", "--tables",
        "--tables-dir", tmp_path,
    )  # fmt: skip
    assert r.returncode == EXIT_INPUT and "mapping only" in r.stderr and ".CMA" in r.stderr
    assert not list(tmp_path.iterdir())
