"""Calibration history: every identification of a physical machine, and every correction
loaded into its controller, kept in a store, so that the drift of each location error can be
followed over months (docs/history.md).

The store is an embedded SQLite file by default (standard library) or a PostgreSQL database
given by a ``postgresql://`` URL (through psycopg 3), for a shop or a vendor that collects the
calibrations of many machines. One code path serves both: the SQL is the common subset, with
the placeholders and two column types set by a small dialect. The schema is versioned
(table ``rotacal_history_schema``); an older store is migrated when opened, a newer one refused.

Every write is one transaction: two writers at once lose nothing (SQLite: WAL and BEGIN
IMMEDIATE, waiting up to ``BUSY_TIMEOUT_S``; PostgreSQL: its own locking), and a writer killed
mid-write leaves the store as it was before that write.
"""
from __future__ import annotations

import datetime
import hashlib
import json
import math
import os
import re
import sqlite3
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator, Mapping, Sequence
from urllib.parse import urlsplit

from . import _core, jsontext

SCHEMA_VERSION = 2
ENV_STORE = "ROTACAL_HISTORY"
BUSY_TIMEOUT_S = 60.0
# Drift is given per mean Gregorian month.
DAYS_PER_MONTH = 365.2425 / 12
# No drift per month from calibrations closer than this: their difference is repeatability and
# the machine's thermal state, and a month's rate from two taken a second apart scales it by
# 2.6 million (issue 32: -230,541,381 um/month).
MIN_DRIFT_SPAN_DAYS = 7.0
DRIFT_SPAN_WHY = "closer calibrations measure repeatability and warm-up, not a rate per month"
# Coverage factor of the expanded uncertainty a change is compared with (GUM, about 95 %).
K_EXPANDED = 2.0
MAX_MACHINE_ID = 100
# The largest location error a model file may hold (io/model_file.hpp, kMaxModelPositionError
# and kMaxModelAngleError): a correction beyond it is a typo or wrong units, not a machine.
MAX_ERROR = {"mm": 100.0, "rad": 0.5}
MAX_NOTE = 2000

IDENTIFICATION, CORRECTION = "identification", "correction"

# Migrations: version -> statements. {id} and {real} are filled in by the dialect. A store of
# version v gets every statement of v+1.. applied in one transaction. Never edit a released
# version: add one.
MIGRATIONS: dict[int, list[str]] = {
    1: [
        # The machine id names the physical machine (e.g. its serial number); its kinematic
        # type is fixed by the first calibration stored.
        "CREATE TABLE machines (machine_id TEXT PRIMARY KEY, machine_type TEXT NOT NULL, "
        "first_stored_at TEXT NOT NULL)",
        # One row per identification or correction. source_sha256: the session's SHA-256 for
        # an identification, the export file's for a correction; a second store is refused.
        "CREATE TABLE calibrations (id {id}, machine_id TEXT NOT NULL REFERENCES machines (machine_id), "
        "kind TEXT NOT NULL, test TEXT NOT NULL, measured_at TEXT NOT NULL, stored_at TEXT NOT NULL, "
        "session TEXT, source_sha256 TEXT NOT NULL, note TEXT, document TEXT NOT NULL, "
        "UNIQUE (kind, source_sha256))",
        # The estimates, one row each, so that a shop can query them in SQL across machines.
        # part: location_errors, map_coefficients (R-test) or correction (amounts loaded).
        "CREATE TABLE estimates (calibration_id BIGINT NOT NULL REFERENCES calibrations (id), "
        "part TEXT NOT NULL, name TEXT NOT NULL, value {real}, std {real}, unit TEXT, "
        "PRIMARY KEY (calibration_id, part, name))",
        "CREATE INDEX calibrations_by_machine ON calibrations (machine_id, measured_at, id)",
    ],
    2: [
        # What the identification said besides the model (noise model, uncertainty budget,
        # diagnosis findings) and the controller parameters active during the test.
        "ALTER TABLE calibrations ADD COLUMN details TEXT",
        "ALTER TABLE calibrations ADD COLUMN controller TEXT",
    ],
}
assert max(MIGRATIONS) == SCHEMA_VERSION


def default_location() -> str:
    """``$ROTACAL_HISTORY`` (a path or a URL), else ``~/.local/share/rotacal/history.sqlite``."""
    env = os.environ.get(ENV_STORE, "")
    if env:
        return env
    return str(Path.home() / ".local" / "share" / "rotacal" / "history.sqlite")


def redact(location: str) -> str:
    """A store location fit to print: the password of a URL replaced by ***."""
    if "://" not in location:
        return location
    try:
        parts = urlsplit(location)
    except ValueError:
        return location.split("://", 1)[0] + "://..."
    if parts.password is None:
        return location
    netloc = parts.netloc.replace(f":{parts.password}@", ":***@", 1)
    return parts._replace(netloc=netloc).geturl()


