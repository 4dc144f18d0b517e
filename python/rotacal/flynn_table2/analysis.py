# SPDX-License-Identifier: BSD-3-Clause
"""Analyse measured before/after identifications against the simulated chain: which values
fall outside the prediction, which kind of cause can produce each, the causes ranked, those
the 8 values cannot tell apart, the extended model and a sweep of the assumptions."""

from __future__ import annotations

import math
from dataclasses import asdict, replace
from typing import Optional, Sequence

import numpy as np

from .. import _core
from .causes import PLAUSIBLE_CHANGE, PLAUSIBLE_CONSTANT, Assumptions, Candidate
from .render import conclusions
from .scenario import scenario, separation
from .table import NAMES, SCALE as _SCALE, UNIT as _UNIT, load_table2


def _size_dict(c: Candidate, s: float, s_std: Optional[float]) -> dict:
    return {
        "size": float(s * c.display),
        "size_std": None if s_std is None else float(s_std * c.display),
        "unit": c.unit,
        "plausible": float(c.plausible * c.display),
        "size_over_plausible": float(abs(s) / c.plausible),
    }


def _vec(v: np.ndarray) -> dict:
    return {n: float(x) for n, x in zip(NAMES, v * _SCALE)}


_FURTHER = {
    "axis_position": "log the temperatures and repeat the uncompensated test after the same interval",
    "axis_orientation": "log the temperatures and repeat the uncompensated test after the same interval",
    "table_shift": "log the temperatures and repeat the uncompensated test after the same interval",
    "tool_offset_Z": "measure the tool length (tool setter) before each run",
    "ballbar_length_offset": "calibrate the bar in its calibrator before each run",
    "drift_over_test": "repeat one test (e.g. radial_C) at the start and at the end of each run",
    "linear_squareness": "measure the linear axes (ballbar circles in XY, YZ, ZX, ISO 230-4) before each run",
    "linear_scale": "measure the linear axes' positioning (laser, ISO 230-2) before each run",
    "pivot": "fix the pivot stand rigidly and compare run 2's sphere-fit pivot with run 1's",
}


def _prediction(sc: dict, before: np.ndarray, after: np.ndarray) -> dict:
    """Each value: measured, predicted mean and std, the k = 2 interval, z, outside or not."""
    std, mean, d = sc["std"], sc["mean"], sc["d"]
    prediction = {}
    for k, n in enumerate(NAMES):
        z = float(d[k] / std[k])
        prediction[n] = {
            "unit": _UNIT[k],
            "before": float(before[k] * _SCALE[k]),
            "measured_after": float(after[k] * _SCALE[k]),
            "predicted_mean": float(mean[k] * _SCALE[k]),
            "predicted_std": float(std[k] * _SCALE[k]),
            "interval_k2": [float(sc["lo"][k] * _SCALE[k]), float(sc["hi"][k] * _SCALE[k])],
            "z": z,
            "outside": bool(after[k] < sc["lo"][k] or after[k] > sc["hi"][k]),
        }
    return prediction


def _ranked(sc: dict, top: int) -> list[dict]:
    """The first `top` causes, one at a time: fitted size, plausible or not, what each explains."""
    ranked = []
    for x in sc["rows"][:top]:
        c = x["c"]
        j = x["j"]
        sp = float(np.clip(x["size"], -c.plausible, c.plausible))
        ranked.append(
            {
                "id": c.id,
                "kind": c.kind,
                "cause": c.cause,
                **_size_dict(c, x["size"], x["size_std"]),
                "plausible_size": bool(abs(x["size"]) <= c.plausible),
                "chi2": x["chi2"],
                "chi2_at_plausible_size": x["chi2_plausible"],
                "explains_at_fitted_size": _vec(x["size"] * sc["R"][:, j]),
                "explains_at_plausible_size": _vec(sp * sc["R"][:, j]),
                "repeat_uncompensated_shift": _vec(x["size"] * sc["Rb"][:, j]),
            }
        )
    return ranked


def _per_value(sc: dict) -> dict:
    """Per measured value: which kind of cause can produce it, at a plausible size, alone."""
    cands, std, d = sc["cands"], sc["std"], sc["d"]
    per_value = {}
    for k, n in enumerate(NAMES):
        dev = float(d[k] * _SCALE[k])
        tol = 2.0 * float(std[k] * _SCALE[k])
        best = {}
        for kind in ("constant", "between_runs"):
            reach = [
                (abs(float(sc["R"][k, j])) * c.plausible * _SCALE[k], c)
                for j, c in enumerate(cands)
                if c.kind == kind
            ]
            reach.sort(key=lambda t: -t[0])
            r0, c0 = reach[0]
            can = [c.id for r, c in reach if r >= abs(dev) - tol]
            best[kind] = {
                "largest_at_plausible_size": float(r0),
                "by": c0.id,
                "can_produce": can[:8],
                "count": len(can),
            }
        if abs(dev) <= tol:
            verdict = "within the predicted spread"
        elif best["constant"]["count"] and best["between_runs"]["count"]:
            verdict = "either kind"
        elif best["between_runs"]["count"]:
            verdict = "only a change between the runs"
        elif best["constant"]["count"]:
            verdict = "only a constant effect"
        else:
            verdict = "no single cause at a plausible size"
        per_value[n] = {
            "unit": _UNIT[k],
            "deviation": dev,
            "two_sigma": tol,
            "verdict": verdict,
            **best,
        }
    return per_value


