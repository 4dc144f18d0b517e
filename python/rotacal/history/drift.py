# SPDX-License-Identifier: BSD-3-Clause
"""The history of a machine's location errors: the machine's own value over time (measured +
compensation loaded), the changes between consecutive calibrations flagged against their
expanded uncertainty or a tolerance, and the drift per month."""

from __future__ import annotations

import datetime
import math
from typing import Mapping, Sequence

from .. import _core
from .entries import CORRECTION, IDENTIFICATION, Entry, unit_of

# Drift is given per mean Gregorian month.
DAYS_PER_MONTH = 365.2425 / 12
# No drift per month from calibrations closer than this: their difference is repeatability and
# the machine's thermal state, and a month's rate from two taken a second apart scales it by
# 2.6 million (issue 32: -230,541,381 um/month).
MIN_DRIFT_SPAN_DAYS = 7.0
DRIFT_SPAN_WHY = "closer calibrations measure repeatability and warm-up, not a rate per month"
# Coverage factor of the expanded uncertainty a change is compared with (GUM, about 95 %).
K_EXPANDED = 2.0


def _epoch_months(at: str) -> float:
    """Months since 1970 of a stored date-time (fixed layout: sliced, not parsed, for speed)."""
    d = datetime.datetime(
        int(at[0:4]),
        int(at[5:7]),
        int(at[8:10]),
        int(at[11:13]),
        int(at[14:16]),
        int(at[17:19]),
        tzinfo=datetime.timezone.utc,
    )
    return d.timestamp() / 86400.0 / DAYS_PER_MONTH


def drift_fit(
    t_months: Sequence[float], y: Sequence[float], std: Sequence[float | None]
) -> dict | None:
    """Least-squares straight line through (t, y) weighted by 1/std^2: slope per month, its
    1-sigma from the stated stds, and chi2/dof (about 1 when the stds explain the scatter).
    Unweighted (and said so) when a point has no positive std. None for fewer than two
    distinct times."""
    n = len(y)
    if n < 2 or max(t_months) - min(t_months) <= 0:
        return None
    weighted = all(s is not None and s > 0 for s in std)
    w = [1.0 / (s * s) for s in std] if weighted else [1.0] * n  # type: ignore[operator]
    sw = sum(w)
    tm = sum(wi * ti for wi, ti in zip(w, t_months)) / sw
    ym = sum(wi * yi for wi, yi in zip(w, y)) / sw
    stt = sum(wi * (ti - tm) ** 2 for wi, ti in zip(w, t_months))
    slope = sum(wi * (ti - tm) * (yi - ym) for wi, ti, yi in zip(w, t_months, y)) / stt
    resid = [yi - ym - slope * (ti - tm) for ti, yi in zip(t_months, y)]
    chi2 = sum(wi * r * r for wi, r in zip(w, resid))
    dof = n - 2
    if weighted:
        slope_std = math.sqrt(1.0 / stt)
    elif dof > 0:  # no stated std: the scatter about the line is all there is
        slope_std = math.sqrt(chi2 / dof / stt)
    else:
        slope_std = None
    return {
        "value": slope,
        "std": slope_std,
        "n": n,
        "span_months": max(t_months) - min(t_months),
        "chi2_per_dof": chi2 / dof if weighted and dof > 0 else None,
        "weighting": "1/std^2" if weighted else "equal (a calibration has no 1-sigma)",
    }


def expand_tolerances(
    tolerances: Mapping[str, float], names: Sequence[str], machine_type: str
) -> dict[str, float]:
    """Tolerance by location error from keys that are error names or ``position`` (every
    error in mm) or ``orientation`` (every error in rad); a name overrides its group."""
    for k, v in tolerances.items():
        if k not in names and k not in ("position", "orientation"):
            raise _core.InvalidArgument(
                f"--tolerance: {k}: not a location error of a {machine_type} "
                f"({' '.join(names)}), nor position or orientation"
            )
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
            raise _core.InvalidArgument(f"--tolerance {k}: must be a number > 0, got {v!r}")
    out = {}
    for n in names:
        group = "position" if unit_of(n) == "mm" else "orientation"
        if n in tolerances or group in tolerances:
            out[n] = float(tolerances.get(n, tolerances.get(group)))
    return out


def error_names(machine_type: str, entries: Sequence[Entry]) -> list[str]:
    """A built-in's location errors by its name; a machine of a description file's as its
    calibrations name them (its models' machine_description defines them)."""
    if machine_type in _core.builtin_machine_names():
        return list(_core.location_error_names(_core.parse_machine_type(machine_type)))
    found = (n for e in entries if e.kind == IDENTIFICATION for n in e.estimates)
    return list(dict.fromkeys(n for n in found if n[:2] == "E_"))


