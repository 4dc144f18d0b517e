# SPDX-License-Identifier: BSD-3-Clause
"""The second hostile round (issue 32, classes 3-7 and what a user sees): hostile JSON in every
file a command reads as JSON, recordings that measure nothing, broken options, nonsense that
used to exit 0, and exit codes of the history store. Each run asserts its exit code and a
property of what it leaves (no crash, no exit 5 on bad input, no replaced input); the CLI runs
in this process except where a crash or a memory bound must be seen from outside. Outputs over
inputs (class 2) are tried in test_command_files.py."""

import json
import os
import resource
import sqlite3
import subprocess
import sys

import pytest

import rotacal
from rotacal import cli
from rotacal.history import open_history
from rotacal.machines import load_machine

EXIT_OK, EXIT_INPUT, EXIT_IO = 0, 3, 4
DEEP = 50_000  # levels of nesting that overflowed the stack of the JSON conversion


def run(capsys, *args):
    code = cli.main([str(a) for a in args])
    out = capsys.readouterr()
    return code, out.out, out.err


def run_outside(*args, memory_bytes=None, timeout=120):
    """The CLI in a child process (a crash or an allocation beyond the limit is seen, not suffered)."""

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (memory_bytes, memory_bytes))

    r = subprocess.run(
        [sys.executable, "-m", "rotacal", *map(str, args)],
        capture_output=True,
        text=True,
        errors="replace",
        timeout=timeout,
        preexec_fn=limit if memory_bytes else None,
    )
    assert r.returncode >= 0, f"killed by signal {-r.returncode}: {r.stderr[-2000:]}"
    assert "Traceback" not in r.stderr and "internal error" not in r.stderr, r.stderr[-2000:]
    return r


@pytest.fixture(scope="module")
def files(shared_data, tmp_path_factory):
    d = tmp_path_factory.mktemp("round2")
    session = d / "s.csv"
    session.write_bytes((shared_data / "ballbar_ac_table2.csv").read_bytes())
    model = d / "m.json"
    assert cli.main(["identify", str(session), "--no-budget", "--save-model", str(model)]) == 0
    doc = json.loads(model.read_text())
    return {
        "dir": d,
        "session": session,
        "model": model,
        "model_doc": doc,
        "machine_doc": json.loads(load_machine("AC-trt").description_json),
    }


def _nested(depth, inner="0"):
    return "[" * depth + inner + "]" * depth


# Hostile JSON texts, each with the exit code and words of its refusal.
HOSTILE_JSON = {
    "deep": (_nested(DEEP), EXIT_INPUT, "nested deeper than 64"),
    "deep objects": ('{"a":' * 70 + "0" + "}" * 70, EXIT_INPUT, "nested deeper than 64"),
    "object flood": ("[" + ",".join(["{}"] * 200_000) + "]", EXIT_INPUT, "objects and arrays"),
    "NaN": ('{"a": NaN}', EXIT_INPUT, "JSON"),
    "1e999": ('{"a": 1e999}', EXIT_INPUT, "JSON"),
    "truncated": ('{"a": [1, 2', EXIT_INPUT, "JSON"),
    "not UTF-8": (b'{"a": "\xff"}', EXIT_INPUT, "UTF-8"),
}


def _write(path, text):
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    return path


# ------------------------------------------------------------------------- class 4: JSON options

