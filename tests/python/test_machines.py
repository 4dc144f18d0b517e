# SPDX-License-Identifier: BSD-3-Clause
"""Every built-in machine and a machine described in a file, through the command line: plan
(NC programs in every dialect), simulate ballbar, identify (known errors recovered), report;
`rotacal machines`; machines.load_machine; descriptions that break formats.md refused with the
file and the field named."""

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rotacal
from conftest import split_by_c
from rotacal import _core, cli
from rotacal.machines import load_machine, machine_dict, machine_drawing

BUILTINS = list(_core.builtin_machine_names())
DIALECTS = ["linuxcnc", "heidenhain", "siemens", "fanuc"]

# A head-table machine unlike any built-in: a C table turning the other way (direction
# negated), an A head whose line is 40 mm below the controlled point, its own lengths.
CUSTOM = {
    "format": "rotacal-machine/1",
    "name": "shop-7 A-head C-table",
    "table_axes": [{"name": "C", "direction": [0, 0, -1], "point": [0, 0, 0]}],
    "head_axes": [
        {"name": "A", "direction": [1, 0, 0], "point": [0, 0, -40], "limits_deg": [-100, 100]}
    ],
    "pivot_length": 120.0,
    "tool_length": 80.0,
    "travel_mm": [[-500, 500], [-400, 400], [-100, 600]],
}


def run(capsys, *args):
    """(exit code, stdout, stderr) of the CLI run in this process."""
    code = cli.main([str(a) for a in args])
    out = capsys.readouterr()
    return code, out.out, out.err


def errors_arg(machine):
    """Location errors of a few um / urad, each its own value, as --errors NAME=VALUE,..."""
    names = list(_core.location_error_names(machine))
    vals = [(0.011, 0.023, 31e-6, -17e-6, -0.019, 0.014, 22e-6, -26e-6)[k] for k in range(8)]
    return dict(zip(names, vals)), ",".join(f"{n}={v}" for n, v in zip(names, vals))


@pytest.fixture()
def custom_file(tmp_path):
    p = tmp_path / "shop7.json"
    p.write_text(json.dumps(CUSTOM, indent=1))
    return p


# ------------------------------------------------------------------------- machines command


def test_machines_lists_every_builtin(capsys):
    code, out, _ = run(capsys, "machines")
    assert code == 0
    for name in BUILTINS:
        m = _core.parse_machine_type(name)
        line = next(l for l in out.splitlines() if l.split()[:1] == [name])
        assert m.configuration in line and "".join(m.axis_names) in line
    code, out, _ = run(capsys, "machines", "--json")
    rows = json.loads(out)
    assert [r["name"] for r in rows] == BUILTINS
    by = {r["name"]: r for r in rows}
    assert by["AC-trt"]["location_error_names"] == list(
        _core.location_error_names(_core.MachineType.AC_trt)
    )
    assert [(a["name"], a["side"], a["role"]) for a in by["B-head-C-table"]["axes"]] == [
        ("C", "table", "rotary"),
        ("B", "head", "tilt"),
    ]
    assert [(a["name"], a["side"]) for a in by["AC-head"]["axes"]] == [("C", "head"), ("A", "head")]


@pytest.mark.parametrize("name", BUILTINS)
def test_machines_show_draws_and_prints_the_description(capsys, name):
    m = _core.parse_machine_type(name)
    code, out, _ = run(capsys, "machines", "show", name)
    assert code == 0
    assert m.description_json in out  # the one-line JSON a session carries
    assert " ".join(_core.location_error_names(m)) in out
    for letter in m.axis_names:
        assert re.search(rf"^\s+\[{letter}\]\s+(table|head) axis", out, re.M)
    # Drawn from the tool down to the workpiece: head axes above X, Y, Z, table axes below the bed.
    rows = out.splitlines()
    at = {
        k: next(i for i, r in enumerate(rows) if r.strip().startswith(k))
        for k in ("(o)", "XYZ", "===", "[W]")
    }
    for letter in m.axis_names:
        i = next(i for i, r in enumerate(rows) if r.strip().startswith(f"[{letter}]"))
        head = f"[{letter}]  head" in rows[i]
        assert (at["(o)"] < i < at["XYZ"]) if head else (at["==="] < i < at["[W]"])
    code, out, _ = run(capsys, "machines", "show", name, "--json")
    d = json.loads(out)
    assert d["description"] == json.loads(m.description_json)
    assert d["default_tilt_range_deg"] == list(_core.default_tilt_range_deg(m))


