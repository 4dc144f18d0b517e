# SPDX-License-Identifier: BSD-3-Clause
"""Flynn et al. (2016) Table 2 as a real-data case: the shipped table against the paper's text,
the analysis on a synthetic before/after pair with a known hidden cause, and on Table 2."""

import json
import re
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest

import rotacal
from rotacal import flynn_table2 as ft

PAPER = (
    Path(__file__).resolve().parents[3] / "shared" / "papers" / "flynn2016-single-setup-ballbar.txt"
)
NAMES = list(rotacal.location_error_names(rotacal.MachineType.AC_trt))


def paper_table2() -> dict:
    """The rows of Table 2 as printed in the paper's text: name -> (uncomp, comp, % inc, unit)."""
    if not PAPER.is_file():
        pytest.fail(f"paper text not found at {PAPER} (expected ../shared beside the repository)")
    lines = PAPER.read_text().splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith("Table 2:"))
    rows = {}
    for ln in lines[start + 1 :]:
        if ln.startswith("ACKNOWLEDGEMENTS"):
            break
        cells = ln.split("\t")
        if not cells[0].startswith("E_{"):
            continue
        assert len(cells) == 9, f"Table 2 row has {len(cells)} cells: {ln!r}"
        unit = {"[mm]": "mm", "[rad.]": "rad"}[cells[8]]
        for half in (cells[0:4], cells[4:8]):
            name = re.fullmatch(r"E_\{(\w+)\}", half[0]).group(1)
            rows["E_" + name] = (half[1], half[2], half[3], unit)
    return rows


def test_table_matches_the_paper_text_character_for_character():
    shipped = json.loads(ft.TABLE2_PATH.read_text())
    paper = paper_table2()
    assert sorted(paper) == sorted(NAMES)
    assert [r["name"] for r in shipped["rows"]] == NAMES
    for r in shipped["rows"]:
        u, c, pct, unit = paper[r["name"]]
        assert (r["uncompensated"], r["compensated"], r["change_percent"], r["unit"]) == (
            u,
            c,
            pct,
            unit,
        ), r["name"]
    assert shipped["source"]["table"].startswith("Table 2")


def _last_digit(text: str) -> float:
    """Half a unit of the last printed digit of a number such as '1.1284 E-5'."""
    mant, _, exp = text.replace(" ", "").upper().partition("E")
    d = Decimal(mant.strip("()"))
    return 0.5 * 10.0 ** (d.as_tuple().exponent + (int(exp) if exp else 0))


def _percent_agrees(row: dict, printed: dict) -> bool:
    b, a = row["before"], row["after"]
    pct = float(row["printed"]["change_percent"].strip("()"))
    db, da = _last_digit(printed["uncompensated"]), _last_digit(printed["compensated"])
    tol = 100 * (da / abs(b) + (abs(a) + da) * db / b**2) + 0.0005
    return abs(100 * (abs(a) - abs(b)) / abs(b) - pct) <= tol


def test_loaded_values_reproduce_the_papers_percent_column():
    # The printed '% Inc.' = 100 (|comp| - |uncomp|) / |uncomp| follows from the printed values
    # to within their rounding in six rows; a typo in one of ours fails here. E_B0A and E_C0A
    # disagree in the paper itself; the file's 'percent_consistent' readings reproduce it.
    printed = ft.load_table2()
    alt = ft.load_table2(reading="percent_consistent")
    shipped = {r["name"]: r for r in json.loads(ft.TABLE2_PATH.read_text())["rows"]}
    for p, q in zip(printed["rows"], alt["rows"]):
        n = p["name"]
        if n in ("E_B0A", "E_C0A"):
            assert not _percent_agrees(p, p["printed"]), n
            assert _percent_agrees(q, {**p["printed"], **shipped[n]["percent_consistent"]}), n
        else:
            assert _percent_agrees(p, p["printed"]), n
            assert (p["before"], p["after"]) == (q["before"], q["after"])


def test_bad_table_files_raise_typed_errors(tmp_path):
    p = tmp_path / "t.json"
    p.write_text('{"rows": [')
    with pytest.raises(rotacal.ParseError, match="t.json"):
        ft.load_table2(p)
    d = json.loads(ft.TABLE2_PATH.read_text())
    d["rows"][2]["compensated"] = "4.42x56 E-7"
    p.write_text(json.dumps(d))
    with pytest.raises(rotacal.InvalidArgument, match=r"rows\[2\] \(E_B0A\) compensated"):
        ft.load_table2(p)
    with pytest.raises(rotacal.IoError, match="missing.json"):
        ft.load_table2(tmp_path / "missing.json")
    with pytest.raises(rotacal.InvalidArgument, match="noise_rho"):
        ft.analyse(assumptions=ft.Assumptions(noise_rho=1.0), draws=10, sweep=[])


