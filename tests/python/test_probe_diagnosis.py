# SPDX-License-Identifier: BSD-3-Clause
"""The touch-probe diagnosis is never confidently wrong (issues 29 and 31), on sessions of the
independent reference simulator (tests/reference/refsim) with set-ups and seeds other than
bench/diagnosis_confusion.py's (sphere at (130, 20, 70), other location errors, other seeds),
noise along each touch's approach direction as the benchmark makes it, coloured where the case
is about coloured noise."""

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
import refsim  # noqa: E402
from refsim import noise, poses, writers  # noqa: E402

import rotacal  # noqa: E402

SPHERE = (130.0, 20.0, 70.0)


def probe_session(tmp_path, machine, effects, seed, kind="white", sigma_um=0.5, sphere=SPHERE):
    """24 poses x 5 touches (refsim's default layout) about `sphere`; the trigger's noise along n,
    one stream over the session: white, "ar1_<rho>" or "pink" (1/f-like)."""
    rng = np.random.default_rng(seed)
    m = refsim.builtin(machine)
    s = poses.probe_poses(m, sphere=sphere)
    errors = {
        n: (rng.normal(0, 0.02) if k % 4 < 2 else rng.normal(0, 4e-5))
        for k, n in enumerate(m.error_names())
    }
    actual = s["sphere"] + rng.normal(0, 0.02, 3)
    latched = refsim.probe_touches(
        refsim.Model(m, errors, effects),
        actual,
        s["sphere"],
        25.0,
        6.0,
        s["n"],
        np.radians(s["angles_deg"]),
        s["time"],
    )
    one = ["touches"] * len(latched)
    sig = sigma_um * 1e-3
    e = (
        noise.white(len(one), sig, rng)
        if kind == "white"
        else noise.pink(one, sig, rng)
        if kind == "pink"
        else noise.ar1(one, float(kind.split("_")[1]), sig, rng)
    )
    n = s["n"] / np.linalg.norm(s["n"], axis=1, keepdims=True)
    path = writers.write_probe(
        tmp_path / f"probe_{machine}_{seed}.csv",
        m,
        s,
        latched + e[:, None] * n,
        25.0,
        6.0,
        noise_um=sigma_um,
    )
    return rotacal.load(path)


def first(d: dict) -> tuple:
    """(named effect or None, the group's members) of the first finding; (None, []) for none."""
    if not d["findings"]:
        return None, []
    f = d["findings"][0]
    return (f["effect"] if f["named"] else None), [g["effect"] for g in f["group"]]


@pytest.mark.parametrize("seed", [801, 816, 819, 824])
def test_every_finding_in_correlated_noise_has_a_determined_parameter(tmp_path, seed):
    """Issue 29 item 6 for the final numbers: in coloured noise the final model is refitted by
    GLS under the noise it leaves (REML); a finding none of whose parameters is then 3 sigma from
    zero is no finding. Before, these sessions (null, and a sag of A) named stylus_radius_offset
    at 0.1 and 1.5 sigma, straightness_ZX, thermal_drift_Z at 0.01 sigma, axial_motion_C_h2."""
    for kind, machine, effects in (
        ("pink", "BC-trt", {}),
        ("ar1_0.9", "AC-trt", {}),
        ("pink", "AC-trt", {"gravity_sag_A": 4e-3}),
    ):
        d = rotacal.diagnose(probe_session(tmp_path, machine, effects, seed, kind=kind)).to_dict()
        for f in d["findings"]:
            ps = [p for p in f["parameters"].values() if p["value"] is not None and p["std"]]
            assert any(abs(p["value"]) >= 3 * p["std"] for p in ps), (kind, f["effect"], ps)


def test_lobing_the_default_touches_cannot_see_is_reported_unobservable(tmp_path):
    """Three-lobed trigger lobing, sampled by four horizontal touches 90 deg apart and one from
    above, moves the touches as a shift of the sphere does: it is reported unobservable and the
    session's finding (a wobble of C) is named, not the lobing."""
    d = rotacal.diagnose(
        probe_session(
            tmp_path,
            "AC-trt",
            {"probe_lobing": [2e-3, -1e-3], "tilt_motion_C_h2": [0, 0, 3e-5, 0]},
            901,
            kind="ar1_0.5",
        )
    ).to_dict()
    assert "probe_lobing" in {u["effect"] for u in d["unobservable"]}
    assert all(f["effect"] != "probe_lobing" for f in d["findings"])
    named, group = first(d)
    assert named == "tilt_motion_C_h2" or "tilt_motion_C_h2" in group, d["findings"][:1]