JSON_OPTIONS = [
    ("--budget-sizes", lambda f, p: ["diagnose", f["session"], "--budget-sizes", p]),
    ("--budget-sizes", lambda f, p: ["identify", f["session"], "--budget-sizes", p]),
    (
        "--correction",
        lambda f, p: [
            "history",
            "add",
            "--correction",
            p,
            "--machine-id",
            "M",
            "--db",
            f["dir"] / "h1.sqlite",
        ],
    ),
    (
        "--diagnosis",
        lambda f, p: [
            "history",
            "add",
            f["model"],
            "--diagnosis",
            p,
            "--machine-id",
            "M",
            "--db",
            f["dir"] / "h1.sqlite",
        ],
    ),
    ("--table", lambda f, p: ["table2", "--table", p, "--draws", "10", "--no-sweep"]),
    ("--machine", lambda f, p: ["plan", "ballbar", "--machine", p, "-o", f["dir"] / "never.ngc"]),
    ("--machine", lambda f, p: ["simulate", "rtest", "--machine", p, "-o", f["dir"] / "never.csv"]),
    ("NAME|FILE", lambda f, p: ["machines", "show", p]),
    (
        "--machine",
        lambda f, p: ["simulate", "ballbar", "--machine", p, "-o", f["dir"] / "never.csv"],
    ),
    ("--machine", lambda f, p: ["design", "ballbar", "--machine", p, "-o", f["dir"] / "never.ngc"]),
    (
        "--machine",
        lambda f, p: ["compensate", "--verify", "--machine", p, "-o", f["dir"] / "never.ngc"],
    ),
    ("--machine", lambda f, p: ["circular", "plan", "--machine", p, "-o", f["dir"] / "never.ngc"]),
    (
        "--current",
        lambda f, p: [
            "export",
            "--model",
            f["model"],
            "--controller",
            "linuxcnc",
            "--current",
            p,
            "-o",
            f["dir"] / "never.hal",
        ],
    ),
]


@pytest.mark.parametrize("case", sorted(HOSTILE_JSON))
@pytest.mark.parametrize(
    "k", range(len(JSON_OPTIONS)), ids=[f"{o}-{i}" for i, (o, _) in enumerate(JSON_OPTIONS)]
)
def test_hostile_json_in_an_option_is_invalid_content(files, tmp_path, capsys, case, k):
    text, code, words = HOSTILE_JSON[case]
    p = _write(tmp_path / "hostile.json", text)
    option, argv = JSON_OPTIONS[k]
    got, _, err = run(capsys, *argv(files, p))
    assert got == code, err
    assert str(p) in err, err
    if option != "--current":  # the controller reader says what it expected instead
        assert words in err or "JSON" in err, err
    assert not [q for q in files["dir"].iterdir() if q.name.startswith("never.")]


# ------------------------------------------------------------------------- class 4: model files


def _model_with(files, member):
    doc = dict(files["model_doc"])
    doc["ignored_by_readers"] = member
    return doc


MODEL_COMMANDS = {
    "predict": lambda f, m, o: ["predict", f["session"], "--model", m, "-o", o],
    "export": lambda f, m, o: ["export", "--model", m, "--controller", "linuxcnc", "-o", o],
    "compensate": lambda f, m, o: ["compensate", "--model", m, "-o", o],
    "history add": lambda f, m, o: ["history", "add", m, "--machine-id", "M", "--db", o],
}


@pytest.mark.parametrize("command", sorted(MODEL_COMMANDS))
def test_deeply_nested_model_member_does_not_crash(files, tmp_path, command):
    # 50,000 nested [ in a member readers ignore: the bindings' conversion overflowed the stack.
    model = tmp_path / "deep.json"
    text = json.dumps(_model_with(files, [])).replace(
        '"ignored_by_readers": []', '"ignored_by_readers": ' + _nested(DEEP)
    )
    model.write_text(text)
    out = tmp_path / "out"
    r = run_outside(*MODEL_COMMANDS[command](files, model, out))
    assert (
        r.returncode == EXIT_INPUT
        and "nested deeper than 64" in r.stderr
        and "deep.json" in r.stderr
    ), r.stderr
    assert not out.exists()


def test_model_of_empty_objects_is_refused_in_bounded_memory(files, tmp_path):
    # 12 MB of {} (under the 16 MB model limit): 4 million objects would take gigabytes.
    model = tmp_path / "flood.json"
    flood = "[" + ",".join(["{}"] * 4_000_000) + "]"
    model.write_text(
        json.dumps(_model_with(files, [])).replace(
            '"ignored_by_readers": []', '"ignored_by_readers": ' + flood
        )
    )
    r = run_outside(
        "predict",
        files["session"],
        "--model",
        model,
        "-o",
        tmp_path / "p.csv",
        memory_bytes=2 << 30,
    )
    assert r.returncode == EXIT_INPUT and "objects and arrays" in r.stderr, r.stderr


