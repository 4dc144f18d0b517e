# SPDX-License-Identifier: BSD-3-Clause
"""Issue 32, class 1: no free text can put a block or a command into a file a controller executes.

Every text that is not the writer's own reaches those files: a machine description's `name`
(NC programs of `plan`, `design -o`, `circular plan`, `compensate`), a session path and the
model's `source.session` and the model path (`export` for every controller), an R-test set-up
label (the ISG sphere-centre program). Each is fed with the dialect's dangerous characters. The
file must then hold the same blocks as for a plain text, every other line being a whole
comment; LinuxCNC's own interpreter (rs274) must run the program with the same canonical
commands. Lines are split as str.splitlines() does (also at U+2028, form feed, NEL, ...): a
reader that breaks lines there must not find a command either.
"""

import hashlib
import json
import re
import shutil

import pytest

from rotacal import _core, cli

from conftest import run_cli

NC_DIALECTS = ("linuxcnc", "heidenhain", "siemens", "fanuc")
CONTROLLERS = ("linuxcnc", "siemens", "isg", "heidenhain", "fanuc")
# A rapid move and program ends behind every way a comment could end early.
HOSTILE_NAMES = (
    "x\nG0 Z-500\n",
    "x\r\nG0 Z-500\rM30",
    "x) G0 Z-500 (y",
    "x; G0 Z-500",
    "%\nG0 Z-500\n%",
    "MSG, x\u2028G0 Z-500\x85M30",
    "x ~\n* G0 Z-500 \\",
    "x" * 300 + "\nG0 Z-500",
)
RS274 = shutil.which("rs274")


def rotacal_cli(*args):
    """The command line in this process (conftest.run_cli); it must succeed."""
    r = run_cli(*args)
    assert r.returncode == cli.EXIT_OK, (
        f"rotacal {' '.join(map(str, args))}: exit code {r.returncode}: {r.stderr}"
    )


def is_comment(dialect, line):
    """A whole comment line of the NC dialect (heidenhain's block number taken off)."""
    if dialect == "heidenhain":
        line = line.split(" ", 1)[1] if re.match(r"^\d+ ", line) else line
    if dialect in ("linuxcnc", "fanuc"):
        return (
            len(line) >= 2
            and line[0] == "("
            and line[-1] == ")"
            and not re.search(r"[()]", line[1:-1])
        )
    return line.startswith(";")


def blocks(dialect, text):
    """The lines of a program that are not whole comments, without heidenhain's numbers."""
    out = []
    for line in text.splitlines():
        if not is_comment(dialect, line):
            out.append(re.sub(r"^\d+ ", "", line) if dialect == "heidenhain" else line)
    return out


def machine_file(path, name):
    d = json.loads(_core.parse_machine_type("AC-trt").description_json)
    d["name"] = name
    path.write_text(json.dumps(d))
    return path


@pytest.fixture(scope="module")
def custom_model(tmp_path_factory):
    """The model of a description machine (a plain name), to rename for compensate."""
    d = tmp_path_factory.mktemp("inject")
    s, m = d / "s.csv", d / "m.json"
    rotacal_cli(
        "simulate", "ballbar", "--machine", machine_file(d / "custom.json", "custom"), "-o", s
    )
    rotacal_cli("identify", s, "--save-model", m)
    return json.loads(m.read_text())


def nc_program(command, tmp_path, name, dialect, model):
    """The program `command` writes for a machine named `name`."""
    tag = "plain" if name == "plain" else "hostile"
    machine = machine_file(tmp_path / f"{tag}.json", name)
    out = tmp_path / f"{tag}.{dialect}"
    if command == "compensate":  # the model of that machine
        m = dict(
            model, machine=name, machine_description=dict(model["machine_description"], name=name)
        )
        mp = tmp_path / f"{tag}_model.json"
        mp.write_text(json.dumps(m))
        rotacal_cli(
            "compensate", "--model", mp, "--machine", machine, "--dialect", dialect, "-o", out
        )
    else:
        rotacal_cli(*command.split(), "--machine", machine, "--dialect", dialect, "-o", out)
    return out.read_text(encoding="utf-8")


@pytest.mark.parametrize(
    "command", ["plan ballbar", "design ballbar", "circular plan", "compensate"]
)
@pytest.mark.parametrize("dialect", NC_DIALECTS)
def test_a_machine_name_adds_no_block(command, dialect, tmp_path, custom_model):
    expected = blocks(dialect, nc_program(command, tmp_path, "plain", dialect, custom_model))
    for name in HOSTILE_NAMES:
        text = nc_program(command, tmp_path, name, dialect, custom_model)
        assert blocks(dialect, text) == expected, f"{command} {dialect}, machine named {name!r}"
        assert re.fullmatch(r"[\x20-\x7e\n]*", text), (
            f"{command} {dialect}: a byte outside printable ASCII"
        )


