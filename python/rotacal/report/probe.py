# SPDX-License-Identifier: BSD-3-Clause
"""The report of a touch-probe session (set-up, location errors of the model the diagnosis
extended where it found an effect, the sphere, noise model and budget, residuals per touch and
the diagnosis) and of one identification from several sessions (the shared location errors
beside each session's alone, the disagreements, each session's own parameters and noise)."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Iterable

import numpy as np

from .page import escape as _e, head, img, write_page
from .sections import (
    diagnosis_section,
    fitted_effects_table,
    location_error_table,
    machine_words,
    noise_budget_section,
    residual_plot,
)


def _fitted_along(d: dict) -> str:
    """The parameters a probe fit carries besides the location errors and the sphere (effects of
    the extended model, tool_offset_Z on a machine with head axes), as fitted_effects_table shows them."""
    from .. import _core

    effects: dict[str, dict] = {}
    for name, p in d.get("other_parameters", {}).items():
        if name.startswith("sphere."):
            continue
        eid, _, pname = name.partition(".")
        try:
            cause = _core.Effect(eid).cause
        except _core.InvalidArgument:
            cause = ""
        effects.setdefault(eid, {"id": eid, "cause": cause, "params": {}})["params"][
            pname or eid
        ] = p
    return fitted_effects_table(list(effects.values()))


def _notes(d: dict, what: str) -> list[str]:
    parts = []
    if d["unobservable"]:
        parts.append(
            f"<p class=warn>Not determined by {_e(what)}:</p><ul>"
            + "".join(f"<li>{_e(u)}</li>" for u in d["unobservable"])
            + "</ul>"
        )
    if d.get("notes"):
        parts.append(
            "<ul class=muted>" + "".join(f"<li>{_e(n)}</li>" for n in d["notes"]) + "</ul>"
        )
    return parts


def probe_report(
    path: str | Path,
    session: Any,
    identification: Any,
    diagnosis: Any | None = None,
    source: str = "",
    extra_sections: Iterable[str] = (),
    inputs: Iterable[str] = (),
) -> Path:
    """Write the HTML report of a touch-probe session (by the output rule; ``inputs`` are
    refused as the target). Where the diagnosis found an effect, the location errors are those
    of the model extended by it (rotacal.identify_probe with its effects), the baseline's beside
    them. Returns the path written."""
    from .. import probe
    from ..diagnosis import uncertainty_budget
    from ..results import budget_dict

    location_only, baseline = identification, None
    if diagnosis is not None and diagnosis.findings and identification.raw.method == "joint":
        noise = "white" if identification.raw.noise.white else "auto"
        identification = probe.identify_probe(
            session, "joint", effects=list(diagnosis.raw.final_fit.effects), noise=noise
        )
        baseline = location_only.to_dict()
    ident = identification.to_dict()
    if diagnosis is not None and identification.raw.method == "joint":
        ident["uncertainty_budget"] = budget_dict(uncertainty_budget(session, diagnosis))
    parts = head("rotacal report", "Touch probe on a sphere", source)
    stds = [ident.get("other_parameters", {}).get("sphere." + c, {}).get("std") for c in "xyz"]
    sphere = (
        ", ".join(f"{v:.4f}" for v in ident["sphere"])
        + " mm"
        + (
            ""
            if None in stds
            else " (1&sigma; " + ", ".join(f"{s * 1e3:.3f}" for s in stds) + " &micro;m)"
        )
    )
    parts.append(
        '<section id="setup"><h2>Machine and set-up</h2><table>'
        f"<tr><th class=l>Machine</th><td class=l>{_e(machine_words(session.machine))}</td></tr>"
        f"<tr><th class=l>Sphere / stylus diameter</th><td class=l>{session.sphere_diameter:.4f} / "
        f"{session.stylus_diameter:.4f} mm</td></tr>"
        f"<tr><th class=l>Nominal sphere centre (table frame)</th>"
        f"<td class=l>{', '.join(f'{v:.4f}' for v in np.ravel(session.sphere))} mm</td></tr>"
        f"<tr><th class=l>Identified sphere centre</th><td class=l>{sphere}</td></tr>"
        f"<tr><th class=l>Touches / poses</th><td class=l>{len(session)} / {len(session.pose_names)}</td></tr>"
        "</table></section>"
    )
    found = [f.effect for f in diagnosis.findings] if baseline is not None else []
    title = (
        f"of the extended model: location errors + {', '.join(found)}"
        if found
        else f"method: {ident['method']}"
    )
    parts.append(f'<section id="location-errors"><h2>Location errors (ISO 230-7), {_e(title)}</h2>')
    parts.append(
        location_error_table(ident["location_errors"], baseline and baseline["location_errors"])
    )
    if found:
        parts += [
            f"<p>The model holds {_e(f.effect)} because {_e(f.model_reason)}.</p>"
            for f in diagnosis.findings
        ]
    parts.append(
        f"<p>Residual RMS {ident['residual_rms_um']:.3f} &micro;m over {ident['n_samples']} touches.</p>"
    )
    parts.append(_fitted_along(ident))
    parts.extend(_notes(ident, "these touches"))
    parts.append("</section>")
    parts.append(noise_budget_section(ident))
    poses = np.asarray(session.poses, dtype=object)
    residuals = [("location-error model", np.asarray(location_only.raw.residuals))]
    if baseline is not None:
        residuals.append(("extended model", np.asarray(identification.raw.residuals)))
    parts.append('<section id="residuals"><h2>Residuals</h2>')
    parts.append(
        img(
            residual_plot(poses, residuals),
            "residual per touch (trigger radius - distance from the "
            "fitted centre), poses side by side",
            "residuals",
        )
    )
    parts.append("</section>")
    if diagnosis is not None:
        parts.append(diagnosis_section(diagnosis.to_dict()))
    parts.extend(extra_sections)
    return write_page(Path(path), parts, inputs)


def _session_rows(d: dict) -> str:
    rows = [
        "<table><tr><th class=l>Session</th><th class=l>Instrument</th><th>Residuals</th><th>RMS (&micro;m)</th>"
        "<th class=l>Its own parameters</th><th class=l>Noise model</th></tr>"
    ]
    for s in d["sessions"]:
        own = "<br>".join(
            f"{_e(n)} = "
            + (
                "unobservable"
                if p["value"] is None
                else f"{p['value']:.4f} {_e(p['unit'])} &plusmn; {p['std'] * 1e3:.3f} &micro;"
                + ("m" if p["unit"] == "mm" else "rad")
            )
            for n, p in s["nuisances"].items()
        )
        rows.append(
            f"<tr><td class=l>{_e(s['name'])}</td><td class=l>{_e(s['instrument'])}</td>"
            f"<td>{s['n_residuals']}</td><td>{s['residual_rms_um']:.3f}</td><td class=l>{own}</td>"
            f"<td class=l>{_e(s['noise_model']['summary'])}</td></tr>"
        )
    rows.append("</table>")
    return "\n".join(rows)


def _alone_table(d: dict) -> str:
    """Each location error jointly and from each session alone (um / urad, 1 sigma)."""
    head_cells = "".join(f"<th>{_e(s['name'])} alone</th>" for s in d["sessions"])
    rows = [f"<table><tr><th class=l>Error</th><th>Joint</th>{head_cells}<th>Unit</th></tr>"]

    def cell(p: dict, f: float) -> str:
        return (
            "unobservable"
            if p["value"] is None
            else f"{p['value'] * f:+.2f} &plusmn; {p['std'] * f:.2f}"
        )

    for name, p in d["location_errors"].items():
        f, unit = (1e3, "&micro;m") if p["unit"] == "mm" else (1e6, "&micro;rad")
        alone = "".join(f"<td>{cell(s['alone'][name], f)}</td>" for s in d["sessions"])
        rows.append(
            f"<tr><td class=l>{_e(name)}</td><td>{cell(p, f)}</td>{alone}<td>{unit}</td></tr>"
        )
    rows.append("</table>")
    return "\n".join(rows)


def multi_report(
    path: str | Path,
    result: Any,
    source: str = "",
    extra_sections: Iterable[str] = (),
    inputs: Iterable[str] = (),
) -> Path:
    """Write the HTML report of one identification from several sessions (rotacal.multi): the
    shared location errors, each session's values alone, the disagreements, each session's own
    parameters and noise model. Returns the path written."""
    d = result.to_dict()
    parts = head("rotacal report", "One identification from several sessions", source)
    parts.append(
        '<section id="setup"><h2>Machine and sessions</h2>'
        f"<p>Machine: {_e(machine_words(result.machine))}; {len(d['sessions'])} sessions, each with its "
        "own parameters and noise model, one set of location errors.</p>"
        + _session_rows(d)
        + "</section>"
    )
    parts.append(
        '<section id="location-errors"><h2>Location errors (ISO 230-7), joint fit of every session</h2>'
    )
    parts.append(location_error_table(d["location_errors"]))
    if d["effects"]:
        parts.append(
            "<p>Shared effects: "
            + ", ".join(
                f"{_e(n)} = "
                + (
                    "unobservable"
                    if p["value"] is None
                    else f"{p['value']:.6g} &plusmn; {p['std']:.2g} {_e(p['unit'])}"
                )
                for n, p in d["effects"].items()
            )
            + "</p>"
        )
    parts.append("<h3>Jointly and from each session alone (1&sigma;)</h3>" + _alone_table(d))
    if d["disagreements"]:
        parts.append(
            "<p class=warn>The sessions alone disagree (difference beyond 3&sigma; of the difference); the "
            "joint value averages them:</p><ul>"
            + "".join(
                f"<li>{_e(g['parameter'])}: {_e(g['sessions'][0])} &minus; {_e(g['sessions'][1])} = "
                f"{g['difference']:.6g} &plusmn; {g['sigma']:.2g} {_e(g['unit'])} (z = {g['z']:+.1f})</li>"
                for g in d["disagreements"]
            )
            + "</ul>"
        )
    else:
        parts.append(
            "<p class=ok>No location error on which two sessions alone differ by more than 3&sigma; of "
            "the difference.</p>"
        )
    parts.extend(_notes(d, "these sessions"))
    parts.append("</section>")
    parts.extend(extra_sections)
    return write_page(Path(path), parts, inputs)
