# SPDX-License-Identifier: BSD-3-Clause
"""Which member of a finding's group the extended model holds (issue 50 item 3), and messages
that fit the session (item 5), on sessions of the independent reference simulator
(tests/reference/refsim) with set-ups, seeds and amplitudes other than the issue's.

The location errors a user loads are the extended model's, so the model holds what the weights
say (DiagnosisOptions.hold_by_weight): the group's member of the highest weight among those with
a determined parameter (issue 29's rule 6), a nested special case of it where that fits within
delta BIC 2, and says why. On main at 77707f3 the model held the search's pick, the best-scoring
member that passed the search's tests, which the weights could rank last of its group, and said
nothing of it; by default it still does (the rule, on by default, fails a safety check of
test_probe_diagnosis.py: see DiagnosisOptions::hold_by_weight), and now says so."""

import json
import re
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_diagnosis_precision import ballbar_session, rtest_session  # noqa: E402
from test_probe_diagnosis import probe_session  # noqa: E402

import rotacal  # noqa: E402
from conftest import run_cli  # noqa: E402


def members(f: dict) -> list:
    """The group's scored members (aliased ones have no weight), highest weight first."""
    return sorted((g for g in f["group"] if not g.get("aliased")), key=lambda g: -g["weight"])


def determined(f: dict) -> bool:
    """Issue 29 rule 6 on the held member: a parameter at least 3 sigma from zero."""
    ps = [p for p in f["parameters"].values() if p["value"] is not None and p["std"]]
    return any(abs(p["value"]) >= 3 * p["std"] for p in ps)


def assert_holds_what_the_weights_say(d: dict) -> None:
    """Every finding's model holds its group's top member, a nested one within delta BIC 2 of it,
    or the next by weight where those above have no parameter determined; it says which."""
    for f in d["findings"]:
        assert f["model"]["holds"] == f["effect"] and f["model"]["why"], f["model"]
        assert determined(f), f
        top = members(f)[0]
        why = f["model"]["why"]
        if f["effect"] == top["effect"]:
            assert abs(f["weight"] - top["weight"]) < 1e-12, f
        elif "special case of " + top["effect"] in why:
            nested = next(r for r in f["rivals"] if r["effect"] == top["effect"])
            assert nested["delta_bic"] >= -2.0, nested  # the held one within 2 of the top
        else:
            assert top["effect"] in why and "none of their parameters is determined" in why, why


def test_the_model_holds_the_member_the_weights_rank_first(tmp_path):
    """A 4 um sag of A on the AC-trt ballbar (another pivot than the issue's, white and AR(1) 0.5
    noise): the search's pick was the sag, ranked second or third by the weights, and the model
    held it. Now the model holds what the weights say, and names the pick it passed over; on main
    at 77707f3 the model held the pick in 4 of these 6 sessions where the weights rank another
    member first."""
    passed_over = 0
    for seed, rho in ((603, 0.0), (605, 0.0), (607, 0.0), (607, 0.5), (601, 0.0), (603, 0.5)):
        d = rotacal.diagnose(
            ballbar_session(
                tmp_path, {"gravity_sag_A": [4e-3]}, seed=seed, pivot=(110.0, -10.0, 65.0), rho=rho
            ),
            hold_by_weight=True,
        ).to_dict()
        assert d["findings"] and "gravity_sag_A" in [g["effect"] for g in d["findings"][0]["group"]]
        assert_holds_what_the_weights_say(d)
        passed_over += "the search's pick, gravity_sag_A" in d["findings"][0]["model"]["why"]
    assert passed_over >= 4, passed_over


def test_a_nested_member_that_fits_as_well_is_held(tmp_path):
    """The sag is a radial motion of A of order 2 less the location errors and the set-up: where
    the weights rank radial_motion_A_h2 first and the sag fits within delta BIC 2 of it, the model
    holds the sag, the simpler one, and says why (seeds 601 and 603 of the test above)."""
    for seed, rho in ((601, 0.0), (603, 0.5)):
        d = rotacal.diagnose(
            ballbar_session(
                tmp_path, {"gravity_sag_A": [4e-3]}, seed=seed, pivot=(110.0, -10.0, 65.0), rho=rho
            ),
            hold_by_weight=True,
        ).to_dict()
        f = d["findings"][0]
        assert members(f)[0]["effect"] == "radial_motion_A_h2", members(f)
        assert f["effect"] == "gravity_sag_A", f["model"]
        assert "special case of radial_motion_A_h2" in f["model"]["why"], f["model"]


