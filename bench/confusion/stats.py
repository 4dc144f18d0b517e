# SPDX-License-Identifier: BSD-3-Clause
"""Statistics of the benchmark (numpy + math only): F distribution, the decision thresholds of
rotacal's DiagnosisOptions, the half-detection noncentrality, noise covariances and whitening,
and the GLS oracle."""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

ALPHA = 0.01  # DiagnosisOptions.alpha (family-wise, Bonferroni over the candidates)
MIN_DELTA_BIC = -10.0  # DiagnosisOptions.min_delta_bic

# noise kind -> [(variance fraction, AR(1) rho)] as refsim.noise makes them (pink: 4 AR(1)s of equal
# variance, rho = exp(-1/tau), tau = 1, 10, 100, 1000 samples).
NOISE_KINDS = {
    "white": [(1.0, 0.0)],
    "ar1_0.5": [(1.0, 0.5)],
    "ar1_0.9": [(1.0, 0.9)],
    "pink": [(0.25, math.exp(-1.0 / t)) for t in (1.0, 10.0, 100.0, 1000.0)],
}


def _betacf(a: float, b: float, x: float) -> float:
    """Continued fraction of the regularized incomplete beta function (Lentz)."""
    tiny = 1e-300
    qab, qap, qam = a + b, a + 1.0, a - 1.0
    c, d = 1.0, 1.0 - qab * x / qap
    d = 1.0 / (d if abs(d) > tiny else tiny)
    h = d
    for m in range(1, 400):
        m2 = 2 * m
        aa = m * (b - m) * x / ((qam + m2) * (a + m2))
        d = 1.0 + aa * d
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + aa / c if abs(1.0 + aa / c) > tiny else tiny
        h *= d * c
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))
        d = 1.0 + aa * d
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + aa / c if abs(1.0 + aa / c) > tiny else tiny
        de = d * c
        h *= de
        if abs(de - 1.0) < 1e-14:
            break
    return h


