"""Speed of the joint ballbar fit against a plain SciPy least_squares implementation of the
same model (vectorised numpy, SciPy's default finite-difference Jacobian), in one run on a
shared session. Target: rotacal at least 30x faster.

Usage: python bench/ballbar_speed.py [SESSION.csv] [--repeat N]
"""
from __future__ import annotations

import argparse
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
    d = r.to_dict()
    names = list(d["location_errors"])
    worst = max(abs(sp.x[k] - d["location_errors"][n]["value"]) / d["location_errors"][n]["std"]
                for k, n in enumerate(names))
    print(f"ballbar_speed: {Path(a.session).name}, {len(s)} samples, best of {a.repeat}")
    print(f"  rotacal joint fit (Ceres, autodiff, + covariance and observability): {t_rc * 1e3:8.1f} ms")
    print(f"  SciPy least_squares (numpy model, finite-difference Jacobian):      {t_sp * 1e3:8.1f} ms "
          f"({sp.nfev} evaluations)")
    print(f"  speed-up: {t_sp / t_rc:.1f}x (target >= 30x); largest difference between the two "
          f"solutions: {worst:.3f} sigma")


if __name__ == "__main__":
    main()
