"""Speed of the joint ballbar fit against a plain SciPy least_squares implementation of the
same model (vectorised numpy, SciPy's default finite-difference Jacobian), in one run on a
shared session. Target: rotacal at least 30x faster.

Usage: python bench/ballbar_speed.py [SESSION.csv] [--repeat N]
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
    a_point, a_dir = np.array([0.0, e[0], e[1]]), np.array([1.0, e[3], -e[2]])      # formats.md, AC-trt
    c_point, c_dir = np.array([e[4], e[5], 0.0]), np.array([e[7], -e[6], 1.0])
    q = np.broadcast_to(pivot, xyz.shape)
    ball = rotate_about_line(a_point, a_dir, tilt, rotate_about_line(c_point, c_dir, rot, q))
    return np.linalg.norm(xyz - ball, axis=1) - length


def scipy_fit(s):
    ang = np.radians(s.angles_deg)
    x0 = np.r_[np.zeros(8), s.pivot]
    return least_squares(residuals, x0, args=(s.xyz, ang[:, 0], ang[:, 1], s.length), x_scale="jac",
                         xtol=1e-12, ftol=1e-12, gtol=1e-12)


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
    return least_squares(residuals_per_sample, np.r_[np.zeros(8), s.pivot], args=(rows,), x_scale="jac",
                         xtol=1e-12, ftol=1e-12, gtol=1e-12)


def best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("session", nargs="?", default=str(ROOT.parent / "shared" / "data" / "ballbar_ac_table2.csv"))
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    s = rotacal.load(a.session)
    t_rc, r = best_of(lambda: rotacal.identify(s), a.repeat)
    t_sp, sp = best_of(lambda: scipy_fit(s), a.repeat)
    t_loop, loop = best_of(lambda: scipy_fit_per_sample(s), 1)
    d = r.to_dict()
    names = list(d["location_errors"])
    worst = max(abs(sp.x[k] - d["location_errors"][n]["value"]) / d["location_errors"][n]["std"]
                for k, n in enumerate(names))
    print(f"ballbar_speed: {Path(a.session).name}, {len(s)} samples, best of {a.repeat}")
    print(f"  rotacal joint fit (Ceres, autodiff, + covariance and observability): {t_rc * 1e3:8.1f} ms")
    print(f"  SciPy least_squares (numpy model, finite-difference Jacobian):      {t_sp * 1e3:8.1f} ms "
          f"({sp.nfev} evaluations)")
    print(f"  SciPy least_squares, the model sample by sample in plain Python:   {t_loop * 1e3:8.1f} ms "
          f"({loop.nfev} evaluations, one run)")
    print(f"  speed-up: {t_sp / t_rc:.1f}x over the vectorised numpy model, {t_loop / t_rc:.0f}x over the "
          f"per-sample one (target >= 30x); largest difference between the solutions: {worst:.3f} sigma")


if __name__ == "__main__":
    main()
