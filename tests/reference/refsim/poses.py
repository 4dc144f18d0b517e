# SPDX-License-Identifier: BSD-3-Clause
"""Simple, explicit pose sets for the tests (not rotacal's planner).

- ballbar: Flynn et al.'s single set-up (sphere_xy/yz/zx arcs at rotary 0, radial_R / axial_R
  of both axes), planned in the table frame and turned into X, Y, Z by the nominal machine;
- R-test: tilt axis outer x rotary axis inner grid, every pose at each nest;
- probe: a C sweep at tilt 0 and a tilt sweep at C 0, 5 touches per pose.
Each returns a dict of arrays: time (N,), xyz (N, 3), angles_deg (N, 2) in chain order, plus
labels (ballbar tests, R-test set-ups, probe poses); probe also n (N, 3).
"""

from __future__ import annotations

import numpy as np

from .kinematics import Model
from .machines import load_machine, unit


def rotary_roles(machine) -> tuple[int, int]:
    """(index of the tilt axis, index of the rotary (C) axis) in chain order."""
    tilt = [a.name for a in machine.tilt_axes()]
    names = machine.axis_names
    i_tilt = names.index(tilt[0])
    return i_tilt, 1 - i_tilt


def default_tilt_range(machine) -> tuple[float, float]:
    """-90..90 deg clipped to the tilt axis' limits (docs/machines.md)."""
    lim = machine.axes[rotary_roles(machine)[0]].limits_deg or (-90.0, 90.0)
    return max(-90.0, lim[0]), min(90.0, lim[1])


def _xyz_for(model: Model, q_table: np.ndarray, angles_rad: np.ndarray) -> np.ndarray:
    """Commanded X, Y, Z that put the ball at table point q at the given angles, nominally."""
    p = model.p_table(
        np.broadcast_to(q_table, (len(angles_rad), 3)), angles_rad, np.zeros(len(angles_rad))
    )
    return model.commanded_xyz(p, angles_rad)


def _radial_direction(axis, pivot: np.ndarray) -> np.ndarray:
    """Table axis: from its line through the pivot; head axis: n x Z (X for a vertical axis)."""
    n = axis.direction
    if axis.side == "table":
        r = pivot - axis.point
        r = r - (r @ n) * n
        return unit(r)
    c = np.cross(n, [0.0, 0.0, 1.0])
    return unit(c) if np.linalg.norm(c) > 1e-9 else np.array([1.0, 0.0, 0.0])


def ballbar_single_setup(
    machine,
    pivot=(120.0, 0.0, 60.0),
    length: float = 100.0,
    step_deg: float = 1.0,
    dt: float = 1.0 / 6.0,
    axial_c_tilt_deg: float | None = None,
) -> dict:
    """The seven tests of the single set-up method, one after the other in time."""
    machine = load_machine(machine)
    nominal = Model(machine)
    pivot = np.asarray(pivot, float)
    i_tilt, i_rot = rotary_roles(machine)
    if axial_c_tilt_deg is None:
        axial_c_tilt_deg = 45.0 if not machine.table_axes else 0.0  # head-head: off the C line
    labels, xyz, ang = [], [], []

    def add(label, q_tool, angles_deg):
        a = np.asarray(angles_deg, float)
        labels.extend([label] * len(a))
        xyz.append(_xyz_for(nominal, np.asarray(q_tool, float), np.radians(a)))
        ang.append(a)

    def arc(label, i, j, stop):
        phi = np.radians(np.arange(0.0, stop + 1e-9, step_deg))
        q = np.tile(pivot, (len(phi), 1))
        q[:, i] += length * np.cos(phi)
        q[:, j] += length * np.sin(phi)
        for k in range(len(phi)):
            add(label, q[k], [[0.0, 0.0]])

    arc("sphere_xy", 0, 1, 360.0 - step_deg)
    arc("sphere_yz", 1, 2, 180.0)
    arc("sphere_zx", 0, 2, 180.0)
    t0, t1 = default_tilt_range(machine)
    sweeps = {
        i_tilt: np.arange(t0, t1 + 1e-9, step_deg),
        i_rot: np.arange(0.0, 360.0 - 1e-9, step_deg),
    }
    for idx in (i_tilt, i_rot):
        axis = machine.axes[idx]
        for kind in ("radial", "axial"):
            a = np.zeros((len(sweeps[idx]), 2))
            a[:, idx] = sweeps[idx]
            if kind == "axial" and idx == i_rot:
                a[:, i_tilt] = axial_c_tilt_deg
            d = _radial_direction(axis, pivot) if kind == "radial" else axis.direction
            add(f"{kind}_{axis.name}", pivot + length * d, a)
    xyz = np.vstack(xyz)
    return {
        "test": labels,
        "time": dt * np.arange(len(xyz)),
        "xyz": xyz,
        "angles_deg": np.vstack(ang),
        "pivot": pivot,
        "ballbar_length": length,
    }


