# SPDX-License-Identifier: BSD-3-Clause
"""Table 2 of Flynn et al. (2016), as printed: the shipped file read strictly, each number as
the paper prints it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import _core

TABLE2_PATH = Path(__file__).resolve().parent.parent / "data" / "flynn2016_table2.json"
NAMES = ("E_Y0A", "E_Z0A", "E_B0A", "E_C0A", "E_X0C", "E_Y0C", "E_A0C", "E_B0C")
# Location errors in mm (positions) and rad (orientations), shown in um and urad.
SCALE = np.array([1e3, 1e3, 1e6, 1e6, 1e3, 1e3, 1e6, 1e6])
UNIT = ["um", "um", "urad", "urad", "um", "um", "urad", "urad"]


def _printed_float(text: str, where: str) -> float:
    """A number as Table 2 prints it: '1.1284 E-5' (space before the exponent), '(183.231)'."""
    t = text.replace(" ", "").strip("()")
    try:
        v = float(t)
    except ValueError:
        raise _core.InvalidArgument(
            f"{where}: '{text}' is not a number as printed in Table 2"
        ) from None
    if not math.isfinite(v):
        raise _core.InvalidArgument(f"{where}: '{text}' is not finite")
    return v


def load_table2(path: str | Path | None = None, reading: str = "printed") -> dict:
    """Table 2 of Flynn et al. (2016): {"source": ..., "rows": [{"name", "unit", "before",
    "after", "printed": {...}}]} with values in mm and rad, in location_error_names order.

    reading : "printed" (default) takes every value as printed; "percent_consistent" takes,
        for the two rows whose printed values disagree with the paper's own '% Inc.' column
        (E_B0A, E_C0A; see the file's notes), the reading that reproduces that column.

    Raises rotacal.IoError if the file cannot be read, rotacal.ParseError if it is not the
    table, rotacal.InvalidArgument for a value that is not a number.
    """
    from ..jsonfile import read_json

    p = Path(path) if path is not None else TABLE2_PATH
    d, _ = read_json(p)  # strict and bounded: deep nesting is a ParseError, not a RecursionError
    if not isinstance(d, dict):
        raise _core.ParseError(f"{p}: Table 2 is a JSON object with 'rows'")
    if reading not in ("printed", "percent_consistent"):
        raise _core.InvalidArgument(
            f"load_table2: reading must be 'printed' or 'percent_consistent', got {reading!r}"
        )
    rows = d.get("rows")
    if not isinstance(rows, list) or [r.get("name") for r in rows] != list(NAMES):
        raise _core.ParseError(
            f"{p}: 'rows' must hold the 8 location errors in the order {', '.join(NAMES)}"
        )
    out = []
    for i, r in enumerate(rows):
        where = f"{p}: rows[{i}] ({r['name']})"
        unit = "mm" if i % 4 < 2 else "rad"
        if r.get("unit") != unit:
            raise _core.ParseError(f"{where}: unit must be '{unit}', got {r.get('unit')!r}")
        alt = r.get("percent_consistent", {}) if reading == "percent_consistent" else {}
        out.append(
            {
                "name": r["name"],
                "unit": unit,
                "before": _printed_float(
                    str(alt.get("uncompensated", r["uncompensated"])), where + " uncompensated"
                ),
                "after": _printed_float(
                    str(alt.get("compensated", r["compensated"])), where + " compensated"
                ),
                "printed": {k: r[k] for k in ("uncompensated", "compensated", "change_percent")},
            }
        )
    return {
        "source": d.get("source", {}),
        "machine": d.get("machine", "AC-trt"),
        "reading": reading,
        "notes": d.get("notes", []),
        "rows": out,
    }