def test_nutating_axis_u_v_as_drawn_move_the_table_as_the_kinematics_does():
    """The u, v printed for B45C-trt's B are the directions its E_U0B, E_V0B shift the line:
    a table point turned 90 deg about a line shifted by d moves by (I - R) d = d - n x d."""
    m = _core.parse_machine_type("B45C-trt")
    text = machine_drawing(m)
    u, v = (
        np.array([float(x) for x in g.split(",")])
        for g in re.search(r"u = \(([^)]*)\), v = \(([^)]*)\)", text).groups()
    )
    n = np.array(json.loads(m.description_json)["table_axes"][0]["direction"])
    q, ang = np.array([[50.0, -30.0, 20.0]]), np.array([[np.pi / 2, 0.0]])
    base = rotacal.forward(m, np.zeros(8), ang, q)[0]
    for k, d in ((0, u), (1, v)):
        e = np.zeros(8)
        e[k] = 1e-3
        moved = (rotacal.forward(m, e, ang, q)[0] - base) / 1e-3
        assert np.allclose(moved, d - np.cross(n, d), atol=2e-4), (k, moved, d)


# ------------------------------------------------------------------------- the chain, every machine


@pytest.mark.parametrize("name", BUILTINS)
def test_single_setup_chain_on_every_builtin(capsys, tmp_path, name):
    m = _core.parse_machine_type(name)
    # plan: every dialect; the linuxcnc program moves the machine's own rotary letters only.
    for dialect in DIALECTS:
        code, _, err = run(
            capsys,
            "plan",
            "ballbar",
            "--machine",
            name,
            "--dialect",
            dialect,
            "-o",
            tmp_path / f"p.{dialect}",
        )
        assert code == 0, err
    text = (tmp_path / "p.linuxcnc").read_text()
    moves = [l for l in text.splitlines() if l.startswith(("G1 ", "G0 "))]
    used = {c for l in moves for c in re.findall(r"\b([ABC])-?[0-9]", l)}
    assert used == set(m.axis_names), (used, m.axis_names)
    # simulate with known errors, identify them back (5 sigma), report.
    truth, arg = errors_arg(m)
    session = tmp_path / "s.csv"
    code, _, err = run(
        capsys,
        "simulate",
        "ballbar",
        "--machine",
        name,
        "--errors",
        arg,
        "--seed",
        3,
        "-o",
        session,
        "--truth",
        tmp_path / "t.json",
    )
    assert code == 0, err
    header = session.read_text().splitlines()[:9]
    assert f"# machine: {name}" in header
    # formats.md's two tables are named; every other machine's file carries its description.
    described = [l for l in header if l.startswith("# machine_description: ")]
    if name in ("AC-trt", "BC-trt"):
        assert not described
    else:
        assert json.loads(described[0].split(": ", 1)[1]) == json.loads(m.description_json)
    cols = next(l for l in header if l.startswith("test,")).split(",")
    assert cols[5:7] == list(m.axis_names)  # rotary columns in chain order
    code, out, err = run(capsys, "identify", session, "--json", "--no-budget")
    assert code == 0, err
    d = json.loads(out)
    assert d["machine"] == name and list(d["location_errors"]) == list(
        _core.location_error_names(m)
    )
    hidden = set()
    for n, p in d["location_errors"].items():
        if p["value"] is None:
            hidden.add(n)
            continue
        assert abs(p["value"] - truth[n]) < 5 * p["std"] + 1e-9, (n, p, truth[n])
    if m.has_head:
        # The head axis' position along the spindle goes with pivot z and the tool length.
        head_along_z = {"A": "E_Z0A", "B": "E_Z0B"}[m.tilt_axis]
        assert hidden == {head_along_z}
        assert [e["id"] for e in d["effects"]] == ["tool_offset_Z"]
        assert any("tool_offset_Z" in u and head_along_z in u for u in d["unobservable"])
        assert any("second tool length" in n for n in d["notes"])
        code, out, _ = run(capsys, "identify", session, "--no-budget")
        assert "tool_offset_Z" in out and "note: " in out
    else:
        assert hidden == set() and not d["unobservable"]
    code, out, err = run(capsys, "report", session, "-o", tmp_path / "r.html", "--no-diagnosis")
    assert code == 0, err
    html = (tmp_path / "r.html").read_text()
    assert f"<td class=l>{name} (" in html
    rot, tilt = m.rot_axis, m.tilt_axis
    for label in (f"radial_{rot}", f"axial_{rot}", f"radial_{tilt}", f"axial_{tilt}"):
        assert f"{label}: measured and model" in html
    assert ("tool_offset_Z" in html) == m.has_head
    # The paper's chain is Flynn's two tables; other machines are told to use the joint fit.
    code, _, err = run(
        capsys, "report", session, "--method", "paper", "-o", tmp_path / "p.html", "--no-diagnosis"
    )
    if name in ("AC-trt", "BC-trt"):
        assert code == 0, err
    else:
        assert code == cli.EXIT_INPUT and "--method joint" in err and name in err
        assert not (tmp_path / "p.html").exists()