def canonical(text, tmp_path):
    """rs274's canonical commands of a program but its comments (a long name takes two)."""
    from test_linuxcnc import run_rs274  # fails on any interpreter error (an unclosed comment, ...)

    return [(name, args) for name, args in run_rs274(text, tmp_path) if name != "COMMENT"]


@pytest.mark.skipif(
    RS274 is None,
    reason="rs274 (LinuxCNC's G-code interpreter) not on PATH: apt-get install linuxcnc-uspace",
)
@pytest.mark.parametrize("command", ["plan ballbar", "circular plan", "compensate"])
def test_linuxcnc_runs_the_same_commands_whatever_the_name(command, tmp_path, custom_model):
    expected = canonical(nc_program(command, tmp_path, "plain", "linuxcnc", custom_model), tmp_path)
    for name in HOSTILE_NAMES:
        got = canonical(nc_program(command, tmp_path, name, "linuxcnc", custom_model), tmp_path)
        assert got == expected, f"{command}, machine named {name!r}"  # no MESSAGE, LOG, move added


# What each export means to write outside its comments (docs/controller_exports.md).
EXPORT_LINES = {
    "linuxcnc": r"setp xyzac-trt-kins\.[a-z-]+ -?\d+\.\d+",
    "siemens": r"\$TC_CARR\d+\[1\]=(-?\d+\.\d+|\"P\")|M17",
    "isg": r"trafo\[0\]\.axis\[[01]\]\.(point|orientation)\[[012]\]  -?\d+\.\d+",
    "heidenhain": r"(?!)",  # mapping sheets: comments only
    "fanuc": r"(?!)",
}
HOSTILE_PATH = (
    "s\nloadusr -w touch X\nsetp xyzac-trt-kins.z-offset 500\n$TC_CARR4[1]=500\nM17\n\u2028M30\\"
)


@pytest.fixture(scope="module")
def hostile_model(tmp_path_factory):
    """A model identified from a session whose path holds commands, saved under such a path."""
    d = tmp_path_factory.mktemp("inject_export")
    s, m = d / (HOSTILE_PATH + ".csv"), d / (HOSTILE_PATH + ".json")
    rotacal_cli("simulate", "ballbar", "--errors", "table2", "-o", s)
    rotacal_cli("identify", s, "--save-model", m)
    assert "loadusr" in json.loads(m.read_text())["source"]["session"]
    plain = d / "plain.json"
    doc = json.loads(m.read_text())
    plain.write_text(json.dumps(dict(doc, source=dict(doc["source"], session="s.csv"))))
    return m, plain


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_an_export_holds_only_its_values_whatever_the_session_path(
    controller, hostile_model, tmp_path
):
    hostile, plain = hostile_model
    comment = ";" if controller == "siemens" else "#"

    def export(model):
        out = tmp_path / f"{controller}.out"
        rotacal_cli("export", "--model", model, "--controller", controller, "-o", out)
        text = out.read_text(encoding="utf-8")
        return text, [line for line in text.splitlines() if not line.startswith(comment)]

    text, got = export(hostile)
    assert got == export(plain)[1]
    for line in got:
        assert re.fullmatch(EXPORT_LINES[controller], line), (
            f"{controller}: {line!r} is not a value line"
        )
    assert re.fullmatch(r"[\x20-\x7e\n]*", text), "a byte outside printable ASCII"
    assert all(len(line) <= 1000 for line in text.splitlines())  # halcmd reads 1023 a line


