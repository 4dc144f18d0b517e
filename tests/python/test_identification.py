# SPDX-License-Identifier: BSD-3-Clause
"""The one identification result (include/rotacal/core/identification.hpp) of the three
instruments' sessions in the shared data: the named parameter blocks are the parameters in
vector order, and each instrument's own part (pivot, sphere, probe zeros) is its block."""

import numpy as np
import pytest

import rotacal
from rotacal import _core
from conftest import truth

FILES = ["ballbar_ac_table2.csv", "probe_ac_table2.csv", "rtest_bc_oyama.csv"]


@pytest.fixture(scope="module", params=FILES)
def identified(request, shared_data):
    path = shared_data / request.param
    session = rotacal.load(path)
    return path, session.machine, rotacal.identify(session).raw


def test_the_blocks_are_the_parameters_in_vector_order(identified):
    _, machine, raw = identified
    assert isinstance(raw, _core.Identification)
    names = [p.name for b in raw.block_names for p in raw.block(b)]
    assert names == [p.name for p in raw.parameters]
    assert [p.name for p in raw.block("location_errors")] == list(
        _core.location_error_names(machine)
    )
    assert raw.parameter(names[0]).value == raw.parameters[0].value
    with pytest.raises(rotacal.InvalidArgument, match="no block named nothing"):
        raw.block("nothing")


def test_each_instruments_part_is_its_block(identified):
    path, _, raw = identified
    if isinstance(raw, _core.BallbarIdentification):
        pivot = [p.value for p in raw.block("pivot")]
        np.testing.assert_array_equal(pivot, raw.model.pivot)
    elif isinstance(raw, _core.ProbeIdentification):
        sphere = raw.block("sphere")
        np.testing.assert_array_equal([p.value for p in sphere], raw.sphere)
        # the block is the actual sphere centre of the independent simulator's truth
        for p, true in zip(sphere, truth(path)["sphere_actual"]):
            assert abs(p.value - true) <= 3 * p.std + 1e-9, (p, true)
    else:
        zeros = raw.block("zeros")
        assert len(zeros) == 3 * len(raw.probe_zeros)
        for p in zeros:  # "zero.<set-up>.<x|y|z>"
            _, setup, axis = p.name.split(".")
            assert p.value == raw.probe_zeros[setup]["xyz".index(axis)]
        # residuals: the flat dx dy dz per sample of the C++ result, (N, 3) in Python
        assert raw.residuals.shape == (raw.n_samples, 3)