def test_the_slow_part_of_1f_noise_is_no_stylus_radius_offset(tmp_path):
    """1/f-like trigger noise holds parts slower than the session: they shift every touch along
    its approach alike, as a stylus radius offset does, and the residuals cannot show them (the
    offset takes them). The diagnosis weighs the offset against the declared noise's variance
    the residuals lack (a level of the stream); before, 11 of these 40 null sessions named it."""
    named = []
    for machine in ("AC-trt", "BC-trt"):
        for seed in range(1101, 1121):
            d = rotacal.diagnose(probe_session(tmp_path, machine, {}, seed, kind="pink")).to_dict()
            if any(
                f["effect"] == "stylus_radius_offset"
                or "stylus_radius_offset" in [g["effect"] for g in f["group"]]
                for f in d["findings"]
            ):
                named.append((machine, seed))
    assert not named, named


@pytest.mark.parametrize(
    "machine,seed", [("AC-trt", 2252), ("AC-trt", 2291), ("BC-trt", 2138), ("BC-trt", 2276)]
)
def test_the_slow_part_of_1f_noise_along_the_poses_is_no_finding(tmp_path, machine, seed):
    """1/f-like trigger noise wanders slowly along the pose order, as a drift, a harmonic of the C
    sweep or a shape of the tilt sweep does. A candidate following it leaves a residual that looks
    white or AR(1), and judged under that model it was found: these null sessions named
    axial_motion_C_h2, linear_scale_Z (alone, weight 0.92) and thermal_drift_Z groups before.
    The residuals lack much of the declared noise's variance (the fit took its slow part), so
    every candidate is judged under the 1/f-like treatment; nothing is found."""
    d = rotacal.diagnose(probe_session(tmp_path, machine, {}, seed, kind="pink")).to_dict()
    assert not d["findings"], [(f["effect"], f["named"], f["weight"]) for f in d["findings"]]


@pytest.mark.parametrize("kind", ["white", "ar1_0.9"])
def test_a_stylus_radius_offset_is_still_named(tmp_path, kind):
    """...while a real offset of a few um (10x its half-detection size on this layout) is named,
    its sigma covering the truth (within 3 sigma; AR(1) 0.9 seed 1201 was 3.4 sigma off before)."""
    for seed in range(1201, 1206):
        d = rotacal.diagnose(
            probe_session(tmp_path, "AC-trt", {"stylus_radius_offset": [5e-3]}, seed, kind=kind)
        ).to_dict()
        named, group = first(d)
        assert named == "stylus_radius_offset", (seed, d["findings"][:1])
        p = d["findings"][0]["parameters"]["stylus_radius_offset"]
        assert abs(p["value"] - 5e-3) <= 3 * p["std"], (seed, p)


def warmup_tau_s(machine) -> float:
    """A warm-up time constant other than the fits' start (300 s): a quarter of the session."""
    return 0.25 * float(poses.probe_poses(refsim.builtin(machine), sphere=SPHERE)["time"][-1])


@pytest.mark.parametrize("seed", [1301, 1302, 1303])
def test_a_warmup_beside_a_wobble_is_named_with_its_amplitude_covered(tmp_path, seed):
    """Two catalogue effects at once in AR(1) 0.5 noise: a warm-up along Y whose time constant
    (a quarter of the session) is not the fits' 300 s start, and a second-order wobble of C. The
    fits hold the time constant there no more (core/time_constant_fit.hpp): the warm-up is named
    first and its amplitude and time constant cover the truth within 3 sigma. Before, tau was
    held at 300 s, the amplitude came out 3-10 sigma off and a thermal_drift took the rest."""
    tau = warmup_tau_s("BC-trt")
    d_mm = 0.012
    d = rotacal.diagnose(
        probe_session(
            tmp_path,
            "BC-trt",
            {"thermal_warmup_Y": [d_mm, tau], "tilt_motion_C_h2": [0, 2e-5, 0, 0]},
            seed,
            kind="ar1_0.5",
        )
    ).to_dict()
    warm = [f for f in d["findings"] if f["effect"] == "thermal_warmup_Y"]
    assert warm, [f["effect"] for f in d["findings"]]
    p = warm[0]["parameters"]
    amp, q = p["thermal_warmup_Y.d"], p["thermal_warmup_Y.ln_tau_300s"]
    assert amp["value"] is not None and abs(amp["value"] - d_mm) <= 3 * amp["std"], amp
    assert q["value"] is not None and abs(q["value"] - np.log(tau / 300.0)) <= 3 * q["std"], q
    assert not any(f["effect"].startswith("thermal_drift") for f in d["findings"]), d["findings"]


