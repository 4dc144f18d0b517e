# SPDX-License-Identifier: BSD-3-Clause
"""The fourth hostile round (issue 57), through the CLI as a user meets it, one section per
class of the issue. Sessions come from the independent reference simulator
(tests/reference/refsim, through test_multi's helpers); the inputs differ from the issue's.
Class 1: sessions that disagree (a ballbar and an R-test session, the R-test's machine 45 um
off in E_Y0C) never become one confident model; the disagreement test corrected for the number
of comparisons (class 7) keeps consistent sessions unflagged."""

import json
import math


import pytest

from conftest import run_cli
from test_multi import MACHINE, ballbar_file, probe_file, rtest_file, truth_errors

EXIT_OK, EXIT_INPUT, EXIT_IO = 0, 3, 4


@pytest.fixture(scope="module")
def disagreeing(tmp_path_factory):
    """A ballbar and an R-test session of two machines that differ by 45 um in E_Y0C."""
    d = tmp_path_factory.mktemp("disagree")
    errors = truth_errors(MACHINE)
    other = dict(errors, E_Y0C=errors["E_Y0C"] + 0.045)
    return d, ballbar_file(d, MACHINE, errors, 11), rtest_file(d, MACHINE, other, 12)


def test_sessions_that_disagree_are_not_saved_stored_or_exported(disagreeing):
    d, bb, rt = disagreeing
    shown = run_cli("identify", bb, rt, "--json", cwd=d)
    assert shown.returncode == EXIT_OK, shown.stderr  # looking at them is fine
    joint = json.loads(shown.stdout)
    assert any(g["parameter"] == "E_Y0C" for g in joint["disagreements"]), joint["disagreements"]
    assert not joint["sigma_inflated"]
    assert not any("averages" in n for n in joint["notes"]), joint["notes"]

    model, db = d / "m.json", d / "h.sqlite"
    for extra in (["--save-model", model], ["--store", "--machine-id", "M-7", "--db", db]):
        r = run_cli("identify", bb, rt, *extra, cwd=d)
        assert r.returncode == EXIT_INPUT, r.stderr
        assert "E_Y0C" in r.stderr and str(bb) in r.stderr and str(rt) in r.stderr, r.stderr
        assert "--inflate-sigma" in r.stderr, r.stderr
        assert "DISAGREE E_Y0C" in r.stdout, r.stdout  # the table is shown before the refusal
    assert not model.exists()
    from rotacal.history import open_history

    with open_history(str(db)) as h:  # the store may exist (checked before any work): empty
        assert h.machines() == []


def test_inflated_sigma_is_kept_and_said(disagreeing):
    d, bb, rt = disagreeing
    plain = json.loads(run_cli("identify", bb, rt, "--json", cwd=d).stdout)
    model = d / "inflated.json"
    r = run_cli("identify", bb, rt, "--inflate-sigma", "--save-model", model, "--json", cwd=d)
    assert r.returncode == EXIT_OK, r.stderr
    out = json.loads(r.stdout)
    assert out["sigma_inflated"]
    widened = out["location_errors"]["E_Y0C"]["std"] / plain["location_errors"]["E_Y0C"]["std"]
    # The Birge ratio of two sessions 45 um apart at a few um each is well above 1.
    assert widened > 2.0, widened
    assert any("E_Y0C" in n and "widened" in n for n in out["notes"]), out["notes"]
    doc = json.loads(model.read_text())
    assert doc["fit"]["sigma_inflated"] is True and doc["disagreements"]

    hal = d / "ok.hal"
    exported = run_cli("export", "--model", model, "--controller", "linuxcnc", "-o", hal, cwd=d)
    assert exported.returncode == EXIT_OK, exported.stderr

    # The same file claiming no inflation (an older rotacal, or edited) is not exported.
    doc["fit"]["sigma_inflated"] = False
    edited = d / "edited.json"
    edited.write_text(json.dumps(doc))
    refused_hal = d / "refused.hal"
    refused = run_cli(
        "export", "--model", edited, "--controller", "siemens", "-o", refused_hal, cwd=d
    )
    assert refused.returncode == EXIT_INPUT, refused.stderr
    assert "disagree" in refused.stderr and "E_Y0C" in refused.stderr
    assert not refused_hal.exists()


def test_inflate_sigma_is_for_several_sessions(disagreeing):
    d, bb, _ = disagreeing
    r = run_cli("identify", bb, "--inflate-sigma", cwd=d)
    assert r.returncode == EXIT_INPUT and "--inflate-sigma" in r.stderr, r.stderr


