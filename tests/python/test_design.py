# SPDX-License-Identifier: BSD-3-Clause
"""`rotacal design ballbar` as an engineer runs it: the designed set-up within the travel, its
predicted uncertainty against the default's at the same run time, the NC program of the
designed test, and refusals by option."""

import json

import pytest

import rotacal


from conftest import SHARED, run_cli

EXIT_INPUT = 3


def rotacal_cli(*args):
    r = run_cli(*args)
    assert "Traceback" not in r.stderr, r.stderr
    return r


def test_design_within_travel_and_better_than_default(tmp_path):
    prog = tmp_path / "designed.ngc"
    r = rotacal_cli(
        "design",
        "ballbar",
        "--step",
        "3",
        "--pivot-x",
        "60,120,180",
        "--pivot-z",
        "30,60,120",
        "--travel",
        "-400,400,-300,300,-300,260",
        "--time",
        "1800",
        "--json",
        "-o",
        prog,
    )
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["time_budget_s"] == 1800
    best, default = d["best"], d["default"]
    assert best["feasible"] and default["feasible"]
    assert best["worst_expanded_um"] <= default["worst_expanded_um"]
    assert d["ratio_to_default"] == pytest.approx(
        best["worst_expanded_um"] / default["worst_expanded_um"]
    )
    # The travel in Z rules some set-ups out, by name.
    out = [c for c in d["candidates"] if not c["feasible"]]
    assert any("Z = " in c["why_not"] for c in out) and all(c["why_not"] for c in out)
    # The program of the designed set-up is what `plan` writes for it.
    L0, pivot = best["ballbar_length"], best["pivot"]
    ref = tmp_path / "ref.ngc"
    assert (
        rotacal_cli(
            "plan",
            "ballbar",
            "--step",
            "3",
            "--length",
            L0,
            "--pivot",
            ",".join(map(str, pivot)),
            "-o",
            ref,
        ).returncode
        == 0
    )
    assert prog.read_text() == ref.read_text()


def test_a_pair_no_single_setup_separates_is_reported():
    r = rotacal_cli(
        "design",
        "ballbar",
        "--step",
        "3",
        "--pivot-x",
        "120",
        "--pivot-z",
        "60",
        "--lengths",
        "100",
        "--effects",
        "axial_motion_C_h2,tilt_motion_C_h2",
        "--json",
    )
    assert r.returncode == 0, r.stderr
    corr = json.loads(r.stdout)["best"]["effect_correlation"]
    assert max(v["max_with_other_effects"] for v in corr.values()) > 0.99


@pytest.mark.parametrize(
    "args,option",
    [
        (("--travel", "1,0,-300,300,-300,400"), "--travel"),
        (("--rho", "1.5"), "--rho"),
        (("--lengths", "0"), "--lengths"),
        (("--travel", "-1,1,-1,1,-1,1"), "no candidate"),
        (("--effects", "no_such_effect"), "no_such_effect"),
    ],
)
def test_design_refuses_by_option(args, option):
    r = rotacal_cli(
        "design", "ballbar", "--step", "5", "--pivot-x", "120", "--pivot-z", "60", *args
    )
    assert r.returncode in (2, EXIT_INPUT) and option in r.stderr, r.stderr


TABLE2 = SHARED / "ballbar_ac_table2.csv"


def test_separate_after_a_session_proposes_the_added_test(tmp_path):
    prog = tmp_path / "added.ngc"
    r = rotacal_cli(
        "design",
        "ballbar",
        "--separate",
        "axial_motion_C_h2,tilt_motion_C_h2",
        "--after",
        TABLE2,
        "--json",
        "-o",
        prog,
    )
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["separable"] and d["found"]
    added = d["added_test"]
    assert added["correlation_after"] < 0.5 < d["correlation_before"]
    assert added["run_time_s"] <= 600
    # Both effects come out better determined than from the session alone.
    for name, after in d["predicted_std_after"].items():
        before = d["predicted_std_before"].get(name)
        if name.startswith(("axial_motion_C_h2", "tilt_motion_C_h2")) and after is not None:
            assert before is None or after <= before * (1 + 1e-9)
    # The program is that of the added test, at the slowed feeds.
    text = prog.read_text()
    assert added["tests"][-1] in text
    # ... and its session template is written beside it, as plan --session writes one (issue 50).
    template = rotacal.load(tmp_path / "added.csv")
    assert sorted(set(template.tests)) == sorted(added["tests"])
    assert len(template) > 0


