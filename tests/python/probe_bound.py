# SPDX-License-Identifier: BSD-3-Clause
"""How small the touch probe's largest expanded uncertainty (k = 2) of the location errors can
get at a number of touches, whatever the design (docs/design.md, "Touch probe"), from the
reference simulator alone (tests/reference/refsim, no rotacal import).

A touch along the unit direction n at a rotary pose reads the sphere's centre relative to the
stylus tip along n, so its row of the Jacobian is n^T G, G (3 x p) the derivative of that
relative position in machine axes with respect to the fit's parameters (the 8 location errors,
tool_offset_Z on a head, the sphere's centre; on a head its z is held, as the fit holds it:
E_Z0B, tool_offset_Z and sphere z move the touches in one combination alike). G is taken by
central differences of refsim.probe_touches along the three machine axes.

`minimax_bound` finds a continuous allocation of touches over candidates minimising the largest
scaled variance (an upper value: a design that reaches it) and certifies a lower bound that no
allocation of the same number of touches, integer or not, can beat: for weights lam over the
errors, phi(M) = sum lam_j s_j^2 (M^-1)_jj, and for every design M' of T touches
phi(M') >= phi(M)^2 / (T max_k d_k), d_k = tr(I_k M^-1 L M^-1) the derivative along candidate k
(Cauchy-Schwarz on tr(L M'^-1) tr(M^-1 L M^-1 M')); the largest variance is >= phi(M'). With
`any_direction`, each pose may be touched along any direction, touch by touch: d_k is then the
largest eigenvalue of G_k M^-1 L M^-1 G_k^T, the derivative along the best direction of that pose.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
import refsim  # noqa: E402
from refsim import poses as refposes  # noqa: E402
from refsim.instruments import _spindle_frame_dirs  # noqa: E402  (the nominal head's rotation)

SIGMA_MM = 0.5e-3
# Touch directions the inner search may use when every touch has its own (n and -n inform
# alike): the axes, the face and the body diagonals. The bound holds for every direction.
SEARCH_DIRECTIONS = np.array(
    [
        (1, 0, 0),
        (0, 1, 0),
        (0, 0, 1),
        (1, 1, 0),
        (1, -1, 0),
        (1, 0, 1),
        (1, 0, -1),
        (0, 1, 1),
        (0, 1, -1),
        (1, 1, 1),
        (1, 1, -1),
        (1, -1, 1),
        (-1, 1, 1),
    ],
    float,
)
SEARCH_DIRECTIONS /= np.linalg.norm(SEARCH_DIRECTIONS, axis=1, keepdims=True)


def sensitivities(machine: str, poses_deg, sphere) -> tuple[np.ndarray, list[str]]:
    """G (P, 3, p) per pose (tilt, rotary; deg) and the parameter names; mm per mm or rad."""
    m = refsim.load_machine(machine)
    i_tilt, i_rot = refposes.rotary_roles(m)
    head = any(a.side == "head" for a in m.axes)
    sphere = np.asarray(sphere, float)
    angles, n = [], []
    for tilt, rot in poses_deg:
        for d in -np.eye(3):
            a = np.zeros(2)
            a[i_tilt], a[i_rot] = tilt, rot
            angles.append(a)
            n.append(d)
    angles, n = np.radians(np.array(angles)), np.array(n)
    time = np.zeros(len(n))

    def reading(errors: dict, effects: dict, actual) -> np.ndarray:
        model = refsim.Model(m, errors, effects)
        return -np.einsum(
            "ij,ij->i", refsim.probe_touches(model, actual, sphere, 25.0, 6.0, n, angles, time), n
        )

    names = list(m.error_names())
    cols = []
    for name in names:
        h = 1e-6 if name[2] in "ABC" else 1e-4
        cols.append((reading({name: h}, {}, sphere) - reading({name: -h}, {}, sphere)) / (2 * h))
    if head:
        names.append("tool_offset_Z")
        cols.append(
            (
                reading({}, {"tool_offset_Z": [1e-4]}, sphere)
                - reading({}, {"tool_offset_Z": [-1e-4]}, sphere)
            )
            / 2e-4
        )
    for k in range(2 if head else 3):
        e = np.zeros(3)
        e[k] = 1e-4
        names.append("sphere." + "xyz"[k])
        cols.append((reading({}, {}, sphere + e) - reading({}, {}, sphere - e)) / 2e-4)
    return np.column_stack(cols).reshape(len(poses_deg), 3, len(names)), names


def scales(names: list[str]) -> np.ndarray:
    """um of 2 sigma per unit of each location error (the first 8): rad x 100 mm, mm. Orientation
    errors: E_A0C-like (about an axis) and E_DU0B-like (a direction error of an inclined axis)."""
    return np.array([2e5 if nm[2] in "ABC" or nm.startswith("E_D") else 2e3 for nm in names[:8]])


def largest_u_um(info: np.ndarray, names: list[str]) -> tuple[float, str]:
    """The largest 2 sigma (um) of the location errors of information `info` and its name."""
    u = np.sqrt(np.diag(np.linalg.inv(info))[:8]) * scales(names)
    return float(u.max()), names[int(np.argmax(u))]


def pattern_information(G: np.ndarray, directions) -> np.ndarray:
    """J^T J / sigma^2 of every pose of G touched once along each direction."""
    D = sum(np.outer(d, d) for d in np.asarray(directions, float))
    return np.einsum("kai,ab,kbj->ij", G, D, G) / SIGMA_MM**2


def contact_directions(
    machine: str, tilt: float, rot: float, max_angle: float = 80.0, step: float = 30.0
) -> np.ndarray:
    """Approach directions (machine frame) whose contact point lies within `max_angle` deg of the
    stylus axis (the spindle's +z turned by refsim's nominal head) at a pose (deg): polar angles
    0, step, ... and max_angle, azimuth every 45 deg in the spindle's frame (the design's
    candidates, docs/design.md)."""
    m = refsim.load_machine(machine)
    i_tilt, i_rot = refposes.rotary_roles(m)
    a = np.zeros((3, 2))
    a[:, i_tilt], a[:, i_rot] = np.radians(tilt), np.radians(rot)
    H = _spindle_frame_dirs(refsim.Model(m, {}, {}), np.eye(3), a)  # row k: H^T e_k, i.e. H's row k
    out = []
    for th in list(np.arange(0.0, max_angle - 1e-9, step)) + [max_angle]:
        for phi in np.radians(np.arange(0.0, 360.0, 45.0)) if th > 0 else [0.0]:
            t = np.radians(th)
            out.append(
                -(H @ np.array([np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), np.cos(t)]))
            )
    return np.array(out)


def candidate_information(
    G: np.ndarray, touches: int, directions=None, touch_directions=None
) -> tuple[np.ndarray, float]:
    """The information of one run of each candidate and the number of runs: a pose of G touched
    once along each of `directions`, or (None) one touch along one of SEARCH_DIRECTIONS, or one
    touch along one of touch_directions[k] (per pose) when given."""
    if touch_directions is not None:
        rows = np.concatenate(
            [np.asarray(dd, float) @ G[k] for k, dd in enumerate(touch_directions)]
        )
        return np.einsum("ki,kj->kij", rows, rows) / SIGMA_MM**2, float(touches)
    if directions is None:
        rows = np.einsum("da,kaj->kdj", SEARCH_DIRECTIONS, G).reshape(-1, G.shape[2])
        return np.einsum("ki,kj->kij", rows, rows) / SIGMA_MM**2, float(touches)
    D = sum(np.outer(d, d) for d in np.asarray(directions, float))
    return np.einsum("kai,ab,kbj->kij", G, D, G) / SIGMA_MM**2, touches / len(directions)


def minimax_bound(
    G: np.ndarray,
    names: list[str],
    touches: int,
    directions=None,
    iterations: int = 300,
    touch_directions=None,
):
    """(U reached by a continuous design, certified lower bound on U, the design's runs per
    candidate) in um over every allocation of `touches` touches to the poses of G: each visit
    touched once along each of `directions`, or (None) each touch along any direction of its own,
    or along one of touch_directions[k] at pose k when given."""
    info, runs = candidate_information(G, touches, directions, touch_directions)
    s2 = scales(names) ** 2
    w = np.full(len(info), runs / len(info))
    lam = np.full(8, 1.0 / 8)
    upper, lower, best = np.inf, 0.0, w
    for _ in range(iterations):
        for _ in range(40):  # the multiplicative algorithm for the weighted A-criterion
            C = np.linalg.inv(np.einsum("k,kij->ij", w, info))
            A = C[:, :8] @ np.diag(lam * s2) @ C[:8, :]
            d = np.einsum("kij,ij->k", info, A)
            w = w * np.sqrt(d / (w @ d / runs))
            w *= runs / w.sum()
        C = np.linalg.inv(np.einsum("k,kij->ij", w, info))
        v = np.diag(C)[:8] * s2
        A = C[:, :8] @ np.diag(lam * s2) @ C[:8, :]
        if (
            directions is None and touch_directions is None
        ):  # the best direction of each pose, per touch
            dmax = max(np.linalg.eigvalsh(g @ A @ g.T)[-1] for g in G) / SIGMA_MM**2
        else:
            dmax = np.einsum("kij,ij->k", info, A).max()
        lower = max(lower, (lam @ v) ** 2 / (runs * dmax))
        if v.max() < upper:
            upper, best = v.max(), w.copy()
        lam = lam * np.exp(2.0 * (v / v.max() - 1.0))
        lam /= lam.sum()
    return float(np.sqrt(upper)), float(np.sqrt(lower)), best


def rounded_u_um(
    G: np.ndarray, names: list[str], touches: int, weights: np.ndarray, directions=None
) -> float:
    """The largest U (um) of the continuous design `weights` rounded to whole runs (Pukelsheim and
    Rieder's efficient rounding on its support), then single runs moved between its candidates
    while that decreases."""
    info, runs = candidate_information(G, touches, directions)
    support = np.where(weights > 1e-3 * runs / len(weights))[0]
    share = weights[support] / weights[support].sum()
    n = np.ceil((round(runs) - len(support) / 2) * share).astype(int)
    while n.sum() != round(runs):
        j = np.argmin(n / share) if n.sum() < runs else np.argmax((n - 1) / share)
        n[j] += 1 if n.sum() < runs else -1
    s2 = scales(names) ** 2

    def u(counts):
        M = np.einsum("k,kij->ij", counts, info[support])
        return (
            np.sqrt((np.diag(np.linalg.inv(M))[:8] * s2).max())
            if np.linalg.cond(M) < 1e14
            else np.inf
        )

    def better_move() -> bool:  # the first single run moved that lowers the value, made
        nonlocal value
        for i in np.where(n > 0)[0]:
            for j in range(len(support)):
                if i == j:
                    continue
                n[i] -= 1
                n[j] += 1
                if u(n) < value - 1e-12:
                    value = u(n)
                    return True
                n[i] += 1
                n[j] -= 1
        return False

    value = u(n)
    while better_move():
        pass
    return float(value)


def grid(
    machine: str, tilt_step: float = 15.0, rot_step: float = 30.0, tilt_limit: float = 90.0
) -> list:
    """Candidate poses (tilt, rotary), deg: rotacal design probe's grid over a full turn."""
    m = refsim.load_machine(machine)
    lim = m.axes[refposes.rotary_roles(m)[0]].limits_deg or (-90.0, 90.0)
    t0, t1 = max(lim[0], -tilt_limit), min(lim[1], tilt_limit)
    tilts = np.arange(t0, t1 + 1e-9, tilt_step)
    return [(t, r) for t in tilts for r in np.arange(0.0, 360.0 - 1e-9, rot_step)]


def default_poses(machine: str) -> np.ndarray:
    """refsim's default poses (tilt, rotary), one row per pose."""
    p = np.asarray(refposes.probe_poses(machine)["angles_deg"])[::5]
    i_tilt, i_rot = refposes.rotary_roles(refsim.load_machine(machine))
    return p[:, [i_tilt, i_rot]]
