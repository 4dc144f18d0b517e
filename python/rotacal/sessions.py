"""Reading and writing session files."""
from __future__ import annotations

from pathlib import Path
from typing import Union

from . import _core

Session = Union[_core.BallbarSession, _core.RtestSession]


def load(path: str | Path) -> Session:
    """Read a ``rotacal-ballbar/1`` or ``rotacal-rtest/1`` file.

    Raises rotacal.ParseError naming file, line and column for a malformed file, and
    rotacal.IoError if it cannot be read.
    """
    return _core.read_session(str(path))


def save(session: Session, path: str | Path) -> None:
    """Write a session (atomically: a temporary file renamed over ``path``)."""
    if isinstance(session, _core.BallbarSession):
        _core.write_ballbar(session, str(path))
    elif isinstance(session, _core.RtestSession):
        _core.write_rtest(session, str(path))
    else:
        raise _core.InvalidArgument(f"save: not a session: {type(session).__name__}")
