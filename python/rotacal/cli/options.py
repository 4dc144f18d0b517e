# SPDX-License-Identifier: BSD-3-Clause
"""What every command of the CLI shares: the exit codes, the epilog that states them, the
message line on stderr, and one argparse type per kind of option value.

A bad value raises OptionError (exit 3, the option named); argparse would turn a ValueError
into a usage error (exit 2), so OptionError is not one.
"""

from __future__ import annotations

import math
import sys
from typing import Any, Callable, Sequence

from .. import _core
from ..sessions import checked_path

EXIT_OK, EXIT_USAGE, EXIT_INPUT, EXIT_IO, EXIT_ERROR = 0, 2, 3, 4, 5

EPILOG = (
    "exit codes: 0 success, 2 usage error, 3 invalid input (malformed file, bad parameter, "
    "degenerate geometry, a request too large for the memory), 4 I/O error, 5 other rotacal error"
)


def terminal_text(text: str, keep: str = " ") -> str:
    """``text`` with its control characters (escape sequences, line ends, C1) as \\xNN, as the
    C++ messages show a bad line: a file name or a note read from a file never drives the
    terminal. Characters in ``keep`` stay as they are."""
    return "".join(
        c
        if c.isprintable() or c in keep
        else f"\\x{ord(c):02X}"
        if ord(c) < 256
        else f"\\u{ord(c):04X}"
        for c in text
    )


def shell_word(text: str) -> str:
    """One word of a suggested command, quoted for a POSIX shell (and shown escaped)."""
    import shlex

    return terminal_text(shlex.quote(str(text)))


class EscapedOutput:
    """A text stream whose writes go through terminal_text, line ends and tabs kept: what a
    command prints names files and quotes notes, which may hold any byte."""

    def __init__(self, inner: Any) -> None:
        self._inner = inner

    def write(self, text: str) -> int:
        return self._inner.write(terminal_text(text, keep=" \n\t"))

    def __getattr__(self, name: str) -> Any:
        return getattr(self._inner, name)


def say(msg: str) -> None:
    """One line for the user on stderr (stdout carries the results), its control characters
    escaped (terminal_text)."""
    print(terminal_text(msg), file=sys.stderr, flush=True)


class OptionError(Exception):
    """An option value that is not acceptable; the message names the option."""


def number(
    option: str, lo: float, hi: float, unit: str = "", integer: bool = False, lo_open: bool = False
) -> Callable[[str], float]:
    """argparse type: a finite number in [lo, hi] (or (lo, hi] with lo_open)."""

    def parse(text: str) -> float:
        try:
            v = int(text, 10) if integer else float(text)
        except ValueError:
            raise OptionError(
                f"{option}: '{text[:40]}' is not {'an integer' if integer else 'a number'}"
            ) from None
        if not math.isfinite(v) or v > hi or v < lo or (lo_open and v == lo):
            rng = f"{'(' if lo_open else '['}{lo:g}, {hi:g}]"
            raise OptionError(f"{option}: {text[:40]} is outside {rng}{' ' + unit if unit else ''}")
        return v

    return parse


def numbers(option: str, n: int, limit: float, unit: str = "") -> Callable[[str], list[float]]:
    """argparse type: n comma-separated finite numbers, each within +-limit."""

    def parse(text: str) -> list[float]:
        try:
            vals = [float(v) for v in text.split(",")]
        except ValueError:
            raise OptionError(
                f"{option}: '{text[:60]}' is not {n} comma-separated numbers"
            ) from None
        if len(vals) != n or not all(math.isfinite(v) for v in vals):
            raise OptionError(f"{option}: '{text[:60]}' must be {n} finite comma-separated numbers")
        if any(abs(v) > limit for v in vals):
            raise OptionError(
                f"{option}: '{text[:60]}': each value must be within +-{limit:g} {unit}".rstrip()
            )
        return vals

    return parse


def number_list(
    option: str, lo: float, hi: float, unit: str = "", most: int = 50
) -> Callable[[str], list[float]]:
    """argparse type: 1 to `most` comma-separated finite numbers, each in [lo, hi]."""

    def parse(text: str) -> list[float]:
        try:
            vals = [float(v) for v in text.split(",")]
        except ValueError:
            raise OptionError(
                f"{option}: '{text[:60]}' is not a comma-separated list of numbers"
            ) from None
        if not 1 <= len(vals) <= most or not all(math.isfinite(v) and lo <= v <= hi for v in vals):
            raise OptionError(
                f"{option}: '{text[:60]}': 1 to {most} values, each in [{lo:g}, {hi:g}] {unit}".rstrip()
            )
        return vals

    return parse


