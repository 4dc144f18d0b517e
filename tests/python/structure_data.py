# SPDX-License-Identifier: BSD-3-Clause
"""Sessions for "structure is not noise" (issue 50 item 4), made by the independent reference
simulator (tests/reference/refsim, never rotacal's own): an R-test of a B/C table whose C angle
is off by a Gaussian bump (an error outside the catalogue, refsim.effects.gaussian_bump), and
sessions of each instrument with nothing hidden in coloured noise (the null rate)."""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
import refsim  # noqa: E402
from refsim import effects as fx  # noqa: E402
from refsim import noise, poses, writers  # noqa: E402

NESTS = ((100.0, 0.0, 60.0), (0.0, -120.0, 140.0))


def location_errors(machine: str, rng) -> dict:
    """Location errors of tens of um and tens of urad, as a machine after assembly has them."""
    return {
        n: (rng.normal(0, 0.02) if k % 4 < 2 else rng.normal(0, 4e-5))
        for k, n in enumerate(refsim.builtin(machine).error_names())
    }


def _noise(groups, n: int, kind: str, sigma_mm: float, rng) -> np.ndarray:
    """white, ar1 (rho 0.5) or pink (1/f-like), per stream of `groups`."""
    if kind == "white":
        return noise.white(n, sigma_mm, rng)
    if kind == "ar1":
        return noise.ar1(groups, 0.5, sigma_mm, rng)
    if kind == "pink":
        return noise.pink(groups, sigma_mm, rng)
    raise ValueError(f"noise kind {kind!r}: expected white, ar1 or pink")


def rtest(
    path,
    seed: int,
    bump=None,
    kind: str = "white",
    noise_um: float = 0.3,
    nests=NESTS,
    machine: str = "BC-trt",
) -> Path:
    """R-test grid (tilt -90..90 every 30 deg x 12 C angles at each nest), white or coloured noise
    per channel; `bump` = (amplitude rad, centre deg, sigma deg) of the C angle, or None."""
    rng = np.random.default_rng(seed)
    m = refsim.builtin(machine)
    s = poses.rtest_grid(m, nests=nests)
    angle_errors = {"C": fx.gaussian_bump(*bump)} if bump else None
    model = refsim.Model(m, location_errors(machine, rng), None, angle_errors=angle_errors)
    d = refsim.rtest_displacements(
        model, s["nests"], s["setup"], s["xyz"], np.radians(s["angles_deg"]), s["time"]
    )
    zeros = {k: rng.normal(0, 5e-3, 3) for k in s["nests"]}  # each set-up's unknown probe zero
    d = d + np.array([zeros[k] for k in s["setup"]])
    for a in range(3):
        d[:, a] += _noise(s["setup"], len(d), kind, noise_um * 1e-3, rng)
    return writers.write_rtest(path, m, s, d, noise_um=noise_um)


def ballbar(path, seed: int, kind: str = "pink", noise_um: float = 0.5, machine="AC-trt") -> Path:
    """The single set-up's seven tests, nothing hidden, coloured noise per test."""
    rng = np.random.default_rng(seed)
    m = refsim.builtin(machine)
    s = poses.ballbar_single_setup(m, pivot=(120.0, 0.0, 60.0))
    model = refsim.Model(m, location_errors(machine, rng))
    pivot = np.asarray(s["pivot"]) + rng.normal(0, 10e-3, 3)  # the set-up error
    length = refsim.ballbar_lengths(model, pivot, s["xyz"], np.radians(s["angles_deg"]), s["time"])
    length = length + _noise(s["test"], len(length), kind, noise_um * 1e-3, rng)
    return writers.write_ballbar(path, m, s, length, noise_um=noise_um)


def probe(path, seed: int, kind: str = "pink", noise_um: float = 0.5, machine="AC-trt") -> Path:
    """The 24-pose probe set, nothing hidden, coloured noise along the touches."""
    rng = np.random.default_rng(seed)
    m = refsim.builtin(machine)
    s = poses.probe_poses(m)
    actual = s["sphere"] + rng.normal(0, 0.02, 3)  # the set-up error
    latched = refsim.probe_touches(
        refsim.Model(m, location_errors(machine, rng)),
        actual,
        s["sphere"],
        25.0,
        6.0,
        s["n"],
        np.radians(s["angles_deg"]),
        s["time"],
    )
    n = s["n"] / np.linalg.norm(s["n"], axis=1, keepdims=True)
    e = _noise(["touches"] * len(latched), len(latched), kind, noise_um * 1e-3, rng)
    latched = latched + e[:, None] * n  # the noise along each touch's approach
    return writers.write_probe(path, m, s, latched, 25.0, 6.0, noise_um=noise_um)