def test_consistent_sessions_are_not_flagged(tmp_path):
    """Ten ballbar sessions of one machine from the reference simulator (independent AR noise):
    45 pairs x 8 location errors compared; Bonferroni's threshold keeps them all within."""
    errors = truth_errors(MACHINE)
    files = [ballbar_file(tmp_path, MACHINE, errors, 100 + k) for k in range(10)]
    r = run_cli("identify", *files, "--json", cwd=tmp_path)
    assert r.returncode == EXIT_OK, r.stderr
    d = json.loads(r.stdout)
    assert d["disagreement_test"]["comparisons"] == 45 * 8, d["disagreement_test"]
    assert d["disagreement_test"]["z"] > 4.0, d["disagreement_test"]
    assert d["disagreements"] == [], d["disagreements"][:3]


# ---------------------------------------------------------------- class 2: touch-probe plausibility


@pytest.fixture(scope="module")
def probe_lines(tmp_path_factory):
    """A good rotacal-probe/1 session of the reference simulator (sphere 25 mm, stylus 6 mm), as
    header lines, column line and rows split at commas; and the BC-trt one likewise."""
    d = tmp_path_factory.mktemp("probe")
    out = {}
    for machine in ("AC-trt", "BC-trt"):
        text = probe_file(d, machine, truth_errors(machine), 21).read_text()
        lines = text.splitlines()
        k = next(i for i, line in enumerate(lines) if line.startswith("pose,"))
        out[machine] = (lines[:k], lines[k], [line.split(",") for line in lines[k + 1 :]])
    return out


def _probe_variant(probe_lines, tmp_path, machine="AC-trt", header=None, column=None, rows=None):
    head, columns, body = probe_lines[machine]
    head = [header(h) for h in head] if header else head
    columns = column(columns) if column else columns
    body = rows([list(r) for r in body]) if rows else body
    p = tmp_path / "variant.csv"
    p.write_text("\n".join([*head, columns, *(",".join(r) for r in body)]) + "\n")
    return p


def _swap_rotary(rows):
    return [[*r[:5], r[6], r[5], *r[7:]] for r in rows]


def _radians(rows):
    return [
        [*r[:5], repr(math.radians(float(r[5]))), repr(math.radians(float(r[6]))), *r[7:]]
        for r in rows
    ]


def _one_touch_off(rows):
    rows[len(rows) // 3][4] = repr(float(rows[len(rows) // 3][4]) + 35.0)  # Z 35 mm off
    return rows


PROBE_HOSTILE = {
    # case: (machine, header edit, column-line edit, rows edit, words the cause must hold)
    "sphere diameter wrong": (
        "AC-trt",
        lambda h: "# sphere_diameter: 31.7500" if h.startswith("# sphere_diameter:") else h,
        None,
        None,
        ["sphere_diameter", "stylus_diameter", "trigger radius"],
    ),
    "stylus of 400 mm": (
        "AC-trt",
        lambda h: "# stylus_diameter: 400" if h.startswith("# stylus_diameter:") else h,
        None,
        None,
        ["trigger radius"],
    ),
    "rotary columns swapped": ("BC-trt", None, None, _swap_rotary, ["columns look swapped"]),
    "angles in radians": ("BC-trt", None, None, _radians, ["radians"]),
    "machine of another kind": (
        "BC-trt",
        lambda h: "# machine: AC-trt" if h.startswith("# machine:") else h,
        lambda c: c.replace(",B,", ",A,"),
        None,
        ["BC-trt", "fix '# machine:'"],
    ),
    "one touch 35 mm off": ("AC-trt", None, None, _one_touch_off, ["outlier touch", "touch "]),
}


@pytest.mark.parametrize("case", sorted(PROBE_HOSTILE))
def test_implausible_probe_session_is_refused_with_its_cause(probe_lines, tmp_path, case):
    machine, header, column, rows, words = PROBE_HOSTILE[case]
    bad = _probe_variant(probe_lines, tmp_path, machine, header, column, rows)
    model, hal = tmp_path / "m.json", tmp_path / "out.hal"
    for method in ("joint", "cycles"):
        extra = ["--save-model", model] if method == "joint" else []
        r = run_cli("identify", bad, "--method", method, *extra, cwd=tmp_path)
        assert r.returncode == EXIT_INPUT, (case, method, r.stdout, r.stderr)
        assert "implausible session" in r.stderr and str(bad) in r.stderr, r.stderr
        for w in words:
            assert w in r.stderr, (case, w, r.stderr)
    assert not model.exists() and not hal.exists()


def test_good_probe_sessions_pass_the_check(probe_lines, tmp_path):
    for machine in ("AC-trt", "BC-trt"):
        good = _probe_variant(probe_lines, tmp_path, machine)
        r = run_cli("identify", good, "--no-budget", cwd=tmp_path)
        assert r.returncode == EXIT_OK, (machine, r.stderr)
