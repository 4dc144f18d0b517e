# SPDX-License-Identifier: BSD-3-Clause
"""Session files, and the one place that tells a ballbar, an R-test and a touch-probe session apart."""

from __future__ import annotations

import codecs
import os
import tempfile
from pathlib import Path
from typing import Any, Iterable, Mapping, TypeVar, Union

from . import _core
from .outputs import write_output

Session = Union[_core.BallbarSession, _core.RtestSession, _core.ProbeSession]

BALLBAR, RTEST, PROBE = "ballbar", "rtest", "probe"
FORMATS = {BALLBAR: "rotacal-ballbar/1", RTEST: "rotacal-rtest/1", PROBE: "rotacal-probe/1"}
_KINDS = {_core.BallbarSession: BALLBAR, _core.RtestSession: RTEST, _core.ProbeSession: PROBE}
_FORMATTERS = {BALLBAR: _core.format_ballbar, RTEST: _core.format_rtest, PROBE: _core.format_probe}
_READERS = {BALLBAR: _core.read_ballbar, RTEST: _core.read_rtest, PROBE: _core.read_probe}
# Labels of each kind: reading them converts every one to Python text.
_LABELS = {BALLBAR: "tests", RTEST: "setups", PROBE: "poses"}
# How far into a file the search for the first byte that is not UTF-8 goes.
_SCAN_LIMIT = 256 << 20

T = TypeVar("T")


def kind(session: Any) -> str:
    """ "ballbar", "rtest" or "probe"; InvalidArgument for anything that is not a session."""
    k = _KINDS.get(type(session))
    if k is None:
        raise _core.InvalidArgument(
            f"not a session: {type(session).__name__} (BallbarSession, RtestSession or "
            "ProbeSession)"
        )
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
        raise _core.InvalidArgument(
            f"{what}: {s.split(chr(0))[0]!r}...: a file name cannot contain a NUL byte"
        )
    return s


def first_non_utf8(path: str, limit: int = _SCAN_LIMIT) -> tuple[int, int, int] | None:
    """(line, column, byte) of the first byte of ``path`` that is not UTF-8, both counted from 1
    (the column in bytes); None if the first ``limit`` bytes are UTF-8. Reads the file once
    (it may be a device that gives other bytes the next time)."""
    decoder = codecs.getincrementaldecoder("utf-8")()
    newlines, line_start, offset = 0, 0, 0
    with open(path, "rb") as f:
        while offset < limit:
            chunk = f.read(1 << 16)
            if not chunk:
                return None
            try:
                decoder.decode(chunk)
            except UnicodeDecodeError as e:
                data = (
                    e.object
                )  # the bytes held back from the last chunk (never a newline) + this chunk
                base = offset - (len(data) - len(chunk))
                nl = data.rfind(b"\n", 0, e.start)
                if nl >= 0:
                    line_start = base + nl + 1
                line = newlines + data.count(b"\n", 0, e.start) + 1
                return line, base + e.start - line_start + 1, data[e.start]
            newlines += chunk.count(b"\n")
            nl = chunk.rfind(b"\n")
            if nl >= 0:
                line_start = offset + nl + 1
            offset += len(chunk)
    return None


def _is_utf16(path: str) -> bool:
    if not os.path.isfile(path):  # a FIFO would block, a device give other bytes
        return False
    try:
        with open(path, "rb") as f:
            return f.read(2) in (b"\xff\xfe", b"\xfe\xff")
    except OSError:
        return False


def _not_utf8(path: str) -> _core.Error:
    """The parse error of a file that is not UTF-8 text, naming file, line and column (a
    regular file: a FIFO cannot be read again, a device gives other bytes)."""
    if not os.path.isfile(path):
        return _core.ParseError(f"{path}: not UTF-8 text (session files are UTF-8 text)")
    try:
        with open(path, "rb") as f:
            head = f.read(4)
        where = first_non_utf8(path)
    except OSError as e:
        return _core.IoError(f"{path}: {e.strerror}")
    if head[:2] in (b"\xff\xfe", b"\xfe\xff"):
        return _core.ParseError(
            f"{path}:1:1: the file is UTF-16 text; rotacal reads UTF-8 (save it as UTF-8)"
        )
    if where is None:
        return _core.ParseError(f"{path}: not UTF-8 text")
    line, col, byte = where
    return _core.ParseError(
        f"{path}:{line}:{col}: byte 0x{byte:02X} is not UTF-8 (session files are UTF-8 text)"
    )


