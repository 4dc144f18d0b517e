# SPDX-License-Identifier: BSD-3-Clause
"""The touch probe on a sphere as an instrument of the confusion benchmark, all from refsim:
refsim.poses.probe_poses (plan probe's default layout, 24 poses x 5 touches), refsim.probe_touches
(formats.md, rotacal-probe/1), refsim.writers.write_probe for the file rotacal reads.

A touch's reading is lam, the distance travelled along its approach direction n from the
commanded start x0 (latched = x0 + lam n, formats.md): only lam carries information, and the
noise is the trigger's scatter along n, one stream per session in time order (white, AR(1) or
1/f-like from refsim.noise, marginal 1-sigma 0.5 um). The baseline is rotacal's probe problem
with no effect: the 8 location errors and the sphere's table position (plus tool_offset_Z on a
machine with a head, which rotacal's probe baseline holds and its candidates leave out)."""

from __future__ import annotations

import itertools
import os

import numpy as np

import refsim
from refsim import noise as rnoise
from refsim import poses, writers

from .setup import Setup

SPHERE_SHIFT = np.array([0.021, -0.017, 0.012])  # the sphere's set-up error on the table, mm
SPHERE_DIAMETER, STYLUS_DIAMETER = 25.0, 6.0
_COUNTER = itertools.count()


class ProbeSetup(Setup):
    """Machine x touch probe (see the module's docstring)."""

    def _make_poses(self, rng: np.random.Generator) -> None:
        s = poses.probe_poses(self.machine)
        n = np.round(s["n"], 6)
        s.update(
            time=np.round(s["time"], 3),
            angles_deg=np.round(s["angles_deg"], 6),
            n=n / np.linalg.norm(n, axis=1, keepdims=True),
        )
        self.s, self.labels = s, ["touches"] * len(s["pose"])
        self.sphere_actual = s["sphere"] + SPHERE_SHIFT
        self.n = len(self.labels)
        self.streams = [np.arange(self.n)]
        self.head = any(a.side == "head" for a in self.machine.axes)
        radius = 0.5 * (SPHERE_DIAMETER + STYLUS_DIAMETER)
        nominal = refsim.probe_touches(
            refsim.Model(self.machine),
            s["sphere"],
            s["sphere"],
            SPHERE_DIAMETER,
            STYLUS_DIAMETER,
            s["n"],
            np.radians(s["angles_deg"]),
            s["time"],
        )
        self.x0 = nominal + radius * s["n"]
        self._workdir = self.path.parent

    def _catalogue(self) -> list:
        ids = super()._catalogue()
        return [e for e in ids if not (self.head and e == "tool_offset_Z")]

    def reading(self, effects: dict, errors=None, sphere_shift=None) -> np.ndarray:
        """lam of every touch, noise-free, of the truth (+ effects)."""
        s = self.s
        model = refsim.Model(self.machine, self.errors if errors is None else errors, effects)
        centre = self.sphere_actual if sphere_shift is None else self.sphere_actual + sphere_shift
        latched = refsim.probe_touches(
            model,
            centre,
            s["sphere"],
            SPHERE_DIAMETER,
            STYLUS_DIAMETER,
            s["n"],
            self.angles,
            s["time"],
        )
        return np.einsum("ij,ij->i", latched - self.x0, s["n"])

    def _nuisance_columns(self) -> list:
        """The sphere's table position, and tool_offset_Z on a machine with a head."""
        cols = []
        for k in range(3):
            d = np.zeros(3)
            d[k] = 1e-3
            cols.append(
                (self.reading({}, sphere_shift=d) - self.reading({}, sphere_shift=-d)) / 2e-3
            )
        if self.head:
            cols.append(
                (self.reading({"tool_offset_Z": [1e-3]}) - self.reading({"tool_offset_Z": [-1e-3]}))
                / 2e-3
            )
        return cols

    def noise(self, kind: str, rng: np.random.Generator) -> np.ndarray:
        if kind == "white":
            return rnoise.white(self.n, self.sigma, rng)
        if kind == "pink":
            return rnoise.pink(self.labels, self.sigma, rng)
        return rnoise.ar1(self.labels, float(kind.split("_")[1]), self.sigma, rng)

    @property
    def template(self):
        return None  # every draw is its own file (a ProbeSession has no with_xyz)

    def session(self, flat: np.ndarray):
        """The rotacal session of these readings, through the file refsim's writer makes."""
        import rotacal

        latched = self.x0 + np.asarray(flat, float)[:, None] * self.s["n"]
        path = self._workdir / f"{self.name}_probe_{os.getpid()}_{next(_COUNTER)}.csv"
        writers.write_probe(
            path,
            self.machine,
            self.s,
            latched,
            SPHERE_DIAMETER,
            STYLUS_DIAMETER,
            noise_um=self.sigma * 1e3,
        )
        try:
            return rotacal.load(path)
        finally:
            path.unlink()
