# SPDX-License-Identifier: BSD-3-Clause
"""The effects catalogue (shared/spec/effects.md, plus docs/effects.md additions): ids, their
parameter vectors, which machines they apply to, and their small building blocks.

Parameter order is the order the spec writes them:
  ballbar_length_offset (dL) | ballbar_thermal_drift (k) | tool_offset_X/Y/Z (d)
  rotary_zero_offset_R (eps) | angular_positioning_R_hn (a, b) | axial_motion_R_hn (a, b)
  radial_motion_R_hn, tilt_motion_R_hn (a, b, c, d) | gravity_sag_T (s) | coning_T (k)
  linear_squareness_* (s) | linear_scale_* (k) | thermal_drift_* (d) | thermal_warmup_* (d, tau)
  straightness_DA (c_2, c_3, c_4) | angular_error_BX / _AY (e1, e2)   [docs/effects.md]
  stylus_radius_offset (d) | probe_lobing (l_c, l_s)
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

LINEAR = "XYZ"
_AXIS_INDEX = {"X": 0, "Y": 1, "Z": 2}
# Radial pair of an ISO axis in its turning frame (cyclic: A -> Y, Z; B -> Z, X; C -> X, Y).
# effects.md does not fix it; a nutating axis uses formats.md's u, v (docs/effects.md).
ISO_RADIAL = {"A": (1, 2), "B": (2, 0), "C": (0, 1)}

_ROTARY = {
    "rotary_zero_offset": 1,
    "angular_positioning": 2,
    "axial_motion": 2,
    "radial_motion": 4,
    "tilt_motion": 4,
    "gravity_sag": 1,
    "coning": 1,
}
_HARMONIC_KINDS = {"angular_positioning", "axial_motion", "radial_motion", "tilt_motion"}
_SIMPLE = {
    "ballbar_length_offset": 1,
    "ballbar_thermal_drift": 1,
    "stylus_radius_offset": 1,
    "probe_lobing": 2,
}
BALLBAR_ONLY = {"ballbar_length_offset", "ballbar_thermal_drift"}
PROBE_ONLY = {"stylus_radius_offset", "probe_lobing"}


@dataclass(frozen=True)
class EffectId:
    """A parsed catalogue id."""

    id: str
    kind: str
    axis: str = ""  # rotary letter, or linear axis / pair letters
    harmonic: int = 0
    num_params: int = 1


def parse(effect_id: str) -> EffectId:
    """Parse an id of effects.md; ValueError for anything else."""
    if effect_id in _SIMPLE:
        return EffectId(effect_id, effect_id, num_params=_SIMPLE[effect_id])
    m = re.fullmatch(
        r"(angular_positioning|axial_motion|radial_motion|tilt_motion)_([A-Z])_h(\d+)", effect_id
    )
    if m:
        n = int(m.group(3))
        if n < 1 or (m.group(1) == "radial_motion" and n < 2):
            raise ValueError(f"bad harmonic in {effect_id}")
        return EffectId(effect_id, m.group(1), m.group(2), n, _ROTARY[m.group(1)])
    m = re.fullmatch(r"(rotary_zero_offset|gravity_sag|coning)_([A-Z])", effect_id)
    if m:
        return EffectId(effect_id, m.group(1), m.group(2), 0, 1)
    m = re.fullmatch(r"(tool_offset|linear_scale|thermal_drift|thermal_warmup)_([XYZ])", effect_id)
    if m:
        return EffectId(
            effect_id, m.group(1), m.group(2), 0, 2 if m.group(1) == "thermal_warmup" else 1
        )
    m = re.fullmatch(r"linear_squareness_(XY|YZ|ZX)", effect_id)
    if m:
        return EffectId(effect_id, "linear_squareness", m.group(1))
    m = re.fullmatch(r"straightness_([XYZ])([XYZ])", effect_id)
    if m and m.group(1) != m.group(2):
        return EffectId(effect_id, "straightness", m.group(1) + m.group(2), 0, 3)
    m = re.fullmatch(r"angular_error_(BX|AY)", effect_id)
    if m:
        return EffectId(effect_id, "angular_error", m.group(1), 0, 2)
    raise ValueError(f"not a catalogue id: {effect_id}")


def applies(e: EffectId, machine) -> bool:
    """Rotary entries need their axis; gravity sag and coning need it to be a tilting axis."""
    if e.kind in _ROTARY:
        if e.axis not in machine.axis_names:
            return False
        if e.kind in ("gravity_sag", "coning"):
            return e.axis in [a.name for a in machine.tilt_axes()]
    return True


def catalogue(machine, max_harmonic: int = 4, instrument: str = "ballbar") -> list[str]:
    """Every static entry that applies to `machine` for `instrument` ("ballbar", "rtest", "probe")."""
    ids = []
    if instrument == "ballbar":
        ids += sorted(BALLBAR_ONLY)
    ids += [f"tool_offset_{a}" for a in LINEAR]
    for ax in machine.axis_names:
        ids.append(f"rotary_zero_offset_{ax}")
        for n in range(1, max_harmonic + 1):
            ids += [
                f"angular_positioning_{ax}_h{n}",
                f"axial_motion_{ax}_h{n}",
                f"tilt_motion_{ax}_h{n}",
            ]
            if n >= 2:
                ids.append(f"radial_motion_{ax}_h{n}")
    ids += [f"gravity_sag_{a.name}" for a in machine.tilt_axes()]
    ids += [f"coning_{a.name}" for a in machine.tilt_axes()]
    ids += [f"linear_squareness_{p}" for p in ("XY", "YZ", "ZX")]
    ids += [f"linear_scale_{a}" for a in LINEAR] + [f"thermal_drift_{a}" for a in LINEAR]
    ids += [f"thermal_warmup_{a}" for a in LINEAR]
    ids += [f"straightness_{d}{a}" for a in LINEAR for d in LINEAR if d != a]
    ids += ["angular_error_BX", "angular_error_AY"]
    if instrument == "probe":
        ids += sorted(PROBE_ONLY)
    return ids


def normalise(effects: dict | None) -> dict:
    """{id: params} -> {EffectId: float array}, checking the parameter count."""
    out = {}
    for k, v in (effects or {}).items():
        e = parse(k)
        p = np.atleast_1d(np.asarray(v, dtype=float))
        if p.size != e.num_params:
            raise ValueError(f"{k} takes {e.num_params} parameters, got {p.size}")
        out[e] = p
    return out


def of_axis(effects: dict, letter: str, kind: str) -> list:
    return [(e, p) for e, p in effects.items() if e.kind == kind and e.axis == letter]


def harmonic(p_cos: float, p_sin: float, n: int, theta: np.ndarray) -> np.ndarray:
    """a cos(n theta) + b sin(n theta)."""
    return p_cos * np.cos(n * theta) + p_sin * np.sin(n * theta)


def gaussian_bump(amplitude_rad: float, centre_deg: float, sigma_deg: float):
    """An error OUTSIDE the catalogue (issue 50 item 4): the angle off by a Gaussian bump,
    amplitude exp(-d^2 / (2 sigma^2)), d the angle's shortest distance to the centre on the
    circle. Returns theta (rad) -> angle error (rad), for Model(angle_errors={letter: ...})."""
    if not sigma_deg > 0.0:
        raise ValueError(f"gaussian_bump: sigma_deg must be > 0, got {sigma_deg}")
    c, s = np.radians(centre_deg), np.radians(sigma_deg)

    def bump(theta):
        d = np.angle(np.exp(1j * (np.asarray(theta, dtype=float) - c)))  # wrapped to (-pi, pi]
        return amplitude_rad * np.exp(-0.5 * (d / s) ** 2)

    return bump


def actual_angle(effects: dict, letter: str, theta: np.ndarray, extra=None) -> np.ndarray:
    """effects.md: actual angle = R + eps (zero offset) + a cos nR + b sin nR (positioning),
    + `extra(theta)` (rad): an angle error outside the catalogue, e.g. gaussian_bump."""
    out = np.array(theta, dtype=float)
    if extra is not None:
        out = out + extra(np.asarray(theta, dtype=float))
    for _, p in of_axis(effects, letter, "rotary_zero_offset"):
        out = out + p[0]
    for e, p in of_axis(effects, letter, "angular_positioning"):
        out = out + harmonic(p[0], p[1], e.harmonic, theta)
    return out


def linear_reference(xyz: np.ndarray) -> np.ndarray:
    """effects.md, straightness: a-bar is the mean commanded position over the session."""
    return np.mean(np.asarray(xyz, dtype=float), axis=0)


def linear_axis_delta(
    effects: dict, xyz: np.ndarray, ball_z: np.ndarray, ref: np.ndarray
) -> np.ndarray:
    """Tool-side ball displacement (N, 3) of the linear-axis entries, functions of the commanded
    X, Y, Z (effects.md rows linear_squareness, linear_scale, straightness; docs angular_error)."""
    d = np.zeros_like(xyz)
    for e, p in effects.items():
        if e.kind == "linear_squareness":
            i, j = _AXIS_INDEX[e.axis[0]], _AXIS_INDEX[e.axis[1]]
            d[:, i] += p[0] * xyz[:, j]  # XY: x += s y, YZ: y += s z, ZX: z += s x
        elif e.kind == "linear_scale":
            i = _AXIS_INDEX[e.axis]
            d[:, i] += p[0] * xyz[:, i]
        elif e.kind == "straightness":
            i, j = _AXIS_INDEX[e.axis[0]], _AXIS_INDEX[e.axis[1]]
            u = (xyz[:, j] - ref[j]) / 100.0
            d[:, i] += sum(c * u**k for k, c in zip((2, 3, 4), p))
        elif e.kind == "angular_error":
            j = _AXIS_INDEX[e.axis[1]]
            u = (xyz[:, j] - ref[j]) / 100.0
            tilt = p[0] * u + p[1] * u**2
            sign = 1.0 if e.axis == "BX" else -1.0  # BX: x += e (z - z_ref); AY: y -= e (z - z_ref)
            d[:, j] += sign * tilt * (ball_z - ref[2])
    return d


def table_translation(effects: dict, machine, angles: np.ndarray, time: np.ndarray) -> np.ndarray:
    """Translations of the table in the machine frame (N, 3): gravity_sag_T of a table tilt axis,
    thermal_drift_* (d t), thermal_warmup_* (d (1 - exp(-t / tau)))."""
    d = np.zeros((len(time), 3))
    names = machine.axis_names
    for e, p in effects.items():
        if e.kind == "gravity_sag" and machine.axis(e.axis).side == "table":
            d[:, 2] -= p[0] * (1.0 - np.cos(angles[:, names.index(e.axis)]))
        elif e.kind == "thermal_drift":
            d[:, _AXIS_INDEX[e.axis]] += p[0] * time
        elif e.kind == "thermal_warmup":
            d[:, _AXIS_INDEX[e.axis]] += p[0] * (1.0 - np.exp(-time / p[1]))
    return d


def head_droop(effects: dict, machine, angles: np.ndarray) -> np.ndarray:
    """docs/effects.md: gravity_sag_R of a head tilt axis, the ball drops by s (1 - cos R)."""
    d = np.zeros((angles.shape[0], 3))
    names = machine.axis_names
    for e, p in effects.items():
        if e.kind == "gravity_sag" and machine.axis(e.axis).side == "head":
            d[:, 2] -= p[0] * (1.0 - np.cos(angles[:, names.index(e.axis)]))
    return d


def tool_offset(effects: dict) -> np.ndarray:
    """tool_offset_X/Y/Z: the ball's offset (spindle frame; the machine frame without head axes)."""
    d = np.zeros(3)
    for e, p in effects.items():
        if e.kind == "tool_offset":
            d[_AXIS_INDEX[e.axis]] += p[0]
    return d
