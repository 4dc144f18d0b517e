# SPDX-License-Identifier: BSD-3-Clause
"""The history of a machine as figures: a PNG of each location error over time, an HTML
section for `rotacal report --history`, a page for `history show --plot`."""

from __future__ import annotations

import datetime
from pathlib import Path
from typing import Sequence

from .. import _core


def write_plot(summary: dict, path: str, inputs: Sequence[str] = ()) -> None:
    """The history as figures: each observable location error over time, the machine's own
    value with its 1-sigma band, corrections as vertical lines, flagged changes in red. A .png
    file, or a .html page with the figure and the flags, written by the output rule."""
    from ..outputs import check_output, write_output

    suffix = Path(path).suffix.lower()
    if suffix not in (".png", ".html", ".htm"):
        raise _core.InvalidArgument(f"--plot: {path}: give a .png or .html file")
    check_output(path, inputs)
    if suffix == ".png":
        write_output(path, _history_png(summary), inputs)
        return
    import html

    e = lambda t: html.escape(str(t), quote=True)  # noqa: E731
    page = (
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>History of {e(summary['machine_id'])}"
        f"</title></head><body>{history_section(summary)}</body></html>"
    )
    write_output(path, page, inputs)


def history_section(summary: dict) -> str:
    """The history as an HTML section (figure and flagged changes), for ``history show --plot
    X.html`` and ``rotacal report --history``. Every text from the store is escaped."""
    import base64
    import html

    png = _history_png(summary)
    e = lambda t: html.escape(str(t), quote=True)  # noqa: E731
    rows = "".join(
        f"<tr><td>{e(f['name'])}</td><td>{e(f['from_at'])}</td><td>{e(f['to_at'])}</td>"
        f"<td>{f['change'] * _scale(f['unit']):+.3f}</td><td>{_fmt_opt(f['expanded_uncertainty'], f['unit'])}</td>"
        f"<td>{_fmt_opt(f['tolerance'], f['unit'])}</td><td>{e(', '.join(f['why']))}</td></tr>"
        for f in summary["flags"]
    )
    return (
        f"<section id='history'><h2>Calibration history of {e(summary['machine_id'])} "
        f"({e(summary['machine_type'])})</h2><p>{summary['identifications']} identifications, "
        f"{len(summary['corrections'])} corrections. Values are the machine's own (measured + compensation "
        f"loaded); bands 1-sigma.</p><img alt='location errors over time' "
        f"src='data:image/png;base64,{base64.b64encode(png).decode('ascii')}'>"
        f"<h2>Changes flagged</h2><table border=1 cellpadding=3><tr><th>error</th><th>from</th><th>to</th>"
        f"<th>change (um/urad)</th><th>U, k=2</th><th>tolerance</th><th>why</th></tr>{rows}</table>"
        "</section>"
    )


def _scale(unit: str) -> float:
    return 1e3 if unit == "mm" else 1e6


def _fmt_opt(v: float | None, unit: str) -> str:
    return "-" if v is None else f"{v * _scale(unit):.3f}"


def _history_png(summary: dict) -> bytes:
    import io
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.dates as mdates
    import matplotlib.pyplot as plt

    names = [n for n, d in summary["location_errors"].items() if d["points"]]
    if not names:
        raise _core.InvalidArgument(
            f"{summary['machine_id']}: no observable location error to plot"
        )

    def when(at: str) -> datetime.datetime:
        return datetime.datetime.strptime(at, "%Y-%m-%dT%H:%M:%SZ")

    cols = 2
    rows = (len(names) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(11, 2.6 * rows), sharex=True, squeeze=False)
    for ax, name in zip(axes.flat, names):
        d = summary["location_errors"][name]
        k = _scale(d["unit"])
        t = [when(p["at"]) for p in d["points"]]
        v = [p["value"] * k for p in d["points"]]
        s = [(p["std"] or 0.0) * k for p in d["points"]]
        ax.fill_between(
            t,
            [a - b for a, b in zip(v, s)],
            [a + b for a, b in zip(v, s)],
            color="C0",
            alpha=0.25,
            linewidth=0,
        )
        ax.plot(t, v, "o-", color="C0", markersize=3, linewidth=1)
        for c in summary["corrections"]:
            if name in c["amounts"]:
                ax.axvline(when(c["at"]), color="C2", linestyle="--", linewidth=1)
        by_entry = {p["entry"]: p for p in d["points"]}
        hit = [
            by_entry[st["to"]]
            for st in d["steps"]
            if st["exceeds_uncertainty"] or st["exceeds_tolerance"]
        ]
        if hit:
            ax.plot(
                [when(p["at"]) for p in hit],
                [p["value"] * k for p in hit],
                "o",
                color="red",
                markersize=5,
            )
        dr = d["drift_per_month"]
        title = name + (f"  drift {dr['value'] * k:+.3f}/month" if dr else "")
        ax.set_title(title, fontsize=9)
        ax.set_ylabel("um" if d["unit"] == "mm" else "urad")
        ax.xaxis.set_major_formatter(mdates.ConciseDateFormatter(ax.xaxis.get_major_locator()))
    for ax in list(axes.flat)[len(names) :]:
        ax.set_visible(False)
    shown_id = str(summary["machine_id"]).replace("$", r"\$")  # never read as mathtext
    fig.suptitle(
        f"{shown_id} ({summary['machine_type']}): 1-sigma band, corrections dashed green, "
        "changes beyond k=2 or tolerance red",
        fontsize=10,
    )
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    return buf.getvalue()
