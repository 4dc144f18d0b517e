# SPDX-License-Identifier: BSD-3-Clause
"""The ``rotacal`` command line: the parser built from the command modules, and ``main``,
which runs a command and turns every failure into a one-line message and its exit code.

Exit codes: 0 success; 2 usage error; 3 invalid input (a malformed file, a bad parameter, a
degenerate geometry, a request too large for the memory); 4 I/O error (cannot read or write a file or device); 5 any other
rotacal error.

Each command module holds ``COMMANDS``, {command: add(subparsers)}; an add returns the
subparsers of the command's kinds (``simulate ballbar|rtest``) or None. A module may also hold
``KINDS``, {command: add(kinds)}, to add its instrument's kind to another module's command
(``simulate probe``): listing the module in MODULES registers it.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Sequence

from .. import _core
from ..command_files import check_command_files
from . import (
    batch,
    circular,
    controller,
    demo,
    design,
    design_probe,
    diagnose,
    history,
    identify,
    instruments,
    machines,
    plan,
    probe,
    simulate,
    thermal,
    thermal_design,
    thermal_sim,
)
from .options import (
    EPILOG,
    EXIT_ERROR,
    EXIT_INPUT,
    EXIT_IO,
    EXIT_OK,
    EscapedOutput,
    OptionError,
    say,
)

MODULES = (
    plan,
    machines,
    simulate,
    identify,
    history,
    diagnose,
    design,
    controller,
    instruments,
    demo,
    circular,
    probe,
    design_probe,
    batch,
    thermal,
    thermal_sim,
    thermal_design,
)

# The order `rotacal --help` lists the commands in.
ORDER = (
    "plan",
    "machines",
    "simulate",
    "identify",
    "history",
    "diagnose",
    "predict",
    "design",
    "export",
    "compensate",
    "virtual",
    "record",
    "import",
    "report",
    "table2",
    "demo",
    "circular",
    "batch",
)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="rotacal",
        description="Calibration of the rotary axes of 5-axis machine tools.",
        epilog=EPILOG,
    )
    sub = p.add_subparsers(dest="command", required=True)
    adders = {name: add for m in MODULES for name, add in m.COMMANDS.items()}
    if set(adders) != set(ORDER):
        raise _core.Error(
            f"rotacal: commands {sorted(set(adders) ^ set(ORDER))} are not both in ORDER and a module"
        )
    for name in ORDER:
        kinds = adders[name](sub)
        extra = [m.KINDS[name] for m in MODULES if name in getattr(m, "KINDS", {})]
        for add in extra:
            add(kinds)
        if extra and kinds.metavar:
            kinds.metavar = "{" + ",".join(kinds.choices) + "}"
    return p


# Options whose values may start with '-' ("--a-range -90,90"): argparse would take the value
# for an option, so such pairs are joined as "--a-range=-90,90" before parsing.
_SIGNED_VALUE_OPTIONS = {
    "--a-range",
    "--sphere",
    "--b-range",
    "--tilt-range",
    "--c-range",
    "--axial-c-tilt",
    "--pivot",
    "--errors",
    "--nest",
    "--probe-dir",
    "--comp-range",
    "--travel",
    "--poses",
    "--pivot-z",
    "--centres-origin",
}


def _join_signed_values(argv: Sequence[str]) -> list[str]:
    out: list[str] = []
    it = iter(argv)
    for tok in it:
        if tok in _SIGNED_VALUE_OPTIONS:
            nxt = next(it, None)
            out.append(tok if nxt is None else f"{tok}={nxt}")
        else:
            out.append(tok)
    return out


def _message(e: BaseException, limit: int = 2000) -> str:
    """An error message fit for a terminal: bounded (a file's line may be megabytes long)."""
    text = str(e)
    return (
        text if len(text) <= limit else text[:limit] + f"... ({len(text) - limit} more characters)"
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code. Every failure ends in a one-line message
    and the documented code, never a traceback (ROTACAL_TRACEBACK=1 shows it for debugging)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    stdout = sys.stdout
    sys.stdout = EscapedOutput(stdout)  # file names and notes never drive the terminal
    try:
        return _run(argv)
    finally:
        sys.stdout = stdout


def _run(argv: list[str]) -> int:
    try:
        args = build_parser().parse_args(_join_signed_values(argv))
        check_command_files(args)  # every output against every input and output, before any work
        code = args.func(args)
        sys.stdout.flush()  # a reader that went away is seen here, inside the handlers below
        return code
    except (OptionError, _core.ParseError, _core.InvalidArgument, _core.DegenerateGeometry) as e:
        say(f"rotacal: error: {_message(e)}")
        return EXIT_INPUT
    except BrokenPipeError:  # `rotacal history show M | head`: the reader has what it wanted
        try:
            os.dup2(
                os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno()
            )  # no second error at exit
        except OSError:
            pass
        return EXIT_OK
    except MemoryError as e:  # a request too large for this machine (std::bad_alloc in C++)
        say(
            "rotacal: error: out of memory: the request is too large for this machine's memory "
            f"(reduce the number of touches, poses or candidates asked for){': ' + _message(e) if str(e) else ''}"
        )
        return EXIT_INPUT
    except UnicodeError as e:  # text that is not UTF-8 where the reader did not say so itself
        say(f"rotacal: error: input is not UTF-8 text: {_message(e)}")
        return EXIT_INPUT
    except (_core.IoError, OSError) as e:
        say(f"rotacal: error: {_message(e) or type(e).__name__}")
        return EXIT_IO
    except _core.Error as e:
        say(f"rotacal: error: {_message(e)}")
        return EXIT_ERROR
    except KeyboardInterrupt:
        say("rotacal: interrupted")
        return 130
    except Exception as e:  # a bug: say what and where, without a traceback
        if os.environ.get("ROTACAL_TRACEBACK"):
            raise
        tb = e.__traceback__
        while tb is not None and tb.tb_next is not None:
            tb = tb.tb_next
        where = f" at {Path(tb.tb_frame.f_code.co_filename).name}:{tb.tb_lineno}" if tb else ""
        say(f"rotacal: internal error ({type(e).__name__}{where}): {_message(e)}")
        return EXIT_ERROR
