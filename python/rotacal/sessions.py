"""Session files, and the one place that tells a ballbar session from an R-test session."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable, Mapping, TypeVar, Union

from . import _core

Session = Union[_core.BallbarSession, _core.RtestSession]

BALLBAR, RTEST = "ballbar", "rtest"
FORMATS = {BALLBAR: "rotacal-ballbar/1", RTEST: "rotacal-rtest/1"}
_KINDS = {_core.BallbarSession: BALLBAR, _core.RtestSession: RTEST}
_WRITERS = {BALLBAR: _core.write_ballbar, RTEST: _core.write_rtest}

T = TypeVar("T")


def kind(session: Any) -> str:
    """"ballbar" or "rtest"; InvalidArgument for anything that is not a session."""
    k = _KINDS.get(type(session))
    if k is None:
        raise _core.InvalidArgument(f"not a session: {type(session).__name__} (BallbarSession or RtestSession)")
    return k


def by_kind(session: Any, table: Mapping[str, T], what: str) -> T:
    """``table[kind(session)]``: how each command handles each kind of session, in one lookup.
    A kind the table lacks is refused naming the format the command needs."""
    k = kind(session)
    if k not in table:
        needs = " or ".join(FORMATS[t] for t in table)
        raise _core.InvalidArgument(f"{what}: needs a {needs} session, this is {FORMATS[k]}")
    return table[k]


def require(session: Any, wanted: str, what: str) -> Any:
    """The session itself if it is of kind ``wanted``, else InvalidArgument naming ``what``."""
    by_kind(session, {wanted: None}, what)
    return session


def checked_path(path: Any, what: str = "path") -> str:
    """``path`` as a string, refusing what no file system path can be: None, a non-path, an
    empty name or one with a NUL byte (which C would cut short and open another file)."""
    if isinstance(path, bytes) or not isinstance(path, (str, os.PathLike)):
        raise _core.InvalidArgument(f"{what}: expected a file path, got {type(path).__name__}")
    s = os.fspath(path)
    if not isinstance(s, str):
        raise _core.InvalidArgument(f"{what}: expected a file path, got {type(s).__name__}")
    if s == "":
        raise _core.InvalidArgument(f"{what}: empty file name")
    if "\x00" in s:
        raise _core.InvalidArgument(f"{what}: {s.split(chr(0))[0]!r}...: a file name cannot contain a NUL byte")
    return s


def load(path: str | Path) -> Session:
    """Read a ``rotacal-ballbar/1`` or ``rotacal-rtest/1`` file.

    Raises rotacal.ParseError naming file, line and column for a malformed file, and
    rotacal.IoError if it cannot be read.
    """
    return _core.read_session(checked_path(path, "load"))


def save(session: Session, path: str | Path) -> None:
    """Write a session (atomically: a temporary file renamed over ``path``)."""
    writer: Callable[[Any, str], None] = _WRITERS[kind(session)]
    writer(session, checked_path(path, "save"))