def test_separate_says_when_no_test_can():
    r = rotacal_cli(
        "design", "ballbar", "--separate", "gravity_sag_A,radial_motion_A_h2", "--after", TABLE2
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("no test can separate gravity_sag_A and radial_motion_A_h2")
    assert "moves the table exactly as" in r.stdout


@pytest.mark.parametrize(
    "args,option",
    [
        (("--separate", "axial_motion_C_h2,tilt_motion_C_h2"), "--after"),
        (("--after", str(TABLE2)), "--separate"),
        (("--separate", "axial_motion_C_h2", "--after", str(TABLE2)), "--separate"),
        (
            ("--separate", "axial_motion_C_h2,no_such_effect", "--after", str(TABLE2)),
            "no_such_effect",
        ),
    ],
)
def test_separate_refuses_by_option(args, option):
    r = rotacal_cli("design", "ballbar", *args)
    assert r.returncode in (2, EXIT_INPUT) and option in r.stderr, r.stderr


def test_design_rtest_beats_the_default_pattern():
    r = rotacal_cli(
        "design",
        "rtest",
        "--radii",
        "50,150",
        "--heights",
        "20,100,140",
        "--b-steps",
        "30,45",
        "--c-steps",
        "30,60",
        "--travel",
        "-400,400,-300,300,-300,190",
        "--json",
    )
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    best, default = d["best"], d["default"]
    assert best["feasible"] and default["feasible"]
    assert best["worst_expanded_um"] < default["worst_expanded_um"]
    assert best["duration_s"] <= d["time_budget_s"] == default["duration_s"]
    reasons = [c["why_not"] for c in d["candidates"] if not c["feasible"]]
    assert any(w.startswith("Z = ") for w in reasons) and any("too coarse" in w for w in reasons)
    text = rotacal_cli(
        "design",
        "rtest",
        "--radii",
        "50,150",
        "--heights",
        "20,100",
        "--b-steps",
        "30",
        "--c-steps",
        "30",
    ).stdout
    assert "run it with: --nest" in text


@pytest.mark.parametrize(
    "args,option",
    [
        (("--rho", "1.5"), "--rho"),
        (("--c-steps", "0"), "--c-steps"),
        (("--travel", "-1,1,-1,1,-1,1"), "no nest pair"),
    ],
)
def test_design_rtest_refuses_by_option(args, option):
    r = rotacal_cli(
        "design",
        "rtest",
        "--radii",
        "100",
        "--heights",
        "60",
        "--b-steps",
        "30",
        "--c-steps",
        "30",
        *args,
    )
    assert r.returncode in (2, EXIT_INPUT) and option in r.stderr, r.stderr


OYAMA = SHARED / "rtest_bc_oyama.csv"


def test_design_rtest_separate_after_a_session():
    r = rotacal_cli(
        "design",
        "rtest",
        "--separate",
        "axial_motion_C_h2,tilt_motion_C_h2",
        "--after",
        OYAMA,
        "--json",
    )
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["found"] and d["added_nest"]["correlation_after"] < 0.5 < d["correlation_before"]
    assert d["added_nest"]["run_time_s"] <= 600
    r = rotacal_cli(
        "design", "rtest", "--separate", "gravity_sag_B,radial_motion_B_h2", "--after", OYAMA
    )
    assert r.returncode == 0 and r.stdout.startswith(
        "no test can separate gravity_sag_B and radial_motion_B_h2"
    )
    # The wrong kind of session is refused by option.
    r = rotacal_cli(
        "design", "rtest", "--separate", "axial_motion_C_h2,tilt_motion_C_h2", "--after", TABLE2
    )
    assert r.returncode in (2, EXIT_INPUT) and "--after" in r.stderr