def rtest_grid(
    machine,
    nests=((100.0, 0.0, 60.0), (0.0, -120.0, 140.0)),
    tilt_step: float = 30.0,
    rot_step: float = 30.0,
    dwell_s: float = 6.0,
) -> dict:
    """Tilt outer, rotary inner; one set-up per nest, one after the other (Oyama's pattern)."""
    machine = load_machine(machine)
    nominal = Model(machine)
    i_tilt, i_rot = rotary_roles(machine)
    t0, t1 = default_tilt_range(machine)
    grid = [
        (b, c)
        for b in np.arange(t0, t1 + 1e-9, tilt_step)
        for c in np.arange(0.0, 360.0 - 1e-9, rot_step)
    ]
    setups, xyz, ang = [], [], []
    for k, nest in enumerate(nests, start=1):
        a = np.zeros((len(grid), 2))
        a[:, i_tilt] = [g[0] for g in grid]
        a[:, i_rot] = [g[1] for g in grid]
        setups.extend([str(k)] * len(grid))
        xyz.append(_xyz_for(nominal, np.asarray(nest, float), np.radians(a)))
        ang.append(a)
    xyz = np.vstack(xyz)
    return {
        "setup": setups,
        "time": dwell_s * np.arange(len(xyz)),
        "xyz": xyz,
        "angles_deg": np.vstack(ang),
        "nests": {str(k): np.asarray(n, float) for k, n in enumerate(nests, start=1)},
    }


def probe_directions() -> np.ndarray:
    """One touch from above and four at 30 deg below the horizontal, towards the centre (machine frame)."""
    s, c = 0.5, np.sqrt(3.0) / 2.0
    return np.array([[0, 0, -1], [-c, 0, -s], [0, -c, -s], [c, 0, -s], [0, c, -s]], float)


def probe_poses(
    machine,
    sphere=(150.0, 0.0, 80.0),
    rot_step: float = 30.0,
    tilt_step: float = 15.0,
    touch_dt: float = 2.0,
    pose_dt: float = 16.0,
) -> dict:
    """12 poses of C at tilt 0, then 12 tilts at C 0 (24 poses x 5 touches)."""
    machine = load_machine(machine)
    i_tilt, i_rot = rotary_roles(machine)
    t0, t1 = default_tilt_range(machine)
    poses = [(0.0, c) for c in np.arange(0.0, 360.0 - 1e-9, rot_step)]
    tilts = [t for t in np.linspace(t0, t1, 13) if abs(t) > 1e-9][:12]
    poses += [(t, 0.0) for t in tilts]
    dirs = probe_directions()
    pose, time, ang, n = [], [], [], []
    for k, (tilt, rot) in enumerate(poses, start=1):
        for j, d in enumerate(dirs):
            a = np.zeros(2)
            a[i_tilt], a[i_rot] = tilt, rot
            pose.append(k)
            time.append((k - 1) * pose_dt + j * touch_dt)
            ang.append(a)
            n.append(d)
    return {
        "pose": pose,
        "time": np.array(time),
        "angles_deg": np.array(ang),
        "n": np.array(n),
        "sphere": np.asarray(sphere, float),
    }
