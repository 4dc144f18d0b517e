# SPDX-License-Identifier: BSD-3-Clause
"""What each controller's compensation tables leave of a model's position-dependent errors
(issue 54, docs/controller_exports.md "What each controller holds"): for every controller that
writes tables (`rotacal export --tables`), the simulated machine has the model's errors that
move with the axes (rotacal's own angle maps of the model, the machine here), the controller
applies its tables as its documentation describes them, and the benchmark prints, per
controller, the residual of each held term over the travel against the interpolation error the
table states, and the size of every term no table holds, in um (angular terms in urad and in um
at 100 mm from the axis).

    PYTHONPATH=build/release/python python3 bench/table_residual_bench.py          # 0.01 deg
    PYTHONPATH=build/release/python python3 bench/table_residual_bench.py --smoke  # 0.1 deg

The model: an AC-trt with a worm-gear C (zero offset, first and third positioning harmonics), an
out-of-round C bearing track (radial, second harmonic), C face runout (axial, first), C wobble
(tilt motion, first) and a sagging A table (gravity sag), sizes of a worn machine."""

from __future__ import annotations

import argparse
import json
import re
import sys
import tempfile
from pathlib import Path

import numpy as np

from rotacal import _core
from rotacal.exports import controller_tables


def est(v: float) -> dict:
    return {"value": v}


MODEL = {
    "format": "rotacal-model/1",
    "kind": "ballbar",
    "machine": "AC-trt",
    "location_errors": {
        n: est(0.0)
        for n in ("E_Y0A", "E_Z0A", "E_B0A", "E_C0A", "E_X0C", "E_Y0C", "E_A0C", "E_B0C")
    },
    "pivot": {"x": est(0.0), "y": est(0.0), "z": est(100.0)},
    "effects": [
        {"id": "rotary_zero_offset_C", "params": {"eps": est(2e-5)}},
        {"id": "angular_positioning_C_h1", "params": {"a": est(1e-4), "b": est(-5e-5)}},
        {"id": "angular_positioning_C_h3", "params": {"a": est(0.0), "b": est(3e-5)}},
        {
            "id": "radial_motion_C_h2",
            "params": {k: est(v) for k, v in zip("abcd", (2e-3, 0, 0, 1e-3))},
        },
        {"id": "axial_motion_C_h1", "params": {"a": est(1e-3), "b": est(5e-4)}},
        {"id": "tilt_motion_C_h1", "params": {k: est(1e-5) for k in "abcd"}},
        {"id": "gravity_sag_A", "params": {"s": est(0.004)}},
    ],
    "source": {"session": "table_residual_bench"},
}


def term_at(maps: dict, axis: str, j: int, x: np.ndarray) -> np.ndarray:
    """The model's term j of an axis at angles x (deg): its angle map, periodic over a turn."""
    m = maps[axis]
    grid = np.asarray(m.angle_deg)
    return np.interp(np.mod(x - grid[0], 360.0) + grid[0], grid, np.asarray(m.values)[:, j])


def positioning_residual_deg(controller: str, t, maps: dict, x: np.ndarray) -> np.ndarray:
    """Actual - commanded angle at commanded x with the table loaded, by the controller's
    semantics (docs/controller_exports.md): the machine's angle at motor command m is
    m + positioning(m)."""
    grid, v = np.asarray(t.nominal_deg), np.asarray(t.value_deg)
    pos = lambda m: np.degrees(term_at(maps, t.axis, 6, m))  # noqa: E731
    modulo = lambda p: grid[0] + np.mod(p - grid[0], grid[-1] - grid[0])  # noqa: E731
    if controller == "linuxcnc":  # trim added to the motor command, ends held, no modulo
        motor = x + np.interp(x, grid, v)
    elif controller == "isg":  # the error taken off the setpoint, modulo over the turn
        motor = x - np.interp(modulo(x) if "modulo" in t.summary else x, grid, v)
    elif controller == "siemens":  # the actual value corrected: the axis settles where
        # a + value(a) = x; solved by iteration (a contraction: the slope is << 1)
        a = x.copy()
        for _ in range(6):
            a = x - np.interp(modulo(a) if "modulo" in t.summary else a, grid, v)
        return a + pos(a) - x
    else:  # fanuc: the running sum of the sections, zero at the reference position (0 deg);
        # the trim there is not in the table (the header gives it as the axis' zero offset)
        absolute = np.concatenate([[0.0], np.cumsum(v)])
        absolute -= absolute[int(np.argmin(np.abs(grid)))]
        trim_ref = 0.0
        for _ in range(4):
            trim_ref = -pos(np.array([trim_ref]))[0]
        motor = x + np.interp(np.mod(x, 360.0), grid, absolute) + trim_ref
    return motor + pos(motor) - x


def run(step: float) -> str:
    out = []
    with tempfile.TemporaryDirectory() as d:
        model = Path(d) / "model.json"
        model.write_text(json.dumps(MODEL))
        maps = {m.axis: m for m in _core.angle_maps(str(model), 0.0, 360.0, 0.05, 1)}
        x = np.arange(0.0, 360.0, step) + step / 3
        out.append(f"commanded angles: 0..360 deg every {step} deg (points and between them)")
        for controller in ("linuxcnc", "siemens", "isg", "fanuc"):
            tabs = controller_tables(model, controller, d, 5.0, {"C": [0.0, 360.0]})
            out.append(f"{controller}:")
            for t in tabs.tables:
                if t.value_mm:  # a cross table: the tool follows the table point (at tilt 0)
                    for o, v in t.value_mm.items():
                        j = "XYZ".index(o)
                        got = np.interp(x, np.asarray(t.nominal_deg), np.asarray(v))
                        res = np.abs(term_at(maps, t.axis, j, x) - got).max() * 1e3
                        stated = t.max_interpolation_error_mm * 1e3
                        out.append(
                            f"  held E_{o}{t.axis} ({Path(t.file_name).name}): residual "
                            f"{res:.4f} um, stated {stated:.4f} um, ratio {res / stated:.4f}"
                        )
                    continue
                res = np.abs(positioning_residual_deg(controller, t, maps, x)).max()
                stated = t.max_interpolation_error_deg
                out.append(
                    f"  held positioning_{t.axis} ({Path(t.file_name).name}): residual "
                    f"{np.radians(res) * 1e6:.4f} urad, stated {np.radians(stated) * 1e6:.4f} "
                    f"urad, ratio {res / stated:.4f}"
                )
            for n in tabs.not_held:
                m = re.match(r"(.+?):? up to ([\d.]+) (um|urad)(.*)", n)
                if not m:
                    out.append(f"  not held: {n}")
                    continue
                um = f" ({float(m[2]) * 0.1:.3f} um at 100 mm)" if m[3] == "urad" else ""
                out.append(f"  not held {m[1]}: {m[2]} {m[3]}{um}{m[4].split(' (')[0]}")
    return "\n".join(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--smoke", action="store_true", help="every 0.1 deg: a quick check")
    a = ap.parse_args()
    print(run(0.1 if a.smoke else 0.01))
    return 0


if __name__ == "__main__":
    sys.exit(main())
