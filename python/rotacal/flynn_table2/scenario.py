# SPDX-License-Identifier: BSD-3-Clause
"""One scenario of the analysis: the Monte Carlo prediction of the after-values, each cause's
response, the one-at-a-time fits and the extended model (greedy, sizes bounded by their
plausible half-widths); and which raw test separates causes the 8 values cannot."""

from __future__ import annotations

import math

import numpy as np

from .. import _core
from .causes import Assumptions, candidates
from .chain import Chain
from .table import SCALE as _SCALE


def _chi2_95(df: int) -> float:
    """95 % quantile of chi2 with df degrees of freedom (Wilson-Hilferty)."""
    if df <= 0:
        return 0.0
    h = 2.0 / (9.0 * df)
    return df * (1.0 - h + 1.6449 * math.sqrt(h)) ** 3


def scenario(
    a: Assumptions,
    before: np.ndarray,
    after: np.ndarray,
    draws: int,
    seed: int,
    max_causes: int,
    want_details: bool,
    cache: dict | None = None,
) -> dict:
    """`cache`: the runs of the analysis' other scenarios (Chain)."""
    ch = Chain(a, cache)
    truth = ch.truth_for(before)
    cands = candidates(a, ch.duration)
    rng = np.random.default_rng(seed)
    const = [c for c in cands if c.kind == "constant"]

    # Prediction: noise in both runs and every constant effect at a random size within its
    # plausible half-width (rectangular), the same in both runs.
    plausible = np.array([c.plausible for c in const])
    runs, seeds = [], []
    for _ in range(draws):
        errs, effs, piv = np.zeros(8), {}, np.zeros(3)
        # The same random stream as one size per cause, then the two runs' noise seeds.
        for c, size in zip(const, rng.uniform(-plausible, plausible)):
            r = c.runs(size)[0]
            errs = errs + r[0]
            piv = piv + r[2]
            for eid, p in r[1].items():
                effs[eid] = [x + y for x, y in zip(effs.get(eid, [0.0] * len(p)), p)]
        runs.append((errs, effs, piv))
        seeds.append((int(rng.integers(0, 2**63)), int(rng.integers(0, 2**63))))
    sims = ch.draws(truth, runs, seeds)[1]
    mean = sims.mean(axis=0)
    std = sims.std(axis=0, ddof=1)
    # Coverage factor k = 2 (about 95 %); the draws are noise-dominated and near-Gaussian.
    lo, hi = mean - 2.0 * std, mean + 2.0 * std
    d = after - mean
    w = 1.0 / std**2

    # Response of the after-values (and of a repeated uncompensated run) to each cause, by a
    # central difference at its plausible size.
    R = np.empty((8, len(cands)))
    Rb = np.zeros((8, len(cands)))
    pairs = [r for c in cands for r in (c.runs(c.plausible), c.runs(-c.plausible))]
    e1, e2 = ch.runs(truth, pairs)
    if want_details:
        # A repeated uncompensated run after the same interval: run 1 on run 2's machine,
        # minus run 1 (zero for a constant effect, the change itself otherwise).
        b2 = ch.befores(truth, [p[1] for p in pairs])
    for j, c in enumerate(cands):
        h = c.plausible
        R[:, j] = (e2[2 * j] - e2[2 * j + 1]) / (2 * h)
        if want_details:
            rp = b2[2 * j] - e1[2 * j]
            rn = b2[2 * j + 1] - e1[2 * j + 1]
            Rb[:, j] = (rp - rn) / (2 * h)

    chi2_0 = float(np.sum(w * d * d))
    rows = []
    for j, c in enumerate(cands):
        r = R[:, j]
        den = float(np.sum(w * r * r))
        reach = np.abs(r) * c.plausible * _SCALE
        if den <= 0 or np.max(reach) < 1e-9:
            rows.append(
                {
                    "c": c,
                    "j": j,
                    "size": 0.0,
                    "size_std": None,
                    "chi2": chi2_0,
                    "chi2_plausible": chi2_0,
                    "reach": reach,
                }
            )
            continue
        s = float(np.sum(w * r * d) / den)
        sp = float(np.clip(s, -c.plausible, c.plausible))
        rows.append(
            {
                "c": c,
                "j": j,
                "size": s,
                "size_std": 1.0 / math.sqrt(den),
                "chi2": float(np.sum(w * (d - s * r) ** 2)),
                "chi2_plausible": float(np.sum(w * (d - sp * r) ** 2)),
                "reach": reach,
            }
        )
    # Rank by what the cause explains at a plausible size, then by what it needs.
    rows.sort(key=lambda x: (x["chi2_plausible"], x["chi2"]))

    # Extended model: greedy forward selection, sizes bounded by their plausible half-widths,
    # a cause kept while it lowers chi2 by more than ln(8) (BIC with 8 values).
    chosen: list[int] = []
    chi2 = chi2_0
    s_sel = np.zeros(0)
    while len(chosen) < max_causes:
        best = None
        for x in rows:
            j = x["j"]
            if j in chosen or x["size_std"] is None:
                continue
            idx = chosen + [j]
            sv = _core.box_least_squares(
                R[:, idx], d, w, np.array([cands[i].plausible for i in idx])
            )
            c2 = float(np.sum(w * (d - R[:, idx] @ sv) ** 2))
            if best is None or c2 < best[0]:
                best = (c2, j, sv)
        # Stop when the deviations are already consistent with the predicted spread (chi2
        # below its 95 % quantile) or the next cause gains less than BIC's ln(8).
        if best is None or chi2 <= _chi2_95(8 - len(chosen)) or chi2 - best[0] <= math.log(8.0):
            break
        chi2, j, s_sel = best
        chosen.append(j)
    ext = R[:, chosen] @ s_sel if chosen else np.zeros(8)

    out = {
        "truth": truth,
        "mean": mean,
        "std": std,
        "lo": lo,
        "hi": hi,
        "d": d,
        "w": w,
        "chi2_0": chi2_0,
        "rows": rows,
        "chosen": chosen,
        "s_sel": s_sel,
        "ext": ext,
        "chi2_ext": chi2,
        "R": R,
        "Rb": Rb,
        "cands": cands,
        "duration": ch.duration,
        "chain": ch,
    }
    return out


def separation(sc: dict, group: list[int]) -> dict:
    """Which test of run 2's raw data tells the causes of `group` apart: each cause at its
    fitted size, run 2's residuals after the paper's identification, RMS difference per test."""
    ch: Chain = sc["chain"]
    res = {}
    for j in group:
        c = sc["cands"][j]
        s = next(x["size"] for x in sc["rows"] if x["j"] == j) or c.plausible
        p1, p2 = c.runs(s)
        res[j] = ch.residuals(sc["truth"], p1, p2)
    tests = res[group[0]][3]
    labels = sorted(set(tests), key=tests.index)
    best = {"test": None, "rms_difference_um": 0.0}
    per = {}
    for lab in labels:
        m = np.array([t == lab for t in tests])
        diffs = [
            float(np.sqrt(np.mean((res[i][2][m] - res[k][2][m]) ** 2)))
            for ii, i in enumerate(group)
            for k in group[ii + 1 :]
        ]
        per[lab] = min(diffs) if diffs else 0.0
        if per[lab] > best["rms_difference_um"]:
            best = {"test": lab, "rms_difference_um": per[lab], "samples": int(m.sum())}
    return {"per_test_rms_difference_um": per, **best}