def test_custom_description_round_trip(capsys, tmp_path, custom_file):
    """A machine from a file: the session carries it, identify and report read it back."""
    code, _, err = run(
        capsys,
        "plan",
        "ballbar",
        "--machine",
        custom_file,
        "-o",
        tmp_path / "c.ngc",
        "--session",
        tmp_path / "c.template.csv",
    )
    assert code == 0, err
    assert "(machine: shop-7 A-head C-table)" in (tmp_path / "c.ngc").read_text()
    m = load_machine(custom_file)
    truth, arg = errors_arg(m)
    session = tmp_path / "c.csv"
    code, _, err = run(
        capsys,
        "simulate",
        "ballbar",
        "--machine",
        custom_file,
        "--errors",
        arg,
        "--seed",
        5,
        "-o",
        session,
    )
    assert code == 0, err
    lines = session.read_text().splitlines()
    desc = next(l for l in lines if l.startswith("# machine_description: "))
    assert json.loads(desc.split(": ", 1)[1]) == json.loads(m.description_json)
    assert rotacal.load(str(session)).machine == m
    code, out, err = run(capsys, "identify", session, "--json", "--no-budget")
    assert code == 0, err
    d = json.loads(out)
    assert d["machine"] == CUSTOM["name"]
    for n, p in d["location_errors"].items():
        if n == "E_Z0A":
            assert p["value"] is None
        else:
            assert abs(p["value"] - truth[n]) < 5 * p["std"], (n, p, truth[n])
    code, _, err = run(capsys, "report", session, "-o", tmp_path / "c.html", "--no-diagnosis")
    assert code == 0, err
    assert "shop-7 A-head C-table (rotary table, tilting head)" in (tmp_path / "c.html").read_text()


def test_model_file_of_a_described_machine(capsys, tmp_path, custom_file):
    session = tmp_path / "c.csv"
    assert (
        run(capsys, "simulate", "ballbar", "--machine", custom_file, "--seed", 5, "-o", session)[0]
        == 0
    )
    code, out, err = run(
        capsys, "identify", session, "--json", "--no-budget", "--save-model", tmp_path / "m.json"
    )
    assert code == 0, err
    code, _, err = run(
        capsys, "predict", session, "--model", tmp_path / "m.json", "-o", tmp_path / "pred.csv"
    )
    assert code == 0, err
    rms = float(re.search(r"RMS ([0-9.]+) um", err).group(1))
    assert rms == pytest.approx(json.loads(out)["residual_rms_um"], abs=1e-3)


