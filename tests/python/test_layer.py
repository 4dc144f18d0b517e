# SPDX-License-Identifier: BSD-3-Clause
"""The Python layer's seams: one dispatch on the session kind, options laid over the C++
defaults, no import cycle in the package, a library that never imports the command line, and
a CLI that draws only when asked."""

import ast
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rotacal
from rotacal import _core, machines, sessions
from rotacal.diagnosis import diagnosis_options

PACKAGE = Path(rotacal.__file__).parent


def _imports(module: str) -> set[str]:
    tree = ast.parse((PACKAGE / f"{module}.py").read_text())
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            out |= {node.module} if node.module else {a.name for a in node.names}
    return out


def test_ballbar_and_rtest_do_not_import_each_other():
    assert "rtest" not in _imports("ballbar")
    assert "ballbar" not in _imports("rtest")


def _module_files() -> dict[str, tuple[Path, bool]]:
    """Every module of the package, subpackages included: dotted name -> (file, is a package)."""
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = ["rotacal", *path.relative_to(PACKAGE).with_suffix("").parts]
        is_package = parts[-1] == "__init__"
        out[".".join(parts[:-1] if is_package else parts)] = (path, is_package)
    return out


def _import_graph() -> dict[str, set[str]]:
    """module -> the modules of the package it imports (relative or absolute, at the top or
    inside a function: a lazy import closes a circle as well). ``from . import x`` is an edge
    to the module x when there is one, else to the package that defines the name."""
    mods = _module_files()
    known = set(mods) | {"rotacal._core"}
    graph = {}
    for mod, (path, is_package) in mods.items():
        here = mod.split(".") if is_package else mod.split(".")[:-1]
        out = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                out |= {a.name for a in node.names if a.name.split(".")[0] == "rotacal"}
                continue
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level:
                base = here[: len(here) - node.level + 1]
            elif node.module and node.module.split(".")[0] == "rotacal":
                base = []
            else:
                continue
            target = ".".join(base + (node.module.split(".") if node.module else []))
            if node.module:
                out.add(target)
            for alias in node.names:
                if f"{target}.{alias.name}" in known:
                    out.add(f"{target}.{alias.name}")
                elif not node.module:
                    out.add(target)
        graph[mod] = {m for m in out if m in mods and m != mod}
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while not comp or comp[-1] != v:
                comp.append(stack.pop())
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    return out


def test_the_package_has_no_import_cycle():
    graph = _import_graph()
    assert (
        "rotacal.diagnosis" in graph["rotacal.analysis"]
        and "rotacal.sessions" in graph["rotacal.diagnosis"]
    )
    readers = {m for m, targets in graph.items() if "rotacal" in targets}
    assert not readers, f"modules importing the package facade: {sorted(readers)}"
    assert _cycles(graph) == []


def test_the_library_never_imports_the_command_line():
    cli = {m for m in _module_files() if m == "rotacal.cli" or m.startswith("rotacal.cli.")}
    entry = {"rotacal.__main__"}  # `python -m rotacal`: the command line's own entry point
    importers = {
        m for m, targets in _import_graph().items() if targets & cli and m not in cli | entry
    }
    assert not importers, f"library modules importing rotacal.cli: {sorted(importers)}"


def test_the_session_kind_is_told_in_one_place():
    for path in PACKAGE.rglob("*.py"):
        assert not re.search(r"isinstance\([^)]*Session", path.read_text()), path.name


def test_by_kind(shared_data):
    b = rotacal.load(shared_data / "ballbar_ac_table2.csv")
    r = rotacal.load(shared_data / "rtest_bc_oyama.csv")
    assert sessions.kind(b) == "ballbar" and sessions.kind(r) == "rtest"
    with pytest.raises(
        rotacal.InvalidArgument, match="needs a rotacal-ballbar/1 session, this is rotacal-rtest/1"
    ):
        sessions.by_kind(r, {"ballbar": 1}, "report")
    with pytest.raises(rotacal.InvalidArgument, match="not a session: str"):
        rotacal.diagnose("ballbar_ac_table2.csv")
    with pytest.raises(rotacal.InvalidArgument, match="takes only `method`"):
        rotacal.identify(r, effects=["gravity_sag_B"])


