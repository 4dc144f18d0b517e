# SPDX-License-Identifier: BSD-3-Clause
"""Typed results of identification and diagnosis, with ``to_dict()`` giving the JSON that
``rotacal identify --json`` and ``rotacal diagnose --json`` print."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .models import ballbar_model_dict, covariance_dict, estimate_dict, fit_model_dict


@dataclass
class Identification:
    """Location errors (and pivot) identified from a ballbar session."""

    raw: Any  # _core.BallbarIdentification
    budget: Any = None  # _core.UncertaintyBudget, attached by identify(..., budget=True)

    @property
    def machine(self):
        return self.raw.model.machine

    @property
    def parameters(self) -> list:
        return list(self.raw.parameters)

    def parameter(self, name: str):
        for p in self.raw.parameters:
            if p.name == name:
                return p
        raise KeyError(name)

    @property
    def residuals(self):
        return self.raw.residuals

    def model_dict(self) -> dict:
        """The model file's content: values of unobservable parameters under the fit's
        convention, so that predictions from the file match the fit."""
        d = ballbar_model_dict(
            self.machine, self.raw.parameters, self.raw.model.effects, convention_values=True
        )
        cov = covariance_dict(self.raw.parameters, self.raw.covariance)
        if cov is not None:
            d["covariance"] = cov
        return d

    def to_dict(self) -> dict:
        m = ballbar_model_dict(self.machine, self.raw.parameters, self.raw.model.effects)
        out = {
            "method": self.raw.method,
            "machine": m["machine"],
            "location_errors": m["location_errors"],
            "pivot": m["pivot"],
            "residual_rms_um": float(self.raw.residual_rms_um),
            "n_samples": int(self.raw.n_samples),
            "sigma_um": float(self.raw.sigma_um),
            "converged": bool(self.raw.converged),
            "iterations": int(self.raw.iterations),
            "unobservable": list(self.raw.unobservable),
            "notes": list(self.raw.notes),
        }
        if m["effects"]:
            out["effects"] = m["effects"]
        if self.raw.method == "joint":
            out["noise_model"] = noise_model_dict(
                self.raw.noise, self.raw.noise_refit, self.raw.noise_correction
            )
        if self.budget is not None:
            out["uncertainty_budget"] = budget_dict(self.budget)
        return out


@dataclass
class DiagnosisResult:
    """What the baseline model gets wrong, the causes found, and the gain."""

    raw: Any  # _core.Diagnosis
    budget: Any = None  # _core.UncertaintyBudget of the final model, if computed

    @property
    def findings(self) -> list:
        return list(self.raw.findings)

    def to_dict(self) -> dict:
        d = self.raw
        b = d.baseline
        out = {
            "baseline": {
                "residual_rms_um": b.residual_rms_um,
                "noise_um": b.noise_um,
                "noise_source": b.noise_source,
                "chi2_per_dof": b.chi2_per_dof,
                "p_value": b.p_value,
                "n": int(b.n),
            },
            "findings": [
                {
                    "effect": f.effect,
                    "cause": f.cause,
                    # How sure the name is (issue 29): the BIC weight among the finding's rivals;
                    # named is False when the finding is the group that holds
                    # DiagnosisOptions.min_weight together, and "effect" is then the member the
                    # extended model holds (diagnose/diagnosis.hpp, Finding::effect).
                    "weight": f.weight,
                    "named": bool(f.named_alone),
                    # Which member of the group the extended model holds, and why (issue 50):
                    # "effect" is that member; its parameters and gain are the ones shown.
                    "model": {"holds": f.effect, "why": f.model_reason},
                    # Non-empty: the finding's signature confined to a few poses fits as well (a
                    # local defect outside the catalogue), which is why it is not named.
                    "lack_of_fit": f.lack_of_fit,
                    "group": [{"effect": f.effect, "weight": f.weight}]
                    + [
                        {
                            "effect": r.effect,
                            "weight": r.weight,
                            **({"aliased": True} if r.aliased else {}),
                        }
                        for r in f.rivals
                        if r.in_group
                    ],
                    "rivals": [
                        {
                            "effect": r.effect,
                            "weight": r.weight,
                            "delta_bic": r.delta_bic,
                            "correlation": r.correlation,
                            "in_group": bool(r.in_group),
                            "aliased": bool(r.aliased),
                        }
                        for r in f.rivals
                    ],
                    "parameters": {p.name: estimate_dict(p) for p in f.parameters},
                    "gain": {
                        "rms_before_um": f.gain.rms_before_um,
                        "rms_after_um": f.gain.rms_after_um,
                        "delta_bic": f.gain.delta_bic,
                        "cv_rms_before_um": f.gain.cv_rms_before_um,
                        "cv_rms_after_um": f.gain.cv_rms_after_um,
                        "f_test_p": f.gain.f_pvalue,
                    },
                    "location_error_changes": [
                        {
                            "name": s.name,
                            "before": s.before,
                            "after": s.after,
                            "std_after": s.std_after,
                            "unit": s.unit,
                        }
                        for s in f.shifts
                    ],
                }
                for f in d.findings
            ],
            "ambiguous": [
                {
                    "effects": list(a.effects),
                    "delta_bic": a.delta_bic,
                    "correlation": a.correlation,
                    "separating_test": a.separating_test,
                }
                for a in d.ambiguous
            ],
            "unobservable": [{"effect": u.effect, "reason": u.reason} for u in d.unobservable],
            "unexplained": {
                "present": d.unexplained.present,
                "chi2_per_dof": d.unexplained.chi2_per_dof,
                "p_value": d.unexplained.p_value,
                "signature": d.unexplained.signature,
                **_where_unexplained(d.unexplained),
            },
            "residual_structure": {
                "before": [_group(g) for g in d.structure_before],
                "after": [_group(g) for g in d.structure_after],
            },
            "candidates_first_round": [
                {
                    "effect": c.effect,
                    "delta_bic": c.delta_bic,
                    "f_test_p": c.f_pvalue,
                    "visible_params": c.visible_params,
                }
                for c in (d.rounds[0] if d.rounds else [])
            ][:10],
            "final_model": fit_model_dict(d.machine, d.final_fit.parameters, d.final_fit.effects),
            "seconds": d.seconds,
        }
        if getattr(d, "noise", None) is not None:  # bound by the diagnosis module
            out["noise_model"] = noise_model_dict(d.noise)
        if getattr(d, "angle_tables", None) is not None:
            out["angle_tables"] = [angle_table_dict(t) for t in d.angle_tables]
        if self.budget is not None:
            out["uncertainty_budget"] = budget_dict(self.budget)
        return out


def _where_unexplained(u: Any) -> dict:
    """Where the unexplained structure is (deg, or s when axis is ""), and, where the noise model
    took structure for noise (issue 50 item 4), why, how large and the test to resolve it."""
    if not u.present:
        return {}
    out = {"group": u.group, "axis": u.axis, "range_from": u.range_from, "range_to": u.range_to}
    if u.noise_structure:
        out["noise_structure"] = {
            "reason": u.noise_structure,
            "f_test_p": u.noise_structure_p,
            "at": u.at,
            "size_um": u.size_um,
            "noise_um": u.noise_um,
            "suggested_test": u.suggested_test,
        }
    return out


def _num(x: float):
    """A JSON number, or None for infinity (no NaN/inf in the JSON: docs/json_schema.md)."""
    return float(x) if math.isfinite(x) else None


def monte_carlo_dict(mc: Any, draws: int, noise_um: float, keep: Any = None) -> dict:
    """What ``identify --monte-carlo`` prints of a C++ Monte Carlo check (its ``parameters``:
    core/monte_carlo.hpp; ``keep``: which parameter names to show, default all):
    {"draws", "noise_um", "noise", "method", "parameters": {name: {"std_reported", "std_mc",
    "ratio", "bias", "unit"}}}."""
    out = {
        p.name: {
            "std_reported": float(p.std_reported),
            "std_mc": float(p.std_mc),
            "ratio": float(p.ratio),
            "bias": float(p.bias),
            "unit": p.unit,
        }
        for p in mc.parameters
        if keep is None or keep(p.name)
    }
    return {
        "draws": draws,
        "noise_um": float(noise_um),
        "noise": mc.noise,
        "method": "joint",
        "parameters": out,
    }


def noise_model_dict(nm, refit: bool | None = None, correction: float | None = None) -> dict:
    """The noise model (core/noise_model.hpp) as JSON: docs/json_schema.md#noise-model."""
    out = {
        "white": bool(nm.white),
        "summary": nm.summary(),
        "n": int(nm.n),
        "sigma_um": float(nm.sigma_um),
        "innovation_sigma_um": float(nm.innovation_sigma_um),
        "max_order": int(nm.max_order),
        "random_walk_step_um": float(nm.random_walk_step_um),
        "correlation_samples": float(nm.correlation_samples),
        "correlation_time_s": float(nm.correlation_time_s),
        "effective_samples": float(nm.effective_samples),
        "streams": [
            {
                "group": st.group,
                "channel": int(st.channel),
                "n": int(st.n),
                "order": len(st.ar),
                "ar": [float(v) for v in st.ar],
                "sigma_um": float(st.marginal_sigma_um),
                "innovation_sigma_um": float(st.innovation_sigma_um),
                "correlation_samples": float(st.correlation_samples),
                "sample_interval_s": float(st.sample_interval_s),
                "correlation_time_s": float(st.correlation_time_s),
                "effective_samples": float(st.effective_samples),
                "random_walk_step_um": float(st.random_walk_step_um),
            }
            for st in nm.streams
        ],
    }
    if refit is not None:
        out["gls_refit"] = bool(refit)
        out["covariance_factor"] = float(correction)
    return out


