# SPDX-License-Identifier: BSD-3-Clause
"""The controller's real-time evaluation (include/rotacal/realtime/) from the command line:
`rotacal export --controller realtime` writes the blob, `rotacal predict --joints` evaluates it
(or the model file) with the same C++ a controller runs, and the blob is refused by field."""

import json
import re
import struct
from pathlib import Path

import numpy as np
import pytest

import rotacal
from rotacal import _core
from rotacal import realtime

from conftest import run_cli

ROOT = Path(__file__).resolve().parents[2]
EXIT_INPUT = 3
NAMES = ["E_Y0A", "E_Z0A", "E_B0A", "E_C0A", "E_X0C", "E_Y0C", "E_A0C", "E_B0C"]
ERRORS = [0.03, -0.02, 5e-5, -4e-5, 0.015, 0.025, -3e-5, 6e-5]


def test_the_realtime_headers_need_eigen_and_the_standard_library_only():
    """Every file the real-time headers include, transitively: rotacal's own only from realtime/
    and the two kinematics headers of the shared formulas; system headers Eigen's or the
    standard library's (no Ceres, no JSON)."""
    allowed_own = {"kinematics/chain_stages.hpp", "kinematics/rotation.hpp"}
    todo = [
        p.relative_to(ROOT / "include/rotacal").as_posix()
        for p in (ROOT / "include/rotacal/realtime").glob("*.hpp")
    ]
    seen, bad = set(), []
    while todo:
        f = todo.pop()
        if f in seen:
            continue
        seen.add(f)
        text = (ROOT / "include/rotacal" / f).read_text()
        for own in re.findall(r'#include "rotacal/([^"]+)"', text):
            if not (own.startswith("realtime/") or own in allowed_own):
                bad.append(f"{f} includes rotacal/{own}")
            todo.append(own)
        for system in re.findall(r"#include <([^>]+)>", text):
            if not (system.startswith("Eigen/") or re.fullmatch(r"c?[a-z_]+", system)):
                bad.append(f"{f} includes <{system}>")
    assert not bad, "\n".join(bad)
    assert "kinematics/chain_stages.hpp" in seen  # the fits' formulas, not a copy


@pytest.fixture()
def model(tmp_path):
    d = {
        "format": "rotacal-model/1",
        "kind": "ballbar",
        "machine": "AC-trt",
        "source": {"session": "$(touch /tmp/pwned) `reboot` ; M30"},
        "location_errors": {
            n: {"value": v, "std": 1e-4, "unit": "rad" if n[2] in "ABC" else "mm"}
            for n, v in zip(NAMES, ERRORS)
        },
        "pivot": {k: {"value": 0.0, "std": 0.0, "unit": "mm"} for k in "xyz"},
    }
    path = tmp_path / "model.json"
    rotacal.save_model(d, path)
    return path


def _joints(tmp_path, n=50, seed=2):
    rng = np.random.default_rng(seed)
    j = np.column_stack(
        [rng.uniform(-150, 150, (n, 3)), rng.uniform(-90, 90, n), rng.uniform(-180, 180, n)]
    )
    path = tmp_path / "joints.csv"
    path.write_text("x,y,z,tilt,rot\n" + "".join(",".join(f"{v:.9f}" for v in r) + "\n" for r in j))
    return path, j


def test_predict_of_the_blob_is_the_model_files_and_the_fits_kinematics(model, tmp_path):
    blob = tmp_path / "model.rtb"
    r = run_cli("export", "--model", model, "--controller", "realtime", "-o", blob)
    assert r.returncode == 0, r.stderr
    assert b"pwned" not in blob.read_bytes() and b"AC-trt" not in blob.read_bytes()
    joints, j = _joints(tmp_path)
    outs = {}
    for name, m in (("blob", blob), ("file", model)):
        outs[name] = tmp_path / f"{name}.csv"
        r = run_cli("predict", "--joints", joints, "--model", m, "-o", outs[name])
        assert r.returncode == 0, r.stderr
    assert outs["blob"].read_text() == outs["file"].read_text()
    got = np.loadtxt(outs["blob"], delimiter=",", skiprows=1)
    j, tip, direction = got[:, :5], got[:, 5:8], got[:, 8:11]
    # The library's rigid kinematics (machine.hpp's forward, not the effects' stages the real-time
    # path runs) puts the tip back at the commanded X, Y, Z.
    at = _core.forward(_core.MachineType.AC_trt, np.array(ERRORS), np.radians(j[:, 3:]), tip)
    assert np.abs(at - j[:, :3]).max() < 1e-9
    # The spindle is the machine's Z.
    z = _core.forward(_core.MachineType.AC_trt, np.array(ERRORS), np.radians(j[:, 3:]), direction)
    z0 = _core.forward(
        _core.MachineType.AC_trt, np.array(ERRORS), np.radians(j[:, 3:]), np.zeros_like(direction)
    )
    assert np.abs(z - z0 - [0, 0, 1]).max() < 1e-12


