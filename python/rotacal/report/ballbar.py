# SPDX-License-Identifier: BSD-3-Clause
"""The report of a ballbar session: set-up, location errors (of the model the diagnosis
extended, where it found an effect), noise model and budget, polar plots of measured against
model with the deviation magnified, residuals and the diagnosis."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Iterable

import numpy as np

from .. import _core
from .page import escape as _e, head, img, plot_text, png, plt, write_page
from .sections import (
    diagnosis_section,
    fitted_effects_table,
    location_error_table,
    machine_words,
    noise_budget_section,
    residual_plot,
    with_budget,
)


def extended_identification(session: Any, identification: Any, diagnosis: Any) -> Any | None:
    """The joint identification of the model the diagnosis extended (its findings' effects
    fitted along), or None when there is nothing to extend: no finding, or a paper-method
    identification. Where the diagnosis found an effect, this is the result a user loads
    (the baseline's location errors carry the effect's bias); issue 29, one value per quantity."""
    if diagnosis is None or not diagnosis.findings or identification.raw.method != "joint":
        return None
    from ..ballbar import identify

    effects = list(diagnosis.raw.final_fit.effects)
    noise = "white" if identification.raw.noise.white else "auto"
    return identify(session, "joint", effects=effects, noise=noise)


def location_errors_section(ident: dict, baseline: dict | None, diagnosis: Any) -> list[str]:
    """The location-error section: the result, and where the diagnosis extended the model,
    which model that is and the baseline's values beside it."""
    if baseline is None:
        parts = [
            f'<section id="location-errors"><h2>Location errors (ISO 230-7), method: {_e(ident["method"])}</h2>',
            location_error_table(ident["location_errors"]),
        ]
    else:
        found = [f.effect for f in diagnosis.findings]
        parts = [
            f'<section id="location-errors"><h2>Location errors (ISO 230-7) of the extended model: '
            f"location errors + {_e(', '.join(found))}</h2>",
            "<p>These are the values to load into the controller: the diagnosis found "
            f"{_e(', '.join(found))} in this session, and a model without it biases the location errors "
            "(Baseline: the fit of the location errors alone, shown for comparison; Shift: result - baseline). "
            "The uncertainty budget below is of this model too.</p>",
            location_error_table(ident["location_errors"], baseline["location_errors"]),
        ]
        parts += [
            f"<p>The model holds {_e(f.effect)} because {_e(f.model_reason)}.</p>"
            for f in diagnosis.findings
        ]
        for f in diagnosis.findings:
            if not f.named_alone:
                others = ", ".join(r.effect for r in f.rivals if r.in_group)
                parts.append(
                    f"<p class=warn>{_e(f.effect)} is one of a group this session cannot separate "
                    f"({_e(others)}); with another member of the group the location errors above would "
                    "differ. `rotacal design ballbar --separate` proposes the test that decides.</p>"
                )
    return parts


def _swept_angle(angles_deg: np.ndarray) -> tuple[np.ndarray, int]:
    span = angles_deg.max(axis=0) - angles_deg.min(axis=0)
    k = int(np.argmax(span))
    return np.radians(angles_deg[:, k]), k


def polar_plots(
    tests: np.ndarray,
    angles_deg: np.ndarray,
    measured: np.ndarray,
    model: np.ndarray,
    nominal: float,
    axis_names: tuple[str, str],
) -> list[str]:
    """One polar plot per rotary test: measured and model deviation from L0, magnified."""
    figs = []
    for t in dict.fromkeys(tests):
        sel = tests == t
        if sel.sum() < 10:
            continue
        theta, k = _swept_angle(angles_deg[sel])
        if np.ptp(theta) < np.radians(30):
            continue  # an arc at fixed rotary angles (sphere tests) has no angle to plot against
        dev_m = (measured[sel] - nominal) * 1e3
        dev_p = (model[sel] - nominal) * 1e3
        span = max(np.ptp(np.r_[dev_m, dev_p]), 1.0)
        base = 2.0 * span  # the reference circle; deviations are drawn magnified around it
        fig = plt.figure(figsize=(4.2, 4.2))
        ax = fig.add_subplot(projection="polar")
        ax.plot(theta, base + dev_m - dev_p.mean(), ".", ms=2, color="#c33", label="measured")
        ax.plot(theta, base + dev_p - dev_p.mean(), "-", lw=1.2, color="#246", label="model")
        ax.plot(np.linspace(0, 2 * np.pi, 361), np.full(361, base), ":", color="#999", lw=0.8)
        ax.set_rmin(0)
        ax.set_rmax(base + span * 1.2)
        ax.set_yticklabels([])
        ax.set_title(
            f"{plot_text(t)}: deviation from L0 against {axis_names[k]}\n"
            f"scale: ring spacing {span / 2:.2g} \u00b5m",
            fontsize=8,
        )
        ax.legend(loc="lower right", fontsize=7)
        figs.append((png(fig), f"{plot_text(t)}: measured and model, deviation magnified"))
    return figs


