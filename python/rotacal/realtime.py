# SPDX-License-Identifier: BSD-3-Clause
"""The controller's real-time evaluation of a fitted model, from Python: the forward and inverse
kinematics that ``include/rotacal/realtime/`` runs in a servo thread, on the same model blob
(``rotacal export --controller realtime``), so that what the controller runs is what the user
checked (``rotacal predict --joints``). The work is done in C++ (``realtime/evaluate.hpp``)."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from . import _core

BLOB_MAGIC = b"RCRTBLOB"
# A blob of the largest model is under 6 kB; anything much larger is not one.
MAX_BLOB_BYTES = 1 << 16
MAX_MODEL_BYTES = 1 << 26  # a model file's size bound for the peek at its kind


def is_blob(path: str | Path) -> bool:
    """True when the file starts with the blob's magic bytes."""
    with open(os.fspath(path), "rb") as f:
        return f.read(len(BLOB_MAGIC)) == BLOB_MAGIC


def is_thermal_model(path: str | Path) -> bool:
    """True for a model file of kind thermal (its gains go into the blob's thermal_gain)."""
    try:
        with open(os.fspath(path), "rb") as f:
            return json.loads(f.read(MAX_MODEL_BYTES)).get("kind") == "thermal"
    except (ValueError, OSError, AttributeError):
        return False  # not JSON or not readable: the C++ reader says what is wrong


def load_realtime(path: str | Path, machine: Any = None) -> Any:
    """A ``_core.RealtimeModel`` from a model file (every location error and effect) or from a
    blob; a blob is refused, naming the field, when it is corrupt, truncated, of another version
    or (``machine`` given) of another machine."""
    p = os.fspath(path)
    if not is_blob(p):
        return _core.realtime_model_of_file(p, thermal=is_thermal_model(p))
    with open(p, "rb") as f:
        data = f.read(MAX_BLOB_BYTES + 1)
    if len(data) > MAX_BLOB_BYTES:
        raise _core.ParseError(f"{p}: more than {MAX_BLOB_BYTES} bytes: not a model blob")
    return _core.realtime_model_of_blob(data, machine, p)


def joints_rad(joints_deg: np.ndarray) -> np.ndarray:
    """(N, 5) x, y, z (mm), tilt, rot (deg) -> the same with the angles in rad."""
    j = np.array(joints_deg, dtype=float, ndmin=2)
    j[:, 3:] = np.radians(j[:, 3:])
    return j


def forward(
    model: Any,
    joints_deg: np.ndarray,
    tool_length: float = 0.0,
    y1: float = 0.0,
    y2: float = 0.0,
    t: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """(tip (N, 3) mm, direction (N, 3)) relative to the workpiece for joints (N, 5): x, y, z
    (mm), tilt, rot (deg). ``tool_length``: spindle nose to tip (head machines) or tip below
    X, Y, Z (table machines); ``y1``, ``y2``: thermal lag states; ``t``: s."""
    return model.forward(joints_rad(joints_deg), tool_length, y1, y2, t)


def inverse(
    model: Any,
    world_deg: np.ndarray,
    tool_length: float = 0.0,
    y1: float = 0.0,
    y2: float = 0.0,
    t: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """(joints (N, 5) with angles in deg, residual (N, 2): tip mm, direction rad) that put the
    tool tip at world[:, :3] (workpiece frame, mm) along the nominal direction of the angles
    world[:, 3:] (deg)."""
    q, residual = model.inverse(joints_rad(world_deg), tool_length, y1, y2, t)
    q = np.array(q)
    q[:, 3:] = np.degrees(q[:, 3:])
    return q, np.asarray(residual)


JOINT_COLUMNS = ("x", "y", "z", "tilt", "rot")
MAX_JOINT_FILE_BYTES = 64 << 20


def read_joints(path: str | Path) -> np.ndarray:
    """(N, 5) joints of a CSV file whose header is ``x,y,z,tilt,rot`` (mm, deg); a row that is
    not five finite numbers is refused, naming the file and the line."""
    p = os.fspath(path)
    with open(p, "rb") as f:
        data = f.read(MAX_JOINT_FILE_BYTES + 1)
    if len(data) > MAX_JOINT_FILE_BYTES:
        raise _core.InvalidArgument(f"{p}: more than {MAX_JOINT_FILE_BYTES} bytes")
    try:
        lines = data.decode("utf-8").splitlines()
    except UnicodeDecodeError:
        raise _core.ParseError(f"{p}: not UTF-8") from None
    if not lines or tuple(c.strip() for c in lines[0].split(",")) != JOINT_COLUMNS:
        raise _core.ParseError(f"{p}:1: the header must be {','.join(JOINT_COLUMNS)} (mm, deg)")
    rows = []
    for n, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        cells = line.split(",")
        try:
            row = [float(c) for c in cells]
        except ValueError:
            row = []
        if len(row) != 5 or not all(np.isfinite(row)):
            raise _core.ParseError(f"{p}:{n}: expected five finite numbers")
        rows.append(row)
    return np.array(rows, dtype=float).reshape(-1, 5)


def joints_csv(joints_deg: np.ndarray, tip: np.ndarray, direction: np.ndarray) -> str:
    """The output of ``rotacal predict --joints``: the joints and the tool's tip and direction
    relative to the workpiece."""
    head = ",".join(JOINT_COLUMNS + ("tip_x", "tip_y", "tip_z", "dir_x", "dir_y", "dir_z"))
    body = np.column_stack([joints_deg, tip, direction])
    return head + "\n" + "".join(",".join(repr(float(v)) for v in r) + "\n" for r in body)