def noise_handling_words(nm: dict) -> str:
    """How the 1-sigma of an identification rest on its noise model (a noise_model_dict with
    gls_refit), in words: what the fit did, not more. A model holding a random walk is the
    R-test's AR(1) + random walk per stream by REML over the fit's residual space, whose
    covariance needs no factor (docs/noise_model.md); a factor other than 1 is the bootstrap
    bias correction of Burg's AR model (core/noise_handling.hpp)."""
    if not nm.get("gls_refit"):
        return "readings taken as independent"
    if nm.get("random_walk_step_um", 0.0) > 0.0:
        return (
            "1-sigma by GLS under it: AR(1) + random walk per stream, estimated by REML over the "
            "fit's residual space (no scale factor)"
        )
    factor = nm.get("covariance_factor", 1.0)
    if factor != 1.0:
        return f"1-sigma by GLS under it, covariance x {factor:.2f} for the correlation the fit absorbs"
    return "1-sigma by GLS under it"


def angle_table_dict(t) -> dict:
    """A per-angle table (structure outside the catalogue): docs/json_schema.md#per-angle-table."""
    g = t.gain
    axis = t.axis if isinstance(t.axis, str) else chr(t.axis)
    return {
        "group": t.group,
        "axis": axis,
        "angle_deg": [float(v) for v in t.angle_deg],
        "value_um": [float(v) for v in t.value_um],
        "std_um": [float(v) for v in t.std_um],
        "count": [int(v) for v in t.count],
        "gain": {
            "rms_before_um": g.rms_before_um,
            "rms_after_um": g.rms_after_um,
            "delta_bic": g.delta_bic,
            "cv_rms_before_um": g.cv_rms_before_um,
            "cv_rms_after_um": g.cv_rms_after_um,
            "f_test_p": g.f_pvalue,
        },
    }