def now_utc() -> str:
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def parse_date(text: str, what: str = "date") -> str:
    """ISO 8601 date or date-time as stored: UTC, ``YYYY-MM-DDTHH:MM:SSZ`` (so that the text
    sorts as the time does). A time without zone is taken as UTC."""
    if not isinstance(text, str):
        raise _core.InvalidArgument(f"{what}: expected an ISO 8601 date, got {type(text).__name__}")
    t = text.strip()
    try:
        d = datetime.datetime.fromisoformat(t[:-1] + "+00:00" if t.endswith("Z") else t)
    except ValueError:
        raise _core.InvalidArgument(f"{what}: {t[:40]!r} is not an ISO 8601 date (e.g. 2026-03-01 "
                                    "or 2026-03-01T14:30:00Z)") from None
    if d.tzinfo is None:
        d = d.replace(tzinfo=datetime.timezone.utc)
    d = d.astimezone(datetime.timezone.utc)
    if not 1970 <= d.year <= 9999:
        raise _core.InvalidArgument(f"{what}: {t[:40]!r} is outside the years 1970..9999")
    return d.strftime("%Y-%m-%dT%H:%M:%SZ")


def check_machine_id(machine_id: Any) -> str:
    """The id of a physical machine: 1..100 printable characters, not only blanks."""
    if not isinstance(machine_id, str) or not machine_id.strip():
        raise _core.InvalidArgument("--machine-id: give the id of the physical machine (e.g. its serial number)")
    if len(machine_id) > MAX_MACHINE_ID or not machine_id.isprintable():
        raise _core.InvalidArgument(f"--machine-id: {machine_id[:40]!r}: at most {MAX_MACHINE_ID} printable characters")
    return machine_id


def _check_note(note: Any) -> str | None:
    if note is None:
        return None
    if not isinstance(note, str) or len(note) > MAX_NOTE or "\x00" in note:
        raise _core.InvalidArgument(f"--note: at most {MAX_NOTE} characters of text")
    return note


def unit_of(name: str) -> str:
    """Unit of a location error by its ISO 230-7 name: E_X.., E_Y.., E_Z.. are positions (mm),
    E_A.., E_B.., E_C.. orientations (rad)."""
    return "mm" if name[2:3] in ("X", "Y", "Z") else "rad"


