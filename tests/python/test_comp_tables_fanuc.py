# SPDX-License-Identifier: BSD-3-Clause
"""`rotacal export --controller fanuc --tables`: FANUC pitch error compensation data, checked by
the semantics of FANUC's parameter manual (parameters 3620-3625, read, not copied), implemented
here and fed only with the exported file: the value of data number R+k is the section from
(k-1) to k intervals past the reference position (R = parameter 3620), incremental, in
detection units times the magnification (3623); the control adds the running sum to the motor
command, zero at the reference position; on a rotary axis (3625 = travel per turn) the numbers
run from R (the farthest negative, holding the last one's value again) to R + turn / interval,
and their sum is zero. Between points the compensation is output at the points or, where the
control interpolates, linearly: both are checked. The machine is effects.md's worm-gear C."""

import json
import re

import numpy as np

from conftest import run_cli
from test_comp_tables import model_doc, positioning_deg

EXIT_OK, EXIT_INPUT = 0, 3


def read_pitch(text):
    """The parameters by number and the values by data number."""
    params = {
        int(m[1]): int(m[2]) for m in re.finditer(r"^PARAMETER (\d+) \w = (-?\d+)", text, re.M)
    }
    data = {int(m[1]): int(m[2]) for m in re.finditer(r"^DATA (\d+) = (-?\d+)", text, re.M)}
    return params, data


def absolute_at_points(params, data):
    """k (intervals past the reference) -> the running sum of the sections' values, 0 at k = 0."""
    ref, lo, hi = params[3620], params[3621], params[3622]
    turn = params[3625] != 0
    first = 0 if turn else lo - ref - 1
    out = {0: 0}
    for k in range(1, hi - ref + 1):
        out[k] = out[k - 1] + data[ref + k]
    for k in range(0, first, -1):
        out[k - 1] = out[k] - data[ref + k]
    return out


def compensation(params, data, pos_deg, unit_deg, mode):
    """The compensation the control adds at each position (deg): `step` holds the value of the
    last point passed moving up, `linear` interpolates between the points."""
    pts = absolute_at_points(params, data)
    interval = params[3624] * unit_deg / params[3623]
    if params[3625]:
        pos_deg = np.mod(pos_deg, params[3625] * unit_deg / params[3623])
    x = pos_deg / interval
    k = np.floor(x).astype(int)
    a = np.array([pts[int(i)] for i in k], dtype=float)
    b = np.array([pts[int(i) + 1] for i in k], dtype=float)
    frac = x - k
    return (a if mode == "step" else a + (b - a) * frac) * unit_deg


def stated(text, what):
    return float(re.search(what + r"[^\d-]*(-?[\d.e+-]+) deg", text, re.I)[1])


def export(tmp_path, doc, *args):
    m = tmp_path / "model.json"
    m.write_text(json.dumps(doc))
    return run_cli(
        "export", "--model", m, "--controller", "fanuc", "--tables", "--tables-dir", tmp_path, *args
    )


def test_a_turn_of_c_sums_to_zero_and_puts_the_axis_where_the_model_says(tmp_path):
    r = export(tmp_path, model_doc(), "--spacing", "10deg", "--fanuc-unit", "0.0001")
    assert r.returncode == EXIT_OK, r.stderr
    text = (tmp_path / "pitch_C.txt").read_text()
    params, data = read_pitch(text)
    ref = params[3620]
    assert params[3621] == ref and params[3622] == ref + 36 and params[3625] == 3600000
    assert params[3624] == 100000  # 10 deg in 0.0001 deg units
    assert sum(data[ref + k] for k in range(1, 37)) == 0 and data[ref] == data[ref + 36]
    unit = 0.0001 * params[3623]
    assert all(abs(v) <= 127 for v in data.values())
    t0 = stated(text, "the trim at the reference position")
    worst = stated(text, "worst error between points:")
    pos = np.linspace(-720.0, 720.0, 28801)[:-1] + 0.0131
    for mode in ("step", "linear"):
        motor = pos + compensation(params, data, pos, unit, mode)
        actual = motor + positioning_deg(motor)
        # The reference position's trim is not in a pitch table: the axis is off by it.
        residual = np.abs(actual - pos + t0)
        assert residual.max() <= worst + 1e-6, (mode, residual.max(), worst)
    assert np.abs(positioning_deg(pos) - positioning_deg(0.0)).max() > 5 * worst  # it does work
    # At the points, the running sum is the trim to half a unit.
    k = np.arange(0, 36)
    motor = k * 10.0 + compensation(params, data, k * 10.0, unit, "linear")
    assert np.abs(motor + positioning_deg(motor) - k * 10.0 + t0).max() <= 0.5 * unit + 1e-6
    assert "E_ZA" in r.stderr and "E_XC" in r.stderr  # error motions: not in a table


def test_a_tilt_range_uses_sections_on_both_sides_of_the_reference(tmp_path):
    doc = model_doc(effects=False)
    doc["effects"].append(
        {"id": "angular_positioning_A_h1", "params": {"a": {"value": 5e-5}, "b": {"value": 8e-5}}}
    )
    r = export(
        tmp_path, doc, "--spacing", "5", "--table-range", "A=-30,42", "--fanuc-first-number", "100"
    )
    assert r.returncode == EXIT_OK, r.stderr
    text = (tmp_path / "pitch_A.txt").read_text()
    params, data = read_pitch(text)
    assert params[3625] == 0 and params[3621] == 100 and min(data) == 100
    assert params[3620] - params[3621] == 5 and params[3622] - params[3620] == 9  # -30..45
    unit = 0.001 * params[3623]
    t0, worst = (
        stated(text, "trim at the reference position"),
        stated(text, "worst error between points:"),
    )

    def pos_a(a_deg):  # effects.md: actual A = A + a cos A + b sin A
        a = np.radians(a_deg)
        return np.degrees(5e-5 * np.cos(a) + 8e-5 * np.sin(a))

    pos = np.linspace(-30.0, 45.0, 3001)[:-1]
    for mode in ("step", "linear"):
        motor = pos + compensation(params, data, pos, unit, mode)
        assert np.abs(motor + pos_a(motor) - pos + t0).max() <= worst + 1e-6


def test_refusals_name_the_limit(tmp_path):
    r = export(tmp_path, model_doc(), "--spacing", "7deg")
    assert r.returncode == EXIT_INPUT and "divides 360" in r.stderr
    r = export(tmp_path, model_doc(), "--spacing", "0.5", "--fanuc-last-number", "500")
    assert r.returncode == EXIT_INPUT and "500" in r.stderr and "data numbers" in r.stderr
    r = export(
        tmp_path,
        model_doc(),
        "--fanuc-max-value",
        "1",
        "--fanuc-magnification",
        "1",
        "--fanuc-unit",
        "1e-4",
    )
    assert r.returncode == EXIT_INPUT and "3623" in r.stderr and "exceeds 1" in r.stderr
    r = export(tmp_path, model_doc(), "--spacing", "5", "--fanuc-unit", "0.003")
    assert r.returncode == EXIT_INPUT and "3624" in r.stderr
    assert not (tmp_path / "pitch_C.txt").exists()  # nothing written by a refused export
