# SPDX-License-Identifier: BSD-3-Clause
"""The poses `plan probe` plans: `--poses` and the JSON of `design probe --json` given as
`--design`, both within one set of bounds (issue 57, class 4): angles within +-720 deg, at most
MAX_POSES poses and MAX_TOUCHES touches, the sphere within +-1e4 mm; the design file read by the
strict, bounded JSON reader (rotacal.jsonfile), each value checked before any work."""

from __future__ import annotations

import argparse

import numpy as np

from .options import OptionError, numbers

# The bounds of a planned pattern, the same for --poses and --design: the angles of --poses
# (+-720 deg), the sphere of --sphere (+-1e4 mm) and the touch cap of `design probe --touches`
# (100,000; 5 per pose at the least, so 20,000 poses).
MAX_ANGLE_DEG, MAX_SPHERE_MM, MAX_TOUCHES = 720.0, 1e4, 100_000
MAX_POSES = MAX_TOUCHES // 5


def _capped_poses(rows: list, what: str) -> np.ndarray:
    if not rows:
        raise OptionError(f"{what}: no pose given (TILT,ROT;TILT,ROT;... deg)")
    if len(rows) > MAX_POSES:
        raise OptionError(f"{what}: {len(rows)} poses, more than the {MAX_POSES} a plan may hold")
    return np.asarray(rows, float)


def poses_option(text: str | None) -> np.ndarray | None:
    """--poses "TILT,ROT;TILT,ROT;..." (deg) -> (P, 2), or None for the default poses."""
    if text is None:
        return None
    items = [item for item in text.split(";") if item.strip()]
    if len(items) > MAX_POSES:  # before parsing them all
        raise OptionError(f"--poses: {len(items)} poses, more than the {MAX_POSES} a plan may hold")
    return _capped_poses([numbers("--poses", 2, MAX_ANGLE_DEG, "deg")(i) for i in items], "--poses")


def _finite_rows(value, width: int, limit: float, where: str, unit: str) -> list:
    """A JSON list of lists of `width` numbers, each finite within +-limit."""
    if not isinstance(value, list):
        raise OptionError(
            f"{where}: must be a list of [{width} numbers], got {type(value).__name__}"
        )
    rows = []
    for i, row in enumerate(value):
        if (
            not isinstance(row, list)
            or len(row) != width
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in row)
        ):
            raise OptionError(f"{where}[{i}]: must be a list of {width} numbers")
        if not all(abs(v) <= limit for v in row):
            raise OptionError(f"{where}[{i}]: {row} is outside +-{limit:g} {unit}")
        rows.append([float(v) for v in row])
    return rows


def design_file(a: argparse.Namespace) -> tuple[np.ndarray, list]:
    """--design FILE: the poses, each pose's directions and the sphere of `design probe --json`
    (its "best"); the sphere into a.sphere unless --sphere is given. Read by the strict, bounded
    JSON reader (rotacal.jsonfile), each value checked as --poses and --sphere check theirs."""
    from ..jsonfile import read_json

    if a.poses is not None:
        raise OptionError("--design: give --poses or --design, not both")
    where = f"--design {a.design}"
    doc, _ = read_json(a.design, "--design")
    best = doc.get("best", doc) if isinstance(doc, dict) else None
    if not isinstance(best, dict) or "poses_deg" not in best:
        raise OptionError(f"{where}: not the JSON of rotacal design probe --json (no poses_deg)")
    poses_deg = best["poses_deg"]
    if isinstance(poses_deg, list) and len(poses_deg) > MAX_POSES:
        raise OptionError(
            f"{where}: {len(poses_deg)} poses, more than the {MAX_POSES} a plan may hold"
        )
    poses = _capped_poses(
        _finite_rows(poses_deg, 2, MAX_ANGLE_DEG, f"{where}: poses_deg", "deg"), where
    )
    directions = best.get("pose_directions", [])
    if not isinstance(directions, list):
        raise OptionError(f"{where}: pose_directions must be a list")
    dirs = [
        np.asarray(_finite_rows(d, 3, 1.0, f"{where}: pose_directions[{k}]", ""), float).reshape(
            -1, 3
        )
        for k, d in enumerate(directions)
    ]
    if dirs and len(dirs) != len(poses):
        raise OptionError(f"{where}: {len(dirs)} direction lists for {len(poses)} poses")
    if sum(len(d) for d in dirs) > MAX_TOUCHES:
        raise OptionError(f"{where}: more than the {MAX_TOUCHES} touches a plan may hold")
    sphere = best.get("sphere")
    if sphere is not None:
        sphere = _finite_rows([sphere], 3, MAX_SPHERE_MM, f"{where}: sphere", "mm")[0]
    if a.sphere is None and sphere is not None:
        a.sphere = np.asarray(sphere, float)
    return poses, dirs
