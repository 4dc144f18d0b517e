# SPDX-License-Identifier: BSD-3-Clause
"""The files every command reads and writes, in one table, and the output rule checked on
all of them in one place, before any work (README, exit codes: an output that is one of
the inputs is a file-system error, exit 4).

Each output is first checked by the output rule itself (:func:`rotacal.outputs.check_output`:
a directory, a missing folder, a file that may not be written), then compared with every
input, every other output and the history store: the same file (same device and inode, or
the same canonical path for files that do not exist yet) is refused with both options named.
A character device or FIFO output (``-o /dev/null``, a pipe) is written through, never
replaced, and so may be named twice. A history store that the command writes may not be any
of its inputs or outputs either. A new command needs its row here: the tests check that every
subcommand of the parser has one.
"""

from __future__ import annotations

import argparse
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

from . import _core
from .outputs import check_output

Getter = Callable[[argparse.Namespace], Sequence[str]]


@dataclass(frozen=True)
class Slot:
    """One option (or positional) of a command that names files."""

    option: str  # as the user writes it: "--model", "-o", "FILE"
    paths: Getter


def arg(option: str, dest: str | None = None) -> Slot:
    """The file(s) of an option; a repeated option gives a list."""
    name = dest or option.lstrip("-").replace("-", "_")

    def get(a: argparse.Namespace) -> Sequence[str]:
        v = getattr(a, name, None)
        if v is None:
            return []
        return [p for p in (v if isinstance(v, list) else [v]) if p]

    return Slot(option, get)


def _machine_file(a: argparse.Namespace) -> Sequence[str]:
    """--machine NAME|FILE: a file unless it is a built-in name (a built-in wins, machines.load_machine)."""
    m = getattr(a, "machine", None)
    return [] if not m or m in _core.builtin_machine_names() else [m]


def _comp_files(a: argparse.Namespace) -> Sequence[str]:
    """export --comp-file AXIS=FILE (repeatable); malformed values are refused by the command."""
    return [f for f in (t.partition("=")[2] for t in a.comp_file or []) if f]


def rtest_truth_path(a: argparse.Namespace) -> str:
    """Where `simulate rtest` writes its truth: --truth, else FILE.truth.json beside -o."""
    return a.truth if a.truth else str(Path(a.output).with_suffix(".truth.json"))


def separation_template_path(a: argparse.Namespace) -> str | None:
    """Where `design ballbar|rtest|probe` writes a session template: --session, else with --separate
    beside -o with the suffix .csv (added.ngc -> added.csv: the added test's program and
    template go together, issue 50); None without either."""
    if getattr(a, "session", None):
        return a.session
    if getattr(a, "separate", None) and getattr(a, "output", None):
        return str(Path(a.output).with_suffix(".csv"))
    return None


TEMPLATE = Slot("--session", lambda a: [p for p in [separation_template_path(a)] if p])
MACHINE = Slot("--machine", _machine_file)
OUTPUT = arg("-o", "output")


@dataclass(frozen=True)
class Files:
    """What a command reads (inputs), writes by the output rule (outputs), and whether it
    reads or writes the history store (--db, default $ROTACAL_HISTORY or the user's store)."""

    inputs: tuple[Slot, ...] = ()
    outputs: tuple[Slot, ...] = ()
    reads_store: Callable[[argparse.Namespace], bool] = lambda a: False
    writes_store: Callable[[argparse.Namespace], bool] = lambda a: False


def _always(a: argparse.Namespace) -> bool:
    return True


