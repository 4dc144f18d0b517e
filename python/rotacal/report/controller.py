# SPDX-License-Identifier: BSD-3-Clause
"""The report's compensation section (``rotacal report --controller NAME``): for the chosen
controller, what its kinematic parameters and its tables will correct, and what remains for
``rotacal compensate``, each term with its size over the travel. The numbers come from the
export itself (``rotacal export``, ``--tables``) run on the report's model, so the section says
what those files hold."""

from __future__ import annotations

import json
import os
import re
import tempfile
from typing import Any

import numpy as np

from .. import _core
from ..exports import controller_tables, export_controller
from .page import escape as _e

TABLE_CONTROLLERS = ("linuxcnc", "siemens", "isg", "fanuc")


def _size(value: float, unit: str) -> str:
    return f"{value * 1e3:.2f} &micro;m" if unit == "mm" else f"{value * 1e6:.2f} &micro;rad"


def _term_rows(model_path: str, tables: Any) -> list[tuple[str, str, str]]:
    """(term, its largest size over a turn, where) of each error motion of the table axes."""
    written = tables.tables if tables else []
    in_table = {t.axis: os.path.basename(t.file_name) for t in written if not t.value_mm}
    # Cross tables (SINUMERIK CEC, ISG kw.crosscomp): E_<output><axis> by (axis, output).
    crossed = {(t.axis, o): os.path.basename(t.file_name) for t in written for o in t.value_mm}
    rows = []
    for m in _core.angle_maps(model_path, -180.0, 180.0, 5.0):
        values = np.abs(np.asarray(m.values))
        for j, (name, unit) in enumerate(zip(m.names, m.units)):
            largest = float(values[:, j].max()) if len(values) else 0.0
            if largest == 0.0 or name == f"E_{m.axis}{m.axis}":  # that one is positioning_
                continue
            if name.startswith("positioning_") and m.axis in in_table:
                where = f"table {in_table[m.axis]}"
            elif (m.axis, name[2]) in crossed and name[2] in "XYZ":
                where = f"table {crossed[(m.axis, name[2])]}"
            else:
                where = "left to rotacal compensate"
            rows.append((name, _size(largest, unit), where))
    # A rotary axis' cross tables hold at tilt 0 only: what remains of them over the tilt range.
    for n in tables.not_held if tables else []:
        m = re.match(r"(.+ away from .+?): up to ([\d.]+) um", n)
        if m:
            rows.append((m[1], f"{float(m[2]):.2f} &micro;m", "left to rotacal compensate"))
    return rows


def controller_section(model: dict, controller: str) -> str:
    """The HTML section of ``model`` (a model file's dict) loaded into ``controller``."""
    with tempfile.TemporaryDirectory(prefix="rotacal_report_") as d:
        path = os.path.join(d, "model.json")
        with open(path, "w") as f:
            json.dump(model, f)
        ex = export_controller(path, controller)
        tables, no_table = None, ""
        if controller in TABLE_CONTROLLERS:
            try:
                tables = controller_tables(path, controller, d)
            except _core.InvalidArgument as e:  # no positioning error: nothing for a table
                no_table = str(e)
        rows = [
            (
                e.name,
                _size(abs(e.value), "mm" if e.name[2] in "XYZUV" else "rad")
                if e.observable
                else "not determined",
                f"kinematics: {e.where}" if e.held else "left to rotacal compensate",
            )
            for e in ex.errors
        ] + _term_rows(path, tables)
    remains = [r for r in rows if r[2] == "left to rotacal compensate" and r[1] != "not determined"]
    out = [
        f'<section id="controller"><h2>Compensation in the controller: {_e(controller)} '
        f"({_e(ex.kinematics)})</h2>",
        "<p>What <code>rotacal export --model MODEL --controller "
        f"{_e(controller)}{' --tables' if tables else ''}</code> writes from this report's model, "
        "and what remains for <code>rotacal compensate</code>. Sizes: the location errors' values, "
        "and each error motion's largest value over a turn of its axis.</p>",
        "<table><tr><th class=l>Term</th><th>Size</th><th class=l>Corrected by</th></tr>",
    ]
    out += [
        f"<tr><td class=l>{_e(n)}</td><td>{s}</td><td class=l>{_e(w)}</td></tr>" for n, s, w in rows
    ]
    out.append("</table>")
    if no_table:
        out.append(f"<p>No table: {_e(no_table)}</p>")
    out.append(
        "<p>Remains after loading: "
        + (", ".join(f"{_e(n)} {s}" for n, s, _ in remains) or "nothing")
        + ".</p></section>"
    )
    return "\n".join(out)
