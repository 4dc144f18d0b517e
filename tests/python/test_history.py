# SPDX-License-Identifier: BSD-3-Clause
"""The calibration history (docs/history.md): drift, corrections and flags computed as the
docs define them, against an independent fit; duplicates, unknown machines, bad locations and
foreign or newer stores refused; older stores migrated; two writers at once and a writer killed
mid-write lose nothing. Every store test runs on SQLite and on a real PostgreSQL server that
this file starts (as the postgres user, on a free port, in a temporary folder) and stops."""

import datetime
import json
import os
import shutil
import signal
import socket
import sqlite3
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

import rotacal
from rotacal import history
from rotacal.history import DAYS_PER_MONTH, open_history

from conftest import run_cli

PG_BIN = Path("/usr/lib/postgresql/15/bin")
EXIT_INPUT, EXIT_IO = 3, 4
AC_NAMES = list(rotacal.location_error_names(rotacal.parse_machine_type("AC-trt")))
T0 = datetime.datetime(2026, 1, 1, tzinfo=datetime.timezone.utc)


# ------------------------------------------------------------------------- a real PostgreSQL


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="session")
def postgres_server():
    """A PostgreSQL server of its own: initdb in a temporary folder, reached through a Unix
    socket there; yields an admin URL, stopped and removed at the end."""
    try:
        import psycopg  # noqa: F401
    except ImportError:
        pytest.skip("psycopg 3 is not installed (scripts/setup.sh installs it)")
    if not (PG_BIN / "initdb").exists():
        pytest.skip(f"PostgreSQL server binaries not found in {PG_BIN} (Debian package postgresql)")
    if os.geteuid() != 0:
        pytest.skip(
            "starting PostgreSQL as the postgres user needs root (initdb refuses to run as root itself)"
        )
    root = Path(tempfile.mkdtemp(prefix="rotacal-pg-"))
    shutil.chown(root, "postgres", "postgres")
    data, port = root / "data", _free_port()

    def as_postgres(*cmd, check=True):
        return subprocess.run(
            ["runuser", "-u", "postgres", "--", *map(str, cmd)],
            capture_output=True,
            text=True,
            check=check,
            timeout=120,
        )

    try:
        as_postgres(PG_BIN / "initdb", "-D", data, "-A", "trust", "-U", "postgres", "--no-sync")
        as_postgres(
            PG_BIN / "pg_ctl",
            "-D",
            data,
            "-l",
            root / "log",
            "-w",
            "-t",
            "60",
            "-o",
            f"-p {port} -k {root} -c listen_addresses='' -c fsync=off",
            "start",
        )
    except subprocess.CalledProcessError as e:
        log = (root / "log").read_text() if (root / "log").exists() else ""
        shutil.rmtree(root, ignore_errors=True)
        pytest.fail(f"could not start PostgreSQL: {e.stderr}\n{log}")
    try:
        yield {
            "url": f"postgresql://postgres@/postgres?host={root}&port={port}",
            "root": root,
            "port": port,
        }
    finally:
        as_postgres(PG_BIN / "pg_ctl", "-D", data, "-m", "immediate", "-w", "stop", check=False)
        shutil.rmtree(root, ignore_errors=True)


_db_counter = [0]


@pytest.fixture(params=["sqlite", "postgresql"])
def store(request, tmp_path):
    """The location of an empty store: a SQLite file, or a new database on the server."""
    if request.param == "sqlite":
        yield str(tmp_path / "history.sqlite")
        return
    yield from _new_database(request.getfixturevalue("postgres_server"))


@pytest.fixture
def pg_store(postgres_server):
    yield from _new_database(postgres_server)


def _new_database(server):
    import psycopg

    _db_counter[0] += 1
    name = f"rotacal_test_{_db_counter[0]}"
    with psycopg.connect(server["url"], autocommit=True) as admin:
        admin.execute(f"CREATE DATABASE {name}")
    yield server["url"].replace("/postgres?", f"/{name}?")
    with psycopg.connect(server["url"], autocommit=True) as admin:
        admin.execute(f"DROP DATABASE {name} WITH (FORCE)")