def _ambiguous(sc: dict, noise_um: float, top: int) -> list[dict]:
    """Causes the 8 values cannot tell apart (responses nearly parallel in the chi2 metric), and
    the raw test or the further measurement that separates them."""
    cands = sc["cands"]
    ambiguous = []
    W = np.sqrt(sc["w"])
    lead = [x for x in sc["rows"][:top] if x["size_std"] is not None]
    seen = set()
    for x in lead:
        j = x["j"]
        if j in seen:
            continue
        u = W * sc["R"][:, j]
        grp = [j]
        for y in sc["rows"]:
            k2 = y["j"]
            if k2 == j or y["size_std"] is None or abs(y["size"]) > 10 * cands[k2].plausible:
                continue
            v = W * sc["R"][:, k2]
            cos = float(abs(u @ v) / (np.linalg.norm(u) * np.linalg.norm(v)))
            if cos > 0.98:
                grp.append(k2)
        if len(grp) > 1:
            seen.update(grp)
            grp = grp[:4]
            sep = separation(sc, grp)
            noise_se = noise_um / math.sqrt(max(sep.get("samples", 1), 1))
            ids = [cands[i].id for i in grp]
            fams = sorted({cands[i].family for i in grp})
            ambiguous.append(
                {
                    "candidates": ids,
                    "separating_test": sep["test"],
                    "rms_difference_um": sep["rms_difference_um"],
                    "per_test_rms_difference_um": sep["per_test_rms_difference_um"],
                    "raw_data_separates": bool(sep["rms_difference_um"] > 3 * noise_se),
                    "further_measurement": [f"{f}: {_FURTHER[f]}" for f in fams if f in _FURTHER],
                }
            )
    return ambiguous


def _extended_model(sc: dict, after: np.ndarray) -> dict:
    """The greedy extended model: its causes and what it leaves unexplained of each value."""
    cands, std, mean = sc["cands"], sc["std"], sc["mean"]
    ext = sc["ext"]
    gain_rows = {}
    tot = {"um": [0.0, 0.0], "urad": [0.0, 0.0]}
    for k, n in enumerate(NAMES):
        meas = after[k] * _SCALE[k]
        basev = mean[k] * _SCALE[k]
        extv = (mean[k] + ext[k]) * _SCALE[k]
        gain_rows[n] = {
            "unit": _UNIT[k],
            "measured": float(meas),
            "baseline": float(basev),
            "extended": float(extv),
            "unexplained_before": float(meas - basev),
            "unexplained_after": float(meas - extv),
            "inside_spread": bool(abs(meas - extv) <= 2 * std[k] * _SCALE[k]),
        }
        tot[_UNIT[k]][0] += abs(meas - basev)
        tot[_UNIT[k]][1] += abs(meas - extv)
    extended = {
        "causes": [
            {
                "id": cands[j].id,
                "kind": cands[j].kind,
                "cause": cands[j].cause,
                **_size_dict(cands[j], s, None),
            }
            for j, s in zip(sc["chosen"], sc["s_sel"])
        ],
        "chi2_before": sc["chi2_0"],
        "chi2_after": sc["chi2_ext"],
        "per_value": gain_rows,
        "sum_abs_unexplained": {
            u: {"baseline": v[0], "extended": v[1], "accounted_for": v[0] - v[1]}
            for u, v in tot.items()
        },
    }
    return extended


def _sweep(
    a: Assumptions,
    before: np.ndarray,
    after: np.ndarray,
    sweep: Sequence[tuple[str, dict]] | None,
    draws: int,
    seed: int,
    max_causes: int,
    cache: dict,
) -> list[dict]:
    """One scenario per changed assumption: what falls outside, the first causes, what the
    extended model leaves."""
    sweeps = []
    for label, changes in DEFAULT_SWEEP if sweep is None else sweep:
        b = replace(a, **changes)
        s2 = scenario(b, before, after, draws, seed, max_causes, False, cache)
        out_n = [n for k, n in enumerate(NAMES) if after[k] < s2["lo"][k] or after[k] > s2["hi"][k]]
        top3 = [
            {
                "id": x["c"].id,
                **_size_dict(x["c"], x["size"], x["size_std"]),
                "plausible_size": bool(abs(x["size"]) <= x["c"].plausible),
            }
            for x in s2["rows"][:3]
        ]
        tot2 = {"um": [0.0, 0.0], "urad": [0.0, 0.0]}
        for k in range(8):
            tot2[_UNIT[k]][0] += abs(after[k] - s2["mean"][k]) * _SCALE[k]
            tot2[_UNIT[k]][1] += abs(after[k] - s2["mean"][k] - s2["ext"][k]) * _SCALE[k]
        sweeps.append(
            {
                "scenario": label,
                "changes": {
                    k: (list(v) if isinstance(v, tuple) else v) for k, v in changes.items()
                },
                "outside": out_n,
                "predicted_std": _vec(s2["std"]),
                "top_causes": top3,
                "extended_causes": [s2["cands"][j].id for j in s2["chosen"]],
                "sum_abs_unexplained": {
                    u: {"baseline": v[0], "extended": v[1]} for u, v in tot2.items()
                },
            }
        )
    return sweeps


