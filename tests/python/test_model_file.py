# SPDX-License-Identifier: BSD-3-Clause
"""rotacal-model/1 files between the languages: what Python's standard json module writes the
C++ reader reads (as every file written before the C++ writer existed), and what the C++
writer writes Python's json module reads back, value for value; strict JSON, versions."""

import json
import math

import numpy as np
import pytest

import rotacal
from rotacal import _core


def _strict_loads(text):
    def refuse(token):
        raise AssertionError(f"non-standard JSON token {token}")

    return json.loads(text, parse_constant=refuse)


@pytest.fixture(scope="module")
def ballbar_fit(shared_data):
    s = rotacal.load(shared_data / "ballbar_ac_table2.csv")
    return s, rotacal.identify(s)


@pytest.fixture(scope="module")
def rtest_fit(shared_data):
    return rotacal.identify(rotacal.load(shared_data / "rtest_bc_oyama.csv"))


def test_python_written_ballbar_model_is_read_by_cpp(ballbar_fit, tmp_path):
    s, r = ballbar_fit
    d = r.model_dict()
    (tmp_path / "py.json").write_text(json.dumps(d, indent=2))  # the writer before C++ had one
    model = rotacal.ballbar_model_from_dict(rotacal.load_model(tmp_path / "py.json"), "py.json")
    names = list(_core.location_error_names(model.machine))
    np.testing.assert_array_equal(model.errors, [d["location_errors"][n]["value"] for n in names])
    np.testing.assert_array_equal(model.pivot, [d["pivot"][a]["value"] for a in "xyz"])
    # The model the C++ reader built predicts the fitted session to the fit's own residual.
    pred = rotacal.predict(model, s).length
    assert np.sqrt(np.mean((pred - s.length) ** 2)) * 1e3 == pytest.approx(
        r.to_dict()["residual_rms_um"], rel=1e-6
    )


def test_cpp_written_ballbar_model_is_read_by_python_json(ballbar_fit, tmp_path):
    _, r = ballbar_fit
    d = r.model_dict()
    rotacal.save_model(d, tmp_path / "cpp.json")
    back = _strict_loads((tmp_path / "cpp.json").read_text())
    assert back["format"] == "rotacal-model/1" and back["kind"] == "ballbar"
    for n, e in d["location_errors"].items():
        assert back["location_errors"][n]["value"] == e["value"]  # shortest round-trip digits
        assert back["location_errors"][n]["std"] == e["std"]
    assert back["pivot"] == d["pivot"]
    # A model built in C++ (no Python dict at all) is read by Python's json module.
    model = rotacal.ballbar_model_from_dict(back)
    doc = _core.ballbar_model_document(model)
    text = _core.format_model_document(doc)
    assert _strict_loads(text)["location_errors"] == doc["location_errors"]


def test_rtest_joint_model_both_ways(rtest_fit, tmp_path):
    d = rtest_fit.model_dict()
    (tmp_path / "py.json").write_text(json.dumps(d, indent=1))
    # Full C++ validation of a file written by Python's json module (basis, coefficients,
    # covariance shape and names, nests, probe zeros).
    full = _core.parse_model_document((tmp_path / "py.json").read_text(), "py.json")
    assert full["covariance"]["parameters"] == d["covariance"]["parameters"]
    rotacal.save_model(d, tmp_path / "cpp.json")
    back = _strict_loads((tmp_path / "cpp.json").read_text())
    np.testing.assert_array_equal(
        np.array(back["covariance"]["matrix"], dtype=float),
        np.array(d["covariance"]["matrix"], dtype=float),
    )
    assert back["map_coefficients"] == d["map_coefficients"]
    # The model read back from the C++-written file is the Python-written one's.
    assert (
        rotacal.load_model(tmp_path / "cpp.json")["location_errors"]
        == rotacal.load_model(tmp_path / "py.json")["location_errors"]
    )


def test_non_finite_numbers_become_null_with_a_reason(ballbar_fit, tmp_path):
    d = json.loads(json.dumps(ballbar_fit[1].model_dict()))
    d["location_errors"]["E_Y0A"]["std"] = math.inf
    d["fit_note"] = {"chi2": math.nan}
    rotacal.save_model(d, tmp_path / "m.json")
    text = (tmp_path / "m.json").read_text()
    back = _strict_loads(text)
    assert back["location_errors"]["E_Y0A"]["std"] is None
    assert back["null_reasons"]["/location_errors/E_Y0A/std"].startswith("+Infinity")
    assert back["null_reasons"]["/fit_note/chi2"].startswith("NaN")
    # A file with a NaN token (not JSON) is refused naming file, line and column.
    (tmp_path / "nan.json").write_text(text.replace('"std": null', '"std": NaN', 1))
    with pytest.raises(rotacal.ParseError, match=r"nan\.json:\d+:\d+: not valid JSON"):
        rotacal.load_model(tmp_path / "nan.json")


@pytest.mark.parametrize(
    "change,match",
    [
        (lambda d: d.update(format="rotacal-model/2"), "newer rotacal"),
        (lambda d: d["location_errors"]["E_Y0C"].update(unit="um"), r"E_Y0C\.unit"),
        (lambda d: d["location_errors"]["E_Y0C"].update(value=1e300), "no machine tool"),
        (lambda d: d.update(machine="BC-trt"), "location_errors lacks"),
    ],
)
def test_bad_models_refused(ballbar_fit, tmp_path, change, match):
    d = json.loads(json.dumps(ballbar_fit[1].model_dict()))
    change(d)
    (tmp_path / "bad.json").write_text(json.dumps(d))
    with pytest.raises(rotacal.InvalidArgument, match=match):
        rotacal.ballbar_model_from_dict(rotacal.load_model(tmp_path / "bad.json"), "bad.json")
    with pytest.raises(rotacal.InvalidArgument, match=match):
        rotacal.save_model(d, tmp_path / "out.json")  # never writes what it could not read back
    assert not (tmp_path / "out.json").exists()


def test_model_file_paths(tmp_path):
    with pytest.raises(rotacal.IoError, match="directory"):
        rotacal.load_model(tmp_path)
    with pytest.raises(rotacal.IoError):
        rotacal.load_model(tmp_path / "missing.json")