# ------------------------------------------------------------------------- models made here


def at(months: float) -> str:
    return (T0 + datetime.timedelta(days=months * DAYS_PER_MONTH)).strftime("%Y-%m-%dT%H:%M:%SZ")


def model(
    values: dict | None = None,
    std: float = 1e-4,
    sha: str = "0" * 64,
    machine: str = "AC-trt",
    when: str | None = None,
) -> dict:
    """A ballbar model: every location error 0 unless given (mm, rad), one std for all."""
    names = rotacal.location_error_names(rotacal.parse_machine_type(machine))
    values = values or {}
    errors = {
        n: {"value": values.get(n, 0.0), "std": std, "unit": history.unit_of(n)} for n in names
    }
    return {
        "format": "rotacal-model/1",
        "kind": "ballbar",
        "machine": machine,
        "location_errors": errors,
        "source": {
            "session": f"session-{sha[:6]}.csv",
            "session_sha256": sha,
            "identified_at": when or at(0),
            "rotacal": "test",
        },
    }


def sha(i: int, tag: str = "a") -> str:
    return (tag + f"{i:x}").rjust(64, "0")


def export_json(values: dict) -> dict:
    """The part of `rotacal export --json` the history reads: the errors the controller holds."""
    return {
        "controller": "linuxcnc",
        "kinematics": "trt",
        "current_given": False,
        "parameters": [],
        "location_errors": [
            {"name": n, "value": v, "std": 1e-4, "held": True, "where": "pin"}
            for n, v in values.items()
        ],
    }


# ------------------------------------------------------------------------- what show computes


def test_drift_per_month_is_the_weighted_line(store):
    # E_Y0A drifts 0.5 um/month with scatter; the stds differ so that the weights matter.
    rng = np.random.default_rng(3)
    t = np.array([0.0, 1.0, 2.5, 4.0, 6.0, 9.0])
    std = np.array([0.1, 0.3, 0.1, 0.2, 0.1, 0.4]) * 1e-3
    y = 0.070 + 0.5e-3 * t + rng.normal(0, 1, t.size) * std
    with open_history(store) as h:
        for i in range(t.size):
            m = model({"E_Y0A": y[i]}, sha=sha(i), when=at(t[i]))
            m["location_errors"]["E_Y0A"]["std"] = std[i]
            h.add_identification("SN-1", m)
        s = h.show("SN-1")
    d = s["location_errors"]["E_Y0A"]["drift_per_month"]
    # numpy's weighted polyfit (w = 1/sigma) with the unscaled covariance: the same definition.
    coef, cov = np.polyfit(t, y, 1, w=1 / std, cov="unscaled")
    assert d["value"] == pytest.approx(coef[0], rel=1e-5)
    assert d["std"] == pytest.approx(np.sqrt(cov[0, 0]), rel=1e-5)
    assert d["n"] == 6 and d["weighting"] == "1/std^2"
    assert abs(d["value"] - 0.5e-3) < 4 * d["std"]
    assert [p["at"] for p in s["location_errors"]["E_Y0A"]["points"]] == [at(x) for x in t]
    # An error that does not move: drift 0 within its sigma.
    z = s["location_errors"]["E_Z0A"]["drift_per_month"]
    assert abs(z["value"]) <= 1e-12