@pytest.mark.parametrize(
    "entry,size", [("thermal_drift_Z", [4e-5]), ("thermal_warmup_Z", [0.015, None])]
)
def test_a_z_drift_in_strongly_correlated_noise_is_found(tmp_path, entry, size):
    """A drift or warm-up along Z moves each touch by its approach direction's Z part, which the
    five touches of a pose repeat: the noise model of the baseline's residuals took it for slow
    noise with a period of five touches (AR(6) of 1.8 um on 0.5 um AR(1) 0.9 readings). It is
    found (named, or the group that holds it) in each of these sessions, with nothing else named
    first. Before, 'nothing' in most: cross-validation in two blocks of half a session, and the
    walk of the 1/f-like treatment estimated with the drift still in the residuals."""
    params = [size[0], warmup_tau_s("AC-trt")] if entry == "thermal_warmup_Z" else size
    missed = []
    for seed in (1401, 1402, 1403, 1404):
        d = rotacal.diagnose(
            probe_session(tmp_path, "AC-trt", {entry: params}, seed, kind="ar1_0.9")
        ).to_dict()
        named, group = first(d)
        if not (named == entry or (named is None and entry in group)):
            missed.append((seed, named, group))
    assert not missed, missed


@pytest.mark.parametrize("seed", [5304, 5398, 5529, 5890])
def test_moderately_correlated_noise_that_looks_less_so_is_no_finding(tmp_path, seed):
    """One stream of 120 touches in AR(1) 0.5 noise: its lag-1 correlation, after the fit's
    directions, spreads as 0.43 +- 0.09, and a session where it comes out low weighs a slow shape
    against too little long-run variance. A finding must hold with the correlation at the upper
    2-sigma bound of its estimate too (diagnose/correlation_bound.cpp). Before, these null
    sessions named axial_motion_C_h2, radial_motion_A_h4, axial_motion_C_h3 and axial_motion_C_h4."""
    d = rotacal.diagnose(probe_session(tmp_path, "AC-trt", {}, seed, kind="ar1_0.5")).to_dict()
    assert not d["findings"], [(f["effect"], f["named"], f["weight"]) for f in d["findings"]]


def test_a_z_drift_in_moderately_correlated_noise_is_still_found(tmp_path):
    """...while a drift along Z of 1e-5 mm/s (a slow shape, the one the bound weighs least) in
    the same noise is found, named or in the group that holds it, in each of these sessions."""
    missed = []
    for seed in (1451, 1452, 1453, 1454):
        d = rotacal.diagnose(
            probe_session(tmp_path, "AC-trt", {"thermal_drift_Z": [1e-5]}, seed, kind="ar1_0.5")
        ).to_dict()
        named, group = first(d)
        if not (named == "thermal_drift_Z" or (named is None and "thermal_drift_Z" in group)):
            missed.append((seed, named, group))
    assert not missed, missed


@pytest.mark.parametrize("seed", [2502, 2504, 2505, 2507])
def test_a_sag_found_beside_an_aliased_shape_is_not_lost_in_the_final_refit(tmp_path, seed):
    """A 10 um gravity sag of A in AR(1) 0.9 noise is found under one name of its group (a shape of
    A or linear_scale_Z), then a nearly aliased second shape; by GLS neither is determined beside
    the other. The final refit dropped the first and all after it ('nothing' in these sessions);
    it drops the last until the rest are determined, and the sag is in the first finding's group."""
    d = rotacal.diagnose(
        probe_session(tmp_path, "AC-trt", {"gravity_sag_A": 0.01}, seed, kind="ar1_0.9")
    ).to_dict()
    named, group = first(d)
    assert named == "gravity_sag_A" or (named is None and "gravity_sag_A" in group), d["findings"][
        :1
    ]


