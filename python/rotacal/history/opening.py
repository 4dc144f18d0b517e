# SPDX-License-Identifier: BSD-3-Clause
"""Opening a calibration history store: a SQLite file (created, switched to WAL and full sync)
or a PostgreSQL database by its ``postgresql://`` URL (psycopg 3); the default location."""

from __future__ import annotations

import os
import sqlite3
import time
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from .. import _core
from .entries import check_machine_id, parse_date
from .store import BUSY_TIMEOUT_S, POSTGRESQL, SQLITE, CalibrationHistory, one_line, redact

ENV_STORE = "ROTACAL_HISTORY"


def default_location() -> str:
    """``$ROTACAL_HISTORY`` (a path or a URL), else ``~/.local/share/rotacal/history.sqlite``."""
    env = os.environ.get(ENV_STORE, "")
    if env:
        return env
    return str(Path.home() / ".local" / "share" / "rotacal" / "history.sqlite")


def refuse_before_storing(
    location: str | None, machine_id: Any, measured_at: str | None = None
) -> None:
    """Refuse, before any work is done for it, what storing an identification would refuse: a
    machine id or date that is not one, a store that cannot be opened."""
    check_machine_id(machine_id)
    if measured_at is not None:
        parse_date(measured_at, "--date")
    open_history(location).close()


def open_history(
    location: str | None = None, create_folder: bool | None = None
) -> CalibrationHistory:
    """Open (creating and migrating as needed) the store at ``location``: a SQLite file path
    or a ``postgresql://`` URL; default :func:`default_location`. The folder of the default
    SQLite file is created; for a path given, its folder must exist."""
    given = location is not None
    loc = default_location() if location is None else location
    if not isinstance(loc, (str, os.PathLike)):
        raise _core.InvalidArgument(
            f"--db: expected a file path or a postgresql:// URL, got {type(loc).__name__}"
        )
    loc = os.fspath(loc)
    if "://" in loc:
        return _open_postgresql(loc)
    if loc == "" or "\x00" in loc:
        raise _core.InvalidArgument("--db: empty file name or NUL byte")
    folder = Path(loc).parent
    if not folder.is_dir():
        if create_folder if create_folder is not None else not given:
            folder.mkdir(parents=True, exist_ok=True)
        else:
            raise _core.IoError(f"{loc}: the folder {folder} does not exist")
    if Path(loc).is_dir():
        raise _core.IoError(f"{loc}: is a directory, not a history store")
    if (
        Path(loc).exists() and not Path(loc).is_file()
    ):  # SQLite would create loc-journal beside /dev/null
        raise _core.IoError(f"{loc}: is a device or FIFO, not a history store (a SQLite file)")
    try:
        conn = sqlite3.connect(
            loc, timeout=BUSY_TIMEOUT_S, isolation_level=None, check_same_thread=False
        )
    except sqlite3.Error as e:
        raise _core.IoError(f"{loc}: cannot open: {e}") from None
    try:
        # WAL: readers do not block the writer; FULL: a stored calibration survives a power cut.
        # Switching a new store to WAL takes an exclusive lock and SQLite does not wait for it
        # (no busy handler there): two processes opening a new store at once retry.
        deadline = time.monotonic() + BUSY_TIMEOUT_S
        while True:
            try:
                conn.execute("PRAGMA journal_mode=WAL")
                break
            except sqlite3.OperationalError as e:
                if "locked" not in str(e) or time.monotonic() > deadline:
                    raise
                time.sleep(0.05)
        conn.execute("PRAGMA synchronous=FULL")
        conn.execute("PRAGMA foreign_keys=ON")
    except sqlite3.DatabaseError as e:
        conn.close()
        if isinstance(e, sqlite3.OperationalError) and ("locked" in str(e) or "readonly" in str(e)):
            raise _core.IoError(f"{loc}: {e}{_why_not_writable(loc)}") from None
        if _is_sqlite_file(loc):  # a valid store that cannot be opened: the file system's doing
            raise _core.IoError(
                f"{loc}: cannot open the history store: {e}{_why_not_writable(loc)}"
            ) from None
        raise _core.InvalidArgument(
            f"{loc}: not a rotacal history store (not an SQLite database: {e})"
        ) from None
    try:
        return CalibrationHistory(conn, SQLITE, loc)
    except BaseException:
        conn.close()
        raise


def _is_sqlite_file(loc: str) -> bool:
    """Whether the file starts with the SQLite header (or is empty: SQLite makes it a database)."""
    try:
        with open(loc, "rb") as f:
            head = f.read(16)
    except OSError:
        return False
    return head in (b"", b"SQLite format 3\x00")


def _why_not_writable(loc: str) -> str:
    """The cause, when the store's folder or file cannot be written (a store writes beside itself)."""
    folder = str(Path(loc).parent)
    try:
        if os.statvfs(folder).f_flag & os.ST_RDONLY:
            return f" ({folder} is on a read-only file system)"
    except OSError:
        return ""
    if not os.access(folder, os.W_OK):
        return f" (the folder {folder} is not writable: SQLite writes its journal there)"
    if os.path.exists(loc) and not os.access(loc, os.W_OK):
        return " (the file is not writable)"
    return ""


def _open_postgresql(url: str) -> CalibrationHistory:
    shown = redact(url)
    scheme = url.split("://", 1)[0]
    if scheme not in ("postgresql", "postgres"):
        raise _core.InvalidArgument(
            f"--db: {shown}: a history store is a SQLite file path or a postgresql:// URL, "
            f"not {scheme}://"
        )
    try:
        parts = urlsplit(url)
        parts.port  # raises on a port that is not a number
    except ValueError as e:
        raise _core.InvalidArgument(f"--db: {shown}: malformed URL ({e})") from None
    try:
        import psycopg
    except ImportError:
        raise _core.Error(
            "a PostgreSQL history store needs psycopg 3: pip install 'rotacal[postgresql]' "
            "(or 'psycopg[binary]')"
        ) from None
    try:
        psycopg.conninfo.conninfo_to_dict(url)
    except psycopg.Error as e:
        raise _core.InvalidArgument(f"--db: {shown}: malformed URL ({one_line(e)})") from None
    try:
        conn = psycopg.connect(url, autocommit=True, connect_timeout=10)
    except psycopg.Error as e:
        raise _core.IoError(f"{shown}: cannot connect: {one_line(e)}") from None
    try:
        return CalibrationHistory(conn, POSTGRESQL, url)
    except BaseException:
        conn.close()
        raise
