# SPDX-License-Identifier: BSD-3-Clause
"""One item of ``rotacal batch``: a session file identified or diagnosed alone, as
``rotacal identify`` and ``rotacal diagnose`` do it, returning plain data (it may cross to a
Dask worker and back). Run by rotacal.batch.executor: module functions, importable by name."""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from ..sessions import PROBE, check_plausible, kind, load


def _session(path: str, options: Mapping[str, Any]) -> Any:
    s = load(path)
    if kind(s) != PROBE:  # session/plausibility has no touch-probe check yet
        check_plausible(s, path, options.get("max_deviation"))
    return s


def _identification(s: Any, path: str, options: Mapping[str, Any]) -> tuple[Any, dict]:
    """The joint identification of ``s`` and what `rotacal identify --json` prints of it."""
    from ..analysis import identification_budget, identify

    noise = options.get("noise", "auto")
    result = identify(s, "joint", noise=noise)
    budget = not options.get("no_budget", False)
    if kind(s) == PROBE:
        d = result.to_dict()
        if budget:
            from ..diagnosis import uncertainty_budget
            from ..results import budget_dict

            d["uncertainty_budget"] = budget_dict(uncertainty_budget(s, sizes=options.get("sizes")))
        return result, d
    if budget:
        result.budget = identification_budget(s, options.get("sizes"), result)
    return result, result.to_dict()


def _stored(result: Any, path: str, options: Mapping[str, Any]) -> dict | None:
    """The model document a history entry holds (analysis.identification_document), with --store."""
    if not options.get("store"):
        return None
    from ..analysis import identification_document

    return identification_document(result, path)


def identify_file(path: str, seed: np.random.SeedSequence, options: Mapping[str, Any]) -> dict:
    """``rotacal identify --json`` of one session file (joint method); with options["store"]
    also the model document its history entry holds. ``seed``: unused, a fit draws nothing."""
    s = _session(path, options)
    result, d = _identification(s, path, options)
    return {
        "warnings": list(s.warnings),
        "identification": d,
        "model": _stored(result, path, options),
    }


def diagnose_file(path: str, seed: np.random.SeedSequence, options: Mapping[str, Any]) -> dict:
    """``rotacal diagnose --json`` of one session file; with options["store"] also its joint
    identification's model document, which the history stores with the diagnosis."""
    from ..diagnosis import diagnose, uncertainty_budget

    s = _session(path, options)
    result = diagnose(s, max_harmonic=options.get("max_harmonic"))
    if not options.get("no_budget", False):
        result.budget = uncertainty_budget(s, result, sizes=options.get("sizes"))
    out = {"warnings": list(s.warnings), "diagnosis": result.to_dict(), "model": None}
    if options.get("store"):
        ident, _ = _identification(s, path, {**options, "no_budget": True})
        out["model"] = _stored(ident, path, options)
    return out


WORK = {"identify": identify_file, "diagnose": diagnose_file}