def test_isg_centres_program_holds_only_its_blocks_whatever_the_setup_label(tmp_path):
    # A set-up label may hold anything a session file allows (no comma, '#', line end or
    # ASCII control character): brackets, semicolons, and Unicode line separators.
    s, m = tmp_path / "r.csv", tmp_path / "r.json"
    rotacal_cli("simulate", "rtest", "--seed", "4", "-o", s)
    rotacal_cli("identify", s, "--save-model", m)
    label = "2 (x) ; % $ * \\ ~\u2028M30\u2029G0 Z-500\x85M30"
    rows = [
        (label + line[1:])
        if line.startswith("2,")
        else line.replace("# nest.2:", f"# nest.{label}:")
        for line in s.read_text().split("\n")
    ]
    hs, hm = tmp_path / "h.csv", tmp_path / "h.json"
    hs.write_text("\n".join(rows), encoding="utf-8")
    doc = json.loads(m.read_text())
    doc["probe_zeros"][label] = doc["probe_zeros"].pop("2")
    doc["nests"][label] = doc["nests"].pop("2")
    doc["source"]["session_sha256"] = hashlib.sha256(
        hs.read_bytes()
    ).hexdigest()  # fitted to hs, as it were
    hm.write_text(json.dumps(doc))

    def program(model, session, setup):
        out = tmp_path / "centres.nc"
        rotacal_cli(
            "export",
            "--model",
            model,
            "--controller",
            "isg",
            "--centres",
            session,
            "--centres-output",
            out,
            "--centres-setup",
            setup,
        )
        return out.read_text(encoding="utf-8")

    text = program(hm, hs, label)
    assert re.fullmatch(r"[\x20-\x7e\n]*", text), "a byte outside printable ASCII"
    got = [line for line in text.splitlines() if not line.startswith(";")]
    assert got == [line for line in program(m, s, "2").splitlines() if not line.startswith(";")]
    assert all(
        re.fullmatch(
            r"#VAR|#ENDVAR|V\.[LP]\.[A-Z_]+ = [-0-9.]+|L CYCLE \[NAME = \"SysCalib\w+\.ecy\"[^\]]*\]|M30",
            line,
        )
        for line in got
    )


def test_comp_tables_hold_only_their_triplets_whatever_the_session_path(hostile_model, tmp_path):
    """`export --tables` (issue 54): the COMP_FILE holds its triplets, then comment lines only;
    the INI lines that load it hold only section, key and comment lines."""
    hostile, plain = hostile_model

    def with_worm_gear(model, name):
        doc = json.loads(model.read_text())
        doc["effects"] = [
            {"id": "angular_positioning_C_h1", "params": {"a": {"value": 1e-4}, "b": {"value": 0}}}
        ]
        doc.pop("covariance", None)
        out = model.parent / name
        out.write_text(json.dumps(doc))
        return out

    def tables(model, d):
        d.mkdir()
        rotacal_cli(
            "export",
            "--model",
            model,
            "--controller",
            "linuxcnc",
            "--tables",
            "--tables-dir",
            d,
            "-o",
            d / "kins.hal",
        )
        return (d / "comp_C.txt").read_text(encoding="utf-8"), (d / "comp_tables.ini").read_text()

    text, ini = tables(with_worm_gear(hostile, HOSTILE_PATH + ".worm.json"), tmp_path / "h")
    plain_text, _ = tables(with_worm_gear(plain, "plain.worm.json"), tmp_path / "p")
    assert "loadusr" in text  # the path is there, as a comment
    data = [ln for ln in text.splitlines() if not ln.startswith("#")]
    assert data == [ln for ln in plain_text.splitlines() if not ln.startswith("#")]
    assert len(data) == 145 and text.splitlines()[:145] == data
    for line in data:
        assert re.fullmatch(r"-?\d+\.\d{6} -?\d+\.\d{9} -?\d+\.\d{9}", line), line
    assert re.fullmatch(r"[\x20-\x7e\n]*", text), "a byte outside printable ASCII"
    for line in ini.splitlines():
        assert re.fullmatch(r"\[JOINT_\d\]|#[\x20-\x7e]*|COMP_FILE = \S+|COMP_FILE_TYPE = 1", line)
    # The SINUMERIK EEC program of the same model: its blocks, then comments only.
    d = tmp_path / "s"
    d.mkdir()
    rotacal_cli(
        "export",
        "--model",
        with_worm_gear(hostile, HOSTILE_PATH + ".worm.json"),
        "--controller",
        "siemens",
        "--tables",
        "--tables-dir",
        d,
    )
    mpf = (d / "eec_C.mpf").read_text(encoding="utf-8")
    assert "loadusr" in mpf and re.fullmatch(r"[\x20-\x7e\n]*", mpf)
    blocks = [ln for ln in mpf.splitlines() if not ln.startswith(";")]
    assert len(blocks) == 2 + 73 + 4 + 1
    for line in blocks:
        assert re.fullmatch(
            r"%_N_AX_EEC_INI|CHANDATA\(1\)|M17|\$AA_ENC_COMP\[0,\d+,C1\]=-?\d+\.\d{9}"
            r"|\$AA_ENC_COMP_(STEP|MIN|MAX|IS_MODULO)\[0,C1\]=-?[\d.]+",
            line,
        ), line
