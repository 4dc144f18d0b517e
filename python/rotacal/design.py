"""Test design before the machine runs it (``rotacal design ballbar``): the pivot and bar length
whose single set-up test gives the smallest largest expanded uncertainty of the location
errors at a run time, within the machine's travel, from the Fisher information of the joint
model (C++: ``rotacal/ballbar/design.hpp``; docs/design.md)."""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from . import _core


def design_ballbar(base: Any, *, lengths: Sequence[float] = (100.0, 150.0),
                   pivot_x: Sequence[float] | None = None, pivot_z: Sequence[float] | None = None,
                   travel: Sequence[float] | None = None, time_s: float = 0.0, rate_hz: float = 100.0,
                   noise_um: float = 0.5, rho: float = 0.0, effects: Sequence[str] = ()) -> Any:
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
    if travel is not None:
        t = np.asarray(travel, dtype=float).reshape(3, 2)
        if np.any(t[:, 0] >= t[:, 1]):
            raise _core.InvalidArgument("--travel: each axis needs min < max (xmin,xmax,ymin,ymax,zmin,zmax)")
        o.travel_min, o.travel_max = t[:, 0], t[:, 1]
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
        if i < 11:
            out.append(("urad", 1e6) if i in (2, 3, 6, 7) else ("um", 1e3))
            continue
        eid, _, pname = n.partition(".")
        eff = _core.Effect(eid)
        unit = eff.param_units[eff.param_names.index(pname) if pname else 0]
        out.append({"mm": ("um", 1e3), "rad": ("urad", 1e6)}.get(unit, (unit, 1.0)))
    return out


def candidate_dict(c: Any) -> dict:
    """One evaluated set-up as JSON."""
    out = {"ballbar_length": c.setup.ballbar_length, "pivot": list(map(float, c.setup.pivot)),
           "feasible": c.feasible, "duration_s": c.duration_s}
    if not c.feasible:
        return out | {"why_not": c.why_not}
    out["predicted_std"] = {n: float(s) for n, s in zip(c.names, c.sigma)}
    out["worst_expanded_um"] = c.worst_expanded_um
    out["worst_error"] = c.worst_error
    effects = [n for n in c.names[11:]]
    if effects:
        out["effect_correlation"] = {n: {"max_with_location_errors": a, "max_with_other_effects": b}
                                     for n, a, b in zip(effects, c.effect_vs_location, c.effect_vs_effects)}
    return out


def design_dict(d: Any) -> dict:
    """The JSON of ``rotacal design ballbar --json``."""
    return {"time_budget_s": d.time_budget_s, "ratio_to_default": d.ratio,
            "best": candidate_dict(d.best), "default": candidate_dict(d.baseline),
            "candidates": [candidate_dict(c) for c in d.candidates]}