def bump_session(tmp_path, machine, seed, kind, height_mm=0.004, in_time=False):
    """A session of probe_session's set-up with a shift outside the catalogue added to the
    touches: the table moves by a Gaussian bump, along X as a function of C (20 deg wide at
    C = 90 deg: a localised defect of the rotary table's track), or along Y as a function of
    time (15 s wide at 70 % of the session: the set-up knocked and settling back)."""
    rng = np.random.default_rng(seed)
    m = refsim.builtin(machine)
    s = poses.probe_poses(m, sphere=SPHERE)
    errors = {
        n: (rng.normal(0, 0.02) if k % 4 < 2 else rng.normal(0, 4e-5))
        for k, n in enumerate(m.error_names())
    }
    actual = s["sphere"] + rng.normal(0, 0.02, 3)
    latched = refsim.probe_touches(
        refsim.Model(m, errors, {}),
        actual,
        s["sphere"],
        25.0,
        6.0,
        s["n"],
        np.radians(s["angles_deg"]),
        s["time"],
    )
    n = s["n"] / np.linalg.norm(s["n"], axis=1, keepdims=True)
    if in_time:
        shift, axis = height_mm * np.exp(-0.5 * ((s["time"] - 0.7 * s["time"][-1]) / 15.0) ** 2), 1
    else:
        gap = (s["angles_deg"][:, poses.rotary_roles(m)[1]] - 90.0 + 180.0) % 360.0 - 180.0
        shift, axis = height_mm * np.exp(-0.5 * (gap / 20.0) ** 2), 0
    latched = latched + (shift * n[:, axis])[:, None] * n  # the touch meets the moved sphere
    one = ["touches"] * len(latched)
    sig = 0.5e-3
    e = (
        noise.pink(one, sig, rng)
        if kind == "pink"
        else noise.ar1(one, float(kind.split("_")[1]), sig, rng)
    )
    path = writers.write_probe(
        tmp_path / f"bump_{machine}_{seed}.csv",
        m,
        s,
        latched + e[:, None] * n,
        25.0,
        6.0,
        noise_um=0.5,
    )
    return rotacal.load(path)


@pytest.mark.parametrize(
    "machine,kind,in_time,seeds",
    [
        ("AC-trt", "ar1_0.5", True, (1501, 1502, 1503, 1504)),
        ("BC-trt", "pink", True, (1501, 1502, 1503, 1504, 1601, 1602)),
        ("AC-trt", "ar1_0.5", False, (1501, 1502, 1503, 1504)),
        ("BC-trt", "ar1_0.5", False, (1601, 1602, 1603, 1604)),
    ],
)
def test_a_shape_outside_the_catalogue_gets_no_confident_name(
    tmp_path, machine, kind, in_time, seeds
):
    """A shape outside the catalogue (bump_session) in coloured noise: the diagnosis may name
    nothing, report unexplained structure or a group, never one catalogue entry with
    confidence. Before the local rival (src/diagnose/local_structure.cpp), the X shift peaking at
    C = 90 deg was named straightness_XY alone (weight 1.00; AC-trt seeds 1502-1504, BC-trt 1602
    and 1603) and the Y shift settling back within 15 s thermal_warmup_Y and thermal_drift_Y
    (weights 0.91-1.00, every BC-trt seed here)."""
    for seed in seeds:
        d = rotacal.diagnose(bump_session(tmp_path, machine, seed, kind, in_time=in_time)).to_dict()
        named = [(f["effect"], f["weight"]) for f in d["findings"] if f["named"]]
        assert not named, (seed, named)


