# SPDX-License-Identifier: BSD-3-Clause
"""Machines of formats.md "Any 5-axis machine": rotary axes, built-ins, location-error names.

Written from /work/shared/spec/formats.md and docs/machines.md only (independent of rotacal).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np

ISO_LETTER_AXIS = {"A": 0, "B": 1, "C": 2}  # letter -> index of the machine axis it turns about
# formats.md, "Location errors": (names of dp components, names of dn components) per ISO axis,
# as (component index, name, sign) triples.
_ISO_DP = {
    "A": [(1, "E_Y0A", 1), (2, "E_Z0A", 1)],
    "B": [(0, "E_X0B", 1), (2, "E_Z0B", 1)],
    "C": [(0, "E_X0C", 1), (1, "E_Y0C", 1)],
}
_ISO_DN = {
    "A": [(1, "E_C0A", 1), (2, "E_B0A", -1)],
    "B": [(0, "E_C0B", -1), (2, "E_A0B", 1)],
    "C": [(0, "E_B0C", 1), (1, "E_A0C", -1)],
}
# Order of the names of an ISO axis in an errors vector (docs/machines.md, built-ins table).
_ISO_ORDER = {
    "A": ["E_Y0A", "E_Z0A", "E_B0A", "E_C0A"],
    "B": ["E_X0B", "E_Z0B", "E_A0B", "E_C0B"],
    "C": ["E_X0C", "E_Y0C", "E_A0C", "E_B0C"],
}


def unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


@dataclass
class Axis:
    """One rotary axis: letter, nominal unit direction n, nominal point p0 (formats.md)."""

    name: str
    direction: np.ndarray
    point: np.ndarray = field(default_factory=lambda: np.zeros(3))
    limits_deg: tuple | None = None
    side: str = "table"  # "table" or "head"

    @property
    def iso_sign(self) -> int:
        """+1 / -1 when the letter matches a direction along +-X/+-Y/+-Z, else 0 (general rule)."""
        k = ISO_LETTER_AXIS.get(self.name)
        if k is None:
            return 0
        e = np.zeros(3)
        e[k] = 1.0
        c = float(self.direction @ e)
        if abs(abs(c) - 1.0) < 1e-12:
            return 1 if c > 0 else -1
        return 0

    def uv(self) -> tuple[np.ndarray, np.ndarray]:
        """formats.md: u = unit(e x n), e the first of +X,+Y,+Z with |e.n| <= 0.5; v = n x u."""
        for k in range(3):
            e = np.zeros(3)
            e[k] = 1.0
            if abs(e @ self.direction) <= 0.5:
                u = unit(np.cross(e, self.direction))
                return u, np.cross(self.direction, u)
        raise ValueError("no basis vector for u")  # impossible for a unit n

    def error_names(self) -> list[str]:
        if self.iso_sign:
            return list(_ISO_ORDER[self.name])
        r = self.name
        return [f"E_U0{r}", f"E_V0{r}", f"E_DU0{r}", f"E_DV0{r}"]

    def actual_line(self, errors: dict) -> tuple[np.ndarray, np.ndarray]:
        """(point p0 + dp, unit(n + dn)) of the actual line (formats.md, "Location errors");
        (N, 3) each where the errors are (N,) arrays (per-row errors of a thermal test)."""
        shape = np.broadcast(*[np.asarray(v) for v in errors.values()], np.zeros(())).shape
        dp, dn = np.zeros(shape + (3,)), np.zeros(shape + (3,))
        s = self.iso_sign
        if s:
            for k, name, sign in _ISO_DP[self.name]:
                dp[..., k] += errors.get(name, 0.0) * sign
            for k, name, sign in _ISO_DN[self.name]:
                dn[..., k] += errors.get(name, 0.0) * sign * s  # dn negated with n
        else:
            u, v = self.uv()
            r = self.name
            g = lambda n: np.asarray(errors.get(n, 0.0))[..., None]  # noqa: E731
            dp = g(f"E_U0{r}") * u + g(f"E_V0{r}") * v
            dn = g(f"E_DU0{r}") * u + g(f"E_DV0{r}") * v
        d = self.direction + dn
        return self.point + dp, d / np.linalg.norm(d, axis=-1, keepdims=True)


@dataclass
class Machine:
    """A rotacal-machine/1 machine: table axes from the bed outwards, head axes from X,Y,Z outwards."""

    name: str
    table_axes: list
    head_axes: list
    pivot_length: float = 0.0
    tool_length: float = 0.0
    travel_mm: list | None = None
    description: dict | None = None  # the JSON dict, for a machine that is not built in

    @property
    def axes(self) -> list:
        """Chain order: table axes, then head axes (the session's rotary columns)."""
        return list(self.table_axes) + list(self.head_axes)

    @property
    def axis_names(self) -> list[str]:
        return [a.name for a in self.axes]

    @property
    def tool_vector(self) -> np.ndarray:
        """t = (0, 0, -(pivot_length + tool_length)) (formats.md, "Head side")."""
        return np.array([0.0, 0.0, -(self.pivot_length + self.tool_length)])

    def error_names(self) -> list[str]:
        return [n for a in self.axes for n in a.error_names()]

    def errors_dict(self, errors) -> dict:
        """Accept a dict (name -> value) or a vector in error_names() order."""
        if isinstance(errors, dict):  # a value may be an (N,) array: per-row errors (thermal.py)
            return {
                k: (float(v) if np.ndim(v) == 0 else np.asarray(v, float))
                for k, v in errors.items()
            }
        vals = np.zeros(8) if errors is None else np.asarray(errors, dtype=float)
        return dict(zip(self.error_names(), vals.tolist()))

    def axis(self, letter: str) -> Axis:
        for a in self.axes:
            if a.name == letter:
                return a
        raise KeyError(letter)

    def tilt_axes(self) -> list:
        """Axes that tilt (not along Z): the T of gravity_sag_T / coning_T."""
        return [a for a in self.axes if abs(abs(a.direction[2]) - 1.0) > 1e-12]


def _axis_from_dict(d: dict, side: str, where: str) -> Axis:
    allowed = {"name", "direction", "point", "limits_deg"}
    extra = set(d) - allowed
    if extra:
        raise ValueError(f"{where}: unknown field {sorted(extra)[0]}")
    n = np.asarray(d["direction"], dtype=float)
    if n.shape != (3,) or np.linalg.norm(n) == 0:
        raise ValueError(f"{where}.direction must be a non-zero 3-vector")
    lim = d.get("limits_deg")
    if lim is not None and not lim[0] < lim[1]:
        raise ValueError(f"{where}.limits_deg must have min < max")
    return Axis(
        str(d["name"]),
        unit(n),
        np.asarray(d.get("point", [0, 0, 0]), dtype=float),
        tuple(lim) if lim is not None else None,
        side,
    )


def machine_from_dict(d: dict) -> Machine:
    """Parse a rotacal-machine/1 dict (formats.md, "Machine description file")."""
    if d.get("format") != "rotacal-machine/1":
        raise ValueError("format must be rotacal-machine/1")
    table = [
        _axis_from_dict(a, "table", f"table_axes[{i}]")
        for i, a in enumerate(d.get("table_axes", []))
    ]
    head = [
        _axis_from_dict(a, "head", f"head_axes[{i}]") for i, a in enumerate(d.get("head_axes", []))
    ]
    if len(table) + len(head) != 2:
        raise ValueError("a machine has two rotary axes in all")
    if len({a.name for a in table + head}) != 2:
        raise ValueError("repeated axis letter")
    return Machine(
        str(d.get("name", "custom")),
        table,
        head,
        float(d.get("pivot_length", 0.0)),
        float(d.get("tool_length", 0.0)),
        d.get("travel_mm"),
        dict(d),
    )


def machine_from_json(text: str) -> Machine:
    return machine_from_dict(json.loads(text))


_X, _Y, _Z = [1, 0, 0], [0, 1, 0], [0, 0, 1]
_S = 0.5**0.5
# docs/machines.md, "The built-ins".
_BUILTIN = {
    "AC-trt": ([("A", _X, None), ("C", _Z, None)], [], 0.0, 0.0),
    "BC-trt": ([("B", _Y, None), ("C", _Z, None)], [], 0.0, 0.0),
    "B-head-C-table": ([("C", _Z, None)], [("B", _Y, (-110, 110))], 150.0, 100.0),
    "AC-head": ([], [("C", _Z, None), ("A", _X, (-110, 110))], 150.0, 100.0),
    "BC-head": ([], [("C", _Z, None), ("B", _Y, (-110, 110))], 150.0, 100.0),
    "B45C-trt": ([("B", [0, -_S, _S], (0, 180)), ("C", _Z, None)], [], 0.0, 0.0),
}
BUILTIN_NAMES = list(_BUILTIN)


def builtin(name: str) -> Machine:
    table, head, pivot, tool = _BUILTIN[name]
    mk = lambda spec, side: [Axis(n, unit(d), np.zeros(3), lim, side) for n, d, lim in spec]  # noqa: E731
    return Machine(name, mk(table, "table"), mk(head, "head"), pivot, tool)


def load_machine(name_or_dict) -> Machine:
    if isinstance(name_or_dict, Machine):
        return name_or_dict
    if isinstance(name_or_dict, dict):
        return machine_from_dict(name_or_dict)
    return builtin(name_or_dict)