def sha256_of_json(doc: Any) -> str:
    return hashlib.sha256(json.dumps(doc, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


# ------------------------------------------------------------------------- dialects

@dataclass(frozen=True)
class _Dialect:
    name: str
    id_type: str
    real: str

    def sql(self, text: str) -> str:
        return text.replace("?", "%s") if self.name == "postgresql" else text


SQLITE = _Dialect("sqlite", "INTEGER PRIMARY KEY", "REAL")
POSTGRESQL = _Dialect("postgresql", "BIGINT GENERATED BY DEFAULT AS IDENTITY PRIMARY KEY", "DOUBLE PRECISION")
# Any constant: serialises concurrent migrations of one PostgreSQL database.
_PG_MIGRATION_LOCK = 0x726F746163616C


# ------------------------------------------------------------------------- entries

@dataclass
class Estimate:
    value: float | None  # None: unobservable
    std: float | None
    unit: str


@dataclass
class Entry:
    """One identification or correction of a machine, as show reads it."""
    id: int
    kind: str
    test: str  # ballbar / rtest-joint / ... ; for a correction the controller
    measured_at: str
    session: str | None
    source_sha256: str
    note: str | None
    estimates: dict[str, Estimate] = field(default_factory=dict)


def _estimates_of(model: Mapping[str, Any], where: str) -> list[tuple[str, str, float | None, float | None, str]]:
    """(part, name, value, std, unit) of a model's location errors and map coefficients,
    checked: a value finite or null, a std finite and >= 0 or null."""
    rows = []
    for part in ("location_errors", "map_coefficients"):
        block = model.get(part, {})
        if not isinstance(block, Mapping):
            raise _core.InvalidArgument(f"{where}: {part}: must be an object")
        for name, est in block.items():
            if not isinstance(est, Mapping):
                raise _core.InvalidArgument(f"{where}: {part}.{name}: must be an estimate object")
            v, s = est.get("value"), est.get("std")
            for key, x in (("value", v), ("std", s)):
                if x is not None and (isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x)):
                    raise _core.InvalidArgument(f"{where}: {part}.{name}.{key}: must be a finite number or null, got {x!r}")
            if s is not None and s < 0:
                raise _core.InvalidArgument(f"{where}: {part}.{name}.std: must be >= 0, got {s!r}")
            unit = est.get("unit", unit_of(name) if part == "location_errors" else "")
            rows.append((part, str(name), None if v is None else float(v),
                         None if v is None or s is None else float(s), str(unit)))
    return rows


def correction_amounts(export: Mapping[str, Any], where: str = "<export>") -> dict[str, float]:
    """The change of compensation a controller export loads, by location error: each error the
    controller holds is now compensated by its identified value, so a later calibration
    measures the machine less that value (docs/history.md)."""
    errors = export.get("location_errors") if isinstance(export, Mapping) else None
    if not isinstance(errors, list) or not isinstance(export.get("controller"), str):
        raise _core.InvalidArgument(f"{where}: not the JSON of 'rotacal export --json' (controller, location_errors)")
    out: dict[str, float] = {}
    for i, e in enumerate(errors):
        if not isinstance(e, Mapping) or not isinstance(e.get("name"), str) or not isinstance(e.get("held"), bool):
            raise _core.InvalidArgument(f"{where}: location_errors[{i}]: needs name and held")
        v = e.get("value")
        if not e["held"] or v is None:
            continue  # not loaded, or unobservable (the export leaves it at its current value)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise _core.InvalidArgument(f"{where}: location_errors[{i}].value: must be a finite number, got {v!r}")
        limit = MAX_ERROR.get(unit_of(e["name"]))
        if limit is not None and abs(v) > limit:
            raise _core.InvalidArgument(f"{where}: location_errors[{i}].value: {v:g} {unit_of(e['name'])} is beyond "
                                        f"+-{limit:g}: no machine tool has such a location error")
        out[e["name"]] = float(v)
    if not out:
        raise _core.InvalidArgument(f"{where}: the export holds none of the location errors: no correction to record")
    return out


# ------------------------------------------------------------------------- the store

class CalibrationHistory:
    """A calibration history store; open with :func:`open_history`. Use as a context manager
    or call :meth:`close`."""

    def __init__(self, conn: Any, dialect: _Dialect, location: str):
        self._conn = conn
        self.dialect = dialect
        self.location = location  # as given, printable through redact()
        self._migrate()

    # -- plumbing

    def close(self) -> None:
        self._conn.close()

    def __enter__(self) -> "CalibrationHistory":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def _x(self, sql: str, params: Sequence[Any] = ()) -> Any:
        return self._conn.execute(self.dialect.sql(sql), params)

    def _many(self, sql: str, rows: list) -> None:
        if self.dialect is SQLITE:
            self._conn.executemany(sql, rows)
        else:
            with self._conn.cursor() as cur:
                cur.executemany(self.dialect.sql(sql), rows)

    @contextmanager
    def _transaction(self, write: bool = True) -> Iterator[None]:
        """One transaction, committed at the end or rolled back on any error. SQLite: a writer
        takes the write lock at BEGIN (IMMEDIATE), so its reads inside see what it writes over."""
        with self._errors():
            if self.dialect is SQLITE:
                self._conn.execute("BEGIN IMMEDIATE" if write else "BEGIN")
                try:
                    yield
                except BaseException:
                    self._conn.execute("ROLLBACK")
                    raise
                self._conn.execute("COMMIT")
            else:
                with self._conn.transaction():
                    yield

    @contextmanager
    def _errors(self) -> Iterator[None]:
        """Database errors as rotacal errors naming the store."""
        where = redact(self.location)
        try:
            yield
        except sqlite3.OperationalError as e:
            msg = str(e)
            if "locked" in msg or "busy" in msg:
                raise _core.IoError(f"{where}: the store stayed busy for {BUSY_TIMEOUT_S:g} s (another writer)") from None
            raise _core.IoError(f"{where}: {msg}") from None
        except sqlite3.DatabaseError as e:
            raise _core.InvalidArgument(f"{where}: not a readable rotacal history store: {e}") from None
        except Exception as e:
            if type(e).__module__.startswith("psycopg"):
                raise _core.IoError(f"{where}: {_one_line(e)}") from None
            raise

    def _tables(self) -> set[str]:
        if self.dialect is SQLITE:
            rows = self._x("SELECT name FROM sqlite_master WHERE type = 'table' AND name NOT LIKE 'sqlite_%'")
        else:
            rows = self._x("SELECT table_name FROM information_schema.tables WHERE table_schema = current_schema()")
        return {r[0] for r in rows.fetchall()}

    def _version(self) -> int | None:
        """The schema version, None for an empty store; refuses a database that is not a store."""
        tables = self._tables()
        if "rotacal_history_schema" not in tables:
            if tables:
                raise _core.InvalidArgument(
                    f"{redact(self.location)}: not a rotacal history store (it holds other tables: "
                    f"{', '.join(sorted(tables)[:5])})")
            return None
        row = self._x("SELECT MAX(version) FROM rotacal_history_schema").fetchone()
        if not row or row[0] is None:
            return 0
        if isinstance(row[0], bool) or not isinstance(row[0], int) or row[0] < 1:
            raise _core.InvalidArgument(f"{redact(self.location)}: schema version {str(row[0])[:40]!r} is not one "
                                        f"rotacal writes (1 .. {SCHEMA_VERSION}): not a rotacal history store")
        return row[0]

    def _migrate(self) -> None:
        with self._errors():
            version = self._version()
        if version is not None and version > SCHEMA_VERSION:
            raise _core.InvalidArgument(
                f"{redact(self.location)}: the history store has schema version {version}, written by a newer "
                f"rotacal; this one reads versions up to {SCHEMA_VERSION}: upgrade rotacal")
        if version == SCHEMA_VERSION:
            return
        with self._transaction():
            if self.dialect is POSTGRESQL:
                self._x("SELECT pg_advisory_xact_lock(?)", (_PG_MIGRATION_LOCK,))
            version = self._version() or 0  # again, under the lock: another process may have done it
            if version > SCHEMA_VERSION:
                raise _core.InvalidArgument(f"{redact(self.location)}: schema version {version} is newer than "
                                            f"{SCHEMA_VERSION}: upgrade rotacal")
            if version == 0:
                self._x("CREATE TABLE rotacal_history_schema (version INTEGER PRIMARY KEY, applied_at TEXT NOT NULL)")
            for v in range(version + 1, SCHEMA_VERSION + 1):
                for stmt in MIGRATIONS[v]:
                    self._x(stmt.format(id=self.dialect.id_type, real=self.dialect.real))
                self._x("INSERT INTO rotacal_history_schema (version, applied_at) VALUES (?, ?)", (v, now_utc()))

    @property
    def schema_version(self) -> int:
        with self._errors():
            return self._version() or 0

    # -- writing

    def _machine(self, machine_id: str, machine_type: str) -> None:
        """Register the machine, or check that it is of this kinematic type."""
        self._x("INSERT INTO machines (machine_id, machine_type, first_stored_at) VALUES (?, ?, ?) "
                "ON CONFLICT (machine_id) DO NOTHING", (machine_id, machine_type, now_utc()))
        known = self._x("SELECT machine_type FROM machines WHERE machine_id = ?", (machine_id,)).fetchone()[0]
        if known != machine_type:
            raise _core.InvalidArgument(f"machine id {machine_id!r} is a {known} in the store; this calibration is "
                                        f"of a {machine_type}: check --machine-id")

    def _refuse_duplicate(self, kind: str, sha: str, what: str) -> None:
        row = self._x("SELECT id, machine_id, measured_at FROM calibrations WHERE kind = ? AND source_sha256 = ?",
                      (kind, sha)).fetchone()
        if row:
            raise _core.InvalidArgument(f"{what} (sha256 {sha[:12]}...) is already stored: entry {row[0]} of machine "
                                        f"{row[1]!r}, {row[2]}")

    def _insert(self, machine_id: str, machine_type: str, kind: str, test: str, measured_at: str,
                session: str | None, sha: str, note: str | None, document: str, details: str | None,
                controller: str | None, estimates: list, what: str) -> int:
        with self._transaction():
            self._refuse_duplicate(kind, sha, what)
            self._machine(machine_id, machine_type)
            try:
                cid = self._x("INSERT INTO calibrations (machine_id, kind, test, measured_at, stored_at, session, "
                              "source_sha256, note, document, details, controller) "
                              "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?) RETURNING id",
                              (machine_id, kind, test, measured_at, now_utc(), session, sha, note, document,
                               details, controller)).fetchone()[0]
            except Exception as e:  # PostgreSQL: another writer stored the same one since the check
                if type(e).__name__ == "UniqueViolation":
                    raise _core.InvalidArgument(f"{what} (sha256 {sha[:12]}...) is already stored") from None
                raise
            self._insert_estimates(cid, estimates)
        return int(cid)

    def _insert_estimates(self, cid: int, estimates: list) -> None:
        self._many("INSERT INTO estimates (calibration_id, part, name, value, std, unit) VALUES (?, ?, ?, ?, ?, ?)",
                   [(cid, *e) for e in estimates])

    def add_identification(self, machine_id: str, model: Mapping[str, Any], *, note: str | None = None,
                           measured_at: str | None = None, details: Mapping[str, Any] | None = None,
                           controller: str | None = None, where: str = "<model>") -> int:
        """Store an identification (a ``rotacal-model/1`` dict, as ``load_model`` returns or
        ``identify --save-model`` writes); returns its entry id. ``measured_at``: ISO 8601,
        default the model's ``source.identified_at``, else now. ``details``: what the
        identification said besides the model (``identify --json``; diagnosis findings).
        ``controller``: the text of the controller parameters active during the test.
        Refuses a session stored before (by its SHA-256), a machine id of another kinematic type."""
        machine_id = check_machine_id(machine_id)
        note = _check_note(note)
        if not isinstance(model, Mapping):
            raise _core.InvalidArgument(f"{where}: a model must be a JSON object")
        machine_type = _core.machine_name(_core.parse_machine_type(str(model.get("machine", ""))))
        names = set(_core.location_error_names(_core.parse_machine_type(machine_type)))
        estimates = _estimates_of(model, where)
        unknown = [e[1] for e in estimates if e[0] == "location_errors" and e[1] not in names]
        if unknown:
            raise _core.InvalidArgument(f"{where}: {', '.join(unknown[:4])}: not location errors of a {machine_type}")
        source = model.get("source") if isinstance(model.get("source"), Mapping) else {}
        sha = source.get("session_sha256")
        if not isinstance(sha, str) or not re.fullmatch(r"[0-9a-f]{64}", sha):
            sha = sha256_of_json(model)  # no session named: the model itself is what is stored once
        session = source.get("session") if isinstance(source.get("session"), str) else None
        if measured_at is not None:
            at = parse_date(measured_at, "--date")
        elif isinstance(source.get("identified_at"), str):
            at = parse_date(source["identified_at"], f"{where}: source.identified_at")
        else:
            at = now_utc()
        what = f"session {session}" if session else f"model {where}"
        return self._insert(machine_id, machine_type, IDENTIFICATION, str(model.get("kind", "ballbar")), at, session,
                            sha, note, jsontext.dumps(dict(model), indent=None),
                            None if details is None else jsontext.dumps(dict(details), indent=None),
                            controller, estimates, what)

    def add_correction(self, machine_id: str, export: Mapping[str, Any], *, applied_at: str | None = None,
                       note: str | None = None, source_sha256: str | None = None, where: str = "<export>") -> int:
        """Record that a controller export (``rotacal export --json``) was loaded into the
        machine's controller at ``applied_at`` (default now): the change it makes is a
        correction, not drift. Returns the entry id."""
        machine_id = check_machine_id(machine_id)
        note = _check_note(note)
        amounts = correction_amounts(export, where)
        row = self._machine_type(machine_id)
        if row is None:
            raise self._unknown(machine_id, "record a correction of it")
        names = set(_core.location_error_names(_core.parse_machine_type(row)))
        foreign = [n for n in amounts if n not in names]
        if foreign:
            raise _core.InvalidArgument(f"{where}: {', '.join(foreign[:4])}: not location errors of {machine_id!r} ({row})")
        at = parse_date(applied_at, "--date") if applied_at is not None else now_utc()
        sha = source_sha256 or sha256_of_json(export)
        estimates = [("correction", n, v, None, unit_of(n)) for n, v in amounts.items()]
        return self._insert(machine_id, row, CORRECTION, str(export["controller"]), at, None, sha, note,
                            jsontext.dumps(dict(export), indent=None), None, None, estimates,
                            f"correction {where}")

    # -- reading

    def _machine_type(self, machine_id: str) -> str | None:
        with self._errors():
            row = self._x("SELECT machine_type FROM machines WHERE machine_id = ?", (machine_id,)).fetchone()
        return None if row is None else row[0]

    def _unknown(self, machine_id: str, to: str) -> Exception:
        known = [m["machine_id"] for m in self.machines()]
        listed = ", ".join(repr(k) for k in known[:10]) + (" ..." if len(known) > 10 else "")
        return _core.InvalidArgument(f"machine id {machine_id!r}: no calibration stored in {redact(self.location)}, "
                                     f"cannot {to} (known: {listed or 'none'})")

    def machines(self) -> list[dict]:
        """Every machine: id, kinematic type, number of identifications and corrections, the
        dates of the first and the last."""
        with self._transaction(write=False):
            rows = self._x(
                "SELECT m.machine_id, m.machine_type, "
                "SUM(CASE WHEN c.kind = 'identification' THEN 1 ELSE 0 END), "
                "SUM(CASE WHEN c.kind = 'correction' THEN 1 ELSE 0 END), MIN(c.measured_at), MAX(c.measured_at) "
                "FROM machines m LEFT JOIN calibrations c ON c.machine_id = m.machine_id "
                "GROUP BY m.machine_id, m.machine_type ORDER BY m.machine_id").fetchall()
        return [{"machine_id": r[0], "machine_type": r[1], "identifications": int(r[2] or 0),
                 "corrections": int(r[3] or 0), "first": r[4], "last": r[5]} for r in rows]

    def entries(self, machine_id: str) -> tuple[str, list[Entry]]:
        """(kinematic type, entries in time order) of a machine; refuses an unknown id."""
        with self._transaction(write=False):
            row = self._x("SELECT machine_type FROM machines WHERE machine_id = ?", (machine_id,)).fetchone()
            if row is None:
                unknown = True
            else:
                unknown = False
                cal = self._x("SELECT id, kind, test, measured_at, session, source_sha256, note FROM calibrations "
                              "WHERE machine_id = ? ORDER BY measured_at, id", (machine_id,)).fetchall()
                est = self._x("SELECT e.calibration_id, e.name, e.value, e.std, e.unit FROM estimates e "
                              "JOIN calibrations c ON c.id = e.calibration_id WHERE c.machine_id = ? "
                              "AND e.part IN ('location_errors', 'correction')", (machine_id,)).fetchall()
        if unknown:
            raise self._unknown(machine_id, "show its history")
        out = {r[0]: Entry(int(r[0]), r[1], r[2], r[3], r[4], r[5], r[6]) for r in cal}
        for cid, name, v, s, unit in est:
            out[cid].estimates[name] = Estimate(v, s, unit)
        return row[0], list(out.values())

    def entry(self, entry_id: int) -> dict:
        """Everything stored of one entry: its model (or export) document, details, controller."""
        with self._transaction(write=False):
            r = self._x("SELECT id, machine_id, kind, test, measured_at, stored_at, session, source_sha256, note, "
                        "document, details, controller FROM calibrations WHERE id = ?", (int(entry_id),)).fetchone()
        if r is None:
            raise _core.InvalidArgument(f"entry {entry_id}: not in {redact(self.location)}")
        keys = ("id", "machine_id", "kind", "test", "measured_at", "stored_at", "session", "source_sha256", "note")
        out = dict(zip(keys, r[:9]))
        out["document"] = json.loads(r[9])
        out["details"] = json.loads(r[10]) if r[10] else None
        out["controller"] = r[11]
        return out

    def show(self, machine_id: str, tolerances: Mapping[str, float] | None = None) -> dict:
        """The history of a machine's location errors: :func:`summarize` of its entries."""
        machine_type, entries = self.entries(machine_id)
        out = summarize(machine_type, entries, tolerances)
        return {"machine_id": machine_id, "store": redact(self.location)} | out


def open_history(location: str | None = None, create_folder: bool | None = None) -> CalibrationHistory:
    """Open (creating and migrating as needed) the store at ``location``: a SQLite file path
    or a ``postgresql://`` URL; default :func:`default_location`. The folder of the default
    SQLite file is created; for a path given, its folder must exist."""
    given = location is not None
    loc = default_location() if location is None else location
    if not isinstance(loc, (str, os.PathLike)):
        raise _core.InvalidArgument(f"--db: expected a file path or a postgresql:// URL, got {type(loc).__name__}")
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
    if Path(loc).exists() and not Path(loc).is_file():  # SQLite would create loc-journal beside /dev/null
        raise _core.IoError(f"{loc}: is a device or FIFO, not a history store (a SQLite file)")
    try:
        conn = sqlite3.connect(loc, timeout=BUSY_TIMEOUT_S, isolation_level=None, check_same_thread=False)
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
            raise _core.IoError(f"{loc}: cannot open the history store: {e}{_why_not_writable(loc)}") from None
        raise _core.InvalidArgument(f"{loc}: not a rotacal history store (not an SQLite database: {e})") from None
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


def _one_line(e: BaseException) -> str:
    return " ".join(str(e).split())


def _open_postgresql(url: str) -> CalibrationHistory:
    shown = redact(url)
    scheme = url.split("://", 1)[0]
    if scheme not in ("postgresql", "postgres"):
        raise _core.InvalidArgument(f"--db: {shown}: a history store is a SQLite file path or a postgresql:// URL, "
                                    f"not {scheme}://")
    try:
        parts = urlsplit(url)
        parts.port  # raises on a port that is not a number
    except ValueError as e:
        raise _core.InvalidArgument(f"--db: {shown}: malformed URL ({e})") from None
    try:
        import psycopg
    except ImportError:
        raise _core.Error("a PostgreSQL history store needs psycopg 3: pip install 'rotacal[postgresql]' "
                          "(or 'psycopg[binary]')") from None
    try:
        psycopg.conninfo.conninfo_to_dict(url)
    except psycopg.Error as e:
        raise _core.InvalidArgument(f"--db: {shown}: malformed URL ({_one_line(e)})") from None
    try:
        conn = psycopg.connect(url, autocommit=True, connect_timeout=10)
    except psycopg.Error as e:
        raise _core.IoError(f"{shown}: cannot connect: {_one_line(e)}") from None
    try:
        return CalibrationHistory(conn, POSTGRESQL, url)
    except BaseException:
        conn.close()
        raise


# ------------------------------------------------------------------------- the history of a machine

def _epoch_months(at: str) -> float:
    """Months since 1970 of a stored date-time (fixed layout: sliced, not parsed, for speed)."""
    d = datetime.datetime(int(at[0:4]), int(at[5:7]), int(at[8:10]), int(at[11:13]), int(at[14:16]),
                          int(at[17:19]), tzinfo=datetime.timezone.utc)
    return d.timestamp() / 86400.0 / DAYS_PER_MONTH


def drift_fit(t_months: Sequence[float], y: Sequence[float], std: Sequence[float | None]) -> dict | None:
    """Least-squares straight line through (t, y) weighted by 1/std^2: slope per month, its
    1-sigma from the stated stds, and chi2/dof (about 1 when the stds explain the scatter).
    Unweighted (and said so) when a point has no positive std. None for fewer than two
    distinct times."""
    n = len(y)
    if n < 2 or max(t_months) - min(t_months) <= 0:
        return None
    weighted = all(s is not None and s > 0 for s in std)
    w = [1.0 / (s * s) for s in std] if weighted else [1.0] * n  # type: ignore[operator]
    sw = sum(w)
    tm = sum(wi * ti for wi, ti in zip(w, t_months)) / sw
    ym = sum(wi * yi for wi, yi in zip(w, y)) / sw
    stt = sum(wi * (ti - tm) ** 2 for wi, ti in zip(w, t_months))
    slope = sum(wi * (ti - tm) * (yi - ym) for wi, ti, yi in zip(w, t_months, y)) / stt
    resid = [yi - ym - slope * (ti - tm) for ti, yi in zip(t_months, y)]
    chi2 = sum(wi * r * r for wi, r in zip(w, resid))
    dof = n - 2
    if weighted:
        slope_std = math.sqrt(1.0 / stt)
    elif dof > 0:  # no stated std: the scatter about the line is all there is
        slope_std = math.sqrt(chi2 / dof / stt)
    else:
        slope_std = None
    return {"value": slope, "std": slope_std, "n": n, "span_months": max(t_months) - min(t_months),
            "chi2_per_dof": chi2 / dof if weighted and dof > 0 else None,
            "weighting": "1/std^2" if weighted else "equal (a calibration has no 1-sigma)"}


def expand_tolerances(tolerances: Mapping[str, float], names: Sequence[str], machine_type: str) -> dict[str, float]:
    """Tolerance by location error from keys that are error names or ``position`` (every
    error in mm) or ``orientation`` (every error in rad); a name overrides its group."""
    for k, v in tolerances.items():
        if k not in names and k not in ("position", "orientation"):
            raise _core.InvalidArgument(f"--tolerance: {k}: not a location error of a {machine_type} "
                                        f"({' '.join(names)}), nor position or orientation")
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
            raise _core.InvalidArgument(f"--tolerance {k}: must be a number > 0, got {v!r}")
    out = {}
    for n in names:
        group = "position" if unit_of(n) == "mm" else "orientation"
        if n in tolerances or group in tolerances:
            out[n] = float(tolerances.get(n, tolerances.get(group)))
    return out


def summarize(machine_type: str, entries: Sequence[Entry], tolerances: Mapping[str, float] | None = None) -> dict:
    """Each location error over time: the values measured with their 1-sigma, the compensation
    the controller held at the time (the sum of the corrections recorded before), the machine's
    own value (measured + compensation), the change between consecutive calibrations with the
    corrections in between taken out, flagged when it exceeds the expanded (k = 2) uncertainty
    of the difference or the tolerance given for that error (same unit as the error), and the
    drift per month (weighted straight line through the machine's own values)."""
    names = list(_core.location_error_names(_core.parse_machine_type(machine_type)))
    tol = expand_tolerances(tolerances or {}, names, machine_type)
    calibrations = [e for e in entries if e.kind == IDENTIFICATION]
    corrections = [e for e in entries if e.kind == CORRECTION]
    months = {e.id: _epoch_months(e.measured_at) for e in calibrations}
    errors: dict[str, dict] = {}
    flags: list[dict] = []
    for name in names:
        unit = unit_of(name)
        points: list[dict] = []
        steps: list[dict] = []
        unobservable: list[int] = []
        held = 0.0  # compensation the controller holds for this error
        since_last = 0.0  # corrections since the previous calibration
        for e in entries:
            est = e.estimates.get(name)
            if e.kind == CORRECTION:
                if est is not None and est.value is not None:
                    held += est.value
                    since_last += est.value
                continue
            if est is None or est.value is None:
                unobservable.append(e.id)
                continue
            p = {"entry": e.id, "at": e.measured_at, "measured": est.value, "std": est.std,
                 "compensation": held, "value": est.value + held}
            if points:
                q = points[-1]
                change = p["value"] - q["value"]
                u = (math.sqrt(q["std"] ** 2 + p["std"] ** 2) * K_EXPANDED
                     if q["std"] is not None and p["std"] is not None else None)
                step = {"from": q["entry"], "to": e.id, "from_at": q["at"], "to_at": e.measured_at,
                        "measured_change": p["measured"] - q["measured"], "corrections": since_last,
                        "change": change, "expanded_uncertainty": u,
                        "exceeds_uncertainty": u is not None and abs(change) > u,
                        "tolerance": tol.get(name), "exceeds_tolerance": name in tol and abs(change) > tol[name]}
                steps.append(step)
                if step["exceeds_uncertainty"] or step["exceeds_tolerance"]:
                    why = [w for w, hit in (("exceeds k=2 uncertainty", step["exceeds_uncertainty"]),
                                            ("exceeds tolerance", step["exceeds_tolerance"])) if hit]
                    flags.append({"name": name, "unit": unit, **{k: step[k] for k in
                                  ("from", "to", "from_at", "to_at", "change", "expanded_uncertainty", "tolerance")},
                                  "why": why})
            since_last = 0.0
            points.append(p)
        drift = None
        if len(points) >= 2:
            t0 = months[points[0]["entry"]]
            drift = drift_fit([months[p["entry"]] - t0 for p in points], [p["value"] for p in points],
                              [p["std"] for p in points])
        if drift is not None and drift["span_months"] * DAYS_PER_MONTH < MIN_DRIFT_SPAN_DAYS:
            drift = None  # the difference of two close calibrations is not a rate per month
        errors[name] = {"unit": unit, "points": points, "steps": steps, "unobservable_in": unobservable,
                        "drift_per_month": drift}
    return {
        "machine_type": machine_type,
        "identifications": len(calibrations),
        "corrections": [{"entry": c.id, "at": c.measured_at, "controller": c.test, "note": c.note,
                         "amounts": {n: est.value for n, est in c.estimates.items()}} for c in corrections],
        "calibrations": [{"entry": c.id, "at": c.measured_at, "test": c.test, "session": c.session,
                          "session_sha256": c.source_sha256, "note": c.note} for c in calibrations],
        "location_errors": errors,
        "flags": flags,
        "definitions": {
            "value": "measured + compensation: the machine's own error, as if no correction had been loaded",
            "compensation": "sum of the corrections recorded before the calibration (a correction loads the "
                            "identified values of the errors the controller holds)",
            "change": "value minus the previous calibration's value: drift, corrections taken out",
            "expanded_uncertainty": f"{K_EXPANDED:g} * sqrt(std1^2 + std2^2)",
            "drift_per_month": f"slope of value over time, least squares weighted by 1/std^2, per "
                               f"{DAYS_PER_MONTH:.4f} days; null when the calibrations span less than "
                               f"{MIN_DRIFT_SPAN_DAYS:g} days ({DRIFT_SPAN_WHY})",
        },
    }


# ------------------------------------------------------------------------- plots

def write_plot(summary: dict, path: str, inputs: Sequence[str] = ()) -> None:
    """The history as figures: each observable location error over time, the machine's own
    value with its 1-sigma band, corrections as vertical lines, flagged changes in red. A .png
    file, or a .html page with the figure and the flags, written by the output rule."""
    from .outputs import check_output, write_output
    suffix = Path(path).suffix.lower()
    if suffix not in (".png", ".html", ".htm"):
        raise _core.InvalidArgument(f"--plot: {path}: give a .png or .html file")
    check_output(path, inputs)
    if suffix == ".png":
        write_output(path, _history_png(summary), inputs)
        return
    import html
    e = lambda t: html.escape(str(t), quote=True)  # noqa: E731
    page = (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>History of {e(summary['machine_id'])}"
            f"</title></head><body>{history_section(summary)}</body></html>")
    write_output(path, page, inputs)


def history_section(summary: dict) -> str:
    """The history as an HTML section (figure and flagged changes), for ``history show --plot
    X.html`` and ``rotacal report --history``. Every text from the store is escaped."""
    import base64
    import html
    png = _history_png(summary)
    e = lambda t: html.escape(str(t), quote=True)  # noqa: E731
    rows = "".join(
        f"<tr><td>{e(f['name'])}</td><td>{e(f['from_at'])}</td><td>{e(f['to_at'])}</td>"
        f"<td>{f['change'] * _scale(f['unit']):+.3f}</td><td>{_fmt_opt(f['expanded_uncertainty'], f['unit'])}</td>"
        f"<td>{_fmt_opt(f['tolerance'], f['unit'])}</td><td>{e(', '.join(f['why']))}</td></tr>"
        for f in summary["flags"])
    return (f"<section id='history'><h2>Calibration history of {e(summary['machine_id'])} "
            f"({e(summary['machine_type'])})</h2><p>{summary['identifications']} identifications, "
            f"{len(summary['corrections'])} corrections. Values are the machine's own (measured + compensation "
            f"loaded); bands 1-sigma.</p><img alt='location errors over time' "
            f"src='data:image/png;base64,{base64.b64encode(png).decode('ascii')}'>"
            f"<h2>Changes flagged</h2><table border=1 cellpadding=3><tr><th>error</th><th>from</th><th>to</th>"
            f"<th>change (um/urad)</th><th>U, k=2</th><th>tolerance</th><th>why</th></tr>{rows}</table>"
            "</section>")


def _scale(unit: str) -> float:
    return 1e3 if unit == "mm" else 1e6


def _fmt_opt(v: float | None, unit: str) -> str:
    return "-" if v is None else f"{v * _scale(unit):.3f}"


def _history_png(summary: dict) -> bytes:
    import io
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.dates as mdates
    import matplotlib.pyplot as plt
    names = [n for n, d in summary["location_errors"].items() if d["points"]]
    if not names:
        raise _core.InvalidArgument(f"{summary['machine_id']}: no observable location error to plot")

    def when(at: str) -> datetime.datetime:
        return datetime.datetime.strptime(at, "%Y-%m-%dT%H:%M:%SZ")

    cols = 2
    rows = (len(names) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(11, 2.6 * rows), sharex=True, squeeze=False)
    for ax, name in zip(axes.flat, names):
        d = summary["location_errors"][name]
        k = _scale(d["unit"])
        t = [when(p["at"]) for p in d["points"]]
        v = [p["value"] * k for p in d["points"]]
        s = [(p["std"] or 0.0) * k for p in d["points"]]
        ax.fill_between(t, [a - b for a, b in zip(v, s)], [a + b for a, b in zip(v, s)], color="C0", alpha=0.25,
                        linewidth=0)
        ax.plot(t, v, "o-", color="C0", markersize=3, linewidth=1)
        for c in summary["corrections"]:
            if name in c["amounts"]:
                ax.axvline(when(c["at"]), color="C2", linestyle="--", linewidth=1)
        by_entry = {p["entry"]: p for p in d["points"]}
        hit = [by_entry[st["to"]] for st in d["steps"] if st["exceeds_uncertainty"] or st["exceeds_tolerance"]]
        if hit:
            ax.plot([when(p["at"]) for p in hit], [p["value"] * k for p in hit], "o", color="red", markersize=5)
        dr = d["drift_per_month"]
        title = name + (f"  drift {dr['value'] * k:+.3f}/month" if dr else "")
        ax.set_title(title, fontsize=9)
        ax.set_ylabel("um" if d["unit"] == "mm" else "urad")
        ax.xaxis.set_major_formatter(mdates.ConciseDateFormatter(ax.xaxis.get_major_locator()))
    for ax in list(axes.flat)[len(names):]:
        ax.set_visible(False)
    shown_id = str(summary["machine_id"]).replace("$", r"\$")  # never read as mathtext
    fig.suptitle(f"{shown_id} ({summary['machine_type']}): 1-sigma band, corrections dashed green, "
                 "changes beyond k=2 or tolerance red", fontsize=10)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    return buf.getvalue()