def test_a_correction_is_not_drift(store):
    # The controller is loaded with E_Y0A = 72 um after the first calibration: the next one
    # measures about 0. The machine did not move by -72 um; it drifted by +0.1 um.
    with open_history(store) as h:
        h.add_identification("SN-1", model({"E_Y0A": 0.072}, sha=sha(1), when=at(0)))
        h.add_correction("SN-1", export_json({"E_Y0A": 0.072}), applied_at=at(0.5), note="loaded")
        h.add_identification("SN-1", model({"E_Y0A": 0.0001}, sha=sha(2), when=at(1)))
        s = h.show("SN-1")
    e = s["location_errors"]["E_Y0A"]
    step = e["steps"][0]
    assert step["measured_change"] == pytest.approx(-0.0719, abs=1e-12)
    assert step["corrections"] == pytest.approx(0.072, abs=1e-15)
    assert step["change"] == pytest.approx(0.0001, abs=1e-12)
    assert e["points"][1]["compensation"] == pytest.approx(0.072) and e["points"][1][
        "value"
    ] == pytest.approx(0.0721)
    assert not step["exceeds_uncertainty"]  # 0.1 um < 2 * sqrt(2) * 0.1 um
    assert e["drift_per_month"]["value"] == pytest.approx(0.0001, rel=1e-3)
    assert (
        s["corrections"][0]["amounts"] == {"E_Y0A": pytest.approx(0.072)}
        and s["corrections"][0]["note"] == "loaded"
    )
    assert [f["name"] for f in s["flags"]] == []
    # Errors the correction did not touch keep compensation 0.
    assert all(p["compensation"] == 0 for p in s["location_errors"]["E_Z0A"]["points"])


def test_flag_beyond_expanded_uncertainty_or_tolerance(store):
    std = 0.1e-3
    u = 2 * np.sqrt(2) * std  # k = 2 uncertainty of a difference of two such calibrations
    with open_history(store) as h:
        h.add_identification("SN-1", model({}, std=std, sha=sha(1), when=at(0)))
        h.add_identification(
            "SN-1", model({"E_Y0A": 0.9 * u, "E_Z0A": 1.1 * u}, std=std, sha=sha(2), when=at(1))
        )
        s = h.show("SN-1")
        assert [(f["name"], f["why"]) for f in s["flags"]] == [
            ("E_Z0A", ["exceeds k=2 uncertainty"])
        ]
        assert s["flags"][0]["expanded_uncertainty"] == pytest.approx(u)
        # A tolerance tighter than the change flags it too; position= applies to every mm error.
        s = h.show("SN-1", {"E_Y0A": 0.5 * u})
        assert {f["name"]: f["why"] for f in s["flags"]} == {
            "E_Y0A": ["exceeds tolerance"],
            "E_Z0A": ["exceeds k=2 uncertainty"],
        }
        s = h.show("SN-1", {"position": 0.5 * u, "E_Z0A": 10 * u})
        assert {f["name"]: f["why"] for f in s["flags"]} == {
            "E_Y0A": ["exceeds tolerance"],
            "E_Z0A": ["exceeds k=2 uncertainty"],
        }
        with pytest.raises(rotacal.InvalidArgument, match="E_Q0Q"):
            h.show("SN-1", {"E_Q0Q": 1.0})


def test_unobservable_values_are_left_out_not_zero(store):
    m2 = model({"E_Y0A": 0.001}, sha=sha(2), when=at(1))
    m2["location_errors"]["E_Y0A"] = {"value": None, "std": None, "unit": "mm", "observable": False}
    with open_history(store) as h:
        h.add_identification("SN-1", model({"E_Y0A": 0.001}, sha=sha(1), when=at(0)))
        e2 = h.add_identification("SN-1", m2)
        h.add_identification("SN-1", model({"E_Y0A": 0.001}, sha=sha(3), when=at(2)))
        e = h.show("SN-1")["location_errors"]["E_Y0A"]
    assert e["unobservable_in"] == [e2] and len(e["points"]) == 2
    assert e["steps"][0]["change"] == pytest.approx(0.0, abs=1e-15)


# ------------------------------------------------------------------------- refused