def betainc(a: float, b: float, x: float) -> float:
    """Regularized incomplete beta I_x(a, b)."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    lbt = (
        math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b) + a * math.log(x) + b * math.log1p(-x)
    )
    if x < (a + 1.0) / (a + b + 2.0):
        return math.exp(lbt) * _betacf(a, b, x) / a
    return 1.0 - math.exp(lbt) * _betacf(b, a, 1.0 - x) / b


def f_sf(f: float, d1: float, d2: float) -> float:
    """P(F(d1, d2) > f)."""
    if f <= 0.0:
        return 1.0
    return betainc(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f))


@lru_cache(maxsize=None)
def f_crit(d1: int, d2: int, p: float) -> float:
    """f with P(F(d1, d2) > f) = p, by bisection."""
    lo, hi = 0.0, 1.0
    while f_sf(hi, d1, d2) > p:
        hi *= 2.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f_sf(mid, d1, d2) > p else (lo, mid)
    return 0.5 * (lo + hi)


def needed_drop(k: int, n: int, p: int, n_candidates: int) -> float:
    """Chi-square drop (whitened, unit variance) that passes both of rotacal's tests for a
    k-parameter extension: the F-test at alpha / n_candidates and delta BIC < -10."""
    f_test = k * f_crit(k, n - p - k, ALPHA / n_candidates)
    bic = -MIN_DELTA_BIC + k * math.log(n)
    return max(f_test, bic)


@lru_cache(maxsize=None)
def half_detection_lambda(k: int, need: float, draws: int = 40000) -> float:
    """Noncentrality lambda at which a noncentral chi2(k, lambda) exceeds `need` half the time
    (Monte Carlo with fixed draws, bisection)."""
    z = np.random.default_rng(12345).standard_normal((draws, k))
    rest = np.sum(z[:, 1:] ** 2, axis=1)
    lo, hi = 0.0, 4.0 * need + 50.0
    for _ in range(60):
        lam = 0.5 * (lo + hi)
        hit = np.mean((z[:, 0] + math.sqrt(lam)) ** 2 + rest > need)
        lo, hi = (lam, hi) if hit < 0.5 else (lo, lam)
    return 0.5 * (lo + hi)


@lru_cache(maxsize=None)
def _stream_whitener(length: int, kind: str) -> np.ndarray:
    """inv(chol(Sigma)) of one stream of `length` rows, Sigma in units of the marginal variance."""
    lag = np.abs(np.subtract.outer(np.arange(length), np.arange(length)))
    cov = sum(
        f * (rho**lag if rho > 0 else (lag == 0).astype(float)) for f, rho in NOISE_KINDS[kind]
    )
    chol = np.linalg.cholesky(cov)
    return np.linalg.inv(chol)


class Whitener:
    """Whitening by the true noise covariance of the streams (lists of row indices, time order)."""

    def __init__(self, streams: list, kind: str, sigma: float):
        self.streams, self.kind, self.sigma = streams, kind, sigma

    def apply(self, x: np.ndarray) -> np.ndarray:
        out = np.empty_like(x, dtype=float)
        for idx in self.streams:
            out[idx] = _stream_whitener(len(idx), self.kind) @ x[idx]
        return out / self.sigma


def orth(a: np.ndarray, rtol: float = 1e-9) -> np.ndarray:
    """Orthonormal basis of the column space of a (numerical rank)."""
    u, s, _ = np.linalg.svd(a, full_matrices=False)
    return u[:, s > rtol * (s[0] if s.size and s[0] > 0 else 1.0)]


class Oracle:
    """GLS with the true noise covariance: the baseline alone against the baseline and the true
    effect's k columns; detection by rotacal's thresholds (F-test at alpha / candidates,
    delta BIC < -10, BIC = chi2 + (number of parameters) ln n with the covariance known)."""

    def __init__(self, whitener: Whitener, j0: np.ndarray, je: np.ndarray, n_candidates: int):
        self.w = whitener
        self.q0 = orth(whitener.apply(j0))
        self.q1 = orth(np.hstack([whitener.apply(j0), whitener.apply(je)]))
        self.k = self.q1.shape[1] - self.q0.shape[1]
        self.n = j0.shape[0]
        self.n_candidates = n_candidates

    def detects(self, r: np.ndarray) -> bool:
        """r: reading minus the truth's baseline reading (no effect), flattened."""
        if self.k <= 0:
            return False
        rw = self.w.apply(r)
        rr = float(rw @ rw)
        chi0 = rr - float(np.sum((self.q0.T @ rw) ** 2))
        chi1 = rr - float(np.sum((self.q1.T @ rw) ** 2))
        drop = chi0 - chi1
        d2 = self.n - self.q1.shape[1]
        f = (drop / self.k) / max(chi1 / d2, 1e-300)
        p = f_sf(f, self.k, d2)
        return p < ALPHA / self.n_candidates and -drop + self.k * math.log(self.n) < MIN_DELTA_BIC


class TrueGls:
    """The effect's parameters by GLS with the true noise covariance on J0 + Je (all its
    parameters, refsim's units): the best a diagnosis that knew the noise could report, on the
    same readings. None where the baseline absorbs a direction of Je (`visible` < Je's columns,
    as the half-detection amplitude counts them: the parameters are not all determined) and for
    thermal_warmup (d only, tau known)."""

    def __init__(self, whitener: Whitener, j0: np.ndarray, je: np.ndarray, visible: int):
        self.w = whitener
        x = np.hstack([whitener.apply(j0), whitener.apply(je)])
        k = je.shape[1]
        self.ok = visible == k
        self.cov = np.linalg.pinv(x.T @ x)
        self.x, self.k = x, k

    def z(self, r: np.ndarray, truth: np.ndarray) -> list | None:
        """(estimate - truth) / sigma per parameter; r: reading minus the truth's baseline reading."""
        if not self.ok:
            return None
        b = (self.cov @ (self.x.T @ self.w.apply(r)))[-self.k :]
        return [float(v) for v in (b - truth) / np.sqrt(np.diag(self.cov)[-self.k :])]
