# SPDX-License-Identifier: BSD-3-Clause
"""The experiment as it was run (Flynn et al. Sec. 4), simulated: measure -> identify ->
compensate -> measure again -> identify."""

from __future__ import annotations

import numpy as np

from .. import _core
from .causes import Assumptions, no_change


class Chain:
    """Measure -> identify -> compensate -> measure again -> identify, on a simulated machine."""

    def __init__(self, a: Assumptions, cache: dict | None = None):
        """`cache`: runs shared by the chains of one analysis. Its keys hold what a run depends
        on (set-up, method, machine of each run; for a Monte Carlo draw also the noise and its
        seeds), so scenarios that change only the noise or the interval reuse each other's
        noise-free runs, and those that change only the interval each other's draws."""
        a.check()
        self.a = a
        self.setup = a.setup()
        self.plan = _core.plan_ballbar_test(self.setup, None)
        self.cmd = self.plan.commanded_session()
        self.duration = float(self.cmd.time[-1] - self.cmd.time[0])
        self.pivot = np.asarray(self.setup.pivot, dtype=float)
        self._cache = {} if cache is None else cache
        self._setup_key = (
            float(a.ballbar_length),
            tuple(map(float, a.pivot)),
            tuple(map(float, a.tilt_range_deg)),
            tuple(map(float, a.rot_range_deg)),
            float(a.step_deg),
            a.method,
        )

    def machine(self, truth, run: tuple):
        """The simulated machine of a run: `truth` plus run = (errors delta, effects, pivot delta)."""
        errors, effects, pivot_delta = run
        ids = list(effects.keys())
        return _core.BallbarMachineModel(
            _core.MachineType.AC_trt,
            np.asarray(truth + errors, float),
            self.pivot + pivot_delta,
            ids,
            [v for i in ids for v in effects[i]],
        )

    def _identify_runs(self, machines: list, compensate_for=None, seeds=()) -> np.ndarray:
        """One run per machine in the core (ballbar/chain_runs.hpp): the test (compensated for
        the rows of `compensate_for`, or nominal) played, recorded with AR(1) noise of seed
        seeds[i] (none: noise-free) against the nominal program, identified."""
        a = self.a
        return np.asarray(
            _core.identify_runs(
                self.setup, machines, compensate_for, list(seeds), a.method, a.noise_um, a.noise_rho
            )
        ).reshape(len(machines), 8)

    def _key(self, truth, *runs: tuple) -> tuple:
        """What a noise-free run on these machines depends on (the effects in their order)."""
        return (
            self._setup_key,
            np.asarray(truth, float).tobytes(),
            *(
                (
                    np.asarray(r[0], float).tobytes(),
                    tuple((k, tuple(map(float, v))) for k, v in r[1].items()),
                    np.asarray(r[2], float).tobytes(),
                )
                for r in runs
            ),
        )

    def befores(self, truth, runs1: list[tuple]) -> np.ndarray:
        """Run 1's identified location errors (noise-free) on each machine, one row per run."""
        keys = [("first", *self._key(truth, r)) for r in runs1]
        todo = {k: r for k, r in zip(keys, runs1) if k not in self._cache}
        if todo:
            e1 = self._identify_runs([self.machine(truth, r) for r in todo.values()])
            self._cache.update(zip(todo, e1))
        return np.array([self._cache[k] for k in keys]).reshape(len(runs1), 8)

    def runs(self, truth, pairs: list[tuple]) -> tuple[np.ndarray, np.ndarray]:
        """(before, after) identified location errors (noise-free), one row per (run1, run2) pair;
        run = (errors delta, effects, pivot delta)."""
        e1 = self.befores(truth, [p[0] for p in pairs])
        keys = [("run", *self._key(truth, *p)) for p in pairs]
        todo = {}
        for k, p, e in zip(keys, pairs, e1):
            if k not in self._cache:
                todo[k] = (p[1], e)
        if todo:
            # Pairs in order: runs compensated alike are consecutive and share one plan.
            e2 = self._identify_runs(
                [self.machine(truth, r2) for r2, _ in todo.values()],
                np.array([e for _, e in todo.values()]),
            )
            self._cache.update(zip(todo, e2))
        return e1, np.array([self._cache[k] for k in keys]).reshape(len(pairs), 8)

    def draws(
        self, truth, runs: list[tuple], seeds: list[tuple[int, int]]
    ) -> tuple[np.ndarray, np.ndarray]:
        """(before, after) identified location errors of each Monte Carlo draw: the machine
        truth + runs[k] in both runs, reading noise seeded seeds[k] = (run 1, run 2)."""
        # A draw depends on the noise as well: scenarios that change only the interval (the
        # same causes' sizes, noise and seeds) repeat the first draws of the analysis.
        noise = (float(self.a.noise_um), float(self.a.noise_rho))
        keys = [("draw", *self._key(truth, r), noise, tuple(s)) for r, s in zip(runs, seeds)]
        todo = {k: (r, s) for k, r, s in zip(keys, runs, seeds) if k not in self._cache}
        if todo:
            machines = [self.machine(truth, r) for r, _ in todo.values()]
            e1 = self._identify_runs(machines, None, [s[0] for _, s in todo.values()])
            e2 = self._identify_runs(machines, e1, [s[1] for _, s in todo.values()])
            self._cache.update(zip(todo, zip(e1, e2)))
        return (
            np.array([self._cache[k][0] for k in keys]).reshape(len(runs), 8),
            np.array([self._cache[k][1] for k in keys]).reshape(len(runs), 8),
        )

    def before(self, truth, run1: tuple) -> np.ndarray:
        """Run 1's identified location errors alone (noise-free)."""
        return self.befores(truth, [run1])[0]

    def residuals(self, truth, run1: tuple, run2: tuple):
        """(before, after, run 2's residuals after its identification in um, run 2's test labels),
        noise-free."""
        from ..ballbar import identify

        e1 = self.before(truth, run1)
        program = _core.plan_ballbar_test(self.setup, e1).commanded_session()
        s2 = _core.record_run(
            self.cmd,
            program,
            self.machine(truth, run2),
            None,
            self.a.method,
            self.a.noise_um,
            self.a.noise_rho,
        )
        r2 = identify(s2, self.a.method)
        pred = _core.predict_session_lengths(r2.raw.model, s2)
        e2 = np.array([p.value for p in r2.raw.parameters[:8]])
        return e1, e2, (s2.length - pred) * 1e3, list(s2.tests)

    def truth_for(self, before: np.ndarray) -> np.ndarray:
        """Location errors whose noise-free run 1 identifies `before` (the chain's own bias
        removed by fixed-point iteration)."""
        truth = before.copy()
        for _ in range(3):
            e1 = self.before(truth, no_change(0))
            truth = truth - (e1 - before)
        return truth
