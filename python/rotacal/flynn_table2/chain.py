"""The experiment as it was run (Flynn et al. Sec. 4), simulated: measure -> identify ->
compensate -> measure again -> identify."""
from __future__ import annotations

import numpy as np

from .. import _core
from .causes import Assumptions, no_change


class Chain:
    """Measure -> identify -> compensate -> measure again -> identify, on a simulated machine."""

    def __init__(self, a: Assumptions, cache: dict | None = None):
        """`cache`: noise-free runs, shared by the chains of one analysis. Its keys hold what
        a noise-free run depends on (set-up, method, machine of each run), not the noise, so
        scenarios that change only the noise or the interval reuse each other's runs."""
        a.check()
        self.a = a
        self.setup = a.setup()
        self.plan = _core.plan_ballbar_test(self.setup, None)
        self.cmd = self.plan.commanded_session()
        self.duration = float(self.cmd.time[-1] - self.cmd.time[0])
        self.pivot = np.asarray(self.setup.pivot, dtype=float)
        self._cache = {} if cache is None else cache
        self._setup_key = (float(a.ballbar_length), tuple(map(float, a.pivot)), tuple(map(float, a.tilt_range_deg)),
                           tuple(map(float, a.rot_range_deg)), float(a.step_deg), a.method)

    def _model(self, errors, effects: dict, pivot_delta):
        ids = list(effects.keys())
        return _core.BallbarMachineModel(_core.MachineType.AC_trt, np.asarray(errors, float),
                                         self.pivot + pivot_delta, ids, [v for i in ids for v in effects[i]])

    def _noise(self, rng, session) -> np.ndarray:
        """AR(1) noise of marginal sigma noise_um, in mm, per test in time order: the core's
        generator (core/noise_model.hpp, noise_gen::ar1), seeded from ``rng``."""
        seed = int(rng.integers(0, 2**63))
        return np.asarray(_core.noise_ar1(list(session.tests), list(session.time), self.a.noise_rho,
                                          self.a.noise_um * 1e-3, seed))

    def _measure(self, program, model, rng):
        s = _core.simulate_ballbar(program, model, 0.0, 1, False)
        length = s.length + (self._noise(rng, s) if rng is not None else 0.0)
        # The ballbar software holds the nominal program: its xyz, whatever the machine ran.
        return _core.BallbarSession(s.machine, s.ballbar_length, self.cmd.pivot, s.tests, s.time,
                                    self.cmd.xyz, s.angles_deg, length, self.a.noise_um)

    def _identify(self, session):
        from ..ballbar import identify
        r = identify(session, self.a.method)
        return np.array([p.value for p in r.raw.parameters[:8]]), r

    def _key(self, truth, *runs: tuple) -> tuple:
        """What a noise-free run on these machines depends on (the effects in their order)."""
        return (self._setup_key, np.asarray(truth, float).tobytes(),
                *((np.asarray(r[0], float).tobytes(), tuple((k, tuple(map(float, v))) for k, v in r[1].items()),
                   np.asarray(r[2], float).tobytes()) for r in runs))

    def _first(self, truth, run1: tuple, rng):
        """Run 1: its identified location errors and the program compensated for them."""
        key = ("first", *self._key(truth, run1)) if rng is None else None
        if key is not None and key in self._cache:
            return self._cache[key]
        s1 = self._measure(self.cmd, self._model(truth + run1[0], run1[1], run1[2]), rng)
        e1, _ = self._identify(s1)
        out = (e1, _core.plan_ballbar_test(self.setup, e1).commanded_session())
        if key is not None:
            self._cache[key] = out
        return out

    def before(self, truth, run1: tuple) -> np.ndarray:
        """Run 1's identified location errors alone (noise-free)."""
        return self._first(truth, run1, None)[0]

    def run(self, truth, run1: tuple, run2: tuple, rng=None, residuals: bool = False):
        """(before, after) identified location errors; run1/run2 = (errors delta, effects, pivot delta)."""
        key = ("run", *self._key(truth, run1, run2)) if rng is None and not residuals else None
        if key is not None and key in self._cache:
            return self._cache[key]
        e1, program = self._first(truth, run1, rng)
        s2 = self._measure(program, self._model(truth + run2[0], run2[1], run2[2]), rng)
        e2, r2 = self._identify(s2)
        if residuals:
            pred = _core.predict_session_lengths(r2.raw.model, s2)
            return e1, e2, (s2.length - pred) * 1e3, list(s2.tests)
        if key is not None:
            self._cache[key] = (e1, e2)
        return e1, e2

    def truth_for(self, before: np.ndarray) -> np.ndarray:
        """Location errors whose noise-free run 1 identifies `before` (the chain's own bias
        removed by fixed-point iteration)."""
        truth = before.copy()
        for _ in range(3):
            e1 = self.before(truth, no_change(0))
            truth = truth - (e1 - before)
        return truth