def test_diagnosis_options_lie_over_the_cpp_defaults():
    cpp = _core.DiagnosisOptions()
    o = diagnosis_options(max_findings=2, alpha=None)
    assert o.max_findings == 2 and o.alpha == cpp.alpha and o.max_harmonic == cpp.max_harmonic
    with pytest.raises(rotacal.InvalidArgument, match="unknown option 'max_harmonics'"):
        diagnosis_options(max_harmonics=3)
    for bad in (0, -1, 100000, 2.5):
        with pytest.raises(rotacal.InvalidArgument, match="max_harmonic"):
            diagnosis_options(max_harmonic=bad)


def test_cli_setup_defaults_are_the_cpp_ones():
    from rotacal.cli import build_parser
    from rotacal.cli.setups import ballbar_setup as _setup

    a = build_parser().parse_args(["plan", "ballbar", "-o", "x.ngc"])
    s, cpp = _setup(a), _core.BallbarSetup()
    assert s.ballbar_length == cpp.ballbar_length and np.allclose(s.pivot, cpp.pivot)
    assert s.step_deg == cpp.step_deg and list(s.tilt_range_deg) == list(cpp.tilt_range_deg)
    assert list(s.rot_range_deg) == [
        0.0,
        359.0,
    ]  # the CLI's own C range (one step short of the turn)


def test_truth_draws_random_errors_then_the_pivot_error():
    a = machines.ballbar_truth(rotacal.MachineType.AC_trt, "random", seed=5)
    b = machines.ballbar_truth(rotacal.MachineType.AC_trt, "zero", seed=5)
    rng = np.random.default_rng(5)
    errors = machines.random_location_errors(rotacal.MachineType.AC_trt, rng)
    assert np.allclose(list(a["errors"].values()), errors)
    assert np.allclose(a["pivot_error"], rng.normal(0.0, machines.PIVOT_ERROR_MM, 3))
    assert (
        b["pivot_error"]
        == np.random.default_rng(5).normal(0.0, machines.PIVOT_ERROR_MM, 3).tolist()
    )
    t2 = machines.ballbar_truth(rotacal.MachineType.AC_trt, "table2")
    assert t2["errors"] == machines.TABLE2_ERRORS
    with pytest.raises(rotacal.InvalidArgument, match="table2 is the paper's AC-trt"):
        machines.ballbar_truth(rotacal.MachineType.BC_trt, "table2")
    with pytest.raises(rotacal.InvalidArgument, match="E_Y0A"):
        machines.ballbar_truth(rotacal.MachineType.BC_trt, {"E_Y0A": 0.1})


def test_identify_does_not_load_matplotlib(shared_data):
    r = subprocess.run(
        [
            sys.executable,
            "-X",
            "importtime",
            "-m",
            "rotacal",
            "identify",
            str(shared_data / "ballbar_ac_table2.csv"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0 and "rotacal.cli" in r.stderr
    assert "matplotlib" not in r.stderr


def test_a_module_adds_its_kind_to_another_modules_command(monkeypatch):
    # The seam a new instrument uses (`simulate probe`): a module with KINDS listed in MODULES.
    import types

    from rotacal.cli import parser

    def add(kinds):
        k = kinds.add_parser("gauge", help="a made-up instrument")
        k.add_argument("-o", "--output", required=True)
        k.set_defaults(func=lambda a: 0)

    extra = types.SimpleNamespace(COMMANDS={}, KINDS={"simulate": add})
    monkeypatch.setattr(parser, "MODULES", parser.MODULES + (extra,))
    p = parser.build_parser()
    assert p.parse_args(["simulate", "gauge", "-o", "x"]).kind == "gauge"
    assert "{ballbar,rtest,probe,thermal,gauge}" in _subparser(p, "simulate").format_help()
    assert p.parse_args(["simulate", "rtest", "-o", "x.csv"]).kind == "rtest"


def _subparser(p, name):
    return next(a for a in p._actions if a.dest == "command").choices[name]