def path(option: str) -> Callable[[str], str]:
    """argparse type: a file name (not empty, no NUL byte)."""

    def parse(text: str) -> str:
        try:
            return checked_path(text, option)
        except _core.InvalidArgument as e:
            raise OptionError(str(e)) from None

    return parse


SEED = number("--seed", 0, 2**32 - 1, integer=True)


def axis_values(
    option: str, keys: Sequence[str], lo: float, hi: float, per_key: int = 1
) -> Callable[[str], dict]:
    """argparse type: KEY=V[,KEY=V...] (per_key 2: KEY=A:B) with KEY in keys, each V in [lo, hi]."""

    def parse(text: str) -> dict:
        out: dict = {}
        for item in text.split(","):
            key, eq, val = item.partition("=")
            key = key.strip().upper() if all(c.isalpha() for c in key.strip()) else key.strip()
            if not eq or key not in keys:
                raise OptionError(
                    f"{option}: '{item[:40]}' must be KEY=VALUE with KEY in {', '.join(keys)}"
                )
            try:
                vals = [float(v) for v in val.split(":")]
            except ValueError:
                raise OptionError(f"{option}: '{item[:40]}' is not a number") from None
            if len(vals) != per_key or not all(math.isfinite(v) and lo <= v <= hi for v in vals):
                form = "A:B" if per_key == 2 else "V"
                raise OptionError(
                    f"{option}: '{item[:40]}': {key}={form}, each in [{lo:g}, {hi:g}]"
                )
            out[key] = vals if per_key > 1 else vals[0]
        return out

    return parse


def names(option: str, known: Sequence[str]) -> Callable[[str], list[str]]:
    """argparse type: a comma-separated list of names out of `known` (either case)."""

    def parse(text: str) -> list[str]:
        vals = [v.strip() for v in text.split(",") if v.strip()]
        bad = [v for v in vals if v not in known and v.upper() not in known]
        if not vals or bad:
            raise OptionError(
                f"{option}: '{text[:40]}': a comma-separated list of {', '.join(known)}"
            )
        return vals

    return parse


def float_list_item(option: str, text: str) -> float:
    """One number of a comma-separated option; refused by name (the plan checks its range)."""
    try:
        return float(text.strip())
    except ValueError:
        raise _core.InvalidArgument(f"{option}: '{text.strip()}' is not a number") from None


def effects_option(items: Sequence[str] | None) -> dict[str, list[float]]:
    """--effect ID=P1,P2 (repeatable) -> {id: [values]}, counts checked against the catalogue."""
    out: dict[str, list[float]] = {}
    for item in items or []:
        key, _, val = item.partition("=")
        eff = _core.Effect(key.strip())
        out[eff.id] = numbers(f"--effect {key.strip()}", eff.num_params, 1e3)(val)
    return out


def errors_option(text: str) -> Any:
    """--errors: random, zero, table2 or NAME=VALUE,... (mm, rad); the names are checked
    against the machine by machines.location_errors."""
    if text in ("random", "zero", "table2"):
        return text
    out: dict[str, float] = {}
    for item in text.split(","):
        key, _, val = item.partition("=")
        out[key.strip()] = numbers(f"--errors {key.strip()}", 1, 10.0)(val)[0]
    return out


def json_object(path: str, option: str) -> tuple[dict, str]:
    """(object, sha256 of the bytes) of a JSON file: strict, bounded (jsonfile), errors naming it."""
    import hashlib
    from ..exports import MAX_CURRENT_BYTES
    from ..jsonfile import read_json

    doc, data = read_json(
        path, option, 64 * MAX_CURRENT_BYTES
    )  # a diagnosis of a long recording is large
    if not isinstance(doc, dict):
        raise _core.InvalidArgument(f"{option} {path}: expected a JSON object")
    return doc, hashlib.sha256(data).hexdigest()


def budget_sizes(path: str | None) -> dict | None:
    """The --budget-sizes object, read once (bounded) and checked before any work; the budget
    then takes the object (a second reading of the file was refused: issue 32)."""
    if not path:
        return None
    from ..diagnosis import plausible_sizes

    doc, _ = json_object(path, "--budget-sizes")
    try:
        plausible_sizes(doc)
    except _core.InvalidArgument as e:
        raise _core.InvalidArgument(f"--budget-sizes {path}: {e}") from None
    return doc


def controller_text(path: str | None) -> str | None:
    """--controller: the controller parameters active during the test, as the text of their file."""
    if path is None:
        return None
    from ..exports import read_current

    return read_current(path)
