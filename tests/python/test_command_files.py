# SPDX-License-Identifier: BSD-3-Clause
"""Issue 32, class 2: no output of any command may be one of its inputs, another of its
outputs or the history store it uses: refused before any work with exit 4, the file left
as it was. The rule is one table (rotacal.command_files.COMMANDS); every subcommand of the
parser must have its row, and every file option of a row is tried here against every other."""

import argparse
import json
import re

import numpy as np
import pytest

import rotacal
from rotacal import cli, command_files
from rotacal.cli import serial_link
from rotacal.history import open_history
from rotacal.machines import load_machine

EXIT_IO = 4
SLOT = re.compile(r"\{([^{}]+)\}")

# One (or two) command lines per row of the table, each file option as {its option}.
TEMPLATES = {
    ("plan", "ballbar"): [
        [
            "plan",
            "ballbar",
            "--machine",
            "{--machine}",
            "--compensate",
            "{--compensate}",
            "--session",
            "{--session}",
            "-o",
            "{-o}",
        ]
    ],
    ("plan", "probe"): [
        ["plan", "probe", "--machine", "{--machine}", "--session", "{--session}", "-o", "{-o}"],
        ["plan", "probe", "--design", "{--design}", "--session", "{--session}", "-o", "{-o}"],
    ],
    ("plan", "thermal"): [
        ["plan", "thermal", "--machine", "{--machine}", "--session", "{--session}", "-o", "{-o}"]
    ],
    ("simulate", "thermal"): [
        ["simulate", "thermal", "--machine", "{--machine}", "--truth", "{--truth}", "-o", "{-o}"]
    ],
    ("import", "probe"): [["import", "probe", "{LOG}", "--plan", "{--plan}", "-o", "{-o}"]],
    ("simulate", "ballbar"): [
        ["simulate", "ballbar", "--machine", "{--machine}", "--truth", "{--truth}", "-o", "{-o}"]
    ],
    ("simulate", "rtest"): [
        ["simulate", "rtest", "--machine", "{--machine}", "--truth", "{--truth}", "-o", "{-o}"]
    ],
    ("simulate", "probe"): [
        ["simulate", "probe", "--machine", "{--machine}", "--truth", "{--truth}", "-o", "{-o}"]
    ],
    ("identify",): [
        [
            "identify",
            "{FILE}",
            "--budget-sizes",
            "{--budget-sizes}",
            "--controller",
            "{--controller}",
            "--save-model",
            "{--save-model}",
            "--store",
            "--machine-id",
            "M1",
            "--db",
            "{--db}",
        ]
    ],
    ("history", "add"): [
        [
            "history",
            "add",
            "{MODEL}",
            "--diagnosis",
            "{--diagnosis}",
            "--controller",
            "{--controller}",
            "--machine-id",
            "M1",
            "--db",
            "{--db}",
        ],
        [
            "history",
            "add",
            "--correction",
            "{--correction}",
            "--machine-id",
            "M1",
            "--db",
            "{--db}",
        ],
    ],
    ("history", "show"): [["history", "show", "M1", "--plot", "{--plot}", "--db", "{--db}"]],
    ("diagnose",): [
        ["diagnose", "{FILE}", "--budget-sizes", "{--budget-sizes}", "--report", "{--report}"]
    ],
    ("predict",): [
        ["predict", "{SESSION}", "--model", "{--model}", "-o", "{-o}"],
        ["predict", "--joints", "{--joints}", "--model", "{--model}", "-o", "{-o}"],
    ],
    ("design", "ballbar"): [
        ["design", "ballbar", "--machine", "{--machine}", "-o", "{-o}"],
        [
            "design",
            "ballbar",
            "--separate",
            "gravity_sag_A,gravity_sag_C",
            "--after",
            "{--after}",
            "-o",
            "{-o}",
            "--session",
            "{--session}",
        ],
    ],
    ("design", "rtest"): [
        [
            "design",
            "rtest",
            "--separate",
            "coning_B,tilt_motion_B_h2",
            "--after",
            "{--after}",
            "--session",
            "{--session}",
        ],
    ],
    ("design", "probe"): [
        ["design", "probe", "--machine", "{--machine}", "-o", "{-o}", "--session", "{--session}"],
        [
            "design",
            "probe",
            "--separate",
            "gravity_sag_A,radial_motion_A_h2",
            "--after",
            "{--after}",
            "-o",
            "{-o}",
            "--session",
            "{--session}",
        ],
    ],
    ("export",): [
        [
            "export",
            "--model",
            "{--model}",
            "--controller",
            "isg",
            "--current",
            "{--current}",
            "--centres",
            "{--centres}",
            "--centres-output",
            "{--centres-output}",
            "--residual-model",
            "{--residual-model}",
            "-o",
            "{-o}",
        ],
        [
            "export",
            "--model",
            "{--model}",
            "--controller",
            "linuxcnc",
            "--comp-file",
            "B={--comp-file}",
        ],
    ],
    ("compensate",): [
        ["compensate", "--machine", "{--machine}", "--model", "{--model}", "-o", "{-o}"]
    ],
    ("virtual", "ballbar"): [
        ["virtual", "ballbar", "--machine", "{--machine}", "--truth", "{--truth}"]
    ],
    ("virtual", "rtest"): [
        ["virtual", "rtest", "--machine", "{--machine}", "--truth", "{--truth}"]
    ],
    ("record", "ballbar"): [
        [
            "record",
            "ballbar",
            "--machine",
            "{--machine}",
            "--port",
            "{--port}",
            "-o",
            "{-o}",
            "--silence",
            "0.1",
            "--no-progress",
        ]
    ],
    ("record", "rtest"): [
        [
            "record",
            "rtest",
            "--machine",
            "{--machine}",
            "--port",
            "{--port}",
            "-o",
            "{-o}",
            "--silence",
            "0.1",
            "--no-progress",
        ]
    ],
    ("report",): [["report", "{FILE}", "--history", "M1", "--db", "{--db}", "-o", "{-o}"]],
    ("circular", "plan"): [
        ["circular", "plan", "--machine", "{--machine}", "--session", "{--session}", "-o", "{-o}"]
    ],
    ("circular", "simulate"): [
        ["circular", "simulate", "--machine", "{--machine}", "--truth", "{--truth}", "-o", "{-o}"]
    ],
    ("circular", "virtual"): [
        ["circular", "virtual", "--machine", "{--machine}", "--truth", "{--truth}"]
    ],
    ("circular", "record"): [
        [
            "circular",
            "record",
            "--machine",
            "{--machine}",
            "--port",
            "{--port}",
            "-o",
            "{-o}",
            "--silence",
            "0.1",
            "--no-progress",
        ]
    ],
    ("circular", "analyze"): [["circular", "analyze", "{FILE}", "--plot", "{--plot}"]],
    **{
        ("batch", kind): [
            [
                "batch",
                kind,
                "{FILE}",
                "--budget-sizes",
                "{--budget-sizes}",
                "--results",
                "{--results}",
                "--store",
                "--db",
                "{--db}",
                "--no-progress",
            ]
        ]
        for kind in ("identify", "diagnose")
    },
}


