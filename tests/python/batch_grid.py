# SPDX-License-Identifier: BSD-3-Clause
"""A small Monte Carlo grid for the batch tests: item (file, noise_um) is the independent
simulator's session (../shared/data) with white noise drawn from the item's own seed, identified
(joint, no budget). Importable by name on a Dask worker whose PYTHONPATH holds this folder."""

from __future__ import annotations

import numpy as np


def noisy_identification(item: tuple, seed: np.random.SeedSequence) -> dict:
    """The location errors fitted to the item's session plus its noise, to full float."""
    import rotacal

    path, noise_um = item
    s = rotacal.load(path)
    rng = np.random.default_rng(seed)
    noisy = s.with_lengths(np.asarray(s.length) + rng.normal(0.0, noise_um * 1e-3, len(s.length)))
    result = rotacal.identify(noisy, "joint", noise="white")
    return {k: v["value"] for k, v in result.to_dict()["location_errors"].items()}


def grid(files: list, n: int) -> list:
    """n items over the files, two noise levels."""
    return [(str(files[i % len(files)]), (0.5, 2.0)[i % 2]) for i in range(n)]


def process_id(item, seed) -> int:
    """Which process ran the item."""
    import os

    return os.getpid()