def budget_dict(b) -> dict:
    """The uncertainty budget (diagnose/uncertainty_budget.hpp): docs/json_schema.md#uncertainty-budget."""
    return {
        "coverage": float(b.coverage),
        "location_errors": {
            e.name: {
                "unit": e.unit,
                "observable": bool(e.observable),
                "value": float(e.value) if e.observable else None,
                "u_a": _num(e.u_a) if e.observable else None,
                "dof_a": _num(e.dof_a) if e.observable else None,
                "u_c": _num(e.u_c) if e.observable else None,
                "nu_eff": _num(e.nu_eff) if e.observable else None,
                "k": _num(e.k) if e.observable else None,
                "expanded": _num(e.expanded) if e.observable else None,
                "dominant": list(e.dominant),
                "type_b": [
                    {
                        "effect": line.effect,
                        "basis": line.basis,
                        "u": float(line.u),
                        "bias_at_size": float(line.bias_at_size),
                        "dof": _num(line.dof),
                        "half_width": [float(h) for h in line.half_width],
                    }
                    for line in e.type_b
                ],
            }
            for e in b.errors
        },
    }


def _group(g) -> dict:
    return {
        "group": g.group,
        "n": int(g.n),
        "rms_um": g.rms_um,
        "mean_um": g.mean_um,
        "angle_axis": g.angle_axis,
        "harmonic_um": list(g.harmonic_um),
        "harmonics_left_out": list(g.harmonics_left_out),
        "harmonic_note": g.harmonic_note,
        "trend_um_per_s": g.trend_um_per_s,
    }


def budget_why(b: dict) -> str | None:
    """Why U can be far above type A, and what shrinks it (None when type A dominates): type B
    is the size each left-out effect plausibly has, assumed (default sizes) until measured and
    given by --budget-sizes. One sentence, for the CLI and the report alike."""
    rows = [
        (n, e)
        for n, e in b["location_errors"].items()
        if e["observable"] and e["type_b"] and e["u_a"] > 0
    ]
    if not rows:
        return None
    name, e = max(rows, key=lambda r: r[1]["u_c"] / r[1]["u_a"])
    if e["u_c"] < 2 * e["u_a"]:
        return None
    line = e["type_b"][0]
    f, unit = (1e6, "urad") if e["unit"] == "rad" else (1e3, "um")
    return (
        f"U is mostly type B: effects the fit leaves out, at plausible sizes that are assumed, not measured "
        f"(largest on {name}: {line['effect']}, {line['u'] * f:.3f} {unit}, {line['basis']}). Measure it and "
        f'give the value with --budget-sizes SIZES.json holding {{"overrides": {{"{line["effect"]}": SIZE}}}} '
        "(SIZE in the effect parameter's unit, mm or rad; docs/json_schema.md)"
    )
