# SPDX-License-Identifier: BSD-3-Clause
"""ISO 230-4 circular tests from the command line and Python: plan -> simulate -> analyze."""

import json
import math
import re

import numpy as np
import pytest

import rotacal
import rotacal.circular as circular
from rotacal import jsontext

from conftest import run_cli as rotacal_cli


def test_help():
    for args in (
        ["circular", "--help"],
        ["circular", "plan", "--help"],
        ["circular", "analyze", "--help"],
    ):
        r = rotacal_cli(*args)
        assert r.returncode == 0 and "exit codes" in r.stdout


def test_cli_round_trip(tmp_path):
    # plan: the NC program, arcs on the circle about the pivot at the planned feeds.
    r = rotacal_cli(
        "circular",
        "plan",
        "--planes",
        "XY",
        "--feeds",
        "1000,3000",
        "--pivot",
        "50,-20,10",
        "--length",
        "150",
        "-o",
        tmp_path / "test.ngc",
        "--session",
        tmp_path / "template.csv",
    )
    assert r.returncode == 0, r.stderr
    nc = (tmp_path / "test.ngc").read_text()
    arcs = re.findall(r"G17 (G[23]) X(-?[\d.]+) Y(-?[\d.]+) I(-?[\d.]+) J(-?[\d.]+) F([\d.]+)", nc)
    assert {a[0] for a in arcs} == {"G2", "G3"} and {a[5] for a in arcs} == {"1000.0", "3000.0"}
    for _, x, y, *_ in arcs:
        assert math.hypot(float(x) - 50.0, float(y) + 20.0) == pytest.approx(150.0, abs=1e-3)
    template = rotacal.load(tmp_path / "template.csv")
    assert set(template.tests) == {
        "circular_XY_ccw_f1000",
        "circular_XY_cw_f1000",
        "circular_XY_ccw_f3000",
        "circular_XY_cw_f3000",
    }

    # simulate: hidden squareness and backlash, little noise so that H is the backlash's.
    bx, by = 4.0, 3.0  # um
    r = rotacal_cli(
        "circular",
        "simulate",
        "--planes",
        "XY",
        "--feeds",
        "1000,3000",
        "--pivot",
        "50,-20,10",
        "--length",
        "150",
        "--rate",
        "100",
        "--squareness",
        "XY=30",
        "--backlash",
        f"X={bx},Y={by}",
        "--noise",
        "0.05",
        "--seed",
        "3",
        "--truth",
        tmp_path / "truth.json",
        "-o",
        tmp_path / "s.csv",
    )
    assert r.returncode == 0, r.stderr
    truth = json.loads((tmp_path / "truth.json").read_text())
    assert truth["backlash"]["X"] == pytest.approx(bx * 1e-3)
    assert (tmp_path / "s.csv").read_text().startswith("# format: rotacal-ballbar/1")

    # analyze: ISO 230-4 results and the named causes, as JSON, and a polar plot.
    r = rotacal_cli(
        "circular", "analyze", tmp_path / "s.csv", "--json", "--plot", tmp_path / "polar.png"
    )
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert [run["label"] for run in d["runs"]] == [
        "circular_XY_ccw_f1000",
        "circular_XY_cw_f1000",
        "circular_XY_ccw_f3000",
        "circular_XY_cw_f3000",
    ]
    assert [round(run["feed_mm_per_min"]) for run in d["runs"]] == [1000, 1000, 3000, 3000]
    assert len(d["pairs"]) == 2
    # Lost motion b_X, b_Y: the cw and ccw paths differ by b_X sgn(sin) cos - b_Y sgn(cos) sin,
    # whose largest size is max(b_X, b_Y) (squareness is the same in both directions); the
    # noise (0.05 um, differenced) adds at most a few tenths.
    for p in d["pairs"]:
        assert max(bx, by) - 0.1 <= p["H_um"] <= max(bx, by) + 0.4
    # Squareness 30 urad: an ellipse of radial amplitude s R / 2 = 2.25 um at 45 deg; with the
    # backlash, G is at least the ellipse's 4.5 um.
    assert all(run["G_um"] > 4.5 for run in d["runs"])
    found = {f["effect"]: f for f in d["diagnosis"]["findings"]}
    assert set(found) == {"squareness_XY", "backlash_X", "backlash_Y"}
    for effect, name, value in (
        ("squareness_XY", "squareness_XY.s", 30e-6),
        ("backlash_X", "backlash_X.b", bx * 1e-3),
        ("backlash_Y", "backlash_Y.b", by * 1e-3),
    ):
        p = next(q for q in found[effect]["parameters"] if q["name"] == name)
        assert abs(p["value"] - value) < 3 * p["std"], p
    assert any(
        u["effect"] == "squareness_YZ" and "YZ plane" in u["reason"]
        for u in d["diagnosis"]["unobservable"]
    )
    assert (tmp_path / "polar.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

    # The text report names the same.
    r = rotacal_cli("circular", "analyze", tmp_path / "s.csv", "--no-diagnose")
    assert r.returncode == 0 and "hysteresis H" in r.stdout and "diagnosis" not in r.stdout


def test_cli_refuses_bad_options_naming_them(tmp_path, shared_data):
    r = rotacal_cli("circular", "plan", "--planes", "XZ", "-o", tmp_path / "x.ngc")
    assert r.returncode == 3 and "--planes" in r.stderr
    r = rotacal_cli("circular", "plan", "--feeds", "1000,-5", "-o", tmp_path / "x.ngc")
    assert r.returncode == 3 and "--feeds" in r.stderr
    r = rotacal_cli("circular", "simulate", "--backlash", "Q=4", "-o", tmp_path / "x.csv")
    assert r.returncode == 3 and "--backlash" in r.stderr
    r = rotacal_cli("circular", "analyze", shared_data / "ballbar_ac_table2.csv")
    assert r.returncode == 3 and "no circular run" in r.stderr
    assert not (tmp_path / "x.ngc").exists() and not (tmp_path / "x.csv").exists()


def test_python_api_partial_arcs():
    # A 220 deg partial arc in ZX, both directions: H over the common arc, results JSON-ready.
    planned = circular.plan(["ZX"], [2000.0], span_deg=220.0, start_deg=-20.0, sample_rate_hz=100.0)
    assert [r.label for r in planned.runs] == ["circular_ZX_ccw", "circular_ZX_cw"]
    e = circular.errors(squareness_urad={"ZX": -40.0})
    s = circular.simulate(planned, e, noise_um=0.1, seed=2)
    res = circular.analyze(s)
    d = json.loads(jsontext.dumps(res.to_dict()))
    assert d["pairs"][0]["common_span_deg"] == pytest.approx(220.0, abs=0.5)
    assert all(run["span_deg"] == pytest.approx(220.0, abs=0.5) for run in d["runs"])
    p = res.diagnosis.findings[0].parameters[0]
    assert res.diagnosis.findings[0].effect == "squareness_ZX" and abs(p.value + 40e-6) < 3 * p.std
    assert np.all(np.isfinite(res.analysis.runs[0].radial_um))
    with pytest.raises(rotacal.InvalidArgument, match="plane"):
        circular.plan(["XQ"])


def test_rotary_commands_point_to_circular_and_report_draws_it(tmp_path):
    """A circular-test session given to the rotary-axis commands is refused with the command that
    analyses it (exit 3), not as "the axes never move"; `rotacal report` writes its own report:
    G per run, G(b) and H, the polar plot and the named causes."""
    s = tmp_path / "c.csv"
    r = rotacal_cli(
        "circular",
        "simulate",
        "--planes",
        "XY",
        "--squareness",
        "XY=35",
        "--backlash",
        "X=4",
        "--seed",
        "3",
        "-o",
        s,
    )
    assert r.returncode == 0, r.stderr
    for cmd in ("identify", "diagnose"):
        r = rotacal_cli(cmd, s)
        assert (
            r.returncode == 3
            and "rotacal circular analyze" in r.stderr
            and "never move" not in r.stderr
        ), r.stderr
    r = rotacal_cli("report", s, "-o", tmp_path / "c.html")
    assert r.returncode == 0, r.stderr
    page = (tmp_path / "c.html").read_text()
    for section in (
        'id="circular-deviation"',
        'id="polar"',
        'id="diagnosis"',
        "data:image/png;base64,",
    ):
        assert section in page
    # The report's numbers are the analysis': G of each run and the causes named.
    res = circular.analyze(rotacal.load(s))
    for run in res.analysis.runs:
        assert f"<td>{run.G_um:.2f}</td>" in page
    named = {f.effect for f in res.diagnosis.findings}
    assert {"squareness_XY", "backlash_X"} <= named
    for eff in named:
        assert f"<b>{eff}</b>" in page
