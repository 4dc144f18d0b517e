# SPDX-License-Identifier: BSD-3-Clause
"""Hostile and careless input at the command line and the Python API (issue 17): each row is a
reproducer of the issue, and each must end in a clean refusal with the documented exit code
(3 invalid content or arguments, 4 file system or device) or a correct result; never a
traceback, never a file destroyed."""

import json
import os
import random
import resource
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rotacal

from conftest import run_cli

EXIT_INPUT, EXIT_IO = 3, 4


def rotacal_cli(*args, cwd=None, timeout=300, memory_bytes=None):
    """In this process, unless under a memory limit (a child's, so that a runaway reader fails
    inside it and does not take the machine)."""

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (memory_bytes, memory_bytes))

    if memory_bytes is None:
        r = run_cli(*args, cwd=cwd)
    else:
        r = subprocess.run(
            [sys.executable, "-m", "rotacal", *map(str, args)],
            capture_output=True,
            text=True,
            errors="replace",
            cwd=cwd,
            timeout=timeout,
            preexec_fn=limit,
        )
    assert "Traceback" not in r.stderr, r.stderr[-3000:]
    return r


def strict_json(text):
    def refuse(name):
        raise ValueError(f"not strict JSON: {name}")

    return json.loads(text, parse_constant=refuse)


# ------------------------------------------------------------------------- the files


def _rows(path):
    """(comment lines + column line, data rows) of a session file."""
    lines = [ln for ln in Path(path).read_text().split("\n") if ln]
    n = next(i for i, ln in enumerate(lines) if not ln.startswith("#")) + 1
    return lines[:n], lines[n:]


def _with_field(rows, k, col, value):
    f = rows[k].split(",")
    f[col] = value
    return rows[:k] + [",".join(f)] + rows[k + 1 :]


@pytest.fixture(scope="module")
def files(shared_data, tmp_path_factory):
    d = tmp_path_factory.mktemp("hostile")
    src = shared_data / "ballbar_ac_table2.csv"
    raw = src.read_bytes()
    head, rows = _rows(src)
    out = {"good": src, "rtest": shared_data / "rtest_bc_oyama.csv"}

    lines = raw.split(b"\n")
    k = len(head) + 3  # a data row: its line number is k + 1
    bad = bytearray(lines[k])
    bad[-2] = 0xFF  # inside the length
    out["nonutf8_line"] = (k + 1, len(lines[k]) - 1)
    lines_bad = list(lines)
    lines_bad[k] = bytes(bad)
    (d / "nonutf8.csv").write_bytes(b"\n".join(lines_bad))
    lines_label = list(lines)
    lines_label[k] = b"\xfe\xfelabel" + lines[k][lines[k].index(b",") :]
    (d / "label.csv").write_bytes(b"\n".join(lines_label))
    (d / "utf16.csv").write_bytes(raw.decode().encode("utf-16"))
    rng = random.Random(17)
    (d / "random.csv").write_bytes(bytes(rng.randrange(256) for _ in range(20000)))
    (d / "cr.csv").write_bytes(raw.replace(b"\n", b"\r"))

    script = "<script>alert(1)</script>"
    first_label = rows[0].split(",")[0]
    (d / "html.csv").write_text(
        "\n".join(
            head
            + [
                script + r[len(first_label) :] if r.startswith(first_label + ",") else r
                for r in rows
            ]
        )
        + "\n"
    )
    # One row, again and again: nothing is determined (NaN and infinity inside the fit).
    same = [
        ",".join([rows[100].split(",")[0], f"{0.1 * i:.1f}", *rows[100].split(",")[2:]])
        for i in range(200)
    ]
    (d / "same.csv").write_text("\n".join(head + same) + "\n")
    (d / "big_length.csv").write_text("\n".join(head + _with_field(rows, 5, 7, "1e308")) + "\n")
    (d / "big_x.csv").write_text("\n".join(head + _with_field(rows, 5, 2, "1e160")) + "\n")
    rhead, rrows = _rows(out["rtest"])
    cols = rhead[-1].split(",")
    (d / "big_dx.csv").write_text(
        "\n".join(rhead + _with_field(rrows, 5, cols.index("dx"), "1e308")) + "\n"
    )
    (d / "big_b.csv").write_text(
        "\n".join(rhead + _with_field(rrows, 5, cols.index("B"), "1e308")) + "\n"
    )
    out.update({p.stem: p for p in d.glob("*.csv")})
    out["dir"] = d
    return out


