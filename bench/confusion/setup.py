# SPDX-License-Identifier: BSD-3-Clause
"""One machine x instrument of the benchmark, all from refsim (never rotacal's simulator): poses,
the true baseline (location errors, ballbar pivot set-up error, R-test probe zeros), readings,
noise, finite-difference Jacobians of the baseline and of each entry, the half-detection
amplitude, and the rotacal session that carries a draw's readings."""

from __future__ import annotations

import math
import tempfile
import zlib
from pathlib import Path

import numpy as np

import refsim
from refsim import effects as rfx
from refsim import noise as rnoise
from refsim import poses, writers

from . import stats

SIGMA_MM = {
    "ballbar": 5e-4,
    "rtest": 3e-4,
    "probe": 5e-4,
}  # white-equivalent marginal 1-sigma of the readings
PIVOT_SHIFT = np.array([0.012, -0.008, 0.015])  # ballbar pivot set-up error, mm
MOTION_PREFIXES = ("backlash_", "servo_lag_", "reversal_spike_")
# A step for the central differences and the largest plausible size (1 mm, 1 mrad, 1 um/s,
# 1e-3 for ratios) of each kind's parameters, in refsim's units.
_UNIT = {
    "ballbar_length_offset": "mm",
    "ballbar_thermal_drift": "mm/s",
    "tool_offset": "mm",
    "rotary_zero_offset": "rad",
    "angular_positioning": "rad",
    "axial_motion": "mm",
    "radial_motion": "mm",
    "tilt_motion": "rad",
    "gravity_sag": "mm",
    "coning": "ratio",
    "linear_squareness": "rad",
    "linear_scale": "ratio",
    "thermal_drift": "mm/s",
    "thermal_warmup": "mm",
    "straightness": "mm",
    "angular_error": "rad",
    "stylus_radius_offset": "mm",
    "probe_lobing": "mm",
}
_STEP = {"mm": 1e-3, "rad": 1e-5, "mm/s": 1e-5, "ratio": 1e-5}
PLAUSIBLE = {"mm": 1.0, "rad": 1e-3, "mm/s": 1e-3, "ratio": 1e-3}


def stable_int(*parts) -> int:
    return zlib.crc32("|".join(str(p) for p in parts).encode())


def _round_poses(s: dict) -> dict:
    """The precision refsim.writers writes, so that rotacal reads the poses the readings are of."""
    s = dict(s)
    s["time"] = np.round(s["time"], 3)
    s["xyz"] = np.round(s["xyz"], 6)
    s["angles_deg"] = np.round(s["angles_deg"], 6)
    return s


