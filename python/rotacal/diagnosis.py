"""Diagnosis: what the fitted model gets wrong, its cause, the extended model and the gain."""
from __future__ import annotations

from typing import Sequence

from . import _core
from .results import DiagnosisResult


def diagnose(session, *, max_harmonic: int = 4, max_findings: int = 4, alpha: float = 0.01,
             only: Sequence[str] = (), reference=None) -> DiagnosisResult:
    """Diagnose a session (see include/rotacal/diagnose/diagnosis.hpp for the method).

    Parameters
    ----------
    session : a BallbarSession or an RtestSession (with dx,dy,dz)
    max_harmonic : highest harmonic order tried for the *_hn catalogue entries
    max_findings : stop after this many effects
    alpha : family-wise false-finding rate per step
    only : restrict the candidates to these catalogue ids
    reference : a complete standard test for the machine (commanded rows) used to name the
        test that separates ambiguous candidates
    """
    o = _core.DiagnosisOptions()
    o.max_harmonic = max_harmonic
    o.max_findings = max_findings
    o.alpha = alpha
    o.only = list(only)
    if isinstance(session, _core.BallbarSession):
        return DiagnosisResult(_core.diagnose_ballbar(session, o, reference))
    if isinstance(session, _core.RtestSession):
        return DiagnosisResult(_core.diagnose_rtest(session, o))
    raise _core.InvalidArgument(f"diagnose: unsupported session type {type(session).__name__}")
