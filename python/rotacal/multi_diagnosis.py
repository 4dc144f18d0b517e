# SPDX-License-Identifier: BSD-3-Clause
"""One diagnosis of several sessions of one machine (include/rotacal/diagnose/multi_session.hpp):
machine effects with one parameter set shared by every session, instrument, set-up and time
effects per session (ids ``name:id``), each finding saying where it holds."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from . import _core, units
from .models import estimate_dict
from .results import DiagnosisResult
from .sessions import kind


def session_names(sessions: list) -> list[str]:
    """Default names: each session's instrument, numbered where several share one."""
    kinds = [kind(s) for s in sessions]
    seen: dict[str, int] = {}
    names = []
    for k in kinds:
        seen[k] = seen.get(k, 0) + 1
        names.append(k + (str(seen[k]) if kinds.count(k) > 1 else ""))
    return names


def named_sessions(sessions: Any) -> list[tuple[str, Any]]:
    """(name, session) pairs from a mapping, a list of pairs, or a list of sessions."""
    if isinstance(sessions, dict):
        return [(str(n), s) for n, s in sessions.items()]
    items = list(sessions)
    if items and all(isinstance(x, tuple) and len(x) == 2 for x in items):
        return [(str(n), s) for n, s in items]
    return list(zip(session_names(items), items))


@dataclass
class MultiDiagnosisResult:
    """The joint diagnosis (``raw``: _core.MultiDiagnosis): the engine's result over every
    session's readings, each session's residual RMS before and after, where each finding holds."""

    raw: Any

    @property
    def findings(self) -> list:
        return list(self.raw.diagnosis.findings)

    @property
    def diagnosis(self) -> DiagnosisResult:
        return DiagnosisResult(self.raw.diagnosis)

    def to_dict(self) -> dict:
        out = self.diagnosis.to_dict()
        # The joint model: the shared location errors and effects, each session's own
        # parameters ("name:parameter") and effects ("name:id") beside them.
        out["final_model"]["kind"] = "joint-diagnosis"
        fit = self.raw.diagnosis.final_fit
        ids = list(fit.effects)

        def of_effect(name: str) -> bool:
            return any(name == i or name.startswith(i + ".") for i in ids)

        out["final_model"]["session_parameters"] = {
            p.name: estimate_dict(p)
            for p in fit.parameters
            if ":" in p.name and not of_effect(p.name)
        }
        for f, where in zip(out["findings"], self.raw.where):
            f["where"] = where  # "machine" or the session's name
        out["sessions"] = [
            {
                "name": s.name,
                "instrument": s.instrument,
                "n": int(s.n),
                "noise_um": s.noise_um,
                "weight": s.weight,
                "residual_rms_before_um": s.rms_before_um,
                "residual_rms_after_um": s.rms_after_um,
            }
            for s in self.raw.sessions
        ]
        # A session not fitted alone (a one-pose probe test joined to the session before it)
        out["session_notes"] = list(self.raw.notes)
        return out


def diagnose_sessions(sessions: Any, options: _core.DiagnosisOptions) -> MultiDiagnosisResult:
    """Diagnose several sessions of one machine together (see the module docstring)."""
    return MultiDiagnosisResult(_core.diagnose_sessions(named_sessions(sessions), options))


def print_several(d: dict) -> None:
    """What the terminal shows of a diagnosis of several sessions beyond one session's: where
    each finding holds, each session's residual RMS, the extended joint model's location errors."""
    for i, f in enumerate(d["findings"], 1):
        where = (
            "the machine (every session)" if f["where"] == "machine" else f"session {f['where']}"
        )
        print(f"finding {i} holds for {where}")
    for note in d.get("session_notes", []):
        print(f"note: {note}")
    print("sessions: residual RMS before -> after the findings")
    for s in d["sessions"]:
        print(
            f"  {s['name']} ({s['instrument']}, {s['n']} readings, noise {s['noise_um']:.3f} um): "
            f"{s['residual_rms_before_um']:.3f} -> {s['residual_rms_after_um']:.3f} um"
        )
    print("location errors of the extended joint model:")
    for name, p in d["final_model"]["location_errors"].items():
        print(f"  {name} = {units.estimate_text(p['value'], p['std'], p['unit'])}")