def summarize(
    machine_type: str, entries: Sequence[Entry], tolerances: Mapping[str, float] | None = None
) -> dict:
    """Each location error over time: the values measured with their 1-sigma, the compensation
    the controller held at the time (the sum of the corrections recorded before), the machine's
    own value (measured + compensation), the change between consecutive calibrations with the
    corrections in between taken out, flagged when it exceeds the expanded (k = 2) uncertainty
    of the difference or the tolerance given for that error (same unit as the error), and the
    drift per month (weighted straight line through the machine's own values)."""
    names = error_names(machine_type, entries)
    tol = expand_tolerances(tolerances or {}, names, machine_type)
    calibrations = [e for e in entries if e.kind == IDENTIFICATION]
    corrections = [e for e in entries if e.kind == CORRECTION]
    months = {e.id: _epoch_months(e.measured_at) for e in calibrations}
    errors: dict[str, dict] = {}
    flags: list[dict] = []
    for name in names:
        unit = unit_of(name)
        points: list[dict] = []
        steps: list[dict] = []
        unobservable: list[int] = []
        held = 0.0  # compensation the controller holds for this error
        since_last = 0.0  # corrections since the previous calibration
        for e in entries:
            est = e.estimates.get(name)
            if e.kind == CORRECTION:
                if est is not None and est.value is not None:
                    held += est.value
                    since_last += est.value
                continue
            if est is None or est.value is None:
                unobservable.append(e.id)
                continue
            p = {
                "entry": e.id,
                "at": e.measured_at,
                "measured": est.value,
                "std": est.std,
                "compensation": held,
                "value": est.value + held,
            }
            if points:
                q = points[-1]
                change = p["value"] - q["value"]
                u = (
                    math.sqrt(q["std"] ** 2 + p["std"] ** 2) * K_EXPANDED
                    if q["std"] is not None and p["std"] is not None
                    else None
                )
                step = {
                    "from": q["entry"],
                    "to": e.id,
                    "from_at": q["at"],
                    "to_at": e.measured_at,
                    "measured_change": p["measured"] - q["measured"],
                    "corrections": since_last,
                    "change": change,
                    "expanded_uncertainty": u,
                    "exceeds_uncertainty": u is not None and abs(change) > u,
                    "tolerance": tol.get(name),
                    "exceeds_tolerance": name in tol and abs(change) > tol[name],
                }
                steps.append(step)
                if step["exceeds_uncertainty"] or step["exceeds_tolerance"]:
                    why = [
                        w
                        for w, hit in (
                            ("exceeds k=2 uncertainty", step["exceeds_uncertainty"]),
                            ("exceeds tolerance", step["exceeds_tolerance"]),
                        )
                        if hit
                    ]
                    flags.append(
                        {
                            "name": name,
                            "unit": unit,
                            **{
                                k: step[k]
                                for k in (
                                    "from",
                                    "to",
                                    "from_at",
                                    "to_at",
                                    "change",
                                    "expanded_uncertainty",
                                    "tolerance",
                                )
                            },
                            "why": why,
                        }
                    )
            since_last = 0.0
            points.append(p)
        drift = None
        if len(points) >= 2:
            t0 = months[points[0]["entry"]]
            drift = drift_fit(
                [months[p["entry"]] - t0 for p in points],
                [p["value"] for p in points],
                [p["std"] for p in points],
            )
        if drift is not None and drift["span_months"] * DAYS_PER_MONTH < MIN_DRIFT_SPAN_DAYS:
            drift = None  # the difference of two close calibrations is not a rate per month
        errors[name] = {
            "unit": unit,
            "points": points,
            "steps": steps,
            "unobservable_in": unobservable,
            "drift_per_month": drift,
        }
    return {
        "machine_type": machine_type,
        "identifications": len(calibrations),
        "corrections": [
            {
                "entry": c.id,
                "at": c.measured_at,
                "controller": c.test,
                "note": c.note,
                "amounts": {n: est.value for n, est in c.estimates.items()},
            }
            for c in corrections
        ],
        "calibrations": [
            {
                "entry": c.id,
                "at": c.measured_at,
                "test": c.test,
                "session": c.session,
                "session_sha256": c.source_sha256,
                "note": c.note,
            }
            for c in calibrations
        ],
        "location_errors": errors,
        "flags": flags,
        "definitions": {
            "value": "measured + compensation: the machine's own error, as if no correction had been loaded",
            "compensation": "sum of the corrections recorded before the calibration (a correction loads the "
            "identified values of the errors the controller holds)",
            "change": "value minus the previous calibration's value: drift, corrections taken out",
            "expanded_uncertainty": f"{K_EXPANDED:g} * sqrt(std1^2 + std2^2)",
            "drift_per_month": f"slope of value over time, least squares weighted by 1/std^2, per "
            f"{DAYS_PER_MONTH:.4f} days; null when the calibrations span less than "
            f"{MIN_DRIFT_SPAN_DAYS:g} days ({DRIFT_SPAN_WHY})",
        },
    }
