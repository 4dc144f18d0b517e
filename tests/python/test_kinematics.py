# SPDX-License-Identifier: BSD-3-Clause
"""Kinematics from Python: nominal forward transforms, shapes, machine names."""

import numpy as np
import pytest

import rotacal


def rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def test_forward_nominal_is_rx_rz():
    rng = np.random.default_rng(1)
    ang = rng.uniform(-1, 1, (10, 2))
    q = rng.uniform(-100, 100, (10, 3))
    p = rotacal.forward(rotacal.MachineType.AC_trt, np.zeros(8), ang, q)
    expected = np.array([rx(a) @ rz(c) @ qi for (a, c), qi in zip(ang, q)])
    np.testing.assert_allclose(p, expected, atol=1e-12)


def test_bad_shapes_raise_typed_error():
    with pytest.raises(rotacal.InvalidArgument, match="errors"):
        rotacal.forward(rotacal.MachineType.AC_trt, np.zeros(7), np.zeros((1, 2)), np.zeros((1, 3)))
    with pytest.raises(rotacal.InvalidArgument, match="same number of rows"):
        rotacal.forward(rotacal.MachineType.AC_trt, np.zeros(8), np.zeros((2, 2)), np.zeros((1, 3)))


def test_names_and_machine_parse():
    assert rotacal.location_error_names(rotacal.MachineType.BC_trt)[0] == "E_X0B"
    with pytest.raises(rotacal.InvalidArgument, match="ZZ-trt"):
        rotacal.parse_machine_type("ZZ-trt")