class Setup:
    """Machine x instrument: the truth's baseline, its Jacobian and the rotacal template session."""

    def __init__(self, machine: str, instrument: str, workdir: Path):
        self.name, self.instrument = machine, instrument
        self.machine = refsim.builtin(machine)
        self.sigma = SIGMA_MM[instrument]
        rng = np.random.default_rng(stable_int("baseline", machine))
        self.errors = np.array(
            [rng.uniform(-0.03, 0.03) if i % 4 < 2 else rng.uniform(-8e-5, 8e-5) for i in range(8)]
        )
        self.path, self._template = Path(workdir) / f"{machine}_{instrument}.csv", None
        self._make_poses(rng)
        self.angles = np.radians(self.s["angles_deg"])
        self.base = self.reading({})
        self.j0 = self._baseline_jacobian()
        self.catalogue = self._catalogue()
        self.n_candidates = len(self.catalogue)
        self.q0 = stats.orth(self.j0)

    def _make_poses(self, rng: np.random.Generator) -> None:
        """Poses, labels, noise streams and n of the instrument; the template file of them."""
        if self.instrument == "ballbar":
            pivot = (120.0, 0.0, 60.0) if self.machine.table_axes else (0.0, 0.0, 0.0)
            self.s = _round_poses(poses.ballbar_single_setup(self.machine, pivot=pivot))
            self.labels = list(self.s["test"])
            self.pivot_actual = self.s["pivot"] + PIVOT_SHIFT
            writers.write_ballbar(
                self.path,
                self.machine,
                self.s,
                np.full(len(self.labels), self.s["ballbar_length"]),
                noise_um=self.sigma * 1e3,
            )
            self.streams = [
                np.flatnonzero(np.array(self.labels) == g) for g in dict.fromkeys(self.labels)
            ]
            self.n = len(self.labels)
            return
        nests = (
            ((100.0, 0.0, 60.0), (0.0, -120.0, 140.0))
            if self.machine.table_axes
            else ((100.0, 0.0, 0.0), (0.0, -80.0, 40.0))
        )
        self.s = _round_poses(poses.rtest_grid(self.machine, nests=nests))
        self.labels = list(self.s["setup"])
        self.zeros = {k: rng.uniform(-0.005, 0.005, 3) for k in self.s["nests"]}
        writers.write_rtest(
            self.path,
            self.machine,
            self.s,
            np.zeros((len(self.labels), 3)),
            noise_um=self.sigma * 1e3,
        )
        n = len(self.labels)
        per = [np.flatnonzero(np.array(self.labels) == g) for g in dict.fromkeys(self.labels)]
        self.streams = [c * n + idx for c in range(3) for idx in per]
        self.n = 3 * n

    def _catalogue(self) -> list:
        return rfx.catalogue(self.machine, 4, self.instrument)

    # ----------------------------------------------------------------- readings
    def reading(self, effects: dict, errors=None, pivot_shift=None) -> np.ndarray:
        """Flattened noise-free readings of the truth (+ effects): lengths, or dx.., dy.., dz..
        with the per-nest probe zeros."""
        model = refsim.Model(self.machine, self.errors if errors is None else errors, effects)
        s = self.s
        if self.instrument == "ballbar":
            pivot = self.pivot_actual if pivot_shift is None else self.pivot_actual + pivot_shift
            return refsim.ballbar_lengths(model, pivot, s["xyz"], self.angles, s["time"])
        d = refsim.rtest_displacements(
            model, s["nests"], self.labels, s["xyz"], self.angles, s["time"]
        )
        d = d + np.array([self.zeros[k] for k in self.labels])
        return d.T.reshape(-1)

    def noise(self, kind: str, rng: np.random.Generator) -> np.ndarray:
        """refsim.noise of `kind`, one stream per ballbar test / per R-test set-up and component."""

        def one():
            if kind == "white":
                return rnoise.white(len(self.labels), self.sigma, rng)
            if kind == "pink":
                return rnoise.pink(self.labels, self.sigma, rng)
            return rnoise.ar1(self.labels, float(kind.split("_")[1]), self.sigma, rng)

        if self.instrument == "ballbar":
            return one()
        return np.concatenate([one() for _ in range(3)])

    @property
    def template(self):
        """rotacal's reading of the file refsim wrote (poses, pivot / nests, declared noise)."""
        if self._template is None:
            import rotacal

            self._template = rotacal.load(self.path)
        return self._template

    def session(self, flat: np.ndarray):
        """The rotacal session of the template's poses with these readings."""
        if self.instrument == "ballbar":
            return self.template.with_lengths(np.asarray(flat, float))
        return self.template.with_displacements(np.asarray(flat, float).reshape(3, -1).T.copy())

    # ----------------------------------------------------------------- Jacobians
    def _baseline_jacobian(self) -> np.ndarray:
        """Central differences of refsim: the 8 location errors, then the pivot (ballbar) or the
        probe zeros of each nest (R-test, exact indicator columns)."""
        cols = []
        for k in range(8):
            h = 1e-3 if k % 4 < 2 else 1e-6
            e = np.zeros(8)
            e[k] = h
            cols.append(
                (self.reading({}, self.errors + e) - self.reading({}, self.errors - e)) / (2 * h)
            )
        return np.column_stack(cols + self._nuisance_columns())

    def _nuisance_columns(self) -> list:
        """The ballbar pivot's columns, or the R-test probe zeros' (exact indicators)."""
        cols = []
        if self.instrument == "ballbar":
            for k in range(3):
                d = np.zeros(3)
                d[k] = 1e-3
                cols.append(
                    (self.reading({}, pivot_shift=d) - self.reading({}, pivot_shift=-d)) / 2e-3
                )
            return cols
        n = len(self.labels)
        for key in self.s["nests"]:
            rows = np.array(self.labels) == key
            for c in range(3):
                col = np.zeros(self.n)
                col[c * n : (c + 1) * n][rows] = 1.0
                cols.append(col)
        return cols

    def warmup_tau(self) -> float:
        """thermal_warmup's time constant in every session: a third of the session's duration."""
        return float(self.s["time"][-1]) / 3.0

    def full_params(self, eid: str, p: np.ndarray) -> np.ndarray:
        """refsim parameters of eid from the benchmark's free ones (thermal_warmup: d, tau fixed)."""
        return (
            np.array([p[0], self.warmup_tau()])
            if rfx.parse(eid).kind == "thermal_warmup"
            else np.asarray(p)
        )

    def effect_jacobian(self, eid: str) -> np.ndarray:
        """Central differences of refsim in the entry's parameters at 0 (thermal_warmup: d only)."""
        e = rfx.parse(eid)
        k = 1 if e.kind == "thermal_warmup" else e.num_params
        h = _STEP[_UNIT[e.kind]]
        cols = []
        for j in range(k):
            p = np.zeros(k)
            p[j] = h
            plus = self.reading({eid: self.full_params(eid, p)})
            minus = self.reading({eid: self.full_params(eid, -p)})
            cols.append((plus - minus) / (2 * h))
        return np.column_stack(cols)


