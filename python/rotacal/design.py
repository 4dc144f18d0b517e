# SPDX-License-Identifier: BSD-3-Clause
"""Test design before the machine runs it (``rotacal design ballbar|rtest|probe``): the pivot and
bar length whose single set-up test gives the smallest largest expanded uncertainty of the
location errors at a run time, within the machine's travel, from the Fisher information of the
joint model (C++: ``rotacal/ballbar/design.hpp``; docs/design.md); the R-test's nests and grid.
The touch probe's poses: probe_design.py."""

from __future__ import annotations

import json
from typing import Any, Sequence

import numpy as np

from . import _core


def design_ballbar(
    base: Any,
    *,
    lengths: Sequence[float] = (100.0, 150.0),
    pivot_x: Sequence[float] | None = None,
    pivot_z: Sequence[float] | None = None,
    travel: Sequence[float] | None = None,
    time_s: float = 0.0,
    rate_hz: float = 100.0,
    noise_um: float = 0.5,
    rho: float = 0.0,
    effects: Sequence[str] = (),
) -> Any:
    """A ``_core.BallbarDesign``: ``.best`` and ``.baseline`` (the ``base`` set-up) with their
    predicted 1-sigma at the same run time (``time_s``, 0: the base set-up's), ``.ratio`` of
    their worst expanded uncertainties, and every candidate tried. ``travel``: xmin, xmax,
    ymin, ymax, zmin, zmax of the machine axes in mm (formats.md frame)."""
    o = _core.BallbarDesignOptions()
    o.base = base
    o.bar_lengths_mm = [float(v) for v in lengths]
    if pivot_x is not None:
        o.pivot_x_mm = [float(v) for v in pivot_x]
    if pivot_z is not None:
        o.pivot_z_mm = [float(v) for v in pivot_z]
    if travel is None:  # the machine's own travel, when its description gives one
        travel = machine_travel(base.machine)
    if travel is not None:
        o.travel_min, o.travel_max = _travel(travel)
    o.time_budget_s = float(time_s)
    o.sample_rate_hz = float(rate_hz)
    o.noise_um = float(noise_um)
    o.noise_rho = float(rho)
    o.effects_of_concern = list(effects)
    return _core.design_ballbar_test(o)


def parameter_units(names: Sequence[str]) -> list[tuple[str, float]]:
    """(display unit, factor from the fit's unit) of each parameter of a design candidate:
    um for mm, urad for rad, the effect's own unit otherwise."""
    out = []
    for i, n in enumerate(names):
        if i < 8:
            out.append(("urad", 1e6) if i in (2, 3, 6, 7) else ("um", 1e3))
            continue
        if n.startswith(
            ("pivot_", "zero_", "sphere.", "tool_offset_")
        ):  # pivot_x (pivot_x#2 of a second set-up),
            # R-test probe zeros, the touch probe's sphere and a head's tool length
            out.append(("um", 1e3))
            continue
        eid, _, pname = n.partition(".")
        eff = _core.Effect(eid)
        unit = eff.param_units[eff.param_names.index(pname) if pname else 0]
        out.append({"mm": ("um", 1e3), "rad": ("urad", 1e6)}.get(unit, (unit, 1.0)))
    return out


def candidate_dict(c: Any) -> dict:
    """One evaluated set-up as JSON."""
    out = {
        "ballbar_length": c.setup.ballbar_length,
        "pivot": list(map(float, c.setup.pivot)),
        "feasible": c.feasible,
        "duration_s": c.duration_s,
    }
    if not c.feasible:
        return out | {"why_not": c.why_not}
    out["predicted_std"] = {n: float(s) for n, s in zip(c.names, c.sigma)}
    out["worst_expanded_um"] = c.worst_expanded_um
    out["worst_error"] = c.worst_error
    effects = [n for n in c.names[11:]]
    if effects:
        out["effect_correlation"] = {
            n: {"max_with_location_errors": a, "max_with_other_effects": b}
            for n, a, b in zip(effects, c.effect_vs_location, c.effect_vs_effects)
        }
    return out


def design_dict(d: Any) -> dict:
    """The JSON of ``rotacal design ballbar --json``."""
    return {
        "time_budget_s": d.time_budget_s,
        "ratio_to_default": d.ratio,
        "best": candidate_dict(d.best),
        "default": candidate_dict(d.baseline),
        "candidates": [candidate_dict(c) for c in d.candidates],
    }