def test_a_session_is_stored_once(store):
    with open_history(store) as h:
        h.add_identification("SN-1", model(sha=sha(1)))
        with pytest.raises(
            rotacal.InvalidArgument, match="already stored: entry 1 of machine 'SN-1'"
        ):
            h.add_identification("SN-2", model(sha=sha(1)))
        c = export_json({"E_Y0A": 0.01})
        h.add_correction("SN-1", c)
        with pytest.raises(rotacal.InvalidArgument, match="already stored"):
            h.add_correction("SN-1", c)
        assert h.machines() == [
            {
                "machine_id": "SN-1",
                "machine_type": "AC-trt",
                "identifications": 1,
                "corrections": 1,
                "first": at(0),
                "last": h.machines()[0]["last"],
            }
        ]


def test_unknown_machine_and_wrong_type(store):
    with open_history(store) as h:
        h.add_identification("SN-1", model(sha=sha(1)))
        with pytest.raises(rotacal.InvalidArgument, match=r"'SN-9'.*known: 'SN-1'"):
            h.show("SN-9")
        with pytest.raises(rotacal.InvalidArgument, match="'SN-9'"):
            h.add_correction("SN-9", export_json({"E_Y0A": 0.01}))
        with pytest.raises(rotacal.InvalidArgument, match="is a AC-trt in the store"):
            h.add_identification("SN-1", model(sha=sha(2), machine="BC-trt"))
        with pytest.raises(rotacal.InvalidArgument, match="machine-id"):
            h.add_identification("  ", model(sha=sha(3)))
        with pytest.raises(rotacal.InvalidArgument, match="--date"):
            h.add_identification("SN-1", model(sha=sha(4)), measured_at="yesterday")
        with pytest.raises(rotacal.InvalidArgument, match="E_Y0A.value"):
            h.add_identification("SN-1", model({"E_Y0A": float("nan")}, sha=sha(5)))
        assert h.machines()[0]["identifications"] == 1


@pytest.mark.parametrize(
    "url, what",
    [
        ("postgresql://user@host:notaport/db", "malformed URL"),
        ("mysql://user@host/db", "not mysql://"),
        ("postgresql://user@host/db?sslmode", "malformed URL"),
    ],
)
def test_malformed_url(url, what):
    pytest.importorskip("psycopg")
    with pytest.raises(rotacal.InvalidArgument, match=what):
        open_history(url)


def test_unreachable_server_is_an_io_error_without_the_password():
    pytest.importorskip("psycopg")
    with pytest.raises(rotacal.IoError) as e:
        open_history(f"postgresql://u:s3cret@127.0.0.1:{_free_port()}/db?connect_timeout=5")
    assert "s3cret" not in str(e.value) and "***" in str(e.value)


def test_sqlite_files_that_are_not_stores(tmp_path):
    text = tmp_path / "notes.txt"
    text.write_text("not a database\n" * 100)
    with pytest.raises(rotacal.InvalidArgument, match="not a rotacal history store"):
        open_history(str(text))
    other = tmp_path / "other.sqlite"
    with sqlite3.connect(other) as c:
        c.execute("CREATE TABLE parts (id INTEGER)")
    with pytest.raises(rotacal.InvalidArgument, match="not a rotacal history store.*parts"):
        open_history(str(other))
    with pytest.raises(rotacal.IoError, match="does not exist"):
        open_history(str(tmp_path / "missing" / "h.sqlite"))


# ------------------------------------------------------------------------- schema versions

