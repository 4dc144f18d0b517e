# SPDX-License-Identifier: BSD-3-Clause
"""Touch-probe test design (``rotacal design probe``): the poses of a sphere test with the
smallest largest expanded uncertainty, and the poses added to separate two effects after a
session (C++: ``rotacal/probe/design.hpp``; docs/design.md)."""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from . import _core
from .design import _check_pair, _search_limits, _separation_common


# Along +X only: the rotary table turns a place along +Y into one along +X (the same poses a
# quarter turn apart), so those would repeat them.
SPHERE_CANDIDATES = ((250.0, 0.0, 80.0), (300.0, 0.0, 40.0))


def design_probe(
    machine: Any,
    *,
    sphere: Sequence[float] = (150.0, 0.0, 80.0),
    sphere_diameter: float = 25.0,
    stylus_diameter: float = 6.0,
    touches: int = 0,
    tilt_step: float = 15.0,
    rot_step: float = 30.0,
    noise_um: float = 0.5,
    touch_directions: bool = True,
    max_contact_angle: float = 80.0,
    sphere_candidates: Any = SPHERE_CANDIDATES,
    sphere_gain: float = 0.05,
) -> Any:
    """A ``_core.ProbeDesign``: the rotary poses (in program order; ``.best.poses_deg``) and each
    touch's approach direction (``.best.pose_directions``; with ``touch_directions=False`` every
    visit along the default directions) that give the smallest largest expanded uncertainty
    (k = 2) of the location errors at ``touches`` touches (0: the default poses'), within the
    machine's axis limits, with the sphere at ``sphere`` or, when that lowers it by
    ``sphere_gain``, at one of ``sphere_candidates`` (``.sphere``); against ``plan probe``'s default
    poses at ``sphere`` and the same number of touches (``.baseline``, ``.ratio``). C++:
    ``rotacal/probe/design.hpp``."""
    o = _core.ProbeDesignOptions()
    o.machine = machine
    o.sphere = np.asarray(sphere, dtype=float)
    o.sphere_diameter = float(sphere_diameter)
    o.stylus_diameter = float(stylus_diameter)
    o.touches = int(touches)
    o.tilt_step_deg = float(tilt_step)
    o.rot_step_deg = float(rot_step)
    o.noise_um = float(noise_um)
    o.touch_directions = bool(touch_directions)
    o.max_contact_angle_deg = float(max_contact_angle)
    o.sphere_candidates = np.asarray(sphere_candidates, dtype=float).reshape(-1, 3)
    o.sphere_gain = float(sphere_gain)
    return _core.design_probe_test(o)


def poses_text(poses_deg: Any) -> str:
    """Pose visits (P, 2) as ``plan probe --poses`` takes them: "T,R;T,R;..." (deg)."""
    return ";".join(f"{t:g},{r:g}" for t, r in np.asarray(poses_deg, dtype=float))


def probe_candidate_dict(c: Any) -> dict:
    """One evaluated set of probe poses as JSON."""
    out = {
        "poses_deg": np.asarray(c.poses_deg).tolist(),
        "directions": np.asarray(c.directions).tolist(),
        "pose_directions": [np.asarray(d).tolist() for d in c.pose_directions],
        "sphere": np.asarray(c.sphere).tolist(),
        # Feasible: every parameter determined. Those no pose can determine are named instead.
        "feasible": c.feasible and not len(c.undetermined),
        "touches": c.touches,
        "undetermined": list(c.undetermined),
    }
    if not c.feasible:
        return out | {"why_not": c.why_not}
    if len(c.undetermined):
        out["why_not"] = (
            f"{', '.join(c.undetermined)}: no probe pose of the candidates determines "
            f"{'it' if len(c.undetermined) == 1 else 'them'} (left out of the largest expanded uncertainty)"
        )
    return out | {
        "predicted_std": {
            n: (float(s) if np.isfinite(s) else None) for n, s in zip(c.names, c.sigma)
        },
        "worst_expanded_um": c.worst_expanded_um,
        "worst_error": c.worst_error,
        "poses_option": poses_text(c.poses_deg),
    }


def probe_design_dict(d: Any) -> dict:
    """The JSON of ``rotacal design probe --json``."""
    return {
        "touches": d.touches,
        "ratio_to_default": d.ratio,
        "poses_tried": d.poses_tried,
        "touches_tried": d.touches_tried,
        "sphere": np.asarray(d.sphere).tolist(),
        "spheres_tried": [
            {
                "sphere": np.asarray(t.sphere).tolist(),
                "plannable": t.plannable,
                **(
                    {"worst_expanded_um": t.worst_expanded_um}
                    if t.plannable
                    else {"why_not": t.why_not}
                ),
            }
            for t in d.spheres
        ],
        "best": probe_candidate_dict(d.best),
        "default": probe_candidate_dict(d.baseline),
        "refused_poses": list(d.refused),
    }


def design_probe_separation(
    session: Any,
    pair: Sequence[str],
    *,
    tilt_step: float = 15.0,
    rot_step: float = 30.0,
    pose_time_s: float = 0.0,
    max_time_s: float = 600.0,
    max_correlation: float = 0.5,
    noise_um: float = 0.0,
) -> Any:
    """A ``_core.ProbeSeparationDesign``: the smallest set of poses (a sweep of one axis, or one
    pose, repeated) to add to ``session`` (a ``ProbeSession``) so that the two effects of
    ``pair`` come out of the joint fit with a canonical correlation below ``max_correlation``,
    or why no test can."""
    _check_pair(pair)
    o = _core.ProbeSeparationOptions()
    o.tilt_step_deg = float(tilt_step)
    o.rot_step_deg = float(rot_step)
    o.pose_time_s = float(pose_time_s)
    _search_limits(o, max_time_s, max_correlation, noise_um)
    return _core.design_probe_separation(session, list(pair), o)


def probe_separation_dict(d: Any) -> dict:
    """The JSON of ``rotacal design probe --separate ... --after SESSION``."""
    out = _separation_common(d)
    if d.candidates_tried:
        c = d.chosen
        out["added_poses"] = {
            "description": c.description,
            "poses_deg": np.asarray(c.poses_deg).tolist(),
            "poses_option": poses_text(c.poses_deg),
            "repeats": c.repeats,
            "run_time_s": c.duration_s * c.repeats,
            "correlation_after": c.correlation,
        }
    return out
