# SPDX-License-Identifier: BSD-3-Clause
"""The report of a thermal test (issue 53, item 6; docs/thermal.md): the duty, and each
location error's measured epochs (the per-epoch peer's values, +- 1 sigma, for a touch-probe
session) against the joint model over the test (its cold value + gain x lag state, +- 1
sigma), one panel each under the duty so that a drift is read against the turning that made
it; then the summary (tau, steady-state change, significance, time to a tolerance) and the
cold errors. C++ computes (identify_thermal, predict_thermal); this module draws."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path
from typing import Iterable

import numpy as np

from .page import escape as _e, head, img, png, write_page
from .sections import error_words, location_error_table

# Model curve points over the test (the lag's shape is smooth: a few hundred suffice).
CURVE_POINTS = 400


def thermal_report(
    out: str | Path,
    session: str,
    *,
    tolerance_mm: float | None = None,
    tolerance_rad: float | None = None,
    inputs: Iterable[str] = (),
    extra_sections: Iterable[str] = (),
) -> Path:
    """Write the HTML report of the thermal session ``session`` (one lag)."""
    from .. import _core

    with open(session, encoding="utf-8", errors="replace") as f:
        probe = "rotacal-probe/" in f.readline()  # the format line (formats.md)
    d = _core.identify_thermal(session, 1, tolerance_mm, tolerance_rad, peer=probe, model=True)
    model = d["model"]
    heat = model["thermal"]["test_heat_input"]
    epochs = d["peer"]["identification"]["epochs"] if probe else None
    t_end = max(heat["start_s"][-1], max(epochs["t_mid_s"]) if epochs else 0.0)
    times = list(np.linspace(0.0, t_end, CURVE_POINTS))
    with tempfile.TemporaryDirectory(prefix="rotacal_thermal_") as tmp:
        path = Path(tmp) / "model.json"
        path.write_text(json.dumps(model))
        curve = _core.predict_thermal(str(path), session, times)
    ident, summary = d["identification"], d["summary"]
    parts = head(
        f"rotacal thermal report: {Path(session).name}",
        f"Thermal test of axis {summary['axis']} ({ident['machine']})",
        session,
    )
    parts.append(
        f"<p>{ident['n_samples']} rows in {ident['n_epochs']} epochs; tested speed "
        f"{summary['tested_speed_rpm']:g} rev/min; residual RMS {ident['residual_rms_um']:.3f} "
        f"&micro;m{'' if ident['converged'] else ' <b class=warn>(not converged)</b>'}.</p>"
    )
    parts.append("<h2>Drift over the test</h2>")
    caption = (
        "the duty (top), then each location error: the joint model (line, +- 1 sigma band)"
        + (" and each epoch identified alone (points, +- 1 sigma)" if epochs else "")
    )
    parts.append(img(png(_drift_figure(heat, curve, epochs)), caption, "thermal"))
    if not epochs:
        parts.append(
            "<p class=muted>The per-epoch values are drawn for touch-probe sessions (the "
            "per-epoch peer); an R-test session shows the model alone.</p>"
        )
    parts.append("<h2>Lags and steady-state change</h2>")
    parts.append(_summary_table(summary))
    parts.append("<h2>Cold location errors</h2>")
    parts.append(location_error_table(model["location_errors"]))
    if ident["notes"] or ident["unobservable"]:
        parts.append(
            "<ul class=muted>"
            + "".join(f"<li>{_e(n)}</li>" for n in ident["unobservable"] + ident["notes"])
            + "</ul>"
        )
    parts.extend(extra_sections)
    return write_page(Path(out), parts, inputs)


def _scale(unit: str) -> tuple[float, str]:
    return (1e3, "um") if unit == "mm" else (1e6, "urad")


def _drift_figure(heat: dict, curve: dict, epochs: dict | None):
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(10, 11))
    grid = fig.add_gridspec(5, 2, height_ratios=[0.7, 1, 1, 1, 1], hspace=0.45)
    duty = fig.add_subplot(grid[0, :])
    hours = np.asarray(curve["times_s"]) / 3600.0
    start = np.asarray(heat["start_s"]) / 3600.0
    speed = 100.0 * np.asarray(heat["u"])  # u = speed / 100 rev/min (effects.md)
    duty.step(np.append(start, hours[-1]), np.append(speed, speed[-1]), where="post", color="C3")
    duty.set_ylabel("rev/min")
    duty.set_title("duty: speed of the heated axis (0 in the epochs)", fontsize=9)
    series = {s["name"]: s for s in epochs["series"]} if epochs else {}
    for k, e in enumerate(curve["errors"]):
        ax = fig.add_subplot(grid[1 + k // 2, k % 2], sharex=duty)
        f, unit = _scale(e["unit"])
        v, s = np.asarray(e["value"]) * f, np.asarray(e["std"]) * f
        ax.plot(hours, v, color="C0", lw=1.2)
        ax.fill_between(hours, v - s, v + s, color="C0", alpha=0.25, lw=0)
        m = series.get(e["name"])
        if m is not None:
            t = np.asarray(epochs["t_mid_s"]) / 3600.0
            known = [i for i, x in enumerate(m["value"]) if x is not None]
            ax.errorbar(
                t[known],
                np.asarray([m["value"][i] for i in known]) * f,
                yerr=np.asarray([m["std"][i] for i in known]) * f,
                fmt=".",
                ms=3,
                color="k",
                elinewidth=0.8,
            )
        ax.set_title(f"{e['name']} ({error_words(e['name'])})", fontsize=8)
        ax.set_ylabel(unit, fontsize=8)
        ax.tick_params(labelsize=7)
        if k >= 6:
            ax.set_xlabel("time from the first row (h)", fontsize=8)
    return fig


def _summary_table(s: dict) -> str:
    rows = []
    for k, lag in enumerate(s["lags"], start=1):
        tau = (
            f"{lag['tau_s'] / 60:.1f} &plusmn; {lag['tau_std_s'] / 60:.1f} min"
            if lag["observable"]
            else "unobservable"
        )
        rows.append(f"<p>Lag {k}: &tau; = {tau}</p>")
    rows.append(
        "<table><tr><th class=l>Error</th><th>Steady-state change</th><th>1&sigma;</th>"
        "<th>Unit</th><th class=l>Drift</th><th class=l>Tolerance reached after</th></tr>"
    )
    for e in s["drifts"]:
        f, unit = _scale(e["unit"])
        if not e["observable"]:
            rows.append(
                f"<tr><td class=l>{_e(e['name'])}</td><td colspan=5 class=l>unobservable: "
                f"{_e(e['reason'])}</td></tr>"
            )
            continue
        after = e.get("exceeds_after_s", "")
        after = "" if after == "" else "never" if after is None else f"{after / 60:.1f} min"
        rows.append(
            f"<tr><td class=l>{_e(e['name'])}</td><td>{e['steady_change'] * f:+.2f}</td>"
            f"<td>{e['steady_std'] * f:.2f}</td><td>{unit}</td><td class=l>"
            f"{'significant' if e['significant'] else 'no significant drift'}</td>"
            f"<td class=l>{after}</td></tr>"
        )
    rows.append("</table>")
    return "\n".join(rows)