def design_separation(
    session: Any,
    pair: Sequence[str],
    *,
    base: Any | None = None,
    lengths: Sequence[float] = (100.0, 150.0),
    pivot_r: Sequence[float] | None = None,
    pivot_angle: Sequence[float] | None = None,
    pivot_z: Sequence[float] | None = None,
    travel: Sequence[float] | None = None,
    tilt_limits: Sequence[float] | None = None,
    max_time_s: float = 600.0,
    max_correlation: float = 0.5,
    noise_um: float = 0.0,
) -> Any:
    """A ``_core.SeparationDesign``: the smallest ballbar test to add to ``session`` (a
    ``BallbarSession``) so that the two effects of ``pair`` (catalogue ids) come out of the
    joint fit with a canonical correlation below ``max_correlation``, the predicted 1-sigma of
    every parameter before and after, or the reason no test can (their table motions are the
    same). ``base``: a ``BallbarSetup`` whose step, feeds and C range the added test uses."""
    _check_pair(pair)
    o = _core.SeparationOptions()
    if base is not None:
        o.added = base
    o.bar_lengths_mm = [float(v) for v in lengths]
    for value, field in (
        (pivot_r, "pivot_radius_mm"),
        (pivot_angle, "pivot_angle_deg"),
        (pivot_z, "pivot_z_mm"),
    ):
        if value is not None:
            setattr(o, field, [float(v) for v in value])
    if travel is None:
        travel = machine_travel(session.machine)
    if travel is not None:
        o.travel_min, o.travel_max = _travel(travel)
    if tilt_limits is not None:
        o.tilt_limits_deg = [float(v) for v in tilt_limits]
    _search_limits(o, max_time_s, max_correlation, noise_um)
    return _core.design_ballbar_separation(session, list(pair), o)


def _check_pair(pair: Sequence[str]) -> None:
    if len(pair) != 2:
        raise _core.InvalidArgument(
            f"--separate: {','.join(pair)}: give two effects, EFFECT,EFFECT"
        )


def _search_limits(o: Any, max_time_s: float, max_correlation: float, noise_um: float) -> None:
    """The limits every separation search takes (design/separation.hpp)."""
    o.max_added_time_s = float(max_time_s)
    o.max_correlation = float(max_correlation)
    o.noise_um = float(noise_um)


def machine_travel(machine: Any) -> list[float] | None:
    """xmin, xmax, ymin, ymax, zmin, zmax of the machine's description (travel_mm), if it has one."""
    t = json.loads(machine.description_json).get("travel_mm")
    return None if t is None else [float(v) for row in t for v in row]


