"""Diagnosis: what the fitted model gets wrong, its cause, the extended model and the gain."""
from __future__ import annotations

from typing import Any

from . import _core
from .results import DiagnosisResult
from .sessions import BALLBAR, RTEST, by_kind

# Highest harmonic order a diagnosis tries: the candidates grow with it, and no session
# resolves orders this high (a ballbar test samples each circle at ~360 points, R-test 12 C angles).
MAX_HARMONIC = 32


def diagnosis_options(**options: Any) -> _core.DiagnosisOptions:
    """The C++ DiagnosisOptions (diagnose/diagnosis.hpp, where the defaults live) with the
    given fields set; an unknown field is refused by name, None leaves the default."""
    o = _core.DiagnosisOptions()
    mh = options.get("max_harmonic")
    if mh is not None and not (isinstance(mh, int) and 1 <= mh <= MAX_HARMONIC):
        raise _core.InvalidArgument(f"diagnose: max_harmonic must be an integer in 1..{MAX_HARMONIC}, got {mh!r}")
    for name, value in options.items():
        if not hasattr(o, name) or name.startswith("_"):
            raise _core.InvalidArgument(f"diagnose: unknown option {name!r}")
        if value is not None:
            setattr(o, name, list(value) if name == "only" else value)
    return o


def diagnose(session: Any, *, reference: Any = None, **options: Any) -> DiagnosisResult:
    """Diagnose a session (see include/rotacal/diagnose/diagnosis.hpp for the method).

    Parameters
    ----------
    session : a BallbarSession or an RtestSession (with dx,dy,dz)
    reference : a complete standard test for the machine (commanded rows) used to name the
        test that separates ambiguous candidates (ballbar only)
    options : fields of DiagnosisOptions over its C++ defaults, e.g. ``max_harmonic`` (highest
        harmonic order tried for the *_hn catalogue entries), ``max_findings`` (stop after this
        many effects), ``alpha`` (family-wise false-finding rate per step), ``only`` (restrict
        the candidates to these catalogue ids)
    """
    o = diagnosis_options(**options)
    run = by_kind(session, {BALLBAR: lambda: _core.diagnose_ballbar(session, o, reference),
                            RTEST: lambda: _core.diagnose_rtest(session, o)}, "diagnose")
    return DiagnosisResult(run())