# Version 1 as released, written out here so that a change to the migrations shows up.
V1 = [
    "CREATE TABLE rotacal_history_schema (version INTEGER PRIMARY KEY, applied_at TEXT NOT NULL)",
    "CREATE TABLE machines (machine_id TEXT PRIMARY KEY, machine_type TEXT NOT NULL, first_stored_at TEXT NOT NULL)",
    "CREATE TABLE calibrations (id {id}, machine_id TEXT NOT NULL REFERENCES machines (machine_id), "
    "kind TEXT NOT NULL, test TEXT NOT NULL, measured_at TEXT NOT NULL, stored_at TEXT NOT NULL, "
    "session TEXT, source_sha256 TEXT NOT NULL, note TEXT, document TEXT NOT NULL, UNIQUE (kind, source_sha256))",
    "CREATE TABLE estimates (calibration_id BIGINT NOT NULL REFERENCES calibrations (id), part TEXT NOT NULL, "
    "name TEXT NOT NULL, value {real}, std {real}, unit TEXT, PRIMARY KEY (calibration_id, part, name))",
    "CREATE INDEX calibrations_by_machine ON calibrations (machine_id, measured_at, id)",
    "INSERT INTO rotacal_history_schema VALUES (1, '2026-01-01T00:00:00Z')",
    "INSERT INTO machines VALUES ('OLD-1', 'AC-trt', '2026-01-01T00:00:00Z')",
    "INSERT INTO calibrations (machine_id, kind, test, measured_at, stored_at, session, source_sha256, note, "
    "document) VALUES ('OLD-1', 'identification', 'ballbar', '2026-01-01T00:00:00Z', '2026-01-01T00:00:00Z', "
    "'old.csv', 'cafe', 'stored by version 1', '{{}}')",
    "INSERT INTO estimates VALUES (1, 'location_errors', 'E_Y0A', 0.07, 0.0001, 'mm')",
]


def _raw(store: str, statements: list[str]) -> None:
    """Run SQL on the store directly, as another program (or an older rotacal) would."""
    if store.startswith("postgresql://"):
        import psycopg

        with psycopg.connect(store, autocommit=True) as c:
            for s in statements:
                c.execute(
                    s.format(
                        id="BIGINT GENERATED BY DEFAULT AS IDENTITY PRIMARY KEY",
                        real="DOUBLE PRECISION",
                    )
                )
    else:
        with sqlite3.connect(store) as c:
            for s in statements:
                c.execute(s.format(id="INTEGER PRIMARY KEY", real="REAL"))
        c.close()


def test_a_version_1_store_is_migrated(store):
    _raw(store, V1)
    with open_history(store) as h:
        assert h.schema_version == history.SCHEMA_VERSION == 2
        old = h.show("OLD-1")
        assert old["calibrations"][0]["note"] == "stored by version 1"
        assert old["location_errors"]["E_Y0A"]["points"][0]["value"] == pytest.approx(0.07)
        new = h.add_identification(
            "OLD-1",
            model({"E_Y0A": 0.0701}, sha=sha(1), when=at(1)),
            details={"identification": {"noise_model": {"white": True}}},
            controller="pin=1",
        )
        assert h.entry(new)["details"] == {"identification": {"noise_model": {"white": True}}}
        assert h.entry(new)["controller"] == "pin=1"
        assert h.entry(1)["details"] is None
    with open_history(store) as h:  # opened again: nothing left to migrate
        assert h.schema_version == 2 and h.machines()[0]["identifications"] == 2


def test_a_newer_store_is_refused(store):
    with open_history(store):
        pass
    _raw(store, ["INSERT INTO rotacal_history_schema VALUES (99, '2030-01-01T00:00:00Z')"])
    with pytest.raises(rotacal.InvalidArgument, match="schema version 99.*newer.*upgrade rotacal"):
        open_history(store)


# ------------------------------------------------------------------------- concurrency and crashes


def _child(code: str) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    return subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(code)],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


HELPERS = f"""
import sys, time, os
from rotacal.history import open_history
T = {T0.isoformat()!r}
def model(i, tag):
    import rotacal
    names = rotacal.location_error_names(rotacal.parse_machine_type("AC-trt"))
    e = {{n: {{"value": 1e-6 * i, "std": 1e-4, "unit": "mm" if n[2] in "XYZ" else "rad"}} for n in names}}
    return {{"format": "rotacal-model/1", "kind": "ballbar", "machine": "AC-trt", "location_errors": e,
            "source": {{"session": f"{{tag}}{{i}}.csv", "session_sha256": (tag + format(i, "x")).rjust(64, "0"),
                       "identified_at": "2026-01-01T00:00:00Z"}}}}
"""


