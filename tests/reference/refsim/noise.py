# SPDX-License-Identifier: BSD-3-Clause
"""Noise generators (docs/noise_model.md kinds), all from a seeded numpy Generator.

Streams: one per group label (ballbar test, R-test set-up); rows keep their order within a stream.
"""

from __future__ import annotations

import numpy as np


def _streams(groups) -> list[np.ndarray]:
    groups = np.asarray(groups, dtype=object)
    return [np.flatnonzero(groups == g) for g in dict.fromkeys(groups.tolist())]


def white(n: int, sigma: float, rng: np.random.Generator) -> np.ndarray:
    return sigma * rng.standard_normal(n)


def ar1(groups, rho: float, sigma: float, rng: np.random.Generator) -> np.ndarray:
    """Stationary AR(1) per stream, x_t = rho x_{t-1} + e_t, marginal 1-sigma `sigma`."""
    out = np.zeros(len(groups))
    innovation = sigma * np.sqrt(1.0 - rho * rho)
    for idx in _streams(groups):
        x = sigma * rng.standard_normal()
        for i in idx:
            out[i] = x
            x = rho * x + innovation * rng.standard_normal()
    return out


def pink(
    groups, sigma: float, rng: np.random.Generator, taus=(1.0, 10.0, 100.0, 1000.0)
) -> np.ndarray:
    """1/f-like: the sum of equal-variance AR(1)s with correlation times `taus` samples
    (rho = exp(-1/tau)), flat per decade over three decades; total marginal 1-sigma `sigma`."""
    part = sigma / np.sqrt(len(taus))
    return sum(ar1(groups, float(np.exp(-1.0 / t)), part, rng) for t in taus)


def random_walk(groups, step: float, rng: np.random.Generator) -> np.ndarray:
    """Random walk per stream from row to row (an R-test probe zero wandering pose to pose),
    starting at 0, steps N(0, step^2)."""
    out = np.zeros(len(groups))
    for idx in _streams(groups):
        out[idx] = np.cumsum(np.concatenate([[0.0], step * rng.standard_normal(len(idx) - 1)]))
    return out