def _subcommands(parser, words=()):
    """Every runnable command of the parser, as the words command_files.command_key makes of it
    (a positional kind or action with choices, as `plan ballbar` and `machines show`, counts)."""
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if subs:
        return [w for name, p in subs[0].choices.items() for w in _subcommands(p, words + (name,))]
    kinds = [a for a in parser._actions if a.dest in ("kind", "action") and a.choices]
    return [words + (c,) for c in kinds[0].choices] if kinds else [words]


def test_every_subcommand_has_a_row():
    missing = [w for w in _subcommands(cli.build_parser()) if w not in command_files.COMMANDS]
    assert not missing, f"commands without a row in command_files.COMMANDS: {missing}"


def _roles(key):
    files = command_files.COMMANDS[key]
    return {s.option for s in files.inputs}, {s.option for s in files.outputs}


@pytest.mark.parametrize("key", sorted(command_files.COMMANDS))
def test_every_file_option_of_a_writing_command_is_tried(key):
    files = command_files.COMMANDS[key]
    if not files.outputs and not files.writes_store(argparse.Namespace(store=True)):
        return  # reads only: nothing to overwrite
    ins, outs = _roles(key)
    tried = {m for t in TEMPLATES[key] for m in SLOT.findall(" ".join(t))}
    assert ins | outs <= tried, (
        f"{key}: options of the table not tried here: {sorted((ins | outs) - tried)}"
    )


