# SPDX-License-Identifier: BSD-3-Clause
"""Speed of the joint ballbar fit against a plain SciPy least_squares implementation of the
same model (vectorised numpy), in one process on a shared session, SciPy run as its users run
it: default tolerances, default 2-point finite-difference Jacobian, x_scale="jac". The 1e-12
tolerance setting is a second, labelled row. Median of --repeat runs each (>= 5), timed two
ways: one call of each in turn (every call starts with caches the other left cold), and 5
calls in a row per turn (warm, as in a loop over sessions). Target (issue 14): rotacal at
least 30x faster than the default-tolerance row. Also times the C++ Monte Carlo check (1000
draws).

Usage: python bench/ballbar_speed.py [SESSION.csv] [--repeat N] [--draws N]
       python bench/ballbar_speed.py --smoke   # every timing once, 10 draws: that it runs (CI)
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

import rotacal

ROOT = Path(__file__).resolve().parents[1]


def rotate_about_line(point, direction, theta, q):
    """Rodrigues (Flynn et al. Eq. 1) for many angles at once: q (N,3), theta (N,)."""
    u = direction / np.linalg.norm(direction)
    v = q - point
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    return point + v * c + np.cross(u, v) * s + u * (v @ u)[:, None] * (1 - c)


def residuals(x, xyz, tilt, rot, length):
    e, pivot = x[:8], x[8:]
    a_point, a_dir = np.array([0.0, e[0], e[1]]), np.array([1.0, e[3], -e[2]])  # formats.md, AC-trt
    c_point, c_dir = np.array([e[4], e[5], 0.0]), np.array([e[7], -e[6], 1.0])
    q = np.broadcast_to(pivot, xyz.shape)
    ball = rotate_about_line(a_point, a_dir, tilt, rotate_about_line(c_point, c_dir, rot, q))
    return np.linalg.norm(xyz - ball, axis=1) - length


def scipy_fit(s, tight=False):
    """SciPy as its users run it (default tolerances); tight=True: xtol=ftol=gtol=1e-12."""
    ang = np.radians(s.angles_deg)
    x0 = np.r_[np.zeros(8), s.pivot]
    tol = dict(xtol=1e-12, ftol=1e-12, gtol=1e-12) if tight else {}
    return least_squares(
        residuals, x0, args=(s.xyz, ang[:, 0], ang[:, 1], s.length), x_scale="jac", **tol
    )


def residuals_per_sample(x, rows):
    """The same model written sample by sample in plain Python (math module), as a direct
    transcription of Flynn et al. Eq. 1 often is."""
    e, p = x[:8], x[8:]
    lines = [((0.0, e[0], e[1]), (1.0, e[3], -e[2])), ((e[4], e[5], 0.0), (e[7], -e[6], 1.0))]
    out = []
    for X, Y, Z, A, C, L in rows:
        q = (p[0], p[1], p[2])
        for (a, d), th in ((lines[1], C), (lines[0], A)):  # C first, then the tilt axis
            n = math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
            u = (d[0] / n, d[1] / n, d[2] / n)
            v = (q[0] - a[0], q[1] - a[1], q[2] - a[2])
            c, s_ = math.cos(th), math.sin(th)
            uv = u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
            cr = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
            q = tuple(a[k] + v[k] * c + cr[k] * s_ + u[k] * uv * (1 - c) for k in range(3))
        out.append(math.sqrt((X - q[0]) ** 2 + (Y - q[1]) ** 2 + (Z - q[2]) ** 2) - L)
    return np.array(out)


def scipy_fit_per_sample(s):
    ang = np.radians(s.angles_deg)
    rows = [(*s.xyz[i], ang[i, 0], ang[i, 1], s.length[i]) for i in range(len(s))]
    return least_squares(
        residuals_per_sample,
        np.r_[np.zeros(8), s.pivot],
        args=(rows,),
        x_scale="jac",
        xtol=1e-12,
        ftol=1e-12,
        gtol=1e-12,
    )


def medians_interleaved(fns, repeat, own_thread=(), block=1):
    """Median wall and CPU time of each function over `repeat` rounds, the functions taking turns
    within a round so that a change of machine load hits them alike; and their last results.
    With block > 1 each function runs `block` times in a row per turn (every call is timed):
    its code and data stay in the caches, as in a loop over sessions. With block 1 every call
    starts after the other functions' calls, which leave the caches cold (SciPy's touch MBs).

    CPU time is the whole process' (time.process_time): it counts the BLAS worker threads that
    SciPy's linear algebra wakes. The functions whose index is in `own_thread` compute in the
    calling thread alone (rotacal's C++), and are charged that thread's CPU time
    (time.thread_time): the process' would also count the BLAS threads that go on spinning for
    a while after the previous SciPy call returned (on a quiet machine it gave rotacal 2.4 ms
    CPU for 1.3 ms wall)."""
    wall = [[] for _ in fns]
    cpu = [[] for _ in fns]
    out = [None] * len(fns)
    clocks = [time.thread_time if k in own_thread else time.process_time for k in range(len(fns))]
    for _ in range(repeat):
        for k, fn in enumerate(fns):
            for _ in range(block):
                t0, c0 = time.perf_counter(), clocks[k]()
                out[k] = fn()
                wall[k].append(time.perf_counter() - t0)
                cpu[k].append(clocks[k]() - c0)
    return [(float(np.median(w)), float(np.median(c)), o) for w, c, o in zip(wall, cpu, out)]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument(
        "session", nargs="?", default=str(ROOT.parent / "shared" / "data" / "ballbar_ac_table2.csv")
    )
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--draws", type=int, default=1000)
    ap.add_argument(
        "--smoke", action="store_true", help="every timing once, 10 Monte Carlo draws (no figures)"
    )
    a = ap.parse_args()
    if a.smoke:
        a.repeat, a.draws = 1, 10
    elif a.repeat < 5:
        ap.error("--repeat must be at least 5 (the figures are medians of >= 5 runs)")
    s = rotacal.load(a.session)
    rotacal.identify(s)  # warm-up: first call pays for imports and allocations
    (t_rc, c_rc, r), (t_sp, c_sp, sp), (t_tight, c_tight, tight) = medians_interleaved(
        [lambda: rotacal.identify(s), lambda: scipy_fit(s), lambda: scipy_fit(s, tight=True)],
        a.repeat,
        own_thread=(0,),
    )
    (t_rc_w, c_rc_w, _), (t_sp_w, c_sp_w, _) = medians_interleaved(
        [lambda: rotacal.identify(s), lambda: scipy_fit(s)], a.repeat, own_thread=(0,), block=5
    )
    ((t_loop, c_loop, loop),) = medians_interleaved([lambda: scipy_fit_per_sample(s)], 1)
    ((t_mc, c_mc, mc),) = medians_interleaved(
        [lambda: rotacal._core.monte_carlo_joint(s, r.raw, a.draws)], 1, own_thread=(0,)
    )
    d = r.to_dict()
    names = list(d["location_errors"])

    def worst(x):
        return max(
            abs(x[k] - d["location_errors"][n]["value"]) / d["location_errors"][n]["std"]
            for k, n in enumerate(names)
        )

    summary = r.raw.summary
    print(
        f"ballbar_speed: {Path(a.session).name}, {len(s)} samples, median of {a.repeat} runs each (wall; CPU)"
    )
    print(
        f"  rotacal joint fit (+ covariance and observability), {summary.jacobian_evaluations} Jacobian "
        f"+ {summary.residual_evaluations} residual evaluations: {t_rc * 1e3:8.2f} ms; {c_rc * 1e3:.2f} ms"
    )
    print(
        f"  SciPy least_squares, default tolerances (2-point Jacobian, x_scale='jac'):     "
        f"{t_sp * 1e3:8.2f} ms; {c_sp * 1e3:.2f} ms ({sp.nfev} evaluations)"
    )
    print(
        f"  SciPy least_squares, xtol=ftol=gtol=1e-12 (second row):                       "
        f"{t_tight * 1e3:8.2f} ms; {c_tight * 1e3:.2f} ms ({tight.nfev} evaluations)"
    )
    print(
        f"  SciPy least_squares, the model sample by sample in plain Python (one run):    "
        f"{t_loop * 1e3:8.2f} ms ({loop.nfev} evaluations)"
    )
    print(
        f"  speed-up over SciPy with default tolerances, one call each in turn: {t_sp / t_rc:.1f}x wall, "
        f"{c_sp / c_rc:.1f}x CPU (target >= 30x); over 1e-12: {t_tight / t_rc:.1f}x; over the per-sample "
        f"model: {t_loop / t_rc:.0f}x"
    )
    print(
        f"  the same, 5 calls in a row per turn (warm caches, as in a loop over sessions): rotacal "
        f"{t_rc_w * 1e3:.2f} ms, SciPy {t_sp_w * 1e3:.2f} ms: {t_sp_w / t_rc_w:.1f}x wall, "
        f"{c_sp_w / c_rc_w:.1f}x CPU (target >= 30x)"
    )
    print(
        f"  largest difference between the solutions: default {worst(sp.x):.4f} sigma, "
        f"1e-12 {worst(tight.x):.5f} sigma"
    )
    ratios = [p.ratio for p in mc.parameters]
    print(
        f"  Monte Carlo check in C++, {a.draws} draws: {t_mc:.2f} s wall, {c_mc:.2f} s CPU "
        f"(target <= 3 s); sigma_MC / sigma_reported {min(ratios):.2f}-{max(ratios):.2f}"
    )


if __name__ == "__main__":
    main()