# ------------------------------------------------------------------------- option limits

SIM = ("simulate", "ballbar")
SIM_R = ("simulate", "rtest")


@pytest.mark.parametrize(
    "args,option",
    [
        (SIM_R + ("--c-step", "1e-7"), "--c-step"),
        (SIM_R + ("--b-step", "1e-7"), "--b-step"),
        (SIM_R + ("--dwell", "-1"), "--dwell"),
        (SIM_R + ("--dwell", "nan"), "--dwell"),
        (SIM_R + ("--noise", "1e5"), "--noise"),
        (SIM_R + ("--seed", "-1"), "--seed"),
        (SIM + ("--seed", "-1"), "--seed"),
        (SIM + ("--seed", "12345678901234567890"), "--seed"),
        (SIM + ("--seed", "1.5"), "--seed"),
        (SIM + ("--pivot-error", "-1"), "--pivot-error"),
        (SIM + ("--noise", "1e5"), "--noise"),
        (SIM + ("--noise", "inf"), "--noise"),
        (SIM + ("--length", "5", "--noise", "999"), "--noise"),
        (SIM + ("--effect", "gravity_sag_A=nan"), "gravity_sag_A"),
        (SIM + ("--errors", "E_Y0A=1e300"), "E_Y0A"),
        (("plan", "ballbar", "--length", "1e9"), "--length"),
        (("plan", "ballbar", "--length", "1e300"), "--length"),
        (("plan", "ballbar", "--length", "0"), "--length"),
        (("plan", "ballbar", "--pivot", "1e300,0,60"), "--pivot"),
        (("plan", "ballbar", "--step", "0"), "--step"),
        (("plan", "ballbar", "--step", "-1"), "--step"),
        (("plan", "ballbar", "--feed", "0"), "--feed"),
        (("plan", "ballbar", "--a-range", "-1e9,90"), "--a-range"),
    ],
)
def test_numeric_options_are_bounded(tmp_path, args, option):
    out = tmp_path / "out.any"
    r = rotacal_cli(*args, "-o", out, timeout=60)
    assert r.returncode == EXIT_INPUT and option in r.stderr, r.stderr
    assert not out.exists()


@pytest.mark.parametrize("value", ["100000", "-1", "0", "x"])
def test_max_harmonic_is_bounded(files, value):
    r = rotacal_cli("diagnose", files["good"], "--max-harmonic", value, timeout=60)
    assert r.returncode == EXIT_INPUT and "--max-harmonic" in r.stderr, r.stderr


@pytest.mark.parametrize(
    "command",
    [
        ("report", "{good}"),
        ("predict", "{good}", "--model", "{good}"),
        ("simulate", "ballbar"),
        ("plan", "ballbar"),
    ],
)
def test_empty_output_name(files, command):
    r = rotacal_cli(*[c.format(**files) for c in command], "-o", "", timeout=60)
    assert r.returncode == EXIT_INPUT and "--output" in r.stderr and "empty" in r.stderr, r.stderr


def test_monte_carlo_draws_bounded(files):
    r = rotacal_cli("identify", files["good"], "--monte-carlo", "-5")
    assert r.returncode == EXIT_INPUT and "--monte-carlo" in r.stderr


# ------------------------------------------------------------------------- input decoding


@pytest.mark.parametrize("command", ["identify", "diagnose", "report"])
def test_non_utf8_byte_names_file_line_column(files, tmp_path, command):
    extra = ["-o", tmp_path / "r.html"] if command == "report" else []
    r = rotacal_cli(command, files["nonutf8"], *extra, timeout=60)
    line, col = files["nonutf8_line"]
    assert r.returncode == EXIT_INPUT, r.stderr
    assert (
        f"nonutf8.csv:{line}:{col}:" in r.stderr
        and "0xff" in r.stderr.lower()
        and "UTF-8" in r.stderr
    )
    assert not (tmp_path / "r.html").exists()


