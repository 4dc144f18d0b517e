# SPDX-License-Identifier: BSD-3-Clause
"""The touch probe on a sphere (rotacal-probe/1): identify a session by the joint fit or by the
controller cycles' method, and simulate one. C++ computes (include/rotacal/probe); this module
only composes."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np

from . import _core
from .models import estimate_dict, machine_members
from .results import Identification, noise_model_dict

METHODS = ("joint", "cycles", "cycles-free-radius")


@dataclass
class ProbeIdentification(Identification):
    """Location errors and the sphere's table position identified from a touch-probe session
    (parameter access as rotacal.Identification)."""

    @property
    def machine(self):
        return self.raw.machine

    def model_dict(self, session_name: str = "session") -> dict:
        """The model file's content (``kind: probe``, docs/model_file.md), written by the C++
        implementation (rotacal/probe/model_document.hpp): location errors with their 1-sigma
        and covariance, the effects fitted along, the session (``session_name``) with its sphere
        and noise model. Only the joint fit has one: the cycles' method gives no uncertainty."""
        return _core.probe_model_document(self.raw, session_name)

    def to_dict(self) -> dict:
        def est(p):
            d = estimate_dict(p)
            if d.get("std") is not None and math.isnan(d["std"]):
                d["std"] = None  # the cycles' method gives no uncertainty
            return d

        out = {
            "method": self.raw.method,
            **machine_members(self.machine),
            "location_errors": {
                p.name: est(p) for p in self.raw.parameters if p.name.startswith("E_")
            },
            "sphere": [float(v) for v in np.asarray(self.raw.sphere).ravel()],
            "residual_rms_um": float(self.raw.residual_rms_um),
            "n_samples": int(self.raw.n_samples),
            "converged": bool(self.raw.converged),
            "unobservable": list(self.raw.unobservable),
            "notes": list(self.raw.notes),
        }
        if self.raw.method == "joint":
            out["sigma_um"] = float(self.raw.sigma_um)
            out["other_parameters"] = {
                p.name: est(p) for p in self.raw.parameters if not p.name.startswith("E_")
            }
            out["noise_model"] = noise_model_dict(
                self.raw.noise, self.raw.noise_refit, self.raw.noise_correction
            )
        else:
            out["dispersion_um"] = float(self.raw.dispersion_um)
        return out


def identify_probe(
    session: _core.ProbeSession,
    method: str = "joint",
    *,
    effects: Sequence[str] = (),
    noise: str = "auto",
) -> ProbeIdentification:
    """Identify a touch-probe session: method "joint" (every touch in one fit, with the noise model:
    ``noise`` "auto" or "white"; ``effects``: catalogue ids fitted along), "cycles" (the controller
    cycles' method with the calibrated radius) or "cycles-free-radius" (the same, radius fitted per pose)."""
    if method == "joint":
        raw = _core.identify_probe(session, list(effects), noise)
    elif method in ("cycles", "cycles-free-radius"):
        if effects:
            raise _core.InvalidArgument("identify_probe: the cycles' method fits no effects")
        raw = _core.identify_probe_cycles(session, method == "cycles")
    else:
        raise _core.InvalidArgument(
            f"identify_probe: method must be one of {', '.join(METHODS)}, got {method!r}"
        )
    return ProbeIdentification(raw)


def monte_carlo_probe(
    session: _core.ProbeSession,
    result: ProbeIdentification,
    draws: int = 100,
    *,
    seed: int = 1,
    noise: str = "auto",
    progress: bool = True,
) -> dict:
    """Check a touch-probe joint fit's 1-sigma by Monte Carlo (probe/monte_carlo.hpp): each draw
    moves every touch along its approach direction to the identified machine plus noise drawn
    from the fit's noise model (AR when the fit was refitted under it, else white), refitted the
    same way (``noise`` as the fit: "auto" or "white"). Same dict as rotacal.ballbar.monte_carlo."""
    from .progress import ProgressBar
    from .results import monte_carlo_dict

    if result.raw.method != "joint":
        raise _core.InvalidArgument(
            "monte_carlo: the cycles' method reports no uncertainty to check; use the joint fit"
        )
    bar = ProgressBar("Monte Carlo", draws, " draws") if progress else None
    mc = _core.monte_carlo_probe(
        session,
        result.raw,
        draws,
        seed,
        noise,
        progress=(lambda done, total: bar.update(done)) if bar else None,
    )
    if bar:
        bar.close()
    return monte_carlo_dict(mc, draws, mc.noise_um)


def simulate_probe(
    machine: str | Any,
    errors: Sequence[float] | None = None,
    effects: Mapping[str, Sequence[float] | float] | None = None,
    *,
    sphere_offset: Sequence[float] = (0.0, 0.0, 0.0),
    noise_um: float = 0.5,
    ar1_rho: float = 0.0,
    seed: int = 1,
    poses_deg: Any = None,
    directions: Any = None,
    sphere: Sequence[float] = (150.0, 0.0, 80.0),
    sphere_diameter: float = 25.0,
    stylus_diameter: float = 6.0,
) -> tuple[_core.ProbeSession, np.ndarray]:
    """Simulate a touch-probe session on a machine (name or MachineType) with location errors
    (8 values, location_error_names order; zeros by default) and catalogue effects
    ({id: parameters}); returns (session, actual sphere centre in the table frame)."""
    mtype = machine if isinstance(machine, _core.MachineType) else _core.parse_machine_type(machine)
    ids, params = [], []
    for eid, p in (effects or {}).items():
        ids.append(eid)
        params.extend(np.atleast_1d(np.asarray(p, dtype=float)).tolist())
    e = np.zeros(8) if errors is None else np.asarray(errors, dtype=float)
    return _core.simulate_probe(
        mtype,
        e,
        ids,
        params,
        np.asarray(sphere_offset, float),
        noise_um,
        ar1_rho,
        seed,
        None if poses_deg is None else np.asarray(poses_deg, float),
        None if directions is None else np.asarray(directions, float),
        np.asarray(sphere, float),
        sphere_diameter,
        stylus_diameter,
    )