def test_a_60_mb_model_file_is_refused_by_its_size(tmp_path):
    model = tmp_path / "big.json"
    with open(model, "w") as f:
        f.write('{"a": [' + ",".join(["{}"] * 20_000_000) + "]}")
    r = run_outside("export", "--model", model, "--controller", "linuxcnc", memory_bytes=2 << 30)
    assert r.returncode == EXIT_IO and "larger than 16 MB" in r.stderr, r.stderr


# Model files every model-reading command must refuse without writing: (text, exit code).
HOSTILE_MODELS = {
    "deep objects": (
        '{"format": "rotacal-model/1", "x": ' + '{"a":' * 70 + "0" + "}" * 70 + "}",
        EXIT_INPUT,
    ),
    "object flood": (
        '{"format": "rotacal-model/1", "x": [' + ",".join(["{}"] * 200_000) + "]}",
        EXIT_INPUT,
    ),
    "NaN": ('{"format": "rotacal-model/1", "kind": "ballbar", "x": NaN}', EXIT_INPUT),
    "1e999": ('{"format": "rotacal-model/1", "kind": "ballbar", "x": 1e999}', EXIT_INPUT),
    "truncated": ('{"format": "rotacal-model/1", "kind": ', EXIT_INPUT),
    "not UTF-8": (b'{"format": "rotacal-model/1", "kind": "\xff"}', EXIT_INPUT),
    "empty": ("", EXIT_INPUT),
    "an array": ("[]", EXIT_INPUT),
    "no format": ('{"kind": "ballbar"}', EXIT_INPUT),
    "a directory": (None, EXIT_IO),
}


@pytest.mark.parametrize("case", sorted(HOSTILE_MODELS))
@pytest.mark.parametrize(
    "command", sorted(MODEL_COMMANDS) + ["plan --compensate", "export siemens", "export isg"]
)
def test_hostile_model_files_are_refused_without_writing(files, tmp_path, capsys, case, command):
    text, expected = HOSTILE_MODELS[case]
    model = tmp_path / "model.json"
    if text is None:
        model.mkdir()
    else:
        _write(model, text)
    out = tmp_path / "out"
    argv = {
        "plan --compensate": lambda: ["plan", "ballbar", "--compensate", model, "-o", out],
        "export siemens": lambda: [
            "export",
            "--model",
            model,
            "--controller",
            "siemens",
            "-o",
            out,
        ],
        "export isg": lambda: ["export", "--model", model, "--controller", "isg", "-o", out],
    }.get(command, lambda: MODEL_COMMANDS[command](files, model, out))()
    code, _, err = run(capsys, *argv)
    assert code == expected, err
    assert "model.json" in err and not out.exists(), err


@pytest.mark.parametrize("case", ["deep", "deep objects", "object flood"])
def test_machine_description_member_in_a_model(files, tmp_path, capsys, case):
    doc = dict(files["model_doc"])
    doc["machine_description"] = {"name": json.loads("0")}
    text = json.dumps(doc).replace('"name": 0', '"name": ' + HOSTILE_JSON[case][0])
    model = _write(tmp_path / "md.json", text)
    code, _, err = run(
        capsys, "predict", files["session"], "--model", model, "-o", tmp_path / "p.csv"
    )
    assert code == EXIT_INPUT and "md.json" in err, err


# ------------------------------------------------------------------------- class 3: recordings


def _silent_port():
    """A pseudo-terminal whose other end never answers: (its path, the master fd to close)."""
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    return path, master


@pytest.mark.parametrize("kind", ["ballbar", "rtest"])
def test_a_recording_with_no_row_leaves_the_old_file(files, tmp_path, capsys, kind):
    old = tmp_path / "recorded.csv"
    old.write_bytes(files["session"].read_bytes())
    before = old.read_bytes()
    port, master = _silent_port()
    try:
        code, _, err = run(
            capsys, "record", kind, "--port", port, "-o", old, "--silence", "0.3", "--no-progress"
        )
    finally:
        os.close(master)
    assert code == EXIT_IO and "not written" in err, err
    assert old.read_bytes() == before
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".part")]


# ------------------------------------------------------------------------- class 5: broken options