def _synthetic_pair(shift_y_mm: float, seed: int) -> dict:
    """Measure -> identify (paper chain) -> compensate -> measure again, written here with the
    core primitives: a machine with Table 2's errors, a pivot set-up error and constant
    effects (squareness, sag, a C-axis runout) in both runs, 0.5 um noise, and the table
    shifted along Y between the runs (the hidden cause)."""
    m = rotacal.MachineType.AC_trt
    setup = rotacal.BallbarSetup()
    cmd = rotacal.plan_ballbar_test(setup, None).commanded_session()
    errors = np.array([r["before"] for r in ft.load_table2()["rows"]])
    pivot = np.asarray(setup.pivot) + np.array([0.004, -0.003, 0.006])
    effects = ["linear_squareness_XY", "gravity_sag_A", "axial_motion_C_h2"]
    params = [15e-6, 0.003, 0.0008, -0.0005]

    def measure(program, errs, piv, s):
        sim = rotacal.simulate_ballbar(
            program, rotacal.BallbarMachineModel(m, errs, piv, effects, params), 0.5, s
        )
        return rotacal.BallbarSession(
            m,
            sim.ballbar_length,
            cmd.pivot,
            sim.tests,
            sim.time,
            cmd.xyz,
            sim.angles_deg,
            sim.length,
            0.5,
        )

    e1 = np.array(
        [
            p.value
            for p in rotacal.identify(measure(cmd, errors, pivot, seed), "paper").parameters[:8]
        ]
    )
    program = rotacal.plan_ballbar_test(setup, e1).commanded_session()
    shift = np.zeros(8)
    shift[[0, 5]] = shift_y_mm  # E_Y0A and E_Y0C: the whole table moved along Y
    s2 = measure(program, errors + shift, pivot + np.array([0.0, shift_y_mm, 0.0]), seed + 1)
    e2 = np.array([p.value for p in rotacal.identify(s2, "paper").parameters[:8]])
    return {
        "rows": [
            {
                "name": n,
                "unit": "mm" if i % 4 < 2 else "rad",
                "before": float(e1[i]),
                "after": float(e2[i]),
            }
            for i, n in enumerate(NAMES)
        ]
    }


def test_a_hidden_table_shift_between_the_runs_is_named_first_with_its_size():
    shift_um = 4.0
    r = ft.analyse(_synthetic_pair(shift_um * 1e-3, seed=7), draws=40, seed=3, sweep=[])
    first = r["ranked_causes"][0]
    assert first["id"] == "between_runs:table_shift_Y", [c["id"] for c in r["ranked_causes"][:3]]
    assert first["unit"] == "um"
    assert abs(first["size"] - shift_um) <= 3 * first["size_std"], first
    assert first["plausible_size"]
    # E_Y0A and E_Y0C move by the shift, far outside the noise-only prediction.
    assert {"E_Y0A", "E_Y0C"} <= set(r["outside"])
    # Constant effects cancel in the chain: they cannot be what the after-values show.
    assert r["per_value"]["E_Y0C"]["verdict"] in ("only a change between the runs", "either kind")
    # The extended model is that cause (noise is not fitted as further causes) and leaves
    # E_Y0C's deviation small.
    assert [c["id"] for c in r["extended_model"]["causes"]][:1] == ["between_runs:table_shift_Y"]
    assert len(r["extended_model"]["causes"]) <= 2
    g = r["extended_model"]["per_value"]["E_Y0C"]
    assert abs(g["unexplained_after"]) < abs(g["unexplained_before"]) / 4


def test_table2_analysis_runs_and_is_strict_json():
    r = ft.analyse(
        draws=30, seed=1, sweep=[("bar 150 mm", {"ballbar_length": 150.0})], sweep_draws=20
    )
    text = json.dumps(r, allow_nan=False)
    back = json.loads(text)
    assert set(back["prediction"]) == set(NAMES)
    # E_Y0A measured 10.0 um after compensation; a 0.5 um-noise chain predicts well under 1 um.
    p = back["prediction"]["E_Y0A"]
    assert p["measured_after"] == pytest.approx(10.0) and p["outside"] and p["predicted_std"] < 1.0
    assert len(back["sweep"]) == 1 and back["sweep"][0]["scenario"] == "bar 150 mm"
    assert (
        back["extended_model"]["sum_abs_unexplained"]["um"]["extended"]
        <= back["extended_model"]["sum_abs_unexplained"]["um"]["baseline"]
    )
    out = ft.render(r)
    for n in NAMES:
        assert n in out
