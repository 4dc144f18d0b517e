# SPDX-License-Identifier: BSD-3-Clause
"""The report of ISO 230-4 circular tests of the linear axes: G per run, G(b) and H per cw/ccw
pair, the polar plot and the named causes."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Iterable

from .page import escape as _e, head, img, png, write_page


def circular_report(
    path: str | Path,
    result: Any,
    title: str | None = None,
    source: str = "",
    inputs: Iterable[str] = (),
    extra_sections: Iterable[str] = (),
) -> Path:
    """The HTML report of a session of ISO 230-4 circular tests (rotacal.circular.analyze):
    G per run, G(b) and H per cw/ccw pair, the polar plot and the named causes."""
    from ..circular import polar_figure

    path = Path(path)
    d = result.to_dict()
    heading = title or "Circular tests of the linear axes (ISO 230-4)"
    parts = head(heading, heading, source)
    rows = [
        "<table><tr><th class=l>Run</th><th class=l>Plane</th><th class=l>Direction</th>"
        "<th>Feed (mm/min)</th><th>Span (deg)</th><th>Readings</th><th>G (&micro;m)</th>"
        "<th>Radius deviation (&micro;m)</th></tr>"
    ]
    for r in d["runs"]:
        rows.append(
            f"<tr><td class=l>{_e(r['label'])}</td><td class=l>{_e(r['plane'])}</td>"
            f"<td class=l>{_e(r['direction'])}</td><td>{r['feed_mm_per_min']:.0f}</td>"
            f"<td>{r['span_deg']:.1f}</td><td>{r['n']}</td><td>{r['G_um']:.2f}</td>"
            f"<td>{r['radius_deviation_um']:.2f}</td></tr>"
        )
    rows.append("</table>")
    parts.append(
        f'<section id="circular-deviation"><h2>Circular deviation G per run (bar length '
        f"{d['ballbar_length']:g} mm)</h2><p>G: the radial separation of the two circles about the "
        "least-squares centre that enclose the path (ISO 230-4).</p>" + "".join(rows)
    )
    if d["pairs"]:
        prs = [
            "<table><tr><th class=l>Plane</th><th>Feed (mm/min)</th><th>G(b) (&micro;m)</th>"
            "<th>H (&micro;m)</th><th>at (deg)</th></tr>"
        ]
        for q in d["pairs"]:
            prs.append(
                f"<tr><td class=l>{_e(q['plane'])}</td><td>{q['feed_mm_per_min']:.0f}</td>"
                f"<td>{q['G_b_um']:.2f}</td><td>{q['H_um']:.2f}</td><td>{q['H_angle_deg']:.1f}</td></tr>"
            )
        prs.append("</table>")
        parts.append(
            "<p>Bidirectional circular deviation G(b) and circular hysteresis H of each "
            "clockwise / counter-clockwise pair:</p>" + "".join(prs)
        )
    if d["ignored_tests"]:
        parts.append(
            f"<p class=warn>Not circular runs, ignored: {_e(', '.join(d['ignored_tests']))}</p>"
        )
    parts.append("</section>")
    parts.append('<section id="polar"><h2>Polar plot</h2>')
    parts.append(
        img(
            png(polar_figure(result)),
            "radial deviation of every run about its least-squares centre",
            "polar",
        )
    )
    parts.append("</section>")
    diag = d.get("diagnosis")
    if diag is not None:
        parts.append(
            '<section id="diagnosis"><h2>Causes (catalogue of docs/effects.md, circular tests)</h2>'
            f"<p>Residual RMS about each run's circle {diag['baseline_rms_um']:.2f} &micro;m; with the "
            f"findings {diag['final_rms_um']:.2f} &micro;m. Noise: {_e(diag['noise'])}.</p>"
        )
        if not diag["findings"]:
            parts.append("<p>No cause in the catalogue is supported by the data.</p>")
        else:
            fr = [
                "<table><tr><th class=l>Cause</th><th class=l>Parameters (1&sigma;)</th>"
                "<th>RMS before (&micro;m)</th><th>after</th></tr>"
            ]
            for f in diag["findings"]:
                ps = "; ".join(
                    f"{_e(p['name'].split('.')[-1])} = {p['value']:.4g} &plusmn; {p['std']:.2g} "
                    f"{_e(p['unit'])}"
                    for p in f["parameters"]
                )
                fr.append(
                    f"<tr><td class=l><b>{_e(f['effect'])}</b><br>{_e(f['cause'])}</td><td class=l>{ps}</td>"
                    f"<td>{f['gain']['rms_before_um']:.2f}</td><td>{f['gain']['rms_after_um']:.2f}</td></tr>"
                )
            fr.append("</table>")
            parts.append("".join(fr))
        if diag["unobservable"]:
            parts.append(
                "<p>Not determined by these runs:</p><ul>"
                + "".join(
                    f"<li>{_e(u['effect'])}: {_e(u['reason'])}</li>" for u in diag["unobservable"]
                )
                + "</ul>"
            )
        parts.append("</section>")
    parts.extend(extra_sections)
    return write_page(path, parts, inputs)
