# SPDX-License-Identifier: BSD-3-Clause
"""Structure is not noise (issue 50 item 4): an error outside the catalogue that the noise model
would take in (a high AR order on a short stream, one instrument's channels at different noise
levels) is reported as unexplained structure, where it sits, how large and which test would
resolve it; with nothing hidden in coloured noise it is not. Data from the independent reference
simulator (tests/reference/refsim via structure_data.py), with seeds, set-ups and amplitudes
other than the issue's; the bigger null count is bench/structure_null.py."""

import pytest
import structure_data as sd
from test_json_schema import check, schemas

import rotacal

OTHER_NESTS = ((130.0, 40.0, 40.0), (-30.0, -100.0, 170.0))


@pytest.mark.parametrize(
    "seed, bump, nests, peak",
    [
        (31, (100e-6, 200.0, 8.0), sd.NESTS, 210.0),
        (32, (80e-6, 200.0, 8.0), OTHER_NESTS, 210.0),
        # Elsewhere, nearly on a sampled angle (82 urad at C 90): no catalogue shape is found and
        # the noise model (AR(7), 1.4 um) took it all; reported as structure at C 90.
        (33, (100e-6, 95.0, 8.0), sd.NESTS, 90.0),
    ],
    ids=["issue_bump", "smaller_other_nests", "bump_at_c95"],
)
def test_rtest_bump_in_c_is_reported_as_structure_where_it_is(tmp_path, seed, bump, nests, peak):
    """12 C angles 30 deg apart see a bump of sigma 8 deg at one or two of them: the diagnosis
    names angular positioning harmonics (the nearest catalogue shape), and then reports the rest
    as structure near the bump, at the instrument's own noise level, not as 'unexplained: no'
    under a noise model twice the instrument's."""
    path = sd.rtest(tmp_path / "bump.csv", seed, bump=bump, nests=nests)
    d = rotacal.diagnose(rotacal.load(path)).to_dict()
    if peak == 210.0:  # named correctly in kind, as before
        assert d["findings"] and d["findings"][0]["effect"].startswith("angular_positioning_C")
    u = d["unexplained"]
    assert u["present"], u
    ns = u["noise_structure"]
    assert u["axis"] == "C" and ns["at"] == pytest.approx(peak), u
    assert u["range_from"] <= peak <= u["range_to"], u
    assert f"C angles between {peak - 30:.0f} and {peak + 30:.0f} deg" in ns["suggested_test"], ns
    assert ns["f_test_p"] < 0.01 and "noise levels of the channels differ" in ns["reason"], ns
    # The instrument's noise is the quiet channels' (0.3 um simulated; 0.42 where nothing is
    # named and the location errors took a little of the bump), the structure beyond it.
    assert 0.22 < ns["noise_um"] < 0.45 and ns["size_um"] > 2 * ns["noise_um"], ns
    assert "structure the noise model took for noise" in u["signature"]
    named = schemas()
    check(u, named["unexplained"], "unexplained", named)  # docs/json_schema.md


def test_rtest_bump_in_the_cli_text(tmp_path):
    path = sd.rtest(tmp_path / "bump.csv", 34, bump=(100e-6, 200.0, 8.0))
    from rotacal.cli import main

    import contextlib
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        main(["diagnose", str(path), "--no-progress"])
    text = out.getvalue()
    assert (
        "unexplained structure remains" in text and "at C 210 deg are structure, not noise" in text
    ), text
    assert "C angles between 180 and 240 deg" in text, text
    # This seed's bump also took the largest AR order on a stream of 84 readings (item 4's (b)).
    assert "largest AR order allowed, AR(8)" in text, text


def null_counts(tmp_path, make, seeds, **kw) -> dict:
    c = {"sessions": 0, "unexplained": 0, "noise_structure": 0, "named_wrong": 0}
    for seed in seeds:
        d = rotacal.diagnose(rotacal.load(make(tmp_path / f"n{seed}.csv", seed, **kw))).to_dict()
        c["sessions"] += 1
        c["unexplained"] += bool(d["unexplained"]["present"])
        c["noise_structure"] += "noise_structure" in d["unexplained"]
        c["named_wrong"] += bool(d["findings"]) and d["findings"][0]["named"]
    return c


@pytest.mark.parametrize(
    "make, kind",
    [(sd.rtest, "ar1"), (sd.rtest, "pink"), (sd.probe, "ar1"), (sd.probe, "pink")],
    ids=["rtest_ar1", "rtest_1f", "probe_ar1", "probe_1f"],
)
def test_nothing_hidden_in_coloured_noise_is_no_structure(tmp_path, make, kind):
    """Counted over 6 sessions a cell (24 in all, a few seconds; 200 in the bench): at most one
    session of a cell with unexplained structure, none named wrong. Before, a probe session of one
    group tested its AR(1) residuals against white noise: 5 of 12 AR(1) 0.5 and 1/f-like probe
    sessions flagged."""
    c = null_counts(tmp_path, make, range(610, 616), kind=kind)
    assert c["unexplained"] <= 1 and c["named_wrong"] == 0, c
