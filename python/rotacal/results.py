"""Typed results of identification and diagnosis, with ``to_dict()`` giving the JSON that
``rotacal identify --json`` and ``rotacal diagnose --json`` print."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from . import _core
from .models import ballbar_model_dict, estimate_dict, fit_model_dict


@dataclass
class Identification:
    """Location errors (and pivot) identified from a ballbar session."""

    raw: Any  # _core.BallbarIdentification

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
        return ballbar_model_dict(self.machine, self.raw.parameters, self.raw.model.effects)

    def to_dict(self) -> dict:
        m = self.model_dict()
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
        return out


@dataclass
class DiagnosisResult:
    """What the baseline model gets wrong, the causes found, and the gain."""

    raw: Any  # _core.Diagnosis

    @property
    def findings(self) -> list:
        return list(self.raw.findings)

    def to_dict(self) -> dict:
        d = self.raw
        b = d.baseline
        return {
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
                        {"name": s.name, "before": s.before, "after": s.after,
                         "std_after": s.std_after, "unit": s.unit}
                        for s in f.shifts
                    ],
                }
                for f in d.findings
            ],
            "ambiguous": [
                {"effects": list(a.effects), "delta_bic": a.delta_bic,
                 "correlation": a.correlation, "separating_test": a.separating_test}
                for a in d.ambiguous
            ],
            "unobservable": [{"effect": u.effect, "reason": u.reason} for u in d.unobservable],
            "unexplained": {
                "present": d.unexplained.present,
                "chi2_per_dof": d.unexplained.chi2_per_dof,
                "p_value": d.unexplained.p_value,
                "signature": d.unexplained.signature,
            },
            "residual_structure": {
                "before": [_group(g) for g in d.structure_before],
                "after": [_group(g) for g in d.structure_after],
            },
            "candidates_first_round": [
                {"effect": c.effect, "delta_bic": c.delta_bic, "f_test_p": c.f_pvalue,
                 "visible_params": c.visible_params} for c in (d.rounds[0] if d.rounds else [])][:10],
            "final_model": fit_model_dict(d.machine, d.final_fit.parameters, d.final_fit.effects),
            "seconds": d.seconds,
        }


def _group(g) -> dict:
    return {"group": g.group, "n": int(g.n), "rms_um": g.rms_um, "mean_um": g.mean_um,
            "angle_axis": g.angle_axis, "harmonic_um": list(g.harmonic_um),
            "harmonics_left_out": list(g.harmonics_left_out), "harmonic_note": g.harmonic_note,
            "trend_um_per_s": g.trend_um_per_s}