def test_budget_sizes_file_is_read_once(files, tmp_path, capsys):
    sizes = _write(
        tmp_path / "sizes.json",
        json.dumps({"squareness_rad": 1e-5, "overrides": {"gravity_sag_A": 0.004}}),
    )
    code, out, err = run(
        capsys, "diagnose", files["session"], "--budget-sizes", sizes, "--json", "--no-progress"
    )
    assert code == EXIT_OK, err
    assert json.loads(out)["uncertainty_budget"]


def test_budget_sizes_with_an_unknown_key_names_the_file(files, tmp_path, capsys):
    sizes = _write(tmp_path / "sizes.json", json.dumps({"no_such_size": 1}))
    code, _, err = run(capsys, "identify", files["session"], "--budget-sizes", sizes)
    assert code == EXIT_INPUT and "sizes.json" in err and "no_such_size" in err, err


def test_huge_axis_direction_is_normalised_not_zero(files, tmp_path, capsys):
    d = json.loads(json.dumps(files["machine_doc"]))
    d["name"] = "huge direction"
    d["table_axes"][0]["direction"] = [1e200, 0, 0]
    p = _write(tmp_path / "huge.json", json.dumps(d))
    code, out, err = run(capsys, "machines", "show", p, "--json")
    assert code == EXIT_OK, err
    assert json.loads(out)["axes"]
    code, _, err = run(capsys, "plan", "ballbar", "--machine", p, "-o", tmp_path / "p.ngc")
    assert code == EXIT_OK, err
    d["table_axes"][0]["direction"] = [1e200, 1e200, 0]
    p = _write(tmp_path / "oblique.json", json.dumps(d))
    for argv in (
        ("machines", "show", p),
        ("plan", "ballbar", "--machine", p, "-o", tmp_path / "q.ngc"),
        ("simulate", "ballbar", "--machine", p, "-o", tmp_path / "q.csv"),
    ):
        code, _, err = run(capsys, *argv)
        assert (
            code in (EXIT_OK, EXIT_INPUT) and "internal" not in err and "StopIteration" not in err
        ), err


@pytest.mark.parametrize(
    "argv", [("simulate", "ballbar"), ("simulate", "rtest"), ("circular", "simulate")]
)
def test_noise_zero_is_saved(tmp_path, capsys, argv):
    out = tmp_path / "s.csv"
    code, _, err = run(capsys, *argv, "--noise", "0", "-o", out)
    assert code == EXIT_OK, err
    s = rotacal.load(str(out))
    assert s.noise_um is None and len(s) > 0


def test_design_rtest_travel_can_widen(capsys):
    # Nests farther out than the built-in BC-trt's travel allows, inside the one given.
    code, out, err = run(
        capsys,
        "design",
        "rtest",
        "--travel=-1000,1000,-1000,1000,-1000,1000",
        "--radii",
        "450",
        "--heights",
        "20,140",
        "--b-steps",
        "30",
        "--c-steps",
        "30",
        "--json",
    )
    assert code == EXIT_OK, err
    best = json.loads(out)["best"]
    assert best["feasible"] and max(abs(v) for n in best["nests"] for v in n) >= 450


# ------------------------------------------------------------------------- class 6: nonsense that exited 0


def test_predict_of_another_set_up_is_refused(files, tmp_path, capsys):
    other = tmp_path / "other.csv"
    assert (
        run(
            capsys,
            "simulate",
            "ballbar",
            "--errors",
            "table2",
            "--pivot",
            "150,0,80",
            "--length",
            "150",
            "-o",
            other,
        )[0]
        == EXIT_OK
    )
    code, _, err = run(
        capsys, "predict", other, "--model", files["model"], "-o", tmp_path / "p.csv"
    )
    assert code == EXIT_INPUT and "pivot" in err, err
    assert not (tmp_path / "p.csv").exists()


