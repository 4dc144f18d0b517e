# SPDX-License-Identifier: BSD-3-Clause
"""Instrument readings (formats.md "Instruments on any machine", "Touch-probe session")."""

from __future__ import annotations

import numpy as np

from . import effects as fx
from .kinematics import Model


def _with_session_reference(model: Model, xyz: np.ndarray) -> Model:
    """The linear-axis polynomials are centred on the session's mean commanded position."""
    if model.linear_ref is None:
        clone = Model.__new__(Model)
        clone.__dict__.update(model.__dict__)
        clone.linear_ref = fx.linear_reference(xyz)
        return clone
    return model


def ballbar_lengths(model: Model, pivot, xyz, angles_rad, time) -> np.ndarray:
    """length = |p_tool - p_table(pivot)| + dL + k t (ballbar_length_offset, ballbar_thermal_drift)."""
    xyz, time = np.atleast_2d(np.asarray(xyz, float)), np.asarray(time, float)
    m = _with_session_reference(model, xyz)
    tool = m.p_tool(xyz, angles_rad, time)
    centre = m.p_table(np.broadcast_to(np.asarray(pivot, float), xyz.shape), angles_rad, time)
    length = np.linalg.norm(tool - centre, axis=1)
    for e, p in m.effects.items():
        if e.kind == "ballbar_length_offset":
            length = length + p[0]
        elif e.kind == "ballbar_thermal_drift":
            length = length + p[0] * time
    return length


def rtest_displacements(model: Model, nests: dict, setups, xyz, angles_rad, time) -> np.ndarray:
    """dx, dy, dz (N, 3): q solving p_table(q) = p_tool, minus the nest of the row's set-up."""
    xyz, time = np.atleast_2d(np.asarray(xyz, float)), np.asarray(time, float)
    m = _with_session_reference(model, xyz)
    tool = m.p_tool(xyz, angles_rad, time)
    tr = m.table_transform(angles_rad, time)
    rot, shift = tr[:, :3, :3], tr[:, :3, 3]
    q = (np.transpose(rot, (0, 2, 1)) @ (tool - shift)[..., None])[..., 0]  # rigid inverse
    nest = np.array([np.asarray(nests[str(s)], float) for s in setups])
    return q - nest


def _spindle_frame_dirs(model: Model, n: np.ndarray, angles_rad) -> np.ndarray:
    """n in the spindle's frame: the inverse of the nominal head rotation (identity without head)."""
    nominal = model.nominal()
    h = nominal._chain(angles_rad, "head")
    return (np.transpose(h[:, :3, :3], (0, 2, 1)) @ n[..., None])[..., 0]


def probe_touches(
    model: Model,
    sphere_actual,
    sphere_nominal,
    sphere_diameter: float,
    stylus_diameter: float,
    n_dirs,
    angles_rad,
    time,
    iterations: int = 30,
) -> np.ndarray:
    """Latched X, Y, Z (N, 3) of touches along n through the nominal centre (formats.md,
    rotacal-probe/1): the stylus tip moves on the line c_nom + lam n of the nominal machine and
    triggers where |p_tool - p_table(q_sphere)| = (D + d)/2 (+ stylus_radius_offset); the
    latched position then moves along n by probe_lobing."""
    n = np.atleast_2d(np.asarray(n_dirs, float))
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    time = np.asarray(time, float)
    angles_rad = np.atleast_2d(np.asarray(angles_rad, float))
    nominal = model.nominal()
    c_nom = nominal.p_table(
        np.broadcast_to(np.asarray(sphere_nominal, float), n.shape), angles_rad, time
    )
    x0 = nominal.commanded_xyz(c_nom, angles_rad)  # controlled point with the tip at c_nom
    radius = 0.5 * (sphere_diameter + stylus_diameter)
    for e, p in model.effects.items():
        if e.kind == "stylus_radius_offset":
            radius += p[0]
    m = model if model.linear_ref is not None else _with_session_reference(model, x0 - radius * n)
    centre = m.p_table(np.broadcast_to(np.asarray(sphere_actual, float), n.shape), angles_rad, time)
    lam = np.full(len(n), -radius)
    for _ in range(iterations):  # Newton on |p_tool(lam) - centre| = radius
        f0 = (
            np.linalg.norm(m.p_tool(x0 + lam[:, None] * n, angles_rad, time) - centre, axis=1)
            - radius
        )
        h = 1e-6
        f1 = (
            np.linalg.norm(m.p_tool(x0 + (lam + h)[:, None] * n, angles_rad, time) - centre, axis=1)
            - radius
        )
        step = f0 / ((f1 - f0) / h)
        lam = lam - step
        if np.max(np.abs(step)) < 1e-13:
            break
    latched = x0 + lam[:, None] * n
    for e, p in model.effects.items():
        if e.kind == "probe_lobing":
            ns = _spindle_frame_dirs(model, n, angles_rad)
            phi = np.arctan2(ns[:, 1], ns[:, 0])
            amount = (p[0] * np.cos(3 * phi) + p[1] * np.sin(3 * phi)) * np.sqrt(
                np.clip(1 - ns[:, 2] ** 2, 0, None)
            )
            latched = latched + amount[:, None] * n
    return latched