@pytest.mark.parametrize("seed", [1701, 1702, 1703])
def test_a_local_shift_outside_the_catalogue_is_reported_where_it_is(tmp_path, seed):
    """bump_session's Y shift settling back within 15 s (at 70 % of the session, in the tilt
    sweep) in AR(1) 0.5 noise: no catalogue entry follows it. Before, the probe's diagnosis said
    nothing at all about it (its structure test fits harmonics of C to the touches' residuals, in
    which the +Y and -Y touches of a pose cancel); it is reported as unexplained structure in the
    poses it holds, in time."""
    m = refsim.builtin("AC-trt")
    s = poses.probe_poses(m, sphere=SPHERE)
    peak = int(
        np.argmin(np.abs(s["time"] - 0.7 * s["time"][-1]))
    )  # the touch nearest the bump's peak
    tilt = s["angles_deg"][peak, poses.rotary_roles(m)[0]]
    res = rotacal.diagnose(bump_session(tmp_path, "AC-trt", seed, "ar1_0.5", in_time=True))
    u = res.raw.unexplained
    assert u.present, u.signature
    # In the tilt sweep the poses' range is told in A (in time where the window's angles do not
    # move one axis alone).
    at = {"A": tilt, "": s["time"][peak]}[u.axis]
    assert u.range_from <= at <= u.range_to, (u.axis, u.range_from, u.range_to, at, u.signature)
    assert not [f for f in res.to_dict()["findings"] if f["named"]]


@pytest.mark.parametrize(
    "machine,sphere,entry,params,kind,seed",
    [
        (
            "AC-trt",
            (0.0, 130.0, 70.0),
            "radial_motion_C_h2",
            [4e-3, 0.0, 0.0, 0.0],
            "ar1_0.9",
            3102,
        ),
        (
            "AC-trt",
            (0.0, 130.0, 70.0),
            "radial_motion_C_h2",
            [4e-3, 0.0, 0.0, 0.0],
            "ar1_0.9",
            3107,
        ),
        (
            "AC-trt",
            (0.0, 130.0, 70.0),
            "radial_motion_C_h2",
            [4e-3, 0.0, 0.0, 0.0],
            "ar1_0.9",
            3120,
        ),
        (
            "BC-trt",
            (120.0, 0.0, 60.0),
            "tilt_motion_B_h2",
            [0.0, 5.8e-5, 0.0, -3.1e-5],
            "ar1_0.5",
            3308,
        ),
    ],
)
def test_a_group_holds_every_rival_a_member_cannot_be_told_apart_from(
    tmp_path, machine, sphere, entry, params, kind, seed
):
    """A sphere on one radius of the table sees a radial motion of C along the tangent only, as an
    angular positioning error of C (and nearly as a tilt of C at the sphere's height): the radial
    motion fits as well with two more parameters. A sphere on the B axis' plane sees a tilt of B
    exactly as an axial motion of B. The first finding is the truth named, or a group holding it.
    Before, the group was the candidates holding 0.9 of the weight and those the best could not
    be told apart from, so [tilt_motion_C_h2, angular_positioning_C_h2] left the radial motion out
    (BIC's Occam term alone put it at 0.01-0.05 weight, the weakest member at about as much), and
    [axial_motion_B_h2, straightness_YZ] the tilt of B at the very weight of the named axial
    motion."""
    d = rotacal.diagnose(
        probe_session(tmp_path, machine, {entry: params}, seed, kind=kind, sphere=sphere)
    ).to_dict()
    named, group = first(d)
    assert named == entry or (named is None and entry in group), d["findings"][:1]


@pytest.mark.parametrize("seed", [3401, 3402, 3403])
def test_a_catalogue_effect_left_in_a_group_is_no_local_defect(tmp_path, seed):
    """A second-order wobble of C in AR(1) 0.5 noise is found as the group of C's second-order
    shapes that one sphere cannot separate. Its local rival (the finding's signature confined to
    a few poses) fits worse, so the finding carries no lack_of_fit and no local structure is
    reported. Before, every finding its catalogue rivals had left without a name was said to be
    explained as well by a local defect, and the wobble's own signal in those poses was reported
    as unexplained local structure (p down to 3e-9)."""
    d = rotacal.diagnose(
        probe_session(
            tmp_path, "BC-trt", {"tilt_motion_C_h2": [0.0, 2e-5, 0.0, 0.0]}, seed, kind="ar1_0.5"
        )
    ).to_dict()
    named, group = first(d)
    assert named == "tilt_motion_C_h2" or (named is None and "tilt_motion_C_h2" in group), d[
        "findings"
    ][:1]
    assert not d["findings"][0].get("lack_of_fit"), d["findings"][0]["lack_of_fit"]
    assert "local structure" not in d["unexplained"].get("signature", ""), d["unexplained"]