@pytest.mark.parametrize("span", ["2", "5"])
def test_circular_arc_too_short_for_a_centre(tmp_path, capsys, span):
    s = tmp_path / "arc.csv"
    assert (
        run(
            capsys,
            "circular",
            "simulate",
            "--planes",
            "XY",
            "--span",
            span,
            "--feeds",
            "1000",
            "--rate",
            "1000",
            "-o",
            s,
        )[0]
        == EXIT_OK
    )
    code, out, err = run(capsys, "circular", "analyze", s)
    assert code == EXIT_INPUT and "cannot determine the circle's centre" in err, err


@pytest.mark.parametrize("kind", ["ballbar", "rtest"])
@pytest.mark.parametrize("value", ["1e-300", "0.5"])
def test_design_time_below_a_second(capsys, kind, value):
    code, _, err = run(capsys, "design", kind, "--time", value)
    assert code == EXIT_INPUT and "--time" in err, err


@pytest.mark.parametrize("value", [1e308, 1e3, -101.0])
def test_correction_beyond_any_machine(files, tmp_path, capsys, value):
    export = _write(
        tmp_path / "export.json",
        json.dumps(
            {
                "controller": "linuxcnc",
                "location_errors": [{"name": "E_Y0A", "held": True, "value": value}],
            }
        ),
    )
    db = tmp_path / "h.sqlite"
    code, _, err = run(
        capsys, "history", "add", "--correction", export, "--machine-id", "M", "--db", db
    )
    assert code == EXIT_INPUT and "location_errors[0].value" in err, err


@pytest.mark.parametrize("form", ["json", "hal"])
@pytest.mark.parametrize("value", ["1e308", "-2e6", "inf"])
def test_current_value_beyond_any_machine(files, tmp_path, capsys, form, value):
    """A controller's current pin of 1e308 mm was written back as a 309-digit value."""
    if form == "json":
        text = '{"controller": "linuxcnc", "parameters": {"xyzac-trt-kins.y-offset": %s}}' % (
            value if value != "inf" else "1e999"
        )
    else:
        text = f"setp xyzac-trt-kins.y-offset {value}\n"
    current = _write(tmp_path / f"current.{form}", text)
    out = tmp_path / "never.hal"
    code, _, err = run(
        capsys,
        "export",
        "--model",
        files["model"],
        "--controller",
        "linuxcnc",
        "--current",
        current,
        "-o",
        out,
    )
    assert code == EXIT_INPUT, err
    assert str(current) in err and ("1e6" in err or "JSON" in err), err
    assert not out.exists()


def test_report_says_why_type_b_dominates(files, tmp_path, capsys):
    out = tmp_path / "r.html"
    code, _, err = run(capsys, "report", files["session"], "-o", out)
    assert code == EXIT_OK, err
    html = out.read_text()
    assert "mostly type B" in html and "--budget-sizes" in html and "not measured" in html


def test_description_named_like_a_builtin(files, tmp_path, capsys):
    d = json.loads(json.dumps(files["machine_doc"]))
    d["table_axes"][0]["point"] = [0, 0, -25]  # other kinematics, the built-in's name
    p = _write(tmp_path / "fake.json", json.dumps(d))
    code, _, err = run(capsys, "plan", "ballbar", "--machine", p, "-o", tmp_path / "p.ngc")
    assert code == EXIT_INPUT and "built-in" in err, err
    same = _write(
        tmp_path / "same.json", json.dumps(files["machine_doc"])
    )  # the built-in itself: fine
    assert run(capsys, "plan", "ballbar", "--machine", same, "-o", tmp_path / "q.ngc")[0] == EXIT_OK


def test_report_history_of_another_machine_type(files, tmp_path, capsys, shared_data):
    db = tmp_path / "h.sqlite"
    rmodel = tmp_path / "r.json"
    assert (
        run(
            capsys,
            "identify",
            shared_data / "rtest_bc_oyama.csv",
            "--no-budget",
            "--save-model",
            rmodel,
        )[0]
        == 0
    )
    assert run(capsys, "history", "add", rmodel, "--machine-id", "BC-1", "--db", db)[0] == EXIT_OK
    out = tmp_path / "r.html"
    code, _, err = run(
        capsys, "report", files["session"], "--history", "BC-1", "--db", db, "-o", out
    )
    assert code == EXIT_INPUT and "BC-trt" in err and "AC-trt" in err, err
    assert not out.exists()