@pytest.fixture(scope="module")
def sources(shared_data, tmp_path_factory):
    """Real files for each input option (content that the command would accept)."""
    d = tmp_path_factory.mktemp("inputs")
    session = d / "session.csv"
    session.write_bytes((shared_data / "ballbar_ac_table2.csv").read_bytes())
    rsession = d / "rtest.csv"
    rsession.write_bytes((shared_data / "rtest_bc_oyama.csv").read_bytes())
    model = d / "model.json"
    assert cli.main(["identify", str(session), "--no-budget", "--save-model", str(model)]) == 0
    machine = d / "machine.json"
    machine.write_text(load_machine("AC-trt").description_json)
    store = d / "history.sqlite"
    open_history(str(store)).close()
    hal = d / "current.hal"
    hal.write_text("setp pivot_length 0\n")
    empty = d / "empty.json"
    empty.write_text("{}\n")
    diag = d / "diagnosis.json"
    diag.write_text(json.dumps({"findings": []}))
    joints = d / "joints.csv"
    joints.write_text("x,y,z,tilt,rot\n10,20,30,40,50\n")
    port = d / "port"
    port.write_text("not a device\n")
    probe_plan = (
        d / "probe_plan.csv"
    )  # a touch-probe session as `import probe --plan` template, and its log
    probe_plan.write_bytes((shared_data / "probe_ac_table2.csv").read_bytes())
    probe = rotacal.load(probe_plan)
    design = d / "design.json"  # what `design probe --json` gives `plan probe --design`
    design.write_text(json.dumps({"poses_deg": [[0, 0], [0, 90], [-30, 180]]}))
    probe_log = d / "probe.log"
    probe_log.write_text(
        "".join(
            f"{k // 5 + 1} {k % 5 + 1} {x:f} {y:f} {z:f}\n"
            for k, (x, y, z) in enumerate(np.asarray(probe.xyz))
        )
    )
    return {
        "FILE": session,
        "SESSION": session,
        "--after": session,
        "--centres": rsession,
        "--model": model,
        "--compensate": model,
        "MODEL": model,
        "--machine": machine,
        "--db": store,
        "--controller": hal,
        "--current": hal,
        "--budget-sizes": empty,
        "--correction": empty,
        "--diagnosis": diag,
        "--joints": joints,
        "--port": port,
        "LOG": probe_log,
        "--plan": probe_plan,
        "--design": design,
    }


def _argv(template, paths):
    return [SLOT.sub(lambda m: str(paths[m.group(1)]), t) for t in template]


def _cases():
    """(key, template index, the output option, the option whose file it is given)."""
    out = []
    for key, templates in TEMPLATES.items():
        files = command_files.COMMANDS[key]
        ins, outs = _roles(key)
        for k, t in enumerate(templates):
            slots = SLOT.findall(" ".join(t))
            store_written = files.writes_store(argparse.Namespace(store=True))
            for o in (s for s in slots if s in outs):
                out += [(key, k, o, other) for other in slots if other != o]
            if store_written and "--db" in slots:
                out += [(key, k, "--db", i) for i in slots if i in ins]
    return out


@pytest.mark.parametrize("key,k,target,other", _cases())
def test_an_output_is_never_another_file_of_its_command(
    sources, tmp_path, capsys, monkeypatch, key, k, target, other
):
    monkeypatch.setattr(
        serial_link, "serve", lambda *a: 0
    )  # a virtual instrument not refused must not wait for a host
    template = TEMPLATES[key][k]
    ins, outs = _roles(key)
    paths = {
        s: sources[s] if s in ins or s == "--db" else tmp_path / f"out{n}{s.strip('-')}"
        for n, s in enumerate(SLOT.findall(" ".join(template)))
    }
    for s in paths:  # a private copy of every input, so a failure cannot spoil the next case
        if s in ins or s == "--db":
            copy = tmp_path / f"in.{s.strip('-')}.{sources[s].name}"
            copy.write_bytes(sources[s].read_bytes())
            paths[s] = copy
    paths[target] = paths[other]
    victim = paths[other]
    before = victim.read_bytes() if victim.exists() else None
    code = cli.main(_argv(template, paths))
    err = capsys.readouterr().err
    assert code == EXIT_IO, err
    assert str(victim) in err and target in err, err
    if before is not None:
        assert victim.read_bytes() == before
    else:
        assert not victim.exists()


