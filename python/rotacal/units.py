# SPDX-License-Identifier: BSD-3-Clause
"""How a parameter of each native unit is shown to a person: um and urad beside the tables,
not mm and rad. The library computes in mm, rad and s; effects bring other units (a servo lag
in s, a log time constant in 1, a drift in mm/s)."""

from __future__ import annotations

# native unit -> (factor, shown unit)
SHOWN = {
    "rad": (1e6, "urad"),
    "mm": (1e3, "um"),
    "s": (1e3, "ms"),
    "mm/s": (1e3, "um/s"),
    "rad/rad": (1e6, "urad/rad"),
    "mm/mm": (1e6, "um/m"),
    "1": (1.0, ""),
}


def shown(unit: str) -> tuple[float, str]:
    """(factor, shown unit) for a native unit; an unknown unit is shown as it is."""
    return SHOWN.get(unit, (1.0, unit))


def estimate_text(value: float | None, std: float | None, unit: str) -> str:
    """'4.21 +- 0.28 um' for a value and 1-sigma in native units; 'unobservable' for None."""
    if value is None:
        return "unobservable"
    factor, u = shown(unit)
    sigma = "" if std is None else f" +- {std * factor:.2g}"
    return f"{value * factor:.4g}{sigma}{(' ' + u) if u else ''}"
