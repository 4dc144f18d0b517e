# SPDX-License-Identifier: BSD-3-Clause
"""Single set-up ballbar test: identification, simulation, prediction, compensation."""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from . import _core
from .machines import ballbar_machine_model, random_location_errors  # noqa: F401  (rotacal.random_location_errors)
from .results import Identification
from .sessions import BALLBAR, require


def identify(
    session: _core.BallbarSession,
    method: str = "joint",
    *,
    fit_length_offset: bool = False,
    effects: Sequence[str] = (),
    tests: Sequence[str] = (),
    noise: str = "auto",
) -> Identification:
    """Identify the 8 location errors (and the actual pivot) of a ballbar session
    (rotacal.identify takes either kind of session).

    Parameters
    ----------
    method : "joint" (default) fits the exact model to every sample with Ceres and reports
        1-sigma uncertainties; "paper" runs Flynn et al.'s chain (sphere fit, Hyper circle
        fit, SVD plane fit).
    fit_length_offset : also fit an offset of the calibrated bar length (joint only).
    effects : catalogue ids to fit along (joint only), e.g. ["gravity_sag_A"].
    tests : restrict to these test labels (default: all).
    noise : "auto" (default) estimates the AR noise model of the residuals per test and, when
        it is correlated, refits by GLS so that the 1-sigma holds; "white" treats the readings
        as independent. The noise model is in ``to_dict()["noise_model"]``.
    """
    require(session, BALLBAR, "identify")
    if method == "joint":
        raw = _core.identify_joint(session, fit_length_offset, list(effects), list(tests), noise)
    elif method == "paper":
        if fit_length_offset or effects:
            raise _core.InvalidArgument(
                "identify: the paper method fits no length offset or effects"
            )
        raw = _core.identify_paper(session)
    else:
        raise _core.InvalidArgument(f"identify: method must be 'joint' or 'paper', got {method!r}")
    return Identification(raw)


def monte_carlo(
    session: _core.BallbarSession,
    result: Identification,
    draws: int = 100,
    *,
    seed: int = 1,
    progress: bool = True,
) -> dict:
    """Check the reported uncertainties by Monte Carlo (GUM Supplement 1 style): simulate
    ``draws`` sessions of the same poses on the identified machine with the fitted noise (the
    AR noise model fitted to the session when the joint fit used it, else white noise),
    identify each the same way, and compare the spread with the reported 1-sigma.

    Returns {"draws", "noise_um", "method", "parameters": {name: {"std_reported", "std_mc",
    "ratio", "bias", "unit"}}} for every observable parameter; a ratio near 1 means the
    reported uncertainty is right, well above 1 that it is optimistic.
    """
    from .progress import ProgressBar

    if draws < 2:
        raise _core.InvalidArgument(f"monte_carlo: draws must be at least 2, got {draws}")
    raw = result.raw
    method = raw.method
    fit_offset = any(p.name == "ballbar_length_offset" for p in raw.parameters)
    if fit_offset:
        raise _core.InvalidArgument("monte_carlo: a fit with a length offset is not supported")
    bar = ProgressBar("Monte Carlo", draws, " draws") if progress else None
    if method == "joint":
        # The C++ loop (ballbar/monte_carlo.hpp): draws from the noise model fitted to the
        # session (AR per test) when the fit used it, refitted the same way; white otherwise.
        mc = _core.monte_carlo_joint(
            session,
            raw,
            draws,
            seed,
            progress=(lambda done, total: bar.update(done)) if bar else None,
        )
        if bar:
            bar.close()
        from .results import monte_carlo_dict

        return monte_carlo_dict(mc, draws, mc.noise_um)
    values = []  # the paper method: simulate and identify again, in Python
    for k in range(draws):
        sim = _core.simulate_ballbar(session, raw.model, float(raw.sigma_um), seed + k)
        r = identify(sim, method)
        values.append([p.value for p in r.raw.parameters])
        if bar:
            bar.update(k + 1)
    if bar:
        bar.close()
    v = np.array(values)
    out = {}
    for j, p in enumerate(raw.parameters):
        if not p.observable:
            continue
        std_mc = float(np.std(v[:, j], ddof=1))
        out[p.name] = {
            "std_reported": float(p.std),
            "std_mc": std_mc,
            "ratio": std_mc / p.std if p.std > 0 else float("inf"),
            "bias": float(np.mean(v[:, j]) - p.value),
            "unit": p.unit,
        }
    return {
        "draws": draws,
        "noise_um": float(raw.sigma_um),
        "noise": "white noise",
        "method": method,
        "parameters": out,
    }


def predict(
    model: _core.BallbarMachineModel, session: _core.BallbarSession
) -> _core.BallbarSession:
    """The session with every length replaced by the model's prediction."""
    return session.with_lengths(_core.predict_session_lengths(model, session))


def compensation_table(report: Any) -> list[dict]:
    """The rows of a CompensationReport (verify_compensation) as dicts, Flynn et al. Table 2 layout."""
    return [
        {
            "name": r.name,
            "unit": r.unit,
            "before": r.before,
            "after": r.after,
            "std_after": r.std_after,
            "change_percent": r.change_percent,
        }
        for r in report.rows
    ]


def nc_program(
    setup: Any, dialect: str = "linuxcnc", model: Any = None, source: str = "<model>"
) -> tuple[Any, str]:
    """(plan, NC program text) of the test of ``setup`` in ``dialect``; with a fitted
    BallbarMachineModel the program is compensated for its location errors (its machine must
    be the set-up's, ``source`` names the model in the error)."""
    identified = None
    if model is not None:
        if model.machine != setup.machine:
            raise _core.InvalidArgument(
                f"{source}: model is for {_core.machine_name(model.machine)}, the test "
                f"for {_core.machine_name(setup.machine)}"
            )
        identified = model.errors
    plan = _core.plan_ballbar_test(setup, identified)
    return plan, _core.write_nc_program(plan, _core.parse_nc_dialect(dialect))


def verify_compensation(setup: Any, truth: Any) -> list[dict]:
    """Flynn et al.'s Table 2 experiment in simulation: measure the test of ``setup`` on the
    machine of ``truth`` (machines.ballbar_truth), identify, compensate, measure again;
    the rows of compensation_table."""
    commanded = _core.plan_ballbar_test(setup, None).commanded_session()
    machine = ballbar_machine_model(setup, truth)
    return compensation_table(
        _core.verify_compensation(commanded, machine, truth["noise_um"], truth["seed"])
    )