def test_python_module_entry_point_with_a_description_file(tmp_path, custom_file):
    """`python -m rotacal` as a user runs it: a file machine shown and simulated."""
    r = subprocess.run(
        [sys.executable, "-m", "rotacal", "machines", "show", str(custom_file), "--json"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["configuration"] == "head-table"


def test_tilt_range_defaults_to_the_machines(capsys, tmp_path):
    """B45C-trt's B turns 0..180: the AC-trt default -90,90 would leave its limits."""
    m = _core.parse_machine_type("B45C-trt")
    code, _, err = run(capsys, "plan", "ballbar", "--machine", "B45C-trt", "-o", tmp_path / "a.ngc")
    assert code == 0, err
    lo, hi = _core.default_tilt_range_deg(m)
    assert f"(B range: {lo:g} .. {hi:g} deg" in (tmp_path / "a.ngc").read_text()
    code, _, err = run(
        capsys,
        "plan",
        "ballbar",
        "--machine",
        "B45C-trt",
        "--b-range",
        "-90,90",
        "-o",
        tmp_path / "b.ngc",
    )
    assert code == cli.EXIT_INPUT and "limits" in err


# ------------------------------------------------------------------------- Python API


def test_load_machine_by_name_file_and_handle(custom_file):
    assert load_machine("BC-trt") == _core.MachineType.BC_trt
    assert load_machine(_core.MachineType.AC_trt) == _core.MachineType.AC_trt
    a, b = load_machine(custom_file), load_machine(str(custom_file))
    assert a == b and a.name == CUSTOM["name"] and not a.is_builtin
    assert a.axis_names == "CA" and a.has_head and a.configuration == "head-table"
    assert machine_dict(custom_file)["axes"][1]["location_errors"] == [
        "E_Y0A",
        "E_Z0A",
        "E_B0A",
        "E_C0A",
    ]
    with pytest.raises(_core.InvalidArgument, match="unknown machine 'XY-trt'.*AC-trt"):
        load_machine("XY-trt")
    with pytest.raises(_core.IoError, match="missing.json"):
        load_machine(custom_file.parent / "missing.json")
    with pytest.raises(_core.InvalidArgument):
        load_machine(3)


# ------------------------------------------------------------------------- bad descriptions

BAD = [
    (
        "zero direction",
        lambda d: d["table_axes"][0].update(direction=[0, 0, 0]),
        "table_axes[0].direction",
    ),
    ("same letter twice", lambda d: d["head_axes"][0].update(name="C"), "'C'"),
    ("letter not A/B/C", lambda d: d["head_axes"][0].update(name="W"), "head_axes[0].name"),
    (
        "limits reversed",
        lambda d: d["head_axes"][0].update(limits_deg=[100, -100]),
        "head_axes[0].limits_deg",
    ),
    (
        "three axes",
        lambda d: d["head_axes"].append({"name": "B", "direction": [0, 1, 0]}),
        "3 rotary axes",
    ),
    ("unknown field", lambda d: d.update(colour="red"), "colour"),
    ("wrong format", lambda d: d.update(format="rotacal-machine/2"), "format"),
    ("tool length text", lambda d: d.update(tool_length="80"), "tool_length"),
]


@pytest.mark.parametrize("what,change,field", BAD, ids=[b[0] for b in BAD])
@pytest.mark.parametrize(
    "command",
    [["plan", "ballbar"], ["simulate", "ballbar"], ["design", "ballbar"], ["machines", "show"]],
)
def test_bad_description_refused_with_file_and_field(
    capsys, tmp_path, what, change, field, command
):
    d = json.loads(json.dumps(CUSTOM))
    change(d)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d))
    args = (
        [*command, bad]
        if command[0] == "machines"
        else [*command, "--machine", bad, "-o", tmp_path / "o"]
    )
    code, _, err = run(capsys, *args)
    assert code == cli.EXIT_INPUT, err
    assert str(bad) in err and field in err, err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    "text,why", [("{", "not valid JSON"), ("[]", "JSON object"), ("\xff", "UTF-8")]
)
def test_not_a_description_refused(capsys, tmp_path, text, why):
    bad = tmp_path / "m.json"
    bad.write_bytes(text.encode("latin-1"))
    code, _, err = run(capsys, "plan", "ballbar", "--machine", bad, "-o", tmp_path / "o.ngc")
    assert code == cli.EXIT_INPUT and str(bad) in err and why in err, err


