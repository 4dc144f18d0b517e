"""Simulated machines: the paper's Table 2 machine, random location errors, effects, and the truth a simulation runs on."""
from __future__ import annotations

from typing import Any, Mapping, Sequence, Union

import numpy as np

from . import _core

# Flynn et al. 2016, Table 2, uncompensated: the AC-trt machine of the paper's experiment (mm, rad).
TABLE2_ERRORS = {"E_Y0A": 0.0726, "E_Z0A": -0.0202, "E_B0A": 1.1284e-05, "E_C0A": -0.000113006,
                 "E_X0C": 0.0283, "E_Y0C": 0.1041, "E_A0C": 5.1954e-06, "E_B0C": -4.1544e-05}

# Defaults of a simulated ballbar machine: 1-sigma pivot placement error (mm) and reading noise (um).
PIVOT_ERROR_MM = 0.02
BALLBAR_NOISE_UM = 0.5

# "random", "zero", "table2", NAME -> value (others zero), or the 8 values in location_error_names order.
Errors = Union[str, Mapping[str, float], Sequence[float], np.ndarray]


def random_location_errors(machine: Any, rng: np.random.Generator, position_mm: float = 0.03,
                           angle_rad: float = 5e-5) -> np.ndarray:
    """Location errors drawn as N(0, position_mm) and N(0, angle_rad), in the machine's order."""
    # Order of every errors vector: tilt position (2), tilt orientation (2), C position (2),
    # C orientation (2).
    scale = np.array([position_mm] * 2 + [angle_rad] * 2 + [position_mm] * 2 + [angle_rad] * 2)
    return rng.normal(0.0, 1.0, 8) * scale


def location_errors(errors: Errors, machine: Any, rng: np.random.Generator) -> np.ndarray:
    """The 8 location errors (mm, rad, location_error_names order) described by ``errors``.
    Only "random" draws from ``rng``, so a seed gives the same pivot error whatever the errors."""
    names = list(_core.location_error_names(machine))
    if isinstance(errors, str):
        if errors == "random":
            return random_location_errors(machine, rng)
        if errors == "zero":
            return np.zeros(8)
        if errors == "table2":
            if machine != _core.MachineType.AC_trt:
                raise _core.InvalidArgument("--errors table2 is the paper's AC-trt machine")
            return np.array([TABLE2_ERRORS[n] for n in names])
        raise _core.InvalidArgument(f"errors: 'random', 'zero', 'table2' or NAME=VALUE pairs, got {errors!r}")
    if isinstance(errors, Mapping):
        unknown = [k for k in errors if k not in names]
        if unknown:
            raise _core.InvalidArgument(f"--errors: {', '.join(map(repr, unknown))} not a location error of "
                                        f"{_core.machine_name(machine)} ({', '.join(names)})")
        v = np.array([float(errors.get(n, 0.0)) for n in names])
    else:
        v = np.asarray(errors, dtype=float)
        if v.shape != (8,):
            raise _core.InvalidArgument(f"errors: expected 8 values in the order {', '.join(names)}")
    if not np.all(np.isfinite(v)):
        raise _core.InvalidArgument("--errors: values must be finite")
    return v


def effect_parameters(effects: Mapping[str, Any] | None) -> tuple[list[str], list[float], dict[str, list[float]]]:
    """Catalogue effects id -> value or values as (ids, parameters back to back, id -> values),
    each checked against its catalogue entry (shared/spec/effects.md)."""
    ids: list[str] = []
    params: list[float] = []
    out: dict[str, list[float]] = {}
    for eid, val in (effects or {}).items():
        eff = _core.Effect(eid)
        vals = [float(v) for v in np.atleast_1d(np.asarray(val, dtype=float))]
        if len(vals) != eff.num_params:
            raise _core.InvalidArgument(f"--effect {eid}: takes {eff.num_params} values "
                                        f"({', '.join(eff.param_names)}), got {len(vals)}")
        if not all(np.isfinite(vals)):
            raise _core.InvalidArgument(f"--effect {eid}: values must be finite")
        ids.append(eff.id)
        params.extend(vals)
        out[eff.id] = vals
    return ids, params, out


def machine_truth(errors: Errors, effects: Mapping[str, Any] | None, machine: str, seed: int):
    """The simulated machine: (machine type, 8 location errors, effect ids, their parameters back
    to back, effects as given for the truth file). Random errors are drawn from ``seed``."""
    mtype = _core.parse_machine_type(machine)
    e = location_errors(errors, mtype, np.random.default_rng(seed))
    ids, params, values = effect_parameters(effects)
    return mtype, e, ids, params, {k: (v[0] if len(v) == 1 else v) for k, v in values.items()}


# ------------------------------------------------------------------------- ballbar

def ballbar_truth(machine: Any, errors: Errors = "random", effects: Mapping[str, Any] | None = None, *,
                  pivot_error_mm: float = PIVOT_ERROR_MM, noise_um: float = BALLBAR_NOISE_UM,
                  seed: int = 1) -> dict:
    """The machine a ballbar simulation runs on, as the truth file holds it: errors by name,
    the pivot set-up error (N(0, pivot_error_mm) per axis), effects, noise and seed. One
    generator from ``seed`` draws random errors first, then the pivot error."""
    names = list(_core.location_error_names(machine))
    rng = np.random.default_rng(seed)
    e = location_errors(errors, machine, rng)
    _, _, values = effect_parameters(effects)
    return {"errors": dict(zip(names, e.tolist())), "pivot_error": rng.normal(0.0, pivot_error_mm, 3).tolist(),
            "effects": values, "noise_um": noise_um, "seed": seed}


def ballbar_machine_model(setup: Any, truth: Mapping) -> _core.BallbarMachineModel:
    """The simulated machine of a ballbar truth dict (errors, pivot error, effects) on ``setup``."""
    names = list(_core.location_error_names(setup.machine))
    ids, params, _ = effect_parameters(truth["effects"])
    return _core.BallbarMachineModel(setup.machine, np.array([truth["errors"][n] for n in names]),
                                     np.asarray(setup.pivot) + np.array(truth["pivot_error"]), ids, params)


def simulate_ballbar_test(setup: Any, truth: Mapping) -> tuple[_core.BallbarSession, _core.BallbarMachineModel]:
    """Plan the test of ``setup``, run it on the machine of ``truth``: (session, machine model)."""
    plan = _core.plan_ballbar_test(setup, None)
    model = ballbar_machine_model(setup, truth)
    return _core.simulate_ballbar(plan.commanded_session(), model, truth["noise_um"], truth["seed"]), model
