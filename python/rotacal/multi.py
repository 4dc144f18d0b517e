# SPDX-License-Identifier: BSD-3-Clause
"""One identification from several sessions of one machine (ballbar, R-test, touch probe):
one set of location errors (and of catalogue effects where asked), each session's own nuisances
and noise model, and the parameters on
which the sessions fitted alone disagree. C++ computes (include/rotacal/multi); this module only
composes."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import Any, Sequence

from . import _core, rtest
from .models import estimate_dict, machine_members
from .results import noise_model_dict
from .sessions import RTEST, kind, session_text


@dataclass
class MultiIdentification:
    """The joint result (``raw``: _core.MultiIdentification)."""

    raw: Any

    @property
    def machine(self):
        return self.raw.machine

    def location_error(self, name: str) -> Any:
        for p in self.raw.location_errors:
            if p.name == name:
                return p
        raise _core.InvalidArgument(f"no location error named {name!r}")

    def model_dict(self) -> dict:
        """The model file's content (``kind: multi``, docs/model_file.md), written by the C++
        implementation (rotacal/multi/model_document.hpp): the shared location errors and effects
        with the joint covariance, each session with its own parameters, its values alone and its
        noise model, and the disagreements."""
        return _core.multi_model_document(self.raw)

    def to_dict(self) -> dict:
        r = self.raw
        return {
            "method": "joint-multi",
            **machine_members(r.machine),
            "location_errors": {p.name: estimate_dict(p) for p in r.location_errors},
            "effects": {p.name: estimate_dict(p) for p in r.effects},
            "sessions": [
                {
                    "name": s.name,
                    "instrument": s.instrument,
                    "nuisances": {p.name: estimate_dict(p) for p in s.nuisances},
                    "alone": {p.name: estimate_dict(p) for p in s.alone},
                    "residual_rms_um": float(s.residual_rms_um),
                    "n_residuals": int(s.n_residuals),
                    "noise_model": noise_model_dict(s.noise, s.noise_refit, s.noise_correction),
                }
                for s in r.sessions
            ],
            "disagreements": [
                {
                    "parameter": d.parameter,
                    "unit": d.unit,
                    "sessions": [d.session_a, d.session_b],
                    "values": [float(d.value_a), float(d.value_b)],
                    "difference": float(d.difference),
                    "sigma": float(d.sigma),
                    "z": float(d.z),
                    "threshold": float(d.threshold),
                }
                for d in r.disagreements
            ],
            "disagreement_test": {
                "comparisons": int(r.comparisons),
                "z": float(r.disagreement_z),
            },
            "converged": bool(r.converged),
            "sigma_inflated": bool(r.sigma_inflated),
            "unobservable": list(r.unobservable),
            "notes": list(r.notes),
        }


def _refuse_duplicates(sessions: Sequence[Any], names: Sequence[str]) -> None:
    """One measurement given twice (a copy, a symlink, the same data under another name) would
    count twice and shrink every sigma by sqrt(2): refused by the SHA-256 of its content (the
    session's file text as rotacal writes it, so comments and spacing do not hide a copy)."""
    seen: dict[str, str] = {}
    for s, name in zip(sessions, names):
        digest = hashlib.sha256(session_text(s, "identify").encode("utf-8")).hexdigest()
        if digest in seen:
            raise _core.InvalidArgument(
                f"identify: {name} and {seen[digest]} hold the same session (content SHA-256 "
                f"{digest[:16]}...): one measurement counted twice would shrink the sigmas by "
                "sqrt(2); give each session once"
            )
        seen[digest] = name


def identify_sessions(
    sessions: Sequence[Any],
    names: Sequence[str] | None = None,
    *,
    noise: str = "auto",
    effects: Sequence[str] = (),
    inflate_sigma: bool = False,
) -> MultiIdentification:
    """Identify several sessions of one machine jointly (rotacal.identify with a list).
    ``names`` name the sessions in the result (default "session 1", ...); ``effects``: catalogue
    ids of the machine fitted along, one set shared by every session (about the machine zero);
    an R-test session's raw d1,d2,d3 readings are converted as identify_rtest converts them.
    While the sessions disagree the result has no model (``model_dict`` refuses it), unless
    ``inflate_sigma`` widened the sigmas of the parameters they disagree on by their scatter."""
    sessions = list(sessions)
    names = [f"session {k + 1}" for k in range(len(sessions))] if names is None else list(names)
    if len(names) != len(sessions):
        raise _core.InvalidArgument(f"identify: {len(names)} names for {len(sessions)} sessions")
    _refuse_duplicates(sessions, names)
    ready = [rtest.with_displacements(s)[0] if kind(s) == RTEST else s for s in sessions]
    return MultiIdentification(
        _core.identify_multi(list(zip(names, ready)), noise, list(effects), inflate_sigma)
    )