def test_inverse_from_python_round_trips(model):
    m = realtime.load_realtime(model)
    rng = np.random.default_rng(4)
    world = np.column_stack(
        [rng.uniform(-150, 150, (200, 3)), rng.uniform(5, 90, 200), rng.uniform(-180, 180, 200)]
    )
    q, residual = realtime.inverse(m, world)
    tip, _ = realtime.forward(m, q)
    assert np.abs(tip - world[:, :3]).max() < 1e-5  # 0.01 um
    assert residual[:, 0].max() < 1e-5


@pytest.mark.parametrize(
    "damage, field",
    [
        (lambda b: b[:40] + bytes([b[40] ^ 1]) + b[41:], "checksum"),
        (lambda b: b[:-3], "length"),
        (lambda b: b[:8] + b"\x07" + b[9:], "version"),
        (lambda b: b"NOTABLOB" + b[8:], "magic"),
    ],
)
def test_a_damaged_blob_is_refused_naming_the_field(model, tmp_path, damage, field):
    blob = tmp_path / "model.rtb"
    assert (
        run_cli("export", "--model", model, "--controller", "realtime", "-o", blob).returncode == 0
    )
    bad = tmp_path / "bad.rtb"
    bad.write_bytes(damage(blob.read_bytes()))
    joints, _ = _joints(tmp_path, n=3)
    if field == "magic":  # not a blob at all: read as a model file, refused as one
        with pytest.raises(rotacal.Error):
            realtime.load_realtime(bad)
        return
    r = run_cli("predict", "--joints", joints, "--model", bad, "-o", tmp_path / "out.csv")
    assert r.returncode == EXIT_INPUT, r.stderr
    assert f"bad.rtb: {field}" in r.stderr
    assert not (tmp_path / "out.csv").exists()
    with pytest.raises(rotacal.ParseError, match="machine.*BC-trt"):
        _core.realtime_model_of_blob(blob.read_bytes(), _core.MachineType.BC_trt, str(blob))


def test_export_realtime_needs_an_output_and_no_other_controllers_options(model, tmp_path):
    r = run_cli("export", "--model", model, "--controller", "realtime")
    assert r.returncode == EXIT_INPUT and "-o FILE" in r.stderr
    r = run_cli(
        "export", "--model", model, "--controller", "realtime", "--json", "-o", tmp_path / "x"
    )
    assert r.returncode == EXIT_INPUT and "--json: not with --controller realtime" in r.stderr


def test_a_thermal_models_blob_carries_its_gains(fast_thermal_model, tmp_path):
    """export --controller realtime of a thermal model: the cold errors and the lag's gains in
    the blob's thermal_gain (column y1; y2 zero for one lag), so that rotacal-kins, fed y1 by the
    HAL chain, evaluates the errors E0 + K y1 (the model at export --state y1)."""
    blob = tmp_path / "thermal.rtb"
    r = run_cli("export", "--model", fast_thermal_model, "--controller", "realtime", "-o", blob)
    assert r.returncode == 0, r.stderr
    doc = json.loads(fast_thermal_model.read_text())
    gains = [doc["thermal"]["lags"][0]["gains"][n]["value"] or 0.0 for n in NAMES]
    cold = [doc["location_errors"][n]["value"] or 0.0 for n in NAMES]
    assert max(abs(g) for g in gains) > 1e-4  # mm per unit of u: gains to carry
    # The layout of realtime/blob.hpp's comment: header, machine..pivot, two axes, errors.
    offset = 20 + 18 + 2 * 195 + 8 * 8
    data = blob.read_bytes()
    assert list(struct.unpack_from("<8d", data, offset)) == gains
    assert struct.unpack_from("<8d", data, offset + 64) == (0.0,) * 8
    assert list(struct.unpack_from("<8d", data, offset - 64)) == cold
    # Evaluated at y1: the plain model of the errors at that state.
    y1 = 2.5
    at = tmp_path / "at.json"
    rotacal.save_model(
        {
            "format": "rotacal-model/1",
            "kind": "ballbar",
            "machine": "AC-trt",
            "location_errors": {
                n: {"value": c + g * y1, "std": 1e-6} for n, c, g in zip(NAMES, cold, gains)
            },
            "pivot": {k: {"value": 0.0, "std": 0.0, "unit": "mm"} for k in "xyz"},
        },
        at,
    )
    _, j = _joints(tmp_path)
    want, _ = realtime.forward(realtime.load_realtime(at), j)
    got, _ = realtime.forward(realtime.load_realtime(blob), j, y1=y1)
    cold_tip, _ = realtime.forward(realtime.load_realtime(blob), j)
    assert np.abs(got - want).max() < 1e-12
    assert np.abs(got - cold_tip).max() > 1e-3  # mm: the state moves the tip
    # The model file itself evaluates the same (rotacal predict --joints of a thermal model).
    direct, _ = realtime.forward(realtime.load_realtime(fast_thermal_model), j, y1=y1)
    assert np.abs(direct - got).max() == 0.0