@pytest.mark.parametrize(
    "command", [("identify",), ("diagnose", "--json"), ("report", "-o", "{out}")]
)
def test_non_utf8_label_refused_by_every_command(files, tmp_path, command):
    # A label that is not UTF-8 used to pass identify and crash report, diagnose --json.
    r = rotacal_cli(
        command[0],
        files["label"],
        *[c.format(out=tmp_path / "r.html") for c in command[1:]],
        timeout=60,
    )
    assert r.returncode == EXIT_INPUT and "label.csv:" in r.stderr and "0xfe" in r.stderr.lower(), (
        r.stderr
    )


def test_utf16_said_so(files):
    r = rotacal_cli("identify", files["utf16"])
    assert r.returncode == EXIT_INPUT and "utf16.csv:1:1" in r.stderr and "UTF-16" in r.stderr


def test_random_bytes(files):
    r = rotacal_cli("identify", files["random"])
    assert r.returncode == EXIT_INPUT and "random.csv:1:" in r.stderr


def test_dev_urandom_ends_in_a_parse_error():
    r = rotacal_cli("identify", "/dev/urandom", timeout=60, memory_bytes=2 << 30)
    assert r.returncode == EXIT_INPUT and "/dev/urandom:" in r.stderr, r.stderr


def test_dev_zero_ends_cleanly_within_bounded_memory():
    # NUL bytes are UTF-8: the C++ reader's line bound must stop it; under a 2 GB cap either
    # way it must end with a documented code and a one-line message, not a traceback.
    r = rotacal_cli("identify", "/dev/zero", timeout=120, memory_bytes=2 << 30)
    assert r.returncode in (EXIT_INPUT, EXIT_IO), r.stderr
    assert len(r.stderr) < 3000


def test_cr_only_file_message_is_bounded(files):
    r = rotacal_cli("identify", files["cr"])
    assert r.returncode == EXIT_INPUT and "cr.csv" in r.stderr
    assert len(r.stderr) < 3000, len(r.stderr)


def test_directory_as_input_is_a_file_system_error(files):
    r = rotacal_cli("identify", files["dir"])
    assert r.returncode == EXIT_IO and "directory" in r.stderr, r.stderr


def test_missing_input_is_a_file_system_error(files):
    r = rotacal_cli("identify", files["dir"] / "missing.csv")
    assert r.returncode == EXIT_IO and "missing.csv" in r.stderr


def test_load_refuses_what_is_no_path(files):
    with pytest.raises(rotacal.InvalidArgument, match="expected a file path"):
        rotacal.load(None)
    with pytest.raises(rotacal.InvalidArgument, match="NUL"):
        rotacal.load(str(files["good"]) + "\x00junk")
    with pytest.raises(rotacal.InvalidArgument, match="empty"):
        rotacal.load("")
    with pytest.raises(rotacal.ParseError, match="not UTF-8"):
        rotacal.load(files["nonutf8"])


# ------------------------------------------------------------------------- HTML and JSON

SCRIPT = "<script>alert(1)</script>"


def test_report_escapes_labels(files, tmp_path):
    out = tmp_path / "r.html"
    r = rotacal_cli("report", files["html"], "-o", out)
    assert r.returncode == 0, r.stderr
    page = out.read_text()
    assert SCRIPT not in page and "&lt;script&gt;alert(1)&lt;/script&gt;" in page


def test_diagnose_report_escapes_labels(files, tmp_path):
    out = tmp_path / "d.html"
    r = rotacal_cli("diagnose", files["html"], "--report", out)
    assert r.returncode == 0, r.stderr
    page = out.read_text()
    assert SCRIPT not in page and "&lt;script&gt;" in page


def test_json_is_strict_on_identical_rows(files, tmp_path):
    # The CLI checks plausibility first: identical rows never move the axes (exit 3, named).
    r = rotacal_cli("diagnose", files["same"], "--json")
    assert r.returncode == 3 and "axes never move" in r.stderr, r.stderr
    # Through the API (which leaves that check to the caller) identical rows leave chi2 and
    # p-values undetermined (NaN, infinity): strict JSON has null there and says why.
    import rotacal
    from rotacal import jsontext

    s = rotacal.load(files["same"])
    d = strict_json(jsontext.dumps(rotacal.diagnose(s).to_dict()))
    assert d["baseline"]["p_value"] is None
    assert "not determined" in d["null_reasons"]["/baseline/p_value"]
    result = rotacal.identify(s)
    assert (
        strict_json(jsontext.dumps(result.to_dict()))["location_errors"]["E_Y0A"]["value"] is None
    )
    model = tmp_path / "m.json"
    rotacal.save_model(result.model_dict(), model)
    strict_json(model.read_text())


