"""R-test: identification of the location errors and error map of a B/C table
(Oyama & Ibaraki), on numpy-backed RtestSession objects."""
from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _core
from .models import estimate_dict

# The measurement pattern of Oyama Sec. 3.3, used for the map grid by default.
B_GRID = list(range(-90, 91, 30))
C_GRID = list(range(0, 360, 30))


@dataclass
class RtestIdentification:
    """Result of identify_rtest; ``to_dict()`` is the JSON of ``rotacal identify --json``."""

    raw: Any
    machine: Any

    def error_map(self, fmt: str = "json") -> str:
        if self.raw.method == "joint":
            return _core.rtest_error_map(self.raw, B_GRID, C_GRID, fmt)
        return _core.rtest_error_map(self.raw, fmt)

    def model_dict(self) -> dict:
        raise _core.InvalidArgument("R-test model files are not available yet: use the error map "
                                    "(rotacal identify --json) or the C++ RtestJointModel to predict")

    def to_dict(self) -> dict:
        r = self.raw
        out = {"method": r.method, "machine": _core.machine_name(self.machine),
               "residual_rms_um": float(r.residual_rms_um), "n_samples": int(r.n_samples),
               "unobservable": list(r.unobservable), "notes": list(r.notes),
               "error_map": json.loads(self.error_map("json"))}
        if r.method == "joint":
            names = list(_core.location_error_names(self.machine))
            by_name = {p.name: p for p in r.parameters}
            out["location_errors"] = {n: estimate_dict(by_name[n]) for n in names}
            out["probe_zeros"] = {k: np.asarray(v).tolist() for k, v in r.probe_zeros.items()}
            out["converged"] = bool(r.converged)
        return out


def identify_rtest(session: _core.RtestSession, method: str = "joint") -> RtestIdentification:
    """Identify an R-test session: method "joint" (Ceres fit with smooth maps, default) or
    "paper" (Oyama & Ibaraki's Eqs. 10-22)."""
    if method == "joint":
        return RtestIdentification(_core.identify_rtest_joint(session), session.machine)
    if method == "paper":
        return RtestIdentification(_core.identify_rtest_paper(session), session.machine)
    raise _core.InvalidArgument(f"identify_rtest: method must be 'joint' or 'paper', got {method!r}")