def analyse(
    table: dict | None = None,
    assumptions: Assumptions | None = None,
    *,
    draws: int = 200,
    seed: int = 1,
    sweep: Sequence[tuple[str, dict]] | None = None,
    sweep_draws: int = 60,
    max_causes: int = 6,
    top: int = 10,
) -> dict:
    """Analyse measured before/after identifications (default: Flynn et al. Table 2).

    Parameters
    ----------
    table : {"rows": [{"name", "unit", "before", "after"}]} in mm and rad in the order of
        location_error_names(AC-trt), e.g. load_table2(); default Table 2.
    assumptions : the unknowns of the experiment (Assumptions()).
    draws : Monte Carlo draws of the predicted chain (noise and constant effects).
    sweep : [(label, {field: value})] scenarios that change one assumption each; default
        DEFAULT_SWEEP. Each runs with sweep_draws draws.
    Returns a JSON-able dict (no NaN); render it with `render(result)`.
    """
    table = table if table is not None else load_table2()
    a = assumptions if assumptions is not None else Assumptions()
    if draws < 10:
        raise _core.InvalidArgument(f"analyse: draws must be at least 10, got {draws}")
    rows = table["rows"]
    if [r["name"] for r in rows] != list(NAMES):
        raise _core.InvalidArgument(f"analyse: table rows must be {', '.join(NAMES)} in this order")
    before = np.array([float(r["before"]) for r in rows])
    after = np.array([float(r["after"]) for r in rows])
    if not (np.all(np.isfinite(before)) and np.all(np.isfinite(after))):
        raise _core.InvalidArgument("analyse: before and after values must be finite")

    cache: dict = {}  # runs shared by the scenarios (Chain)
    sc = scenario(a, before, after, draws, seed, max_causes, True, cache)
    prediction = _prediction(sc, before, after)
    per_value = _per_value(sc)
    result = {
        "source": table.get("source", {}),
        "assumptions": {
            **{k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(a).items()},
            "test_duration_s": sc["duration"],
            "draws": draws,
            "seed": seed,
            "thermal_change_fraction": 1.0
            - math.exp(-a.hours_between_runs / a.thermal_time_constant_h),
            "plausible_constant": dict(PLAUSIBLE_CONSTANT),
            "plausible_change_full_warmup": dict(PLAUSIBLE_CHANGE),
        },
        "simulated_truth": _vec(sc["truth"]),
        "prediction": prediction,
        "outside": [n for n in NAMES if prediction[n]["outside"]],
        "constant_effects_largest_after_value": {
            n: per_value[n]["constant"]["largest_at_plausible_size"] for n in NAMES
        },
        "per_value": per_value,
        "ranked_causes": _ranked(sc, top),
        "ambiguous": _ambiguous(sc, a.noise_um, top),
        "extended_model": _extended_model(sc, after),
        "sweep": _sweep(a, before, after, sweep, sweep_draws, seed, max_causes, cache),
    }
    result["conclusions"] = conclusions(result)
    _check_finite(result, "result")
    return result


DEFAULT_SWEEP = (
    ("bar 150 mm", {"ballbar_length": 150.0}),
    ("pivot O_x 80, O_z 40", {"pivot": (80.0, 0.0, 40.0)}),
    ("A range -60..60", {"tilt_range_deg": (-60.0, 60.0)}),
    ("noise 1 um, AR(1) 0.9", {"noise_um": 1.0, "noise_rho": 0.9}),
    ("15 min between runs", {"hours_between_runs": 0.25}),
    ("8 h between runs", {"hours_between_runs": 8.0}),
)


def _check_finite(x, path: str) -> None:
    if isinstance(x, float) and not math.isfinite(x):
        raise _core.Error(f"flynn_table2: non-finite value at {path}")
    if isinstance(x, dict):
        for k, v in x.items():
            _check_finite(v, f"{path}.{k}")
    elif isinstance(x, (list, tuple)):
        for i, v in enumerate(x):
            _check_finite(v, f"{path}[{i}]")