def ballbar_report(
    path: str | Path,
    session: Any,
    identification: Any,
    diagnosis: Any | None = None,
    title: str | None = None,
    source: str = "",
    extra_sections: Iterable[str] = (),
    inputs: Iterable[str] = (),
) -> Path:
    """Write the HTML report of a ballbar session (by the output rule; ``inputs`` are refused
    as the target). Every text from a file is escaped. Returns the path written."""

    path = Path(path)
    baseline, location_only = None, identification
    extended = extended_identification(session, identification, diagnosis)
    if extended is not None:
        baseline, identification = identification.to_dict(), extended
    with_budget(identification, session, diagnosis)
    ident = identification.to_dict()
    tests = np.asarray(session.tests, dtype=object)  # object: a long label must not widen every row
    angles = np.asarray(session.angles_deg)
    measured = np.asarray(session.length)
    model = _core.predict_session_lengths(identification.raw.model, session)
    machine = session.machine
    # session.angles_deg holds (tilt, rotary) on every machine, whatever their chain order.
    axis_names = (machine.tilt_axis, machine.rot_axis)
    parts = head(title or "rotacal report", title or "Single set-up ballbar test", source)

    pv = ident["pivot"]
    pivot_txt = ", ".join(
        "unobservable" if pv[a]["value"] is None else f"{pv[a]['value']:.4f}" for a in "xyz"
    )
    parts.append(
        '<section id="setup"><h2>Machine and set-up</h2><table>'
        f"<tr><th class=l>Machine</th><td class=l>{_e(machine_words(machine))}</td></tr>"
        f"<tr><th class=l>Ballbar length L0</th><td class=l>{session.ballbar_length:.4f} mm</td></tr>"
        f"<tr><th class=l>Nominal pivot (table frame)</th><td class=l>{', '.join(f'{v:.4f}' for v in session.pivot)} mm</td></tr>"
        f"<tr><th class=l>Identified pivot</th><td class=l>{pivot_txt} mm</td></tr>"
        f"<tr><th class=l>Samples / tests</th><td class=l>{len(tests)} / {_e(', '.join(dict.fromkeys(tests)))}</td></tr>"
        "</table></section>"
    )

    parts.extend(location_errors_section(ident, baseline, diagnosis))
    parts.append(
        f"<p>Residual RMS {ident['residual_rms_um']:.3f} &micro;m over {ident['n_samples']} samples.</p>"
    )
    parts.append(fitted_effects_table(ident.get("effects", [])))
    if ident["unobservable"]:
        parts.append(
            "<p class=warn>Not determined by this session's tests:</p><ul>"
            + "".join(f"<li>{_e(u)}</li>" for u in ident["unobservable"])
            + "</ul>"
        )
    if ident.get("notes"):
        parts.append(
            "<ul class=muted>" + "".join(f"<li>{_e(n)}</li>" for n in ident["notes"]) + "</ul>"
        )
    parts.append("</section>")
    parts.append(noise_budget_section(ident))

    parts.append('<section id="polar"><h2>Ballbar plots: measured against model</h2>')
    for src, cap in polar_plots(tests, angles, measured, model, session.ballbar_length, axis_names):
        parts.append(img(src, cap, "polar"))
    parts.append("</section>")

    residuals = [("location-error model", np.asarray(location_only.residuals))]
    if diagnosis is not None and diagnosis.findings:
        residuals.append(("extended model", np.asarray(diagnosis.raw.final_fit.residuals)))
    parts.append('<section id="residuals"><h2>Residuals</h2>')
    parts.append(
        img(residual_plot(tests, residuals), "residual per sample (measured - model)", "residuals")
    )
    parts.append("</section>")

    if diagnosis is not None:
        parts.append(diagnosis_section(diagnosis.to_dict()))
    parts.extend(extra_sections)
    return write_page(path, parts, inputs)