def test_jsontext_writes_null_with_reasons():
    from rotacal import jsontext

    d = strict_json(
        jsontext.dumps({"a": float("inf"), "b/c": [1.0, float("nan")], "d": -float("inf")})
    )
    assert d["a"] is None and d["b/c"] == [1.0, None]
    assert d["null_reasons"] == {
        "/a": "+Infinity: not determined by the data",
        "/b~1c/1": "NaN: not determined by the data",
        "/d": "-Infinity: not determined by the data",
    }


def test_first_non_utf8_counts_lines_across_chunks(tmp_path):
    from rotacal.sessions import first_non_utf8

    text = ("a" * 99 + "\n") * 700  # 70 kB: past the first 64 kB chunk
    body = text.encode() + "é\n".encode() + b"xy\xc3" + b"(\n"  # a broken two-byte sequence
    (tmp_path / "f").write_bytes(body)
    assert first_non_utf8(str(tmp_path / "f")) == (702, 3, 0xC3)
    (tmp_path / "g").write_bytes(text.encode())
    assert first_non_utf8(str(tmp_path / "g")) is None
    # a two-byte character split across the chunk boundary is not an error
    split = b"a" * ((1 << 16) - 1) + "é".encode() + b"\n\xff"
    (tmp_path / "h").write_bytes(split)
    assert first_non_utf8(str(tmp_path / "h")) == (2, 1, 0xFF)


def test_predict_refuses_a_model_with_infinity(files, tmp_path):
    model = tmp_path / "m.json"
    assert rotacal_cli("identify", files["good"], "--save-model", model).returncode == 0
    d = json.loads(model.read_text())
    d["location_errors"]["E_Y0A"]["value"] = float("inf")
    model.write_text(json.dumps(d))  # Python writes the non-standard Infinity
    r = rotacal_cli("predict", files["good"], "--model", model, "-o", tmp_path / "p.csv")
    assert r.returncode == EXIT_INPUT and ("m.json:1:" in r.stderr or "E_Y0A" in r.stderr), r.stderr
    assert not (tmp_path / "p.csv").exists()


# ------------------------------------------------------------------------- outputs


def test_predict_refuses_to_overwrite_its_input(files, tmp_path):
    session = tmp_path / "s.csv"
    session.write_bytes(files["good"].read_bytes())
    model = tmp_path / "m.json"
    assert rotacal_cli("identify", session, "--save-model", model).returncode == 0
    before = session.read_bytes()
    r = rotacal_cli("predict", session, "--model", model, "-o", session)
    assert r.returncode == EXIT_IO and "s.csv" in r.stderr, r.stderr
    assert session.read_bytes() == before
    r = rotacal_cli("predict", session, "--model", model, "-o", model)
    assert r.returncode == EXIT_IO
    r = rotacal_cli("identify", session, "--save-model", session)
    assert r.returncode == EXIT_IO and session.read_bytes() == before


@pytest.mark.parametrize("kind", ["ballbar", "rtest"])
def test_simulate_refuses_the_same_file_for_session_and_truth(tmp_path, kind):
    x = tmp_path / "x.csv"
    r = rotacal_cli("simulate", kind, "-o", x, "--truth", x, timeout=120)
    assert r.returncode == EXIT_IO and "x.csv" in r.stderr, r.stderr
    assert not x.exists()


def test_plan_refuses_the_same_file_for_program_and_session(tmp_path):
    p = tmp_path / "p.ngc"
    r = rotacal_cli("plan", "ballbar", "-o", p, "--session", p)
    assert r.returncode == EXIT_IO and not p.exists()


def test_missing_output_folder_is_an_error(files, tmp_path):
    out = tmp_path / "no" / "such" / "r.html"
    r = rotacal_cli("report", files["good"], "--no-diagnosis", "-o", out)
    assert r.returncode == EXIT_IO, r.stderr
    assert not (tmp_path / "no").exists()