def test_two_writers_at_once_lose_nothing(store, tmp_path):
    go = tmp_path / "go"
    procs = []
    for tag in ("a", "b"):
        procs.append(
            _child(
                HELPERS
                + f"""
h = open_history({store!r})
while not os.path.exists({str(go)!r}):
    time.sleep(0.01)
for i in range(200):
    h.add_identification("SN-{tag}" if i % 2 else "SN-shared", model(i, {tag!r}))
h.close()
print("done")
"""
            )
        )
    time.sleep(0.5)
    go.write_text("go")
    for p in procs:
        out, err = p.communicate(timeout=600)
        assert p.returncode == 0 and out.strip() == "done", err
    with open_history(store) as h:
        m = {x["machine_id"]: x["identifications"] for x in h.machines()}
        assert m == {"SN-a": 100, "SN-b": 100, "SN-shared": 200}
        assert len(h.entries("SN-shared")[1]) == 200
        assert all(len(e.estimates) == 8 for e in h.entries("SN-shared")[1])


def test_a_writer_killed_mid_write_leaves_the_store_readable(store):
    # The child stores 3 calibrations, then dies (SIGKILL) after inserting the 4th one's row
    # and before its estimates: the transaction never commits.
    p = _child(
        HELPERS
        + f"""
import signal
from rotacal.history import CalibrationHistory
h = open_history({store!r})
for i in range(3):
    h.add_identification("SN-1", model(i, "k"))
CalibrationHistory._insert_estimates = lambda *a: os.kill(os.getpid(), signal.SIGKILL)
h.add_identification("SN-1", model(3, "k"))
print("not killed")
"""
    )
    out, err = p.communicate(timeout=120)
    assert p.returncode == -signal.SIGKILL, (out, err)
    with open_history(store) as h:
        kind, entries = h.entries("SN-1")
        assert len(entries) == 3 and all(len(e.estimates) == 8 for e in entries)
        h.add_identification(
            "SN-1", model(sha=sha(3, "k"))
        )  # the killed one goes in now: nothing half-stored blocks it
        assert len(h.entries("SN-1")[1]) == 4


# ------------------------------------------------------------------------- the command line


def cli(*args, env=None):
    r = run_cli(*args, env=env)
    assert "Traceback" not in r.stderr, r.stderr
    return r