def test_unreadable_or_unknown_machine(capsys, tmp_path):
    code, _, err = run(
        capsys, "simulate", "ballbar", "--machine", tmp_path / "none.json", "-o", tmp_path / "o.csv"
    )
    assert code == cli.EXIT_IO and "none.json" in err
    code, _, err = run(capsys, "plan", "ballbar", "--machine", tmp_path, "-o", tmp_path / "o.ngc")
    assert code == cli.EXIT_IO and "directory" in err
    code, _, err = run(capsys, "plan", "ballbar", "--machine", "XY-trt", "-o", tmp_path / "o.ngc")
    assert code == cli.EXIT_INPUT and "B-head-C-table" in err
    code, _, err = run(capsys, "machines", "show")
    assert code == cli.EXIT_INPUT and "machines show" in err


def test_axial_c_tilt_on_a_head_head_machine(capsys, tmp_path):
    """AC-head: at tilt 0 the ball sits on the C head's line, so its four errors are seen only in
    one combination; the default 45 deg takes the ball off the line and all four are determined."""
    seen = {}
    for tilt in (None, 0):
        extra = [] if tilt is None else ["--axial-c-tilt", tilt]
        s = tmp_path / f"s{tilt}.csv"
        code, _, err = run(
            capsys, "simulate", "ballbar", "--machine", "AC-head", "--seed", 1, *extra, "-o", s
        )
        assert code == 0, err
        code, out, err = run(capsys, "identify", s, "--json", "--no-budget")
        assert code == 0, err
        seen[tilt] = {
            n for n, p in json.loads(out)["location_errors"].items() if p["value"] is not None
        }
    assert seen[None] == set(_core.location_error_names(load_machine("AC-head"))) - {"E_Z0A"}
    assert seen[0] == {"E_Y0A", "E_B0A", "E_C0A"}


# ------------------------------------------------------------------------- docs/machines.md

DOC = Path(__file__).resolve().parents[2] / "docs" / "machines.md"