@pytest.mark.parametrize(
    "amplitude,seed,rho",
    [(2e-6, 71, 0.5), (2e-6, 75, 0.0), (4e-6, 70, 0.5), (6e-6, 74, 0.0), (6e-6, 79, 0.0)],
)
def test_the_model_member_of_a_drift_has_a_determined_parameter(tmp_path, amplitude, seed, rho):
    """R-test, BC-trt, other nests and amplitudes than the issue's, a linear Z drift: the search
    picked thermal_warmup_Z, whose d and tau trade off along the drift (seed 75: d = 50 +- 345 um,
    ln tau = 4.3 +- 7.1), and the model held it. Rule 6 (a parameter of 3 sigma) now reaches the
    model member: it holds the drift, and every finding's numbers are determined."""
    d = rotacal.diagnose(
        rtest_session(
            tmp_path,
            {"thermal_drift_Z": [amplitude]},
            seed=seed,
            nests=((120.0, 20.0, 50.0), (-20.0, -110.0, 150.0)),
            rho=rho,
        ),
        hold_by_weight=True,
    ).to_dict()
    assert d["findings"], d["unobservable"]
    assert d["findings"][0]["effect"] == "thermal_drift_Z", d["findings"][0]["model"]
    assert_holds_what_the_weights_say(d)


def test_the_report_the_cli_and_export_say_what_the_model_holds(tmp_path):
    """The report, `diagnose` and `export` of the extended model say which member it holds and
    why (the demo's model file carries it: `held_because`); by default the search's pick, with
    the member the weights rank first named beside it, and with hold_by_weight (the CLI's
    --hold-by-weight) that member, naming the pick it passed over."""
    from rotacal import report
    from rotacal.diagnosis import held_effects, model_text

    s = ballbar_session(tmp_path, {"gravity_sag_A": [4e-3]}, seed=605, pivot=(110.0, -10.0, 65.0))
    base = rotacal.identify(s)
    diag = rotacal.diagnose(s)
    f = diag.to_dict()["findings"][0]
    assert "the weights rank radial_motion_A_h3 first" in f["model"]["why"], f["model"]
    by_weight = rotacal.diagnose(s, hold_by_weight=True).to_dict()
    assert_holds_what_the_weights_say(by_weight)
    w = by_weight["findings"][0]
    assert w["effect"] == "radial_motion_A_h3" != f["effect"], (w["model"], f["model"])
    assert f"the search's pick, {f['effect']}" in w["model"]["why"], w["model"]
    page = report.ballbar_report(tmp_path / "r.html", s, base, diag).read_text()
    assert f"The model holds {f['effect']} because" in page
    assert model_text(f).startswith(f"the model holds {f['effect']} because ")
    ext = report.extended_identification(s, base, diag)
    model = ext.model_dict()
    why = {h["id"]: h["held_because"] for h in held_effects(diag)}
    for entry in model["effects"]:
        entry["held_because"] = why[entry["id"]]
    rotacal.save_model(model, tmp_path / "model.json")
    r = run_cli("export", "--model", tmp_path / "model.json", "--controller", "linuxcnc", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["model_effects"] == [{"id": f["effect"], "held_because": f["model"]["why"]}]
    assert f"the values come from a model with {f['effect']}: it holds it because" in r.stderr
    # The CLI holds the same member as the library, and the other with --hold-by-weight.
    path = tmp_path / "ballbar_605.csv"  # the session's file, as ballbar_session wrote it
    for flag, held in (([], f["effect"]), (["--hold-by-weight"], w["effect"])):
        r = run_cli("diagnose", path, "--json", "--no-progress", "--no-budget", *flag)
        assert r.returncode == 0, r.stderr
        assert json.loads(r.stdout)["findings"][0]["model"]["holds"] == held, flag


@pytest.mark.parametrize("seed", [600, 603])
def test_a_probe_finding_names_the_probe_design(tmp_path, seed):
    """Item 5: a touch-probe session (AC-trt, a 4 um sag, the default cross, white noise) whose
    finding is a group points to `rotacal design probe --separate`, never to the ballbar's or
    the R-test's design (it told a probe user to run `rotacal design ballbar|rtest`)."""
    d = rotacal.diagnose(
        probe_session(tmp_path, "AC-trt", {"gravity_sag_A": [4e-3]}, seed)
    ).to_dict()
    assert d["ambiguous"], d["findings"][:1]
    assert set(design_commands(d)) == {"probe"}, [a["separating_test"] for a in d["ambiguous"]]


def design_commands(d: dict) -> list:
    """Every `rotacal design ...` command the diagnosis' ambiguity texts name."""
    texts = [a["separating_test"] for a in d["ambiguous"]]
    return re.findall(r"rotacal design (\S+)", " ".join(texts))