def test_cli_end_to_end(shared_data, tmp_path):
    db = tmp_path / "h.sqlite"
    session = shared_data / "ballbar_ac_table2.csv"
    r = cli(
        "identify",
        session,
        "--store",
        "--machine-id",
        "DMU-1234",
        "--note",
        "after crash",
        "--date",
        "2026-01-10",
        "--no-budget",
        "--db",
        db,
    )
    assert r.returncode == 0, r.stderr
    assert "stored as entry 1 of machine 'DMU-1234'" in r.stderr
    r = cli("identify", session, "--store", "--machine-id", "DMU-1234", "--no-budget", "--db", db)
    assert r.returncode == EXIT_INPUT and "already stored" in r.stderr
    # A second calibration a month later, and the export loaded in between.
    model_path, sim = tmp_path / "m2.json", tmp_path / "s2.csv"
    assert (
        cli(
            "simulate", "ballbar", "--errors", "table2", "--seed", "5", "--noise", "0.5", "-o", sim
        ).returncode
        == 0
    )
    assert cli("identify", sim, "--save-model", model_path, "--no-budget").returncode == 0
    export = tmp_path / "export.json"
    r = cli("export", "--model", model_path, "--controller", "linuxcnc", "--json")
    assert r.returncode == 0, r.stderr
    export.write_text(r.stdout)
    assert (
        cli(
            "history",
            "add",
            "--correction",
            export,
            "--machine-id",
            "DMU-1234",
            "--date",
            "2026-01-20",
            "--db",
            db,
        ).returncode
        == 0
    )
    r = cli(
        "history", "add", model_path, "--machine-id", "DMU-1234", "--date", "2026-02-10", "--db", db
    )
    assert r.returncode == 0, r.stderr
    r = cli("history", "show", "DMU-1234", "--json", "--db", db, "--tolerance", "position=1000")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["identifications"] == 2 and len(s["corrections"]) == 1
    e = s["location_errors"]["E_Y0A"]
    held = s["corrections"][0]["amounts"]["E_Y0A"]
    assert e["steps"][0]["change"] == pytest.approx(e["steps"][0]["measured_change"] + held)
    assert e["steps"][0]["tolerance"] == pytest.approx(1.0)  # 1000 um in mm
    r = cli("history", "show", "DMU-1234", "--db", db, "--plot", tmp_path / "h.png")
    assert r.returncode == 0 and "DMU-1234 (AC-trt): 2 identifications" in r.stdout
    assert (tmp_path / "h.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (
        cli("history", "show", "DMU-1234", "--db", db, "--plot", tmp_path / "h.html").returncode
        == 0
    )
    assert "data:image/png;base64," in (tmp_path / "h.html").read_text()
    # The session report carries the same history section; an unknown machine is refused first.
    rep = tmp_path / "report.html"
    r = cli("report", sim, "--no-diagnosis", "--history", "DMU-1234", "--db", db, "-o", rep)
    assert r.returncode == 0, r.stderr
    page = rep.read_text()
    assert "Calibration history of DMU-1234" in page and page.count("data:image/png;base64,") >= 3
    r = cli(
        "report", sim, "--no-diagnosis", "--history", "NOPE", "--db", db, "-o", tmp_path / "r2.html"
    )
    assert r.returncode == EXIT_INPUT and not (tmp_path / "r2.html").exists()
    r = cli("history", "list", "--json", "--db", db)
    assert json.loads(r.stdout)["machines"][0]["machine_id"] == "DMU-1234"
    # ROTACAL_HISTORY names the default store.
    assert "DMU-1234" in cli("history", "list", env={"ROTACAL_HISTORY": str(db)}).stdout
    # Refused: exit 3 for content and arguments, 4 for the file system.
    for args, code, text in [
        (("history", "show", "NOPE", "--db", db), EXIT_INPUT, "'NOPE'"),
        (
            ("history", "show", "DMU-1234", "--db", "postgresql://u@h:xx/d"),
            EXIT_INPUT,
            "malformed URL",
        ),
        (
            ("history", "show", "DMU-1234", "--db", db, "--tolerance", "E_Y0A=-1"),
            EXIT_INPUT,
            "--tolerance",
        ),
        (
            ("history", "show", "DMU-1234", "--db", db, "--plot", tmp_path / "h.pdf"),
            EXIT_INPUT,
            ".png or .html",
        ),
        (
            ("history", "add", model_path, "--machine-id", "X", "--db", session),
            EXIT_INPUT,
            "not a rotacal history",
        ),
        (("history", "add", "--machine-id", "X", "--db", db), EXIT_INPUT, "--correction"),
        (
            ("history", "add", "--correction", model_path, "--machine-id", "DMU-1234", "--db", db),
            EXIT_INPUT,
            "rotacal export --json",
        ),
        (("history", "list", "--db", tmp_path / "no" / "h.sqlite"), EXIT_IO, "does not exist"),
        (("identify", session, "--machine-id", "M"), EXIT_INPUT, "--store"),
    ]:
        r = cli(*args)
        assert r.returncode == code and text in r.stderr, (args, r.returncode, r.stderr)


def test_cli_against_postgresql(pg_store, shared_data):
    store = pg_store
    r = cli(
        "identify",
        shared_data / "ballbar_ac_table2.csv",
        "--store",
        "--machine-id",
        "DMU-1",
        "--no-budget",
        "--db",
        store,
    )
    assert r.returncode == 0, r.stderr
    r = cli("history", "show", "DMU-1", "--json", "--db", store)
    assert r.returncode == 0 and json.loads(r.stdout)["identifications"] == 1