def test_doc_example_description_is_the_tested_one(tmp_path):
    """The complete example of docs/machines.md is a valid description, the one tested above."""
    block = re.search(r"```json\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S).group(1)
    assert json.loads(block) == CUSTOM
    f = tmp_path / "shop7.json"
    f.write_text(block)
    assert load_machine(f).configuration == "head-table"


def test_doc_table_of_builtins_matches_the_descriptions():
    rows = re.findall(
        r"^\| (\S+) \| (table-table|head-table|head-head) \| ([A-C]), ([A-C]) \| ([E_A-Z0-9 ]+) \|$",
        DOC.read_text(encoding="utf-8"),
        re.M,
    )
    assert [r[0] for r in rows] == BUILTINS
    for name, conf, a0, a1, names in rows:
        m = _core.parse_machine_type(name)
        assert (conf, a0 + a1) == (m.configuration, m.axis_names)
        assert names.split() == list(_core.location_error_names(m))


@pytest.mark.parametrize("name", ["B-head-C-table", "AC-head", "B45C-trt", "AC-trt", "custom"])
def test_rtest_model_file_predicts_held_out_poses_on_any_machine(
    capsys, tmp_path, custom_file, name
):
    """Fit on C = 0, 30, ...; save the rtest-joint model; predict C = 15, 45, ... from the file.
    The prediction (the file's probe zeros added) matches the simulated machine's noise-free
    readings to well under the noise: the maps, tool_offset_Z of a head and the convention
    values of unobservable combinations (a head's probe zero z with its position along the
    spindle) all travel through the file."""
    machine = str(custom_file) if name == "custom" else name
    session = tmp_path / "r.csv"
    code, _, err = run(
        capsys,
        "simulate",
        "rtest",
        "--machine",
        machine,
        "--c-step",
        15,
        "--seed",
        3,
        "--effect",
        "gravity_sag_" + load_machine(machine).tilt_axis + "=0.004",
        "-o",
        session,
    )
    assert code == 0, err
    fit, held = split_by_c(session, 30)
    code, _, err = run(capsys, "identify", fit, "--no-budget", "--save-model", tmp_path / "m.json")
    assert code == 0, err
    code, _, err = run(
        capsys,
        "predict",
        held,
        "--model",
        tmp_path / "m.json",
        "--probe-zeros",
        "fitted",
        "-o",
        tmp_path / "p.csv",
    )
    assert code == 0, err
    saved = rotacal.load_model(tmp_path / "m.json")
    m = load_machine(machine)
    assert ("tool_offset_Z" in saved) == m.has_head
    assert saved["basis"]["maps"] == list(_core.rtest_map_names(m))
    truth = json.loads((tmp_path / "r.truth.json").read_text())
    s_held = rotacal.load(held)
    err_mm = np.asarray(rotacal.load(tmp_path / "p.csv").d) - rotacal.rtest.truth_readings(
        truth, s_held
    )
    noise_mm = truth["noise_um"] * 1e-3
    # The model's own error ~ noise * sqrt(p / n) (about 0.35 noise here); 2x margin.
    assert np.sqrt(np.mean(err_mm**2)) < 0.7 * noise_mm
    # The file predicts exactly as the fit in memory does.
    ident = rotacal.identify_rtest(rotacal.load(fit))
    in_memory = rotacal.rtest.predict_rtest(ident.model_dict(), s_held, probe_zeros="fitted")
    assert np.allclose(
        np.asarray(in_memory.d), np.asarray(rotacal.load(tmp_path / "p.csv").d), atol=1e-12
    )


def test_rtest_model_file_layout_is_checked_per_machine(capsys, tmp_path):
    """A head machine's file without tool_offset_Z, a table machine's with one, and maps that are
    not the machine's are refused, naming the member."""
    session = tmp_path / "r.csv"
    assert run(capsys, "simulate", "rtest", "--machine", "B-head-C-table", "-o", session)[0] == 0
    assert (
        run(capsys, "identify", session, "--no-budget", "--save-model", tmp_path / "m.json")[0] == 0
    )
    good = json.loads((tmp_path / "m.json").read_text())
    for change, member in (
        (lambda d: d.pop("tool_offset_Z"), "tool_offset_Z"),
        (lambda d: d["basis"].update(maps=["BY", "CB"]), "basis.maps"),
    ):
        d = json.loads(json.dumps(good))
        change(d)
        bad = tmp_path / "bad.json"
        bad.write_text(json.dumps(d))
        code, _, err = run(capsys, "predict", session, "--model", bad, "-o", tmp_path / "p.csv")
        assert code != 0 and member in err, err
    d = json.loads(json.dumps(good))
    d.pop("machine_description")
    d["machine"] = "BC-trt"
    d["basis"].pop("maps")
    with pytest.raises(_core.InvalidArgument, match="tool_offset_Z: only a machine with head axes"):
        rotacal.rtest.predict_rtest(d, rotacal.load(session))


def test_rtest_pattern_options_start_from_the_machines_default(capsys, tmp_path):
    """A step given without a range keeps the machine's default range: B45C-trt tilts 0..180
    (its nutating B), so --b-step 45 gives 0, 45, ..., 180, not the paper's -90..90 (refused
    there); --c-step 15 keeps the full turn."""
    s = tmp_path / "r.csv"
    code, out, err = run(
        capsys,
        "simulate",
        "rtest",
        "--machine",
        "B45C-trt",
        "--b-step",
        45,
        "--c-step",
        15,
        "-o",
        s,
    )
    assert code == 0, err
    angles = np.asarray(rotacal.load(s).angles_deg)
    assert sorted(set(angles[:, 0])) == [0.0, 45.0, 90.0, 135.0, 180.0]
    assert sorted(set(angles[:, 1])) == [15.0 * k for k in range(24)]
    # A range outside the limits is still refused, naming the axis.
    code, _, err = run(
        capsys, "simulate", "rtest", "--machine", "B45C-trt", "--b-range", "-90,90", "-o", s
    )
    assert code != 0 and "B" in err, err