def half_detection(setup: Setup, eid: str, je: np.ndarray) -> dict:
    """The entry's half-detection amplitude (see the benchmark's docstring). None when the
    baseline absorbs it or it needs more than a plausible size at 10x."""
    perp = je - setup.q0 @ (setup.q0.T @ je)
    _, sv, vt = np.linalg.svd(perp, full_matrices=False)
    scale = np.linalg.svd(je, compute_uv=False)[0] if je.size else 0.0
    # Directions left with < 1e-3 of their signal are absorbed (what remains of them is second
    # order: the location errors' size times the parameter, and the differences' error).
    k = int(np.sum(sv > 1e-3 * max(scale, 1e-300)))
    unit = _UNIT[rfx.parse(eid).kind]
    out = {
        "entry": eid,
        "k": k,
        "unit": unit,
        "visible_fraction": float(sv[0] / scale) if scale > 0 else 0.0,
        "je_visible": je @ vt[:k].T,
    }
    if k == 0 or sv[0] * PLAUSIBLE[unit] < 1e-3 * setup.sigma:
        return {**out, "a_half": None, "why": "absorbed by the baseline or invisible"}
    need = stats.needed_drop(k, setup.n, setup.q0.shape[1], setup.n_candidates)
    lam = stats.half_detection_lambda(k, need)
    a_half = math.sqrt(lam) * setup.sigma / sv[0]
    u = vt[0] * (1.0 if vt[0][np.argmax(np.abs(vt[0]))] > 0 else -1.0)
    if 10.0 * a_half * np.max(np.abs(u)) > PLAUSIBLE[unit]:
        return {**out, "a_half": None, "why": f"needs {10 * a_half:.3g} {unit} at 10x"}
    return {**out, "a_half": float(a_half), "direction": u.tolist(), "lambda": lam, "need": need}


def motion_only_entries(machine: str) -> list:
    """rotacal's catalogue entries that need a direction of travel (refsim does not model them)."""
    import rotacal

    mt = rotacal.parse_machine_type(machine)
    return sorted(
        e.id
        for e in rotacal.effect_catalogue(mt, 4)
        if e.applies_to(mt) and e.id.startswith(MOTION_PREFIXES)
    )


def tempdir() -> Path:
    return Path(tempfile.mkdtemp(prefix="confusion_"))
