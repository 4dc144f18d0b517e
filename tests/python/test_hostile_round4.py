# SPDX-License-Identifier: BSD-3-Clause
"""The fourth hostile round (issue 57), through the CLI as a user meets it, one section per
class of the issue. Sessions come from the independent reference simulator
(tests/reference/refsim, through test_multi's helpers); the inputs differ from the issue's.
Class 1: sessions that disagree (a ballbar and an R-test session, the R-test's machine 45 um
off in E_Y0C) never become one confident model; the disagreement test corrected for the number
of comparisons (class 7) keeps consistent sessions unflagged."""

import json


import pytest

from conftest import run_cli
from test_multi import MACHINE, ballbar_file, rtest_file, truth_errors

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