def load(path: str | Path, format: str | None = None) -> Session:
    """Read a ``rotacal-ballbar/1``, ``rotacal-rtest/1`` or ``rotacal-probe/1`` file, chosen by its
    format line, or by ``format`` ("ballbar", "rtest", "probe" or the format's name), which the
    file must then be.

    Raises rotacal.ParseError naming file, line and column for a malformed file (bytes that
    are not UTF-8 included), and rotacal.IoError if it cannot be read.
    """
    p = checked_path(path, "load")
    if os.path.isdir(p):
        raise _core.IoError(f"{p}: is a directory, not a session file")
    wanted = None
    if format is not None:
        wanted = {v: k for k, v in FORMATS.items()}.get(format, format)
        if wanted not in _READERS:
            raise _core.InvalidArgument(
                f"load: format must be one of {', '.join(FORMATS)} (or "
                f"{', '.join(FORMATS.values())}), got {format!r}"
            )
    try:
        session = _READERS[wanted](p) if wanted else _core.read_instrument_session(p)
        getattr(session, _LABELS[kind(session)])  # every label must be text Python can hold
    except UnicodeDecodeError:
        raise _not_utf8(p) from None
    except _core.ParseError as e:
        if _is_utf16(p):  # say what the file is, not only its first byte
            raise _not_utf8(p) from None
        raise e
    return session


def check_plausible(
    session: Session,
    source: str = "<session>",
    max_deviation_mm: float | None = None,
    rotary_axes_may_rest: bool = False,
) -> Any:
    """Check a session against the nominal kinematics before any fit (C++ session/plausibility):
    refuses, with the likely cause named ("angles look like radians", "lengths look like
    inches", "all rotary angles equal", a wrong L0, ...), a session no machine with realistic
    errors can have produced. ``max_deviation_mm`` widens the limit on ``|measured - nominal|`` of
    a ballbar length or of an R-test centre for an unusual session. ``rotary_axes_may_rest``:
    a session whose rotary axes never move is not refused for it (the one-pose added test of a
    diagnosis of several sessions, joined to the session it was designed after). Returns the
    report."""
    opts = _core.PlausibilityOptions()
    if rotary_axes_may_rest:
        opts.min_rotary_span_deg = 0.0
    if max_deviation_mm is not None:
        if not (0.0 < max_deviation_mm <= 1000.0):
            raise _core.InvalidArgument(
                f"--max-deviation {max_deviation_mm}: must be in (0, 1000] mm"
            )
        opts.max_length_deviation_mm = max_deviation_mm
        opts.max_position_deviation_mm = max_deviation_mm
    return _core.check_plausible(session, source, opts)


def session_text(session: Session, what: str = "save") -> str:
    """The file text of a session, refused (InvalidArgument naming ``what``) unless ``load``
    reads it back: no file is written that rotacal would refuse to read."""
    text = _FORMATTERS[kind(session)](session)
    with tempfile.TemporaryDirectory(prefix="rotacal-check-") as d:
        probe = os.path.join(d, "session.csv")
        with open(probe, "w", encoding="utf-8") as f:
            f.write(text)
        try:
            _core.read_instrument_session(probe)
        except _core.ParseError as e:
            reason = str(e).replace(probe, "the session")
            raise _core.InvalidArgument(
                f"{what}: this session would make a file that load refuses: {reason}"
            ) from None
    return text


def save(
    session: Session,
    path: str | Path,
    inputs: Iterable[str | Path] = (),
    other_outputs: Iterable[str | Path] = (),
) -> None:
    """Write a session by the output rule (rotacal.outputs: a regular file replaced atomically,
    a device written through); ``inputs`` and ``other_outputs`` of the command are refused as
    targets. A session that would make a file ``load`` refuses is not written."""
    p = checked_path(path, "save")
    write_output(
        p,
        lambda: session_text(session),
        [str(i) for i in inputs if i is not None],
        [str(o) for o in other_outputs if o is not None],
    )
