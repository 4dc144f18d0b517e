# SPDX-License-Identifier: BSD-3-Clause
"""Diagnosis: what the fitted model gets wrong, its cause, the extended model and the gain."""

from __future__ import annotations

from typing import Any

from . import _core
from .results import DiagnosisResult
from .sessions import BALLBAR, PROBE, RTEST, by_kind

# Highest harmonic order a diagnosis tries: the candidates grow with it, and no session
# resolves orders this high (a ballbar test samples each circle at ~360 points, R-test 12 C angles).
MAX_HARMONIC = 32


def diagnosis_options(**options: Any) -> _core.DiagnosisOptions:
    """The C++ DiagnosisOptions (diagnose/diagnosis.hpp, where the defaults live) with the
    given fields set; an unknown field is refused by name, None leaves the default."""
    o = _core.DiagnosisOptions()
    mh = options.get("max_harmonic")
    if mh is not None and not (isinstance(mh, int) and 1 <= mh <= MAX_HARMONIC):
        raise _core.InvalidArgument(
            f"diagnose: max_harmonic must be an integer in 1..{MAX_HARMONIC}, got {mh!r}"
        )
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
    session : a BallbarSession, an RtestSession (with dx,dy,dz) or a ProbeSession; or several
        sessions of one machine (a list, (name, session) pairs or a dict by name), diagnosed
        together (multi_diagnosis.py: a MultiDiagnosisResult)
    reference : a complete standard test for the machine (commanded rows) used to name the
        test that separates ambiguous candidates (ballbar only)
    options : fields of DiagnosisOptions over its C++ defaults, e.g. ``max_harmonic`` (highest
        harmonic order tried for the ``*_hn`` catalogue entries), ``max_findings`` (stop after this
        many effects), ``alpha`` (family-wise false-finding rate per step), ``only`` (restrict
        the candidates to these catalogue ids)
    """
    if isinstance(session, (list, tuple, dict)):  # several sessions of one machine (issue 50)
        from .multi_diagnosis import diagnose_sessions

        # Several sessions hold the search's pick unless asked: there the rule still changes
        # which members a group holds (bench/diagnosis_loop.py, a ballbar session and its added
        # arc hiding tilt_motion_A_h2: a group without the truth in 10 of 20 with it, 0 without).
        if options.get("hold_by_weight") is None:
            options = {**options, "hold_by_weight": False}
        return diagnose_sessions(session, diagnosis_options(**options))  # type: ignore[return-value]
    o = diagnosis_options(**options)
    run = by_kind(
        session,
        {
            BALLBAR: lambda: _core.diagnose_ballbar(session, o, reference),
            RTEST: lambda: _core.diagnose_rtest(session, o),
            PROBE: lambda: _core.diagnose_probe(session, o),
        },
        "diagnose",
    )
    return DiagnosisResult(run())


def plausible_sizes(sizes: Any = None) -> _core.PlausibleSizes:
    """The budget's default plausible sizes (diagnose/uncertainty_budget.hpp, half-widths of
    rectangular distributions) with overrides from ``sizes``: a mapping or the path of a JSON
    file holding one, e.g. {"squareness_rad": 1e-5, "overrides": {"gravity_sag_A": 0.004}}.
    Keys are PlausibleSizes fields (units in their names), "overrides" maps a catalogue id or
    "id.parameter" to a size in the parameter's unit, "use_session_bounds" a bool. An unknown
    key or a non-finite or negative size is refused by name (with the file's name)."""
    import json
    import math
    from pathlib import Path

    o = _core.PlausibleSizes()
    if sizes is None:
        return o
    where = "sizes"
    if isinstance(sizes, (str, Path)):
        where = str(sizes)
        try:
            sizes = json.loads(Path(sizes).read_text(encoding="utf-8"))
        except OSError as e:
            raise _core.IoError(f"{where}: cannot read: {e.strerror}") from None
        except json.JSONDecodeError as e:
            raise _core.InvalidArgument(
                f"{where}: line {e.lineno}, column {e.colno}: {e.msg}"
            ) from None
    if not isinstance(sizes, dict):
        raise _core.InvalidArgument(f"{where}: expected a JSON object of plausible sizes")
    for key, value in sizes.items():
        if key.startswith("_") or not hasattr(o, key):
            raise _core.InvalidArgument(f"{where}: unknown plausible size {key!r}")
        if key == "use_session_bounds":
            if not isinstance(value, bool):
                raise _core.InvalidArgument(f"{where}: use_session_bounds must be true or false")
            o.use_session_bounds = value
            continue
        items = value.items() if key == "overrides" and isinstance(value, dict) else [(key, value)]
        if key == "overrides" and not isinstance(value, dict):
            raise _core.InvalidArgument(f"{where}: overrides must be an object of sizes")
        for name, v in items:
            if (
                isinstance(v, bool)
                or not isinstance(v, (int, float))
                or not math.isfinite(v)
                or v < 0
            ):
                raise _core.InvalidArgument(
                    f"{where}: {name}: a size must be a finite number >= 0, got {v!r}"
                )
        if key == "overrides":
            o.overrides = {str(k): float(v) for k, v in value.items()}
        else:
            setattr(o, key, float(value))
    return o


def uncertainty_budget(
    session: Any,
    diagnosis: DiagnosisResult | None = None,
    *,
    sizes: Any = None,
    coverage: float = 0.95,
) -> Any:
    """GUM / ISO/TR 230-9 budget of the location errors (diagnose/uncertainty_budget.hpp):
    type A from the noise model, type B per catalogue effect the diagnosed model leaves out.
    Runs ``diagnose(session)`` if no diagnosis is given (a ballbar session of more than 16,384
    readings: its search on every k-th reading, _core.budget_diagnosis_ballbar). ``sizes``:
    plausible_sizes() input."""
    if diagnosis is None:  # a long ballbar session is searched on a reduced design
        diagnosis = by_kind(
            session,
            {
                BALLBAR: lambda: DiagnosisResult(
                    _core.budget_diagnosis_ballbar(session, diagnosis_options())
                ),
                RTEST: lambda: diagnose(session),
                PROBE: lambda: diagnose(session),
            },
            "uncertainty_budget",
        )()
    o = plausible_sizes(sizes)
    return by_kind(
        session,
        {
            BALLBAR: lambda: _core.uncertainty_budget_ballbar(session, diagnosis.raw, o, coverage),
            RTEST: lambda: _core.uncertainty_budget_rtest(session, diagnosis.raw, o, coverage),
            PROBE: lambda: _core.uncertainty_budget_probe(session, diagnosis.raw, o, coverage),
        },
        "uncertainty_budget",
    )()


def group_text(finding: dict) -> str:
    """A group finding's members as a reader should see them: by BIC weight, largest first,
    the member the extended model holds (whose parameters are shown) marked."""
    members = sorted(finding["group"], key=lambda m: -1.0 if m.get("aliased") else -m["weight"])
    return ", ".join(
        f"{m['effect']} ({'aliased' if m.get('aliased') else format(m['weight'], '.2f')}"
        f"{'; in the extended model' if m['effect'] == finding['effect'] else ''})"
        for m in members
    )


def model_text(finding: dict) -> str:
    """Why the extended model holds the finding's effect, as one sentence."""
    return f"the model holds {finding['model']['holds']} because {finding['model']['why']}"


def held_effects(diagnosis: Any) -> list[dict]:
    """The effects the extended model holds, each with why (``held_because``), as a model
    file's ``effects`` entries carry them (docs/model_file.md)."""
    return [{"id": f.effect, "held_because": f.model_reason} for f in diagnosis.findings]