def _travel(travel: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(travel, dtype=float).reshape(3, 2)
    if np.any(t[:, 0] >= t[:, 1]):
        raise _core.InvalidArgument(
            "--travel: each axis needs min < max (xmin,xmax,ymin,ymax,zmin,zmax)"
        )
    return t[:, 0], t[:, 1]


def added_setup(d: Any) -> Any:
    """The set-up of the chosen added test with its feeds divided by the slow-down (what its
    NC program runs)."""
    s = d.chosen.setup
    s.feed_mm_per_min = s.feed_mm_per_min / d.chosen.slow_down
    s.feed_deg_per_min = s.feed_deg_per_min / d.chosen.slow_down
    return s


def separation_dict(d: Any) -> dict:
    """The JSON of ``rotacal design ballbar --separate ... --after SESSION``."""
    out = _separation_common(d)
    if d.candidates_tried:
        c = d.chosen
        out["added_test"] = {
            "description": c.description,
            "tests": [_core.test_label(t, c.setup.machine) for t in c.setup.tests],
            "ballbar_length": c.setup.ballbar_length,
            "pivot": list(map(float, c.setup.pivot)),
            "new_pivot": c.new_pivot,
            "tilt_range_deg": list(c.setup.tilt_range_deg),
            "radial_c_side": c.setup.radial_c_side.name,
            "run_time_s": c.duration_s * c.slow_down,
            "slow_down": c.slow_down,
            "correlation_after": c.correlation,
        }
    return out


def design_rtest(
    *,
    radii: Sequence[float] | None = None,
    heights: Sequence[float] | None = None,
    b_steps: Sequence[float] | None = None,
    c_steps: Sequence[float] | None = None,
    b_limits: Sequence[float] | None = None,
    travel: Sequence[float] | None = None,
    time_s: float = 0.0,
    noise_um: float = 0.3,
    rho: float = 0.0,
    dwell_s: float | None = None,
) -> Any:
    """A ``_core.RtestDesign``: the two R-test nests and the B/C grid with the smallest
    predicted largest expanded uncertainty of the location errors at the run time ``time_s``
    (0: the default pattern's), against the default pattern (C++: ``rotacal/rtest/design.hpp``)."""
    o = _core.RtestDesignOptions()
    for value, field in (
        (radii, "nest_radius_mm"),
        (heights, "nest_height_mm"),
        (b_steps, "b_step_deg"),
        (c_steps, "c_step_deg"),
    ):
        if value is not None:
            setattr(o, field, [float(v) for v in value])
    if b_limits is not None:
        o.b_limits_deg = [float(v) for v in b_limits]
    if travel is not None:
        o.travel_min, o.travel_max = _travel(travel)
    if dwell_s is not None:
        base = o.base
        base.dwell_s = float(dwell_s)
        o.base = base
    o.time_budget_s = float(time_s)
    o.noise_um = float(noise_um)
    o.noise_rho = float(rho)
    return _core.design_rtest_test(o)


def rtest_candidate_dict(c: Any) -> dict:
    """One evaluated R-test pattern as JSON."""
    p = c.pattern
    out = {
        "nests": [list(map(float, n)) for n in p.nests],
        "b_deg": list(p.b_deg),
        "c_deg": list(p.c_deg),
        "dwell_s": p.dwell_s,
        "feasible": c.feasible,
        "duration_s": c.duration_s,
    }
    if not c.feasible:
        return out | {"why_not": c.why_not}
    return out | {
        "predicted_std": {n: float(s) for n, s in zip(c.names, c.sigma)},
        "worst_expanded_um": c.worst_expanded_um,
        "worst_error": c.worst_error,
    }


def rtest_design_dict(d: Any) -> dict:
    """The JSON of ``rotacal design rtest --json``."""
    return {
        "time_budget_s": d.time_budget_s,
        "ratio_to_default": d.ratio,
        "best": rtest_candidate_dict(d.best),
        "default": rtest_candidate_dict(d.baseline),
        "candidates": [rtest_candidate_dict(c) for c in d.candidates],
    }


def design_rtest_separation(
    session: Any,
    pair: Sequence[str],
    *,
    radii: Sequence[float] | None = None,
    angles: Sequence[float] | None = None,
    heights: Sequence[float] | None = None,
    b_steps: Sequence[float] | None = None,
    c_steps: Sequence[float] | None = None,
    b_limits: Sequence[float] | None = None,
    travel: Sequence[float] | None = None,
    dwell_s: float = 0.0,
    max_time_s: float = 600.0,
    max_correlation: float = 0.5,
    noise_um: float = 0.0,
) -> Any:
    """A ``_core.RtestSeparationDesign``: the smallest R-test nest (position and grid) to add to
    ``session`` (an ``RtestSession``) so that the two effects of ``pair`` come out of the joint
    fit with a canonical correlation below ``max_correlation``, or why no test can."""
    _check_pair(pair)
    o = _core.RtestSeparationOptions()
    for value, field in (
        (radii, "nest_radius_mm"),
        (angles, "nest_angle_deg"),
        (heights, "nest_height_mm"),
        (b_steps, "b_step_deg"),
        (c_steps, "c_step_deg"),
    ):
        if value is not None:
            setattr(o, field, [float(v) for v in value])
    if b_limits is not None:
        o.b_limits_deg = [float(v) for v in b_limits]
    if travel is not None:
        o.travel_min, o.travel_max = _travel(travel)
    o.dwell_s = float(dwell_s)
    _search_limits(o, max_time_s, max_correlation, noise_um)
    return _core.design_rtest_separation(session, list(pair), o)


def _separation_common(d: Any) -> dict:
    def sig(v: Any) -> dict:
        return {n: (float(s) if np.isfinite(s) else None) for n, s in zip(d.names, v)}

    out = {
        "effects": list(d.effects),
        "separable": not d.motion.same_motion,
        "already_separated": d.already_separated,
        "found": d.found,
        "verdict": d.verdict,
        "table_motion": {
            "same_motion": d.motion.same_motion,
            "cosine": d.motion.cosine,
            "why": d.motion.why,
        },
        "correlation_before": d.correlation_before,
        "predicted_std_before": sig(d.sigma_before),
        "noise_um": d.noise_um,
        "effective_samples_per_reading": d.effective_per_reading,
        "candidates_tried": d.candidates_tried,
    }
    if d.candidates_tried:
        out["predicted_std_after"] = sig(d.sigma_after)
    return out


def rtest_separation_dict(d: Any) -> dict:
    """The JSON of ``rotacal design rtest --separate ... --after SESSION``."""
    out = _separation_common(d)
    if d.candidates_tried:
        c = d.chosen
        p = c.added
        out["added_nest"] = {
            "description": c.description,
            "nest": list(map(float, p.nests[0])),
            "b_deg": list(p.b_deg),
            "c_deg": list(p.c_deg),
            "dwell_s": p.dwell_s,
            "repeats": c.repeats,
            "run_time_s": c.duration_s * c.repeats,
            "correlation_after": c.correlation,
        }
    return out


# ------------------------------------------------------------------------- touch probe

# Where the engineer may place the sphere on the table instead of plan probe's (150, 0, 80), table
# frame, mm: farther out on the rotary table (a longer lever for its orientation errors) and
# lower (docs/design.md, "Touch probe"); `design probe` takes one when the design there pays.
