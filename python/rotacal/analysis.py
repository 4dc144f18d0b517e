# SPDX-License-Identifier: BSD-3-Clause
"""What each command does with each kind of session: identify, predict and report a ballbar, an R-test or a touch-probe session."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from . import _core, ballbar, multi, probe, rtest
from .diagnosis import diagnose, plausible_sizes, uncertainty_budget
from .models import ballbar_model_from_dict
from .sessions import BALLBAR, PROBE, RTEST, by_kind, kind

# A ballbar model holds the pivot where its own session's ball sat (nominal + a set-up error of
# some 10 um): a session whose nominal pivot is farther from it was set up elsewhere, and its
# lengths would be predicted from the wrong ball position (issue 32: 114-270 mm for a 150 mm bar).
MAX_PIVOT_SHIFT_MM = 1.0


def identify(
    session: Any,
    method: str = "joint",
    *,
    fit_length_offset: bool = False,
    effects: Sequence[str] = (),
    tests: Sequence[str] = (),
    noise: str = "auto",
) -> Any:
    """Identify the location errors of a ballbar session (rotacal.ballbar.identify: options
    ``fit_length_offset``, ``effects``, ``tests``), of an R-test session
    (rotacal.identify_rtest: ``method`` only) or of a touch-probe session (rotacal.identify_probe:
    ``method`` "joint", "cycles" or "cycles-free-radius", ``effects``). ``noise``: "auto" (AR noise
    model of the residuals, GLS refit when correlated) or "white".
    A list of sessions of one machine is identified jointly (rotacal.multi.identify_sessions:
    ``effects`` shared by every session, ``noise``)."""
    if isinstance(session, (list, tuple)):
        if method != "joint" or fit_length_offset or tests:
            raise _core.InvalidArgument(
                "identify: a list of sessions takes only `effects` and `noise`"
            )
        return multi.identify_sessions(session, noise=noise, effects=effects)

    def rtest_identify():
        if fit_length_offset or effects or tests:
            raise _core.InvalidArgument("identify: an R-test session takes only `method`")
        return rtest.identify_rtest(session, method, noise=noise)

    def probe_identify():
        if fit_length_offset or tests:
            raise _core.InvalidArgument(
                "identify: a touch-probe session takes `method`, `effects` and `noise`"
            )
        return probe.identify_probe(session, method, effects=effects, noise=noise)

    run = by_kind(
        session,
        {
            BALLBAR: lambda: ballbar.identify(
                session,
                method,
                fit_length_offset=fit_length_offset,
                effects=effects,
                tests=tests,
                noise=noise,
            ),
            RTEST: rtest_identify,
            PROBE: probe_identify,
        },
        "identify",
    )
    return run()


def identification_budget(session: Any, sizes: Any = None, identification: Any = None) -> Any:
    """The GUM budget of a joint identification of ``session`` (diagnose/uncertainty_budget.hpp):
    it rests on the diagnosis of what the model leaves out. An R-test session's raw d1,d2,d3
    readings are converted as identify_rtest converts them. Given the R-test ``identification``
    (identify_rtest's joint result), the budget is of its own model, maps included
    (diagnose/rtest_budget.hpp): the values and type A are the ones it reports.
    ``sizes``: plausible_sizes() input."""
    if identification is not None and kind(session) == RTEST:
        return _core.uncertainty_budget_rtest_identification(
            rtest.with_displacements(session)[0], identification.raw, plausible_sizes(sizes)
        )
    fitted = by_kind(
        session,
        {BALLBAR: lambda: session, RTEST: lambda: rtest.with_displacements(session)[0]},
        "identify",
    )()
    return uncertainty_budget(fitted, sizes=sizes)


def monte_carlo(session: Any, identification: Any, draws: int, *, seed: int = 1) -> dict:
    """Check an identification's 1-sigma by ``draws`` simulated repeats of the session with its
    fitted noise model (rotacal.ballbar.monte_carlo, rotacal.rtest.monte_carlo_rtest,
    rotacal.probe.monte_carlo_probe)."""
    return by_kind(
        session,
        {
            BALLBAR: lambda: ballbar.monte_carlo(session, identification, draws, seed=seed),
            RTEST: lambda: rtest.monte_carlo_rtest(session, identification, draws, seed=seed),
            PROBE: lambda: probe.monte_carlo_probe(session, identification, draws, seed=seed),
        },
        "monte_carlo",
    )()


def identification_document(
    identification: Any,
    session_path: str | Path | Sequence[str | Path],
    controller: str | None = None,
) -> dict:
    """What a model file and a history entry hold of an identification: its model with the
    ``source`` (the session as named, its SHA-256, when, by which rotacal; for a joint
    identification of several sessions, ``session_path`` lists them) and, when given, the
    text of the controller parameters active during the test (the kinematics the errors are
    relative to, for the export and the history)."""
    from .models import source_dict

    source = source_dict(session_path)
    if controller is not None:
        source["controller_parameters"] = controller
    if isinstance(identification, probe.ProbeIdentification):
        return identification.model_dict(source["session"]) | {"source": source}
    return identification.model_dict() | {"source": source}


def predict_session(
    model: Mapping, session: Any, probe_zeros: str = "none", source: str = "<model>"
) -> tuple[Any, str | None]:
    """A session predicted by a model dict (rotacal.load_model), and a line saying how well it
    matches the measurement (None when the session has no readings to compare)."""

    def ballbar_predict():
        if probe_zeros != "none":
            raise _core.InvalidArgument("predict: --probe-zeros is for R-test sessions")
        fitted = ballbar_model_from_dict(dict(model), source)  # refuses a model of another kind
        # A model of another machine predicts nonsense: refuse, naming both.
        _core.check_model_machine(fitted.machine, session.machine, source)
        model_pivot, pivot = np.asarray(fitted.pivot).ravel(), np.asarray(session.pivot).ravel()
        shift = float(np.linalg.norm(model_pivot - pivot))
        if not shift <= MAX_PIVOT_SHIFT_MM:
            raise _core.InvalidArgument(
                f"predict: the session's pivot ({', '.join(f'{v:g}' for v in pivot)}) mm is {shift:.3f} mm from the "
                f"model's ({', '.join(f'{v:.3f}' for v in model_pivot)}; {source}): a ballbar model predicts the "
                "set-up it was fitted on; identify this session instead"
            )
        out = ballbar.predict(fitted, session)
        res = (np.asarray(session.length) - np.asarray(out.length)) * 1e3
        return (
            out,
            f"measured - predicted: RMS {np.sqrt(np.mean(res**2)):.3f} um over {len(session)} samples",
        )

    def rtest_predict():
        out = rtest.predict_rtest(model, session, probe_zeros, source=source)
        if not (rtest.has_displacements(session) or session.probe_dirs):
            return out, None
        return out, (
            f"measured - predicted: RMS {rtest.prediction_rms_um(model, session, source):.3f} um over "
            f"{len(session)} poses (one constant per set-up removed: its probe zero)"
        )

    return by_kind(session, {BALLBAR: ballbar_predict, RTEST: rtest_predict}, "predict")()


def write_report(
    path: str | Path,
    session: Any,
    method: str = "joint",
    with_diagnosis: bool = True,
    source: str = "",
    inputs: Sequence[str] = (),
    extra_sections: Sequence[str] = (),
    controller: str | None = None,
) -> Path:
    """The HTML report of a session (rotacal.report): identification, plots and diagnosis,
    written by the output rule (``inputs`` of the command are refused as the target);
    ``extra_sections``: HTML sections appended (e.g. rotacal.history.history_section);
    ``controller``: a section of what that controller's export and tables correct of the
    report's model (the extended one where the diagnosis extended it), and what remains."""
    from . import report  # draws: matplotlib is imported only here

    def with_controller(ident: Any) -> Sequence[str]:
        if controller is None:
            return extra_sections
        from .report.controller import controller_section

        model = identification_document(ident, source or "session")
        return [*extra_sections, controller_section(model, controller)]

    def ballbar_report():
        ident = ballbar.identify(session, method)
        d = diagnose(session) if with_diagnosis else None
        extended = report.extended_identification(session, ident, d) if controller else None
        return report.ballbar_report(
            path,
            session,
            ident,
            d,
            source=source,
            inputs=inputs,
            extra_sections=with_controller(extended or ident),
        )

    def rtest_report():
        if method != "joint":
            raise _core.InvalidArgument(
                "report: an R-test report draws the joint fit's smooth maps; the paper "
                "method's per-angle map is in `rotacal identify --method paper`"
            )
        s, _ = rtest.with_displacements(
            session
        )  # raw d1,d2,d3 with the file's probe.N.dir (identify notes it too)
        ident = rtest.identify_rtest(s, "joint")
        d = diagnose(s) if with_diagnosis else None
        return report.rtest_report(
            path, s, ident, d, source=source, inputs=inputs, extra_sections=with_controller(ident)
        )

    def probe_report():
        if method != "joint":
            raise _core.InvalidArgument(
                "report: a touch-probe report draws the joint fit; the cycles' method is "
                "in `rotacal identify --method cycles`"
            )
        d = diagnose(session) if with_diagnosis else None
        ident = probe.identify_probe(session, "joint")
        return report.probe_report(
            path,
            session,
            ident,
            d,
            source=source,
            inputs=inputs,
            extra_sections=with_controller(ident),
        )

    return by_kind(
        session, {BALLBAR: ballbar_report, RTEST: rtest_report, PROBE: probe_report}, "report"
    )()


def write_joint_report(
    path: str | Path,
    sessions: Sequence[Any],
    names: Sequence[str],
    source: str = "",
    inputs: Sequence[str] = (),
    extra_sections: Sequence[str] = (),
) -> Path:
    """The HTML report of one identification from several sessions of one machine
    (rotacal.multi.identify_sessions; ``names`` name them, e.g. their files)."""
    from . import report

    result = multi.identify_sessions(sessions, names)
    return report.multi_report(
        path, result, source=source, inputs=inputs, extra_sections=extra_sections
    )


def write_diagnosis_report(
    path: str | Path, session: Any, result: Any, source: str = "", inputs: Sequence[str] = ()
) -> Path:
    """``diagnose --report``: the ballbar or touch-probe report with this diagnosis, or the
    diagnosis alone (R-test)."""
    from . import report

    return by_kind(
        session,
        {
            BALLBAR: lambda: report.ballbar_report(
                path, session, ballbar.identify(session), result, source=source, inputs=inputs
            ),
            RTEST: lambda: report.diagnosis_report(
                path, result.to_dict(), title="R-test diagnosis", source=source, inputs=inputs
            ),
            PROBE: lambda: report.probe_report(
                path, session, probe.identify_probe(session), result, source=source, inputs=inputs
            ),
        },
        "diagnose --report",
    )()