# Keyed by the words of the command: (command,) or (command, kind|action).
COMMANDS: dict[tuple[str, ...], Files] = {
    ("plan", "ballbar"): Files((MACHINE, arg("--compensate")), (OUTPUT, arg("--session"))),
    ("plan", "probe"): Files((MACHINE, arg("--design")), (OUTPUT, arg("--session"))),
    ("plan", "thermal"): Files((MACHINE,), (OUTPUT, arg("--session"))),
    ("machines", "list"): Files(),
    ("machines", "show"): Files((arg("NAME|FILE", "machine"),)),
    ("simulate", "ballbar"): Files((MACHINE,), (OUTPUT, arg("--truth"))),
    ("simulate", "rtest"): Files(
        (MACHINE,), (OUTPUT, Slot("--truth", lambda a: [rtest_truth_path(a)]))
    ),
    ("simulate", "probe"): Files((MACHINE,), (OUTPUT, arg("--truth"))),
    ("simulate", "thermal"): Files((MACHINE,), (OUTPUT, arg("--truth"))),
    ("identify",): Files(
        (arg("FILE", "file"), arg("--budget-sizes"), arg("--controller")),
        (arg("--save-model"),),
        writes_store=lambda a: bool(a.store),
    ),
    ("history", "add"): Files(
        (arg("MODEL", "model"), arg("--correction"), arg("--diagnosis"), arg("--controller")),
        writes_store=_always,
    ),
    ("history", "show"): Files(outputs=(arg("--plot"),), reads_store=_always),
    ("history", "list"): Files(reads_store=_always),
    ("diagnose",): Files((arg("FILE", "file"), arg("--budget-sizes")), (arg("--report"),)),
    ("predict",): Files((arg("SESSION", "session"), arg("--model"), arg("--joints")), (OUTPUT,)),
    ("design", "ballbar"): Files((MACHINE, arg("--after")), (OUTPUT, TEMPLATE)),
    ("design", "rtest"): Files((arg("--after"),), (TEMPLATE,)),
    ("design", "probe"): Files((MACHINE, arg("--after")), (OUTPUT, TEMPLATE)),
    ("design", "thermal"): Files((MACHINE,)),
    ("export",): Files(
        (arg("--model"), arg("--current"), arg("--centres")),
        (
            OUTPUT,
            arg("--residual-model"),
            arg("--centres-output"),
            Slot("--comp-file", _comp_files),
        ),
    ),
    # Without --model nothing is written (-o has a default): --verify alone prints.
    ("compensate",): Files(
        (MACHINE, arg("--model")), (Slot("-o", lambda a: [a.output] if a.model else []),)
    ),
    ("virtual", "ballbar"): Files((MACHINE,), (arg("--truth"),)),
    ("virtual", "rtest"): Files((MACHINE,), (arg("--truth"),)),
    ("record", "ballbar"): Files((MACHINE, arg("--port")), (OUTPUT,)),
    ("record", "rtest"): Files((MACHINE, arg("--port")), (OUTPUT,)),
    ("import", "probe"): Files((arg("LOG", "log"), arg("--plan")), (OUTPUT,)),
    ("report",): Files((arg("FILE", "file"),), (OUTPUT,), reads_store=lambda a: bool(a.history)),
    ("table2",): Files((arg("--table"),)),
    ("demo",): Files(),  # -o is a folder of its own files; the command reads none
    ("circular", "plan"): Files((MACHINE,), (OUTPUT, arg("--session"))),
    ("circular", "simulate"): Files((MACHINE,), (OUTPUT, arg("--truth"))),
    ("circular", "virtual"): Files((MACHINE,), (arg("--truth"),)),
    ("circular", "record"): Files((MACHINE, arg("--port")), (OUTPUT,)),
    ("circular", "analyze"): Files((arg("FILE", "file"),), (arg("--plot"),)),
    ("batch", "identify"): Files(
        (arg("FILE", "file"), arg("--budget-sizes")),
        (arg("--results"),),
        writes_store=lambda a: bool(a.store),
    ),
    ("batch", "diagnose"): Files(
        (arg("FILE", "file"), arg("--budget-sizes")),
        (arg("--results"),),
        writes_store=lambda a: bool(a.store),
    ),
}


def command_key(a: argparse.Namespace) -> tuple[str, ...]:
    return tuple(w for w in (a.command, getattr(a, "kind", None), getattr(a, "action", None)) if w)


def _store(a: argparse.Namespace) -> list[tuple[str, str]]:
    """The history store as a file, or nothing for a postgresql:// URL."""
    from .history import default_location

    loc = getattr(a, "db", None) or default_location()
    return [] if "://" in loc else [("--db", loc)]


def _identity(path: str) -> tuple:
    """What makes two paths the same file: device and inode if it exists, else the canonical path."""
    real = os.path.realpath(path)
    try:
        st = os.stat(real)
    except (OSError, ValueError):
        return ("path", real)
    return ("inode", st.st_dev, st.st_ino)


def _refuse_same(path: str, option: str, others: Sequence[tuple[str, str]], what: str) -> None:
    me = _identity(path)
    for other_option, other in others:
        if _identity(other) == me:
            raise _core.IoError(
                f"{option} {path}: is also the command's {other_option} ({other}): {what}"
            )


def check_command_files(a: argparse.Namespace) -> None:
    """Refuse, before any work, an output the output rule refuses or that is one of the
    command's inputs, another of its outputs or the history store it uses. IoError (exit 4)."""
    key = command_key(a)
    if key not in COMMANDS:
        raise _core.Error(
            f"rotacal {' '.join(key)}: no row in command_files.COMMANDS (a new command?)"
        )
    files = COMMANDS[key]
    inputs = [(s.option, p) for s in files.inputs for p in s.paths(a)]
    outputs = [(s.option, p) for s in files.outputs for p in s.paths(a)]
    written_store = _store(a) if files.writes_store(a) else []
    if files.reads_store(a):
        inputs += _store(a)
    for k, (option, p) in enumerate(outputs):
        try:
            kind = check_output(p)
        except _core.IoError as e:
            raise _core.IoError(f"{option}: {e}") from None
        if kind == "write-through":
            continue  # a device or FIFO is never replaced: /dev/null may be named twice
        _refuse_same(p, option, inputs + written_store, "refusing to overwrite it")
        _refuse_same(
            p, option, outputs[:k] + outputs[k + 1 :], "two outputs of one command in one file"
        )
    for option, p in written_store:
        _refuse_same(p, option, inputs, "refusing to write the history store over it")
