# SPDX-License-Identifier: BSD-3-Clause
"""The touch probe on a sphere (issue 31) from Python: rotacal.load recognises rotacal-probe/1,
rotacal.identify fits it (joint, and the cycles' method as the peer), and sessions made by the
independent reference simulator (tests/reference/refsim: other seeds, AR(1) noise, an effect)
are identified within 3 sigma. The truth of every check comes from /work/shared/data or refsim,
never from rotacal's own simulator."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
import refsim  # noqa: E402
from refsim import noise, poses, writers  # noqa: E402

import rotacal  # noqa: E402

SHARED = Path(__file__).resolve().parents[3] / "shared" / "data"
TABLE2 = SHARED / "probe_ac_table2.csv"


def truth(path: Path) -> dict:
    return json.loads(path.with_suffix(".truth.json").read_text())


def within_3_sigma(result, errors: dict) -> list[str]:
    bad = []
    for name, value in errors.items():
        p = result.parameter(name)
        if not p.observable or abs(p.value - value) > 3 * p.std:
            bad.append(f"{name}: {p.value:.6g} +- {p.std:.2g}, truth {value:.6g}")
    return bad


def test_the_shared_session_loads_and_every_error_is_within_3_sigma():
    s = rotacal.load(TABLE2)
    assert isinstance(s, rotacal.ProbeSession)
    assert len(s) == 120 and len(s.pose_names) == 24
    assert s.trigger_radius == 15.5
    t = truth(TABLE2)
    r = rotacal.identify(s)
    assert r.raw.converged and not r.raw.unobservable
    assert not within_3_sigma(r, t["errors"]), within_3_sigma(r, t["errors"])
    sphere = np.asarray(r.raw.sphere)
    for k in range(3):
        p = r.parameter("sphere." + "xyz"[k])
        assert abs(sphere[k] - t["sphere_actual"][k]) <= 3 * p.std
    d = r.to_dict()
    assert d["method"] == "joint" and set(d["location_errors"]) == set(t["errors"])
    assert d["noise_model"]["white"] in (True, False)


def test_the_cycles_method_runs_as_the_peer():
    s = rotacal.load(TABLE2)
    t = truth(TABLE2)
    for method in ("cycles", "cycles-free-radius"):
        r = rotacal.identify(s, method)
        d = r.to_dict()
        assert d["method"] == "cycles" and d["dispersion_um"] > 0
        assert all(v["std"] is None for v in d["location_errors"].values())  # the cycles give none
        # Same data, same truth: the peer lands near it too (within 10 um / 50 urad here).
        for name, value in t["errors"].items():
            tol = 50e-6 if r.parameter(name).unit == "rad" else 10e-3
            assert abs(r.parameter(name).value - value) < tol, (method, name)
    with pytest.raises(rotacal.InvalidArgument, match="method"):
        rotacal.identify(s, "paper")


def refsim_session(
    tmp_path,
    machine: str,
    errors: dict,
    effects: dict,
    rho: float,
    seed: int,
    sigma_um: float = 0.5,
):
    """A session by the reference simulator: its poses, its touch model, AR(1) noise per latched
    coordinate from touch to touch, written by its writer."""
    m = refsim.builtin(machine)
    ses = poses.probe_poses(m)
    sphere_actual = ses["sphere"] + np.array([0.031, -0.024, 0.017])
    model = refsim.Model(machine, errors, effects)
    latched = refsim.probe_touches(
        model,
        sphere_actual,
        ses["sphere"],
        25.0,
        6.0,
        ses["n"],
        np.radians(ses["angles_deg"]),
        ses["time"],
    )
    rng = np.random.default_rng(seed)
    one = ["touches"] * len(latched)
    latched = latched + np.column_stack(
        [noise.ar1(one, rho, sigma_um * 1e-3, rng) for _ in range(3)]
    )
    path = writers.write_probe(
        tmp_path / f"{machine}_{seed}.csv", m, ses, latched, 25.0, 6.0, noise_um=sigma_um
    )
    return path, sphere_actual


@pytest.mark.parametrize("machine,seed", [("AC-trt", 11), ("BC-trt", 12), ("AC-trt", 13)])
def test_reference_sessions_in_ar1_noise_with_an_effect(tmp_path, machine, seed):
    names = refsim.builtin(machine).error_names()
    rng = np.random.default_rng(seed)
    errors = {
        n: (rng.normal(0, 0.03) if k % 4 < 2 else rng.normal(0, 4e-5)) for k, n in enumerate(names)
    }
    path, sphere_actual = refsim_session(
        tmp_path, machine, errors, {"stylus_radius_offset": 1.5e-3}, rho=0.8, seed=seed
    )
    s = rotacal.load(path, format="probe")
    r = rotacal.identify(s, effects=["stylus_radius_offset"])
    assert r.raw.noise.n == len(
        s
    )  # the noise model of the residuals (AR per coordinate seen along n)
    assert not within_3_sigma(r, errors), within_3_sigma(r, errors)
    assert not within_3_sigma(r, {"stylus_radius_offset": 1.5e-3})
    # Teeth: the offset is determined (well away from zero), and the baseline alone leaves it in
    # its residuals.
    d = r.parameter("stylus_radius_offset")
    assert abs(d.value) > 5 * d.std
    base = rotacal.identify(s, noise="white")
    assert base.raw.residual_rms_um > 1.3 * r.raw.residual_rms_um


def test_rotacal_simulation_round_trips_through_a_file(tmp_path):
    names = rotacal.location_error_names(rotacal.MachineType.AC_trt)
    s, sphere = rotacal.simulate_probe(
        "AC-trt", np.full(8, 1e-5), {"probe_lobing": [1e-3, 0.0]}, seed=3
    )
    assert len(s) == 120 and np.asarray(sphere).shape == (3,)
    path = tmp_path / "sim.csv"
    rotacal.save(s, path)
    again = rotacal.load(path)
    assert np.array_equal(np.asarray(again.xyz), np.asarray(s.xyz))
    assert np.array_equal(np.asarray(again.n), np.asarray(s.n))
    assert len(names) == 8


def test_bad_probe_files_are_refused_naming_file_line_and_column(tmp_path):
    lines = TABLE2.read_text().splitlines()
    bad = list(lines)
    bad[8] = bad[8].replace("-0.866025,-0.000000,-0.500000", "-0.9,-0.000000,-0.500000")
    p = tmp_path / "bad.csv"
    p.write_text("\n".join(bad) + "\n")
    with pytest.raises(rotacal.ParseError, match=r"bad\.csv:9:\d+: approach direction"):
        rotacal.load(p)
    bad = list(lines)
    bad[7] = bad[7].replace(",0.0000,0.0000,", ",0.0000,nan,", 1)
    p.write_text("\n".join(bad) + "\n")
    with pytest.raises(rotacal.ParseError, match=r"bad\.csv:8:\d+: C"):
        rotacal.load(p)
    p.write_text("\n".join(lines[:6] + ["pose,time,X,Y,Z,A,C,nx,ny"] + lines[7:9]) + "\n")
    with pytest.raises(rotacal.ParseError, match="missing required column 'nz'"):
        rotacal.load(p)
    with pytest.raises(rotacal.ParseError, match="rotacal-probe/1"):
        rotacal.load(SHARED / "ballbar_ac_table2.csv", format="probe")
    with pytest.raises(rotacal.InvalidArgument, match="format"):
        rotacal.load(TABLE2, format="gcode")


def test_a_wrong_stylus_radius_in_a_reference_session_is_named(tmp_path):
    """The diagnosis on data from the reference simulator: a stylus 3 um larger than its
    calibration is named stylus_radius_offset with its size; the same session without it names
    nothing."""
    names = refsim.builtin("AC-trt").error_names()
    errors = dict(
        zip(
            names,
            [0.0726, -0.0202, 1.1284e-05, -0.000113006, 0.0283, 0.1041, 5.1954e-06, -4.1544e-05],
        )
    )
    path, _ = refsim_session(
        tmp_path, "AC-trt", errors, {"stylus_radius_offset": 3e-3}, rho=0.0, seed=31
    )
    d = rotacal.diagnose(rotacal.load(path), max_harmonic=2)
    assert d.raw.findings and d.raw.findings[0].effect == "stylus_radius_offset"
    p = d.raw.findings[0].parameters[0]
    assert abs(p.value - 3e-3) <= 3 * p.std
    path, _ = refsim_session(tmp_path, "AC-trt", errors, {}, rho=0.0, seed=32)
    assert not rotacal.diagnose(rotacal.load(path), max_harmonic=2).raw.findings


def test_the_budget_of_a_probe_session_carries_the_stylus_calibration():
    """The GUM budget of the shared session: every location error has a type-A part and type-B
    lines, among them the probe's own stylus_radius_offset; a larger plausible stylus error
    gives a larger line."""
    s = rotacal.load(TABLE2)
    d = rotacal.diagnose(s, max_harmonic=2)
    b = rotacal.uncertainty_budget(s, d)
    assert len(b.errors) == 8
    stylus = {}
    for e in b.errors:
        assert e.u_a > 0 and e.u_c >= e.u_a
        stylus[e.name] = sum(line.u for line in e.type_b if line.effect == "stylus_radius_offset")
    assert any(v > 0 for v in stylus.values())
    wide = rotacal.uncertainty_budget(s, d, sizes={"stylus_radius_mm": 5e-3})
    for e in wide.errors:
        u = sum(line.u for line in e.type_b if line.effect == "stylus_radius_offset")
        assert u >= stylus[e.name] - 1e-15
