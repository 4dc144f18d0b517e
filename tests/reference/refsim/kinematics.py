# SPDX-License-Identifier: BSD-3-Clause
"""Forward kinematics of formats.md "Any 5-axis machine", with the effects of effects.md.

Every rigid motion is a (N, 4, 4) homogeneous matrix, vectorised over poses:
  p_table = S(T1) . S(T2) . q  (+ table translations)
  p_tool  = (X, Y, Z) + linear-axis errors + S(H1) . S(H2) . (t + tool offset)  (+ head droop)
with, per axis R (effects.md, "R's turning frame": the error motion acts before R's rotation,
coning after it, about the machine axis through the frame's origin):
  S(R) = Cone(k R) . Rot(R-line, R_actual) . E(R)
"""

from __future__ import annotations

import numpy as np

from . import effects as fx
from .machines import load_machine


def rodrigues(axis: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """(N, 3, 3) right-handed rotations by theta (N,) about the unit vector axis (3,) or (N, 3)."""
    theta = np.asarray(theta, dtype=float)
    k = np.broadcast_to(np.asarray(axis, dtype=float), theta.shape + (3,))
    kx = np.zeros(theta.shape + (3, 3))
    kx[..., 0, 1], kx[..., 0, 2] = -k[..., 2], k[..., 1]
    kx[..., 1, 0], kx[..., 1, 2] = k[..., 2], -k[..., 0]
    kx[..., 2, 0], kx[..., 2, 1] = -k[..., 1], k[..., 0]
    s, c = np.sin(theta)[..., None, None], np.cos(theta)[..., None, None]
    return np.eye(3) + s * kx + (1.0 - c) * (kx @ kx)


def rotation_vector(w: np.ndarray) -> np.ndarray:
    """(N, 3, 3) rotation of the rotation vector w (N, 3) (angle |w| about w / |w|)."""
    ang = np.linalg.norm(w, axis=-1)
    safe = np.where(ang > 0, ang, 1.0)
    return rodrigues(w / safe[..., None], ang)


def homogeneous(
    rot: np.ndarray | None = None, shift: np.ndarray | None = None, n: int = 1
) -> np.ndarray:
    """(N, 4, 4) from rotations (N, 3, 3) and translations (N, 3) applied after them."""
    m = np.tile(np.eye(4), (n, 1, 1))
    if rot is not None:
        m[:, :3, :3] = rot
    if shift is not None:
        m[:, :3, 3] = shift
    return m


def about_line(point: np.ndarray, unit_dir: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """x -> R (x - p) + p: rotation about the line through p along unit_dir (formats.md);
    p and unit_dir (3,) or per pose (N, 3)."""
    r = rodrigues(unit_dir, theta)
    p = np.broadcast_to(np.asarray(point, float), (len(theta), 3))
    return homogeneous(r, p - (r @ p[..., None])[..., 0], len(theta))


def error_motion(effects: dict, axis, theta: np.ndarray) -> np.ndarray:
    """E(R) (N, 4, 4): radial, axial and tilt error motions of axis R in its turning frame."""
    n = len(theta)
    if axis.iso_sign:
        i, j = fx.ISO_RADIAL[axis.name]
        r1, r2 = np.eye(3)[i], np.eye(3)[j]
    else:
        r1, r2 = axis.uv()
    shift, w = np.zeros((n, 3)), np.zeros((n, 3))
    for e, p in fx.of_axis(effects, axis.name, "radial_motion"):
        shift += np.outer(fx.harmonic(p[0], p[1], e.harmonic, theta), r1)
        shift += np.outer(fx.harmonic(p[2], p[3], e.harmonic, theta), r2)
    for e, p in fx.of_axis(effects, axis.name, "axial_motion"):
        shift += np.outer(fx.harmonic(p[0], p[1], e.harmonic, theta), axis.direction)
    for e, p in fx.of_axis(effects, axis.name, "tilt_motion"):
        w += np.outer(fx.harmonic(p[0], p[1], e.harmonic, theta), r1)
        w += np.outer(fx.harmonic(p[2], p[3], e.harmonic, theta), r2)
    return homogeneous(rotation_vector(w), shift, n)


def coning_axis(axis) -> np.ndarray:
    """effects.md: X for B, Y for A (perpendicular to T and Z); docs/effects.md: u for a nutating axis."""
    if axis.iso_sign and axis.name == "B":
        return np.array([1.0, 0.0, 0.0])
    if axis.iso_sign and axis.name == "A":
        return np.array([0.0, 1.0, 0.0])
    return axis.uv()[0]


def axis_stage(model, axis, theta: np.ndarray) -> np.ndarray:
    """S(R) = Cone(k R) . Rot(R-line, actual R) . E(R), theta the commanded angle (rad)."""
    point, direction = axis.actual_line(model.errors)
    extra = model.angle_errors.get(axis.name)
    s = about_line(point, direction, fx.actual_angle(model.effects, axis.name, theta, extra))
    s = s @ error_motion(model.effects, axis, theta)
    for _, p in fx.of_axis(model.effects, axis.name, "coning"):
        s = homogeneous(rodrigues(coning_axis(axis), p[0] * theta), None, len(theta)) @ s
    return s


class Model:
    """A machine with location errors and effects: the truth a session is measured on."""

    def __init__(self, machine, errors=None, effects=None, linear_ref=None, angle_errors=None):
        """angle_errors: {axis letter: theta (rad) -> angle error (rad)}, errors outside the
        catalogue added to the actual angle (effects.gaussian_bump)."""
        self.machine = load_machine(machine)
        self.angle_errors = dict(angle_errors or {})
        for letter in self.angle_errors:
            if letter not in self.machine.axis_names:
                raise ValueError(f"angle_errors: {self.machine.name} has no axis {letter}")
        self.errors = self.machine.errors_dict(errors if errors is not None else {})
        self.effects = fx.normalise(effects)
        for e in self.effects:
            if not fx.applies(e, self.machine):
                raise ValueError(f"{e.id} does not apply to {self.machine.name}")
        self.linear_ref = None if linear_ref is None else np.asarray(linear_ref, dtype=float)

    def nominal(self) -> "Model":  # no errors, no effects, no angle errors
        return Model(self.machine)

    def _chain(self, angles: np.ndarray, side: str) -> np.ndarray:
        angles = np.atleast_2d(np.asarray(angles, dtype=float))
        m = np.tile(np.eye(4), (angles.shape[0], 1, 1))
        for k, axis in enumerate(self.machine.axes):
            if axis.side == side:
                m = m @ axis_stage(self, axis, angles[:, k])
        return m

    def table_transform(self, angles: np.ndarray, time: np.ndarray) -> np.ndarray:
        """(N, 4, 4): p_table(q) = T . q (formats.md "Table side") with table effects."""
        m = self._chain(angles, "table")
        shift = fx.table_translation(
            self.effects, self.machine, np.atleast_2d(angles), np.asarray(time, float)
        )
        return homogeneous(None, shift, len(m)) @ m

    def p_table(self, q: np.ndarray, angles: np.ndarray, time: np.ndarray) -> np.ndarray:
        t = self.table_transform(angles, time)
        return (t[:, :3, :3] @ np.asarray(q, float).reshape(-1, 3, 1))[..., 0] + t[:, :3, 3]

    def p_tool(self, xyz: np.ndarray, angles: np.ndarray, time: np.ndarray) -> np.ndarray:
        """(N, 3): tool-side ball (formats.md "Head side") with tool-side effects."""
        xyz = np.atleast_2d(np.asarray(xyz, dtype=float))
        h = self._chain(angles, "head")
        t = self.machine.tool_vector + fx.tool_offset(self.effects)
        ball = xyz + (h[:, :3, :3] @ t) + h[:, :3, 3]
        ref = self.linear_ref if self.linear_ref is not None else fx.linear_reference(xyz)
        ball = ball + fx.linear_axis_delta(self.effects, xyz, ball[:, 2], ref)
        return ball + fx.head_droop(self.effects, self.machine, np.atleast_2d(angles))

    def commanded_xyz(self, p_ball: np.ndarray, angles: np.ndarray) -> np.ndarray:
        """Inverse of the nominal head chain: X, Y, Z that put the ball at p_ball (machine frame)."""
        nominal = self.nominal()
        zero = np.zeros((np.atleast_2d(angles).shape[0], 3))
        return np.atleast_2d(p_ball) - nominal.p_tool(zero, angles, np.zeros(len(zero)))