@pytest.mark.parametrize("kind", ["ballbar", "rtest"])
def test_record_checks_its_output_before_opening_the_port(tmp_path, kind):
    # The port does not exist either: the output is refused first, by the output rule.
    out = tmp_path / "no" / "rec.csv"
    r = rotacal_cli("record", kind, "--port", tmp_path / "ttyNONE", "-o", out, "--no-progress")
    assert r.returncode == EXIT_IO, r.stderr
    assert "does not exist" in r.stderr and "rec.csv" in r.stderr, r.stderr
    r = rotacal_cli("record", kind, "--port", tmp_path / "ttyNONE", "-o", tmp_path, "--no-progress")
    assert r.returncode == EXIT_IO and "directory" in r.stderr, r.stderr


def test_devices_written_through_not_replaced(files):
    for args in (
        ("simulate", "ballbar", "-o", "/dev/null"),
        ("plan", "ballbar", "-o", "/dev/null"),
        ("report", files["good"], "--no-diagnosis", "-o", "/dev/null"),
    ):
        r = rotacal_cli(*args)
        assert r.returncode == 0, (args, r.stderr)
        assert stat.S_ISCHR(os.stat("/dev/null").st_mode)


@pytest.mark.skipif(os.geteuid() != 0, reason="mknod needs root")
def test_own_null_device_is_not_replaced(files, tmp_path):
    # The reproducer: mknod mynull c 1 3; rotacal report S.csv -o mynull
    mynull = tmp_path / "mynull"
    os.mknod(mynull, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    r = rotacal_cli("report", files["good"], "--no-diagnosis", "-o", mynull)
    assert r.returncode == 0, r.stderr
    assert stat.S_ISCHR(os.stat(mynull).st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mynull"]


def test_failure_leaves_nothing_behind(files, tmp_path):
    for args in (
        ("report", files["nonutf8"], "-o", tmp_path / "r.html"),
        ("simulate", "ballbar", "--effect", "no_such_effect=1", "-o", tmp_path / "s.csv"),
        ("predict", files["good"], "--model", files["good"], "-o", tmp_path / "p.csv"),
    ):
        r = rotacal_cli(*args)
        assert r.returncode == EXIT_INPUT, (args, r.stderr)
    assert list(tmp_path.iterdir()) == []


def test_megabyte_label_report_is_bounded(files, tmp_path):
    # A 1 MB test label took 14 GB in report: numpy widened every row's label to the longest.
    head, rows = _rows(files["good"])
    first = rows[0].split(",")[0]
    label = "L" * 1_000_000
    src = tmp_path / "label.csv"
    src.write_text(
        "\n".join(
            head + [label + r[len(first) :] if r.startswith(first + ",") else r for r in rows]
        )
        + "\n"
    )
    r = rotacal_cli(
        "report",
        src,
        "--no-diagnosis",
        "-o",
        tmp_path / "r.html",
        timeout=300,
        memory_bytes=4 << 30,
    )
    assert r.returncode in (0, EXIT_INPUT), r.stderr[-500:]


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_full_disk_is_a_file_system_error(files):
    for args in (
        ("simulate", "ballbar", "-o", "/dev/full"),
        ("identify", files["good"], "--save-model", "/dev/full"),
        ("plan", "ballbar", "-o", "/dev/full"),
    ):
        r = rotacal_cli(*args)
        assert r.returncode == EXIT_IO and "/dev/full" in r.stderr and "space" in r.stderr, (
            args,
            r.stderr,
        )


def test_fifo_written_through(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    reader = subprocess.Popen(["cat", str(fifo)], stdout=subprocess.PIPE)
    r = rotacal_cli("simulate", "ballbar", "-o", fifo)
    text = reader.communicate(timeout=60)[0].decode()
    assert r.returncode == 0, r.stderr
    assert stat.S_ISFIFO(os.stat(fifo).st_mode) and text.startswith("# format: rotacal-ballbar/1")


def test_users_tmp_file_and_symlink_kept(files, tmp_path):
    out = tmp_path / "p.ngc"
    (tmp_path / "p.ngc.tmp").write_text("mine")
    target = tmp_path / "real.csv"
    target.write_text("old")
    link = tmp_path / "link.csv"
    link.symlink_to(target)
    assert rotacal_cli("plan", "ballbar", "-o", out, "--session", link).returncode == 0
    assert (tmp_path / "p.ngc.tmp").read_text() == "mine"
    assert link.is_symlink() and rotacal.load(link) is not None and target.read_text() != "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "link.csv",
        "p.ngc",
        "p.ngc.tmp",
        "real.csv",
    ]


def test_long_file_name(files, tmp_path):
    out = tmp_path / ("n" * 250 + ".html")  # the old writer's ".tmp" suffix made 255 fail
    r = rotacal_cli("report", files["good"], "--no-diagnosis", "-o", out)
    assert r.returncode == 0, r.stderr
    assert out.exists()


# ------------------------------------------------------------------------- sessions from Python


def _columns(length):
    n = len(length)
    return dict(
        machine=rotacal.MachineType.AC_trt,
        ballbar_length=100.0,
        pivot=np.array([120.0, 0.0, 60.0]),
        tests=["radial_A"] * n,
        time=np.arange(n, dtype=float),
        xyz=np.tile([120.0, 0.0, 160.0], (n, 1)),
        angles_deg=np.zeros((n, 2)),
        length=np.asarray(length, dtype=float),
    )


@pytest.mark.parametrize("length", [[100.0, 0.0, 100.0], [100.0, -100.0, 100.0]])
def test_ballbar_session_refuses_non_positive_lengths(length):
    with pytest.raises(rotacal.InvalidArgument, match="length"):
        rotacal.BallbarSession(**_columns(length))


def test_save_never_writes_a_file_load_refuses(tmp_path, monkeypatch):
    # Whatever a session holds, save checks its text with the reader first: a text the reader
    # refuses (here a formatter made to drop the format line) writes nothing.
    from rotacal import sessions

    s = rotacal.BallbarSession(**_columns([100.0, 100.01, 99.99]))
    broken = {
        k: (lambda session, f=f: f(session).split("\n", 1)[1])
        for k, f in sessions._FORMATTERS.items()
    }
    monkeypatch.setattr(sessions, "_FORMATTERS", broken)
    with pytest.raises(rotacal.InvalidArgument, match="would make a file that load refuses"):
        rotacal.save(s, tmp_path / "bad.csv")
    assert list(tmp_path.iterdir()) == []


def test_save_writes_what_load_reads(tmp_path):
    s = rotacal.BallbarSession(**_columns([100.0, 100.01, 99.99]))
    rotacal.save(s, tmp_path / "ok.csv")
    assert np.allclose(rotacal.load(tmp_path / "ok.csv").length, [100.0, 100.01, 99.99])
    with pytest.raises(rotacal.InvalidArgument, match="empty"):
        rotacal.save(s, "")


# ------------------------------------------------------------------------- huge finite numbers


@pytest.mark.parametrize(
    "name,command",
    [
        ("big_length", "identify"),
        ("big_length", "diagnose"),
        ("big_x", "identify"),
        ("big_dx", "identify"),
        ("big_b", "identify"),
    ],
)
def test_huge_finite_numbers_are_refused(files, name, command):
    # Used to end in a segmentation fault (exit 139) inside the fit.
    r = rotacal_cli(command, files[name], timeout=120)
    assert r.returncode == EXIT_INPUT and f"{name}.csv:" in r.stderr, (
        r.returncode,
        r.stderr[-500:],
    )


def test_repeated_rows_are_reported(files, tmp_path):
    # Rows written twice count twice in a fit (sigma shrinks by sqrt(2)): say so.
    head, rows = _rows(files["good"])
    src = tmp_path / "dup.csv"
    src.write_text("\n".join(head + rows[:50] + [rows[49]] * 3 + rows[50:]) + "\n")
    r = rotacal_cli("identify", src)
    assert r.returncode == 0 and "warning" in r.stderr and "repeat" in r.stderr, r.stderr
    r = rotacal_cli("identify", files["good"])
    assert "warning" not in r.stderr


# ------------------------------------------------------------------------- plausibility before fitting


def _transformed(src, dst, angle=None, linear=None, meta=None):
    """A copy of the ballbar session ``src`` with the angle columns (A, C) and/or the linear
    columns and lengths mapped, and metadata lines replaced (``meta``: key -> value)."""
    head, rows = _rows(src)
    out_rows = []
    for r in rows:
        f = r.split(",")
        if angle:
            f[5], f[6] = (f"{angle(float(v)):.9f}" for v in f[5:7])
        if linear:
            f[2], f[3], f[4], f[7] = (f"{linear(float(v)):.9f}" for v in (f[2], f[3], f[4], f[7]))
        out_rows.append(",".join(f))
    for key, value in (meta or {}).items():
        head = [f"# {key}: {value}" if ln.startswith(f"# {key}:") else ln for ln in head]
    Path(dst).write_text("\n".join(head + out_rows) + "\n")
    return dst


@pytest.mark.parametrize(
    "case, cause",
    [
        ("radians", "radians"),
        ("inches", "inches"),
        ("long_l0", "ballbar_length 150"),
    ],
)
@pytest.mark.parametrize("command", ["identify", "diagnose"])
def test_implausible_sessions_are_refused_with_the_cause(
    shared_data, tmp_path, case, cause, command
):
    src = shared_data / "ballbar_ac_table2.csv"
    dst = tmp_path / f"{case}.csv"
    if case == "radians":
        _transformed(src, dst, angle=np.radians)
    elif case == "inches":
        _transformed(
            src,
            dst,
            linear=lambda v: v / 25.4,
            meta={"ballbar_length": f"{100 / 25.4:.6f}", "pivot": "4.724409, 0.000000, 2.362205"},
        )
    else:
        _transformed(src, dst, meta={"ballbar_length": "150.0000"})
    r = rotacal_cli(command, dst)
    assert r.returncode == EXIT_INPUT, r.stdout + r.stderr
    assert cause in r.stderr and str(dst) in r.stderr, r.stderr


def test_max_deviation_widens_the_check_for_an_unusual_session(shared_data, tmp_path):
    # A session 3 mm off its nominal lengths everywhere (a bar 3 mm longer than declared) is
    # refused at the default limit and accepted when the user widens it.
    dst = _transformed(
        shared_data / "ballbar_ac_table2.csv",
        tmp_path / "off.csv",
        meta={"ballbar_length": "97.0000"},
    )
    assert rotacal_cli("identify", dst).returncode == EXIT_INPUT
    r = rotacal_cli("identify", dst, "--max-deviation", "5", "--length-offset")
    assert r.returncode == 0, r.stderr
    assert rotacal_cli("identify", dst, "--max-deviation", "0").returncode == EXIT_INPUT


def test_deviation_message_names_the_cli_option(shared_data, tmp_path):
    # An R-test nest declared 3 mm from where the program put it: refused, and the message
    # says how to widen the limit in the CLI's own words.
    text = (shared_data / "rtest_bc_oyama.csv").read_text()
    line = next(ln for ln in text.splitlines() if ln.startswith("# nest.1:"))
    dst = tmp_path / "nest_off.csv"
    dst.write_text(text.replace(line, "# nest.1: 103.0000, 0.0000, 60.0000"))
    r = rotacal_cli("identify", dst)
    assert r.returncode == EXIT_INPUT and "--max-deviation" in r.stderr, r.stderr
    assert rotacal_cli("identify", dst, "--max-deviation", "4").returncode == 0


def test_predict_with_a_model_of_another_machine_is_refused(shared_data, tmp_path):
    model, bc = tmp_path / "ac.json", tmp_path / "bc.csv"
    assert (
        rotacal_cli(
            "identify", shared_data / "ballbar_ac_table2.csv", "--save-model", model
        ).returncode
        == 0
    )
    assert (
        rotacal_cli(
            "simulate",
            "ballbar",
            "--machine",
            "BC-trt",
            "-o",
            bc,
            "--truth",
            tmp_path / "t.json",
            "--step",
            "5",
        ).returncode
        == 0
    )
    r = rotacal_cli("predict", bc, "--model", model, "-o", tmp_path / "p.csv")
    assert r.returncode == EXIT_INPUT, r.stdout + r.stderr
    assert "AC-trt" in r.stderr and "BC-trt" in r.stderr, r.stderr
    assert not (tmp_path / "p.csv").exists()
