# SPDX-License-Identifier: BSD-3-Clause
"""Python geometric fits (circle, sphere, plane) against an independent SciPy fit, and their typed errors."""

import numpy as np
import pytest
from scipy.optimize import least_squares

import rotacal


def test_circle_fits_match_an_independent_geometric_fit():
    rng = np.random.default_rng(1)
    t = np.linspace(0.2, 2.5, 60)
    p = np.c_[3 + 40 * np.cos(t), -1 + 40 * np.sin(t)] + rng.normal(0, 0.01, (60, 2))
    # SciPy's geometric fit as the independent reference.
    ref = least_squares(lambda c: np.hypot(p[:, 0] - c[0], p[:, 1] - c[1]) - c[2], [0, 0, 30]).x
    f = rotacal.hyper_circle_fit(p, refine=True)
    np.testing.assert_allclose([*f.centre, f.radius], ref, atol=1e-8)
    h = rotacal.hyper_circle_fit(p)
    assert abs(h.radius - ref[2]) < 3 * np.sqrt(h.covariance[2, 2])
    assert f.covariance.shape == (3, 3)


def test_sphere_and_plane():
    rng = np.random.default_rng(2)
    d = rng.normal(size=(200, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    d[:, 2] = np.abs(d[:, 2])
    p = np.array([120.0, 0.0, 60.0]) + 100 * d
    s = rotacal.sphere_fit(p, radius=100.0)
    np.testing.assert_allclose(s.centre, [120, 0, 60], atol=1e-9)
    q = np.c_[rng.uniform(-1, 1, (50, 2)), np.full(50, 5.0)]
    pl = rotacal.svd_plane_fit(q, normal_hint=np.array([0, 0, -1.0]))
    np.testing.assert_allclose(pl.normal, [0, 0, -1], atol=1e-12)


def test_degenerate_input_raises_typed_errors():
    with pytest.raises(rotacal.DegenerateGeometry, match="collinear"):
        rotacal.hyper_circle_fit(np.c_[np.arange(5.0), 2 * np.arange(5.0)])
    with pytest.raises(rotacal.InvalidArgument, match="points"):
        rotacal.sphere_fit(np.zeros((5, 2)))