def _output_cases():
    return [
        (key, k, o)
        for key, templates in TEMPLATES.items()
        for k, t in enumerate(templates)
        for o in SLOT.findall(" ".join(t))
        if o in _roles(key)[1]
    ]


@pytest.mark.parametrize("where", ["a directory", "a missing folder"])
@pytest.mark.parametrize("key,k,target", _output_cases())
def test_an_output_in_no_place_to_write_is_refused_first(
    sources, tmp_path, capsys, monkeypatch, key, k, target, where
):
    monkeypatch.setattr(serial_link, "serve", lambda *a: 0)
    template = TEMPLATES[key][k]
    ins, _ = _roles(key)
    paths = {
        s: sources[s] if s in ins or s == "--db" else tmp_path / f"out{n}{s.strip('-')}"
        for n, s in enumerate(SLOT.findall(" ".join(template)))
    }
    if where == "a directory":
        paths[target] = tmp_path / "a_folder"
        paths[target].mkdir()
    else:
        paths[target] = tmp_path / "no" / "such" / "out"
    code = cli.main(_argv(template, paths))
    err = capsys.readouterr().err
    assert code == EXIT_IO and target in err, err
    assert [p.name for p in tmp_path.iterdir()] in (["a_folder"], []), (
        "an output was written before the refusal"
    )


def test_simulate_rtest_default_truth_is_checked(sources, tmp_path, capsys):
    # -o m.csv writes its truth to m.truth.json: a machine description of that name is an input.
    machine = tmp_path / "m.truth.json"
    machine.write_bytes(sources["--machine"].read_bytes())
    before = machine.read_bytes()
    code = cli.main(["simulate", "rtest", "--machine", str(machine), "-o", str(tmp_path / "m.csv")])
    assert code == EXIT_IO, capsys.readouterr().err
    assert machine.read_bytes() == before and not (tmp_path / "m.csv").exists()


def test_separation_default_template_is_checked(sources, tmp_path, capsys):
    # design --separate -o s.ngc writes the added test's template to s.csv: the --after session
    # of that name is an input, never overwritten (issue 50).
    after = tmp_path / "s.csv"
    after.write_bytes(sources["--after"].read_bytes())
    before = after.read_bytes()
    code = cli.main(
        ["design", "ballbar", "--separate", "gravity_sag_A,gravity_sag_C", "--after", str(after)]
        + ["-o", str(tmp_path / "s.ngc")]
    )
    assert code == EXIT_IO, capsys.readouterr().err
    assert after.read_bytes() == before and not (tmp_path / "s.ngc").exists()


def test_postgresql_store_is_no_file(sources, tmp_path, capsys):
    # A URL names no file: it is neither refused as one nor compared with the outputs.
    files = command_files.COMMANDS[("report",)]
    a = cli.build_parser().parse_args(
        [
            "report",
            str(sources["FILE"]),
            "--history",
            "M1",
            "--db",
            "postgresql://u@localhost/x",
            "-o",
            str(tmp_path / "r.html"),
        ]
    )
    assert files.reads_store(a)
    command_files.check_command_files(a)  # does not raise


def test_devices_may_be_named_twice(sources, tmp_path):
    a = cli.build_parser().parse_args(
        ["simulate", "ballbar", "--truth", "/dev/null", "-o", "/dev/null"]
    )
    command_files.check_command_files(a)  # written through, never replaced: not refused


def test_builtin_machine_name_is_no_file(tmp_path, monkeypatch):
    # A built-in name wins over a file of that name (machines.load_machine): no input file then.
    monkeypatch.chdir(tmp_path)
    a = cli.build_parser().parse_args(["plan", "ballbar", "--machine", "AC-trt", "-o", "AC-trt"])
    command_files.check_command_files(a)
    assert rotacal.outputs.check_output("AC-trt") == "replace"