# ------------------------------------------------------------------------- class 7: the store's exit codes


def test_schema_version_minus_five(tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    open_history(str(db)).close()
    with sqlite3.connect(db) as c:
        c.execute("DELETE FROM rotacal_history_schema")
        c.execute("INSERT INTO rotacal_history_schema (version, applied_at) VALUES (-5, 'x')")
    code, _, err = run(capsys, "history", "list", "--db", db)
    assert code == EXIT_INPUT and "schema version" in err, err


@pytest.mark.parametrize("device", ["/dev/null", "/dev/zero"])
def test_device_as_store(capsys, device):
    journal = device + "-journal"
    existed = os.path.exists(journal)
    code, _, err = run(capsys, "history", "list", "--db", device)
    assert code == EXIT_IO and device in err, err
    assert os.path.exists(journal) == existed


def test_store_on_a_read_only_file_system(tmp_path):
    db = tmp_path / "h.sqlite"
    open_history(str(db)).close()
    mnt = tmp_path / "ro"
    mnt.mkdir()
    script = (
        f"mount -t tmpfs -o size=4m tmpfs {mnt} && cp {db} {mnt}/h.sqlite && mount -o remount,ro {mnt} && "
        f"exec {sys.executable} -m rotacal history list --db {mnt}/h.sqlite"
    )
    probe = subprocess.run(
        ["unshare", "-m", "sh", "-c", f"mount -t tmpfs tmpfs {mnt}"], capture_output=True
    )
    if probe.returncode != 0:
        pytest.skip("no mount namespace here (needs root): " + probe.stderr.decode()[-200:])
    r = subprocess.run(
        ["unshare", "-m", "sh", "-c", script],
        capture_output=True,
        text=True,
        timeout=60,
        env=os.environ | {"PYTHONPATH": os.pathsep.join(sys.path)},
    )
    assert r.returncode == EXIT_IO and "read-only" in r.stderr, r.stderr


# ------------------------------------------------------------------------- what a user sees


def _entry(model_doc, when):
    doc = json.loads(json.dumps(model_doc))
    doc.setdefault("source", {})["identified_at"] = when
    doc["source"]["session_sha256"] = when  # two entries, not one stored twice
    return doc


def test_no_drift_from_calibrations_a_second_apart(files, tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    for k, when in enumerate(("2026-03-01T10:00:00Z", "2026-03-01T10:00:01Z")):
        m = _write(tmp_path / f"m{k}.json", json.dumps(_entry(files["model_doc"], when)))
        code, _, err = run(
            capsys, "history", "add", m, "--machine-id", "M", "--date", when, "--db", db
        )
        assert code == EXIT_OK, err
    code, out, err = run(capsys, "history", "show", "M", "--db", db, "--json")
    assert code == EXIT_OK, err
    assert all(e["drift_per_month"] is None for e in json.loads(out)["location_errors"].values())
    code, out, err = run(capsys, "history", "show", "M", "--db", db)
    assert code == EXIT_OK and "less than 7 days" in out, out


def test_a_closed_pipe_is_not_an_error():
    p = subprocess.Popen(
        [sys.executable, "-m", "rotacal", "table2", "--draws", "10", "--no-sweep"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    p.stdout.close()  # the reader (head) went away before the first line
    err = p.stderr.read().decode()
    assert p.wait(timeout=120) == EXIT_OK, err
    assert "Broken pipe" not in err and "Exception ignored" not in err, err


def test_pyproject_names_psycopg_for_postgresql():
    import tomllib
    from pathlib import Path

    pyproject = tomllib.loads((Path(__file__).resolve().parents[2] / "pyproject.toml").read_text())
    extras = pyproject["project"]["optional-dependencies"]
    assert any(d.startswith("psycopg") for deps in extras.values() for d in deps)


def test_budget_says_why_type_b_dominates_and_what_to_measure(files, capsys):
    code, out, err = run(capsys, "identify", files["session"])
    assert code == EXIT_OK, err
    why = next(ln for ln in out.splitlines() if "mostly type B" in ln)
    assert "--budget-sizes" in why and "overrides" in why and "not measured" in why, why
