# SPDX-License-Identifier: BSD-3-Clause
"""The history of a machine's thermal behaviour (issue 53, item 6): each thermal test stored
(``identify THERMAL --store``, or ``history add`` of a thermal model) keeps its lags' tau and
gains beside its cold location errors; this follows them over months as drift.py follows the
location errors: the values with their 1-sigma, the change between consecutive tests flagged
against its expanded uncertainty, and the drift per month."""

from __future__ import annotations

import math
from typing import Sequence

from .drift import DAYS_PER_MONTH, K_EXPANDED, MIN_DRIFT_SPAN_DAYS, _epoch_months, drift_fit
from .entries import IDENTIFICATION, Entry


def thermal_names(entries: Sequence[Entry]) -> list[str]:
    """The lag parameters the thermal tests stored (``lag1.tau``, ``lag1.E_X0C``, ...)."""
    found = (
        n
        for e in entries
        if e.kind == IDENTIFICATION and e.test == "thermal"
        for n in e.estimates
        if n.startswith("lag")
    )
    # By lag, its tau first, then the gains by name (the store keeps no order of its own).
    return sorted(set(found), key=lambda n: (n.split(".")[0], not n.endswith(".tau"), n))


def thermal_history(entries: Sequence[Entry]) -> dict:
    """Per lag parameter: the thermal tests' values (tau in s; a gain in mm or rad per unit of
    heat input, u = speed / 100 rev/min) with their 1-sigma, each change from the previous test
    and whether it exceeds its expanded (k = 2) uncertainty, and the drift per month (weighted
    straight line; none over less than MIN_DRIFT_SPAN_DAYS). Empty without thermal tests."""
    out: dict[str, dict] = {}
    for name in thermal_names(entries):
        points: list[dict] = []
        unobservable: list[int] = []
        unit = ""
        for e in entries:
            est = e.estimates.get(name)
            if e.test != "thermal" or est is None:
                continue
            if est.value is None:
                unobservable.append(e.id)
                continue
            unit = est.unit
            p = {"entry": e.id, "at": e.measured_at, "value": est.value, "std": est.std}
            if points:
                q = points[-1]
                u = (
                    K_EXPANDED * math.hypot(q["std"], p["std"])
                    if q["std"] is not None and p["std"] is not None
                    else None
                )
                p["change"] = p["value"] - q["value"]
                p["expanded_uncertainty"] = u
                p["exceeds_uncertainty"] = u is not None and abs(p["change"]) > u
            points.append(p)
        drift = None
        if len(points) >= 2:
            t = [_epoch_months(p["at"]) for p in points]
            drift = drift_fit(
                [ti - t[0] for ti in t], [p["value"] for p in points], [p["std"] for p in points]
            )
        if drift is not None and drift["span_months"] * DAYS_PER_MONTH < MIN_DRIFT_SPAN_DAYS:
            drift = None
        out[name] = {
            "unit": unit,
            "points": points,
            "unobservable_in": unobservable,
            "drift_per_month": drift,
        }
    return out
