# SPDX-License-Identifier: BSD-3-Clause
"""The report of an R-test session: set-up, location errors, the error maps of the tilt and
the rotary axis against their angles with 1-sigma bands (Oyama & Ibaraki Sec. 5.2),
residuals and the diagnosis."""

from __future__ import annotations

import base64
from pathlib import Path
from typing import Any, Iterable

import numpy as np

from .. import _core
from .page import escape as _e, head, img, png, plt, write_page
from .sections import (
    diagnosis_section,
    location_error_table,
    machine_words,
    noise_budget_section,
    residual_plot,
    with_budget,
)


_COMPONENTS = ["dx", "dy", "dz", "alpha", "beta", "gamma"]


def _component_scale(k: int) -> tuple[float, str]:
    return (1e3, "\u00b5m") if k < 3 else (1e6, "\u00b5rad")


def _band(ax, x: np.ndarray, v: np.ndarray, s: np.ndarray, color: str, label: str | None) -> None:
    if not np.all(np.isfinite(s)):
        # Part of an unobservable combination: the value is the fit's convention, not a
        # measurement; drawn grey and dashed so that nobody reads it as one.
        ax.plot(x, v, "--", lw=1.0, color="#999", label=label)
        return
    ax.plot(x, v, "-", lw=1.2, color=color, label=label)
    ax.fill_between(x, v - s, v + s, color=color, alpha=0.25, lw=0)


def _map_words(model: Any) -> tuple[str, str, str, str]:
    """(tilt axis letter, rotary axis letter, tilt map name, rotary map name) of the model's
    machine: "B", "C", "BY", "CB" on BC-trt (rotacal.rtest_map_names)."""
    m = model.machine
    maps = list(_core.rtest_map_names(m))
    return m.tilt_axis, m.rot_axis, maps[0], maps[1]


def _fitted_components(model: Any, which: int) -> int:
    """Components of a map the basis fits: translations only on a head axis (the sphere is one
    point), gamma of the rotary map only with gamma_cb."""
    basis = model.basis.for_machine(model.machine)
    if which == 0:
        return 6 if basis.b_rotations else 3
    return (6 if basis.gamma_cb else 5) if basis.c_rotations else 3


def rtest_b_map_plot(model: Any, b_range_deg: tuple[float, float]) -> str:
    """The six errors of the tilt axis' map (w_BY on BC-trt) against its angle, 1-sigma bands."""
    tilt, _, tilt_map, _ = _map_words(model)
    fitted = _fitted_components(model, 0)
    b = np.linspace(b_range_deg[0], b_range_deg[1], 181)
    v, s = (np.asarray(a) for a in model.w_by(np.radians(b)))
    fig, axes = plt.subplots(2, 3, figsize=(10, 5.2), sharex=True)
    for k, ax in enumerate(axes.flat):
        scale, unit = _component_scale(k)
        if k < fitted:
            _band(ax, b, v[:, k] * scale, s[:, k] * scale, "#246", None)
        else:
            ax.text(
                0.5,
                0.5,
                "not fitted: a head axis' rotations\nonly move the one sphere",
                ha="center",
                va="center",
                transform=ax.transAxes,
                fontsize=8,
                color="#777",
            )
        ax.axhline(0, color="#999", lw=0.6)
        ax.set_title(
            f"{_COMPONENTS[k]}_{tilt_map} ({unit})"
            + ("" if k >= fitted or np.all(np.isfinite(s[:, k])) else ", not determined (dashed)"),
            fontsize=9,
        )
        ax.tick_params(labelsize=7)
        if k >= 3:
            ax.set_xlabel(f"{tilt} (deg)", fontsize=8)
    fig.suptitle(
        f"{tilt}-axis errors beyond its location errors, joint fit (band: 1\u03c3)", fontsize=10
    )
    fig.tight_layout()
    return png(fig)


def rtest_c_map_plot(model: Any, b_values_deg: Iterable[float]) -> str:
    """The errors of the rotary axis' map (w_CB on BC-trt) against its angle, one curve per
    tilt angle, with their 1-sigma bands."""
    tilt, rot, _, rot_map = _map_words(model)
    c = np.linspace(0.0, 360.0, 181)
    b_values = list(b_values_deg)
    colors = plt.cm.viridis(np.linspace(0.0, 0.9, max(len(b_values), 1)))
    fig, axes = plt.subplots(2, 3, figsize=(10, 5.2), sharex=True)
    fitted = _fitted_components(model, 1)
    for bi, b in enumerate(b_values):
        ang = np.column_stack([np.full_like(c, np.radians(b)), np.radians(c)])
        v, s = (np.asarray(a) for a in model.w_cb(ang))
        for k in range(fitted):
            scale, _ = _component_scale(k)
            _band(
                axes.flat[k],
                c,
                v[:, k] * scale,
                s[:, k] * scale,
                colors[bi],
                f"{tilt} = {b:g}\u00b0",
            )
    for k, ax in enumerate(axes.flat):
        scale, unit = _component_scale(k)
        ax.set_title(f"{_COMPONENTS[k]}_{rot_map} ({unit})", fontsize=9)
        ax.tick_params(labelsize=7)
        if k >= 3:
            ax.set_xlabel(f"{rot} (deg)", fontsize=8)
        if k >= fitted:
            why = (
                "assumed 0\n(Oyama Sec. 4.2)"
                if k == 5 and fitted == 5
                else "a head axis' rotations\nonly move the one sphere"
            )
            ax.text(
                0.5,
                0.5,
                "not fitted: " + why,
                ha="center",
                va="center",
                transform=ax.transAxes,
                fontsize=8,
                color="#777",
            )
        ax.axhline(0, color="#999", lw=0.6)
    axes.flat[0].legend(fontsize=6, ncol=2)
    fig.suptitle(
        f"{rot}-axis errors beyond its location errors, joint fit (bands: 1\u03c3)", fontsize=10
    )
    fig.tight_layout()
    return png(fig)


def rtest_residual_plot(setups: np.ndarray, residuals: np.ndarray) -> str:
    """Residual (measured - model) of each reading component per pose."""
    labels = np.array([f"set-up {s}" for s in setups], dtype=object)
    return residual_plot(labels, [(f"d{a}", residuals[:, k]) for k, a in enumerate("xyz")])


def rtest_report(
    path: str | Path,
    session: Any,
    identification: Any,
    diagnosis: Any | None = None,
    title: str | None = None,
    source: str = "",
    inputs: Iterable[str] = (),
    extra_sections: Iterable[str] = (),
) -> Path:
    """Write the HTML report of an R-test session: set-up, location errors (ISO 230-7 table),
    the error map against B and C with uncertainty bands, residuals and the diagnosis."""

    path = Path(path)
    with_budget(identification, session, diagnosis)
    ident = identification.to_dict()
    if ident["method"] != "joint":
        raise _core.InvalidArgument(
            "rtest_report: needs the joint identification (its model draws the map)"
        )
    model = identification.raw.model
    setups = np.asarray(session.setups, dtype=object)
    angles = np.asarray(session.angles_deg)
    b_meas = sorted(set(np.round(angles[:, 0], 6).tolist()))
    c_meas = sorted(set(np.round(angles[:, 1], 6).tolist()))
    heading = title or "R-test: location errors and error map of the rotary axes"
    parts = head(heading, heading, source)

    rows = [
        f"<tr><th class=l>Machine</th><td class=l>{_e(machine_words(session.machine))}</td></tr>"
    ]
    for label, q in sorted(session.nests.items()):
        rows.append(
            f"<tr><th class=l>Nest {_e(label)} (table frame)</th>"
            f"<td class=l>{', '.join(f'{v:.4f}' for v in q)} mm</td></tr>"
        )
    for n, d in sorted(session.probe_dirs.items()):
        rows.append(
            f"<tr><th class=l>Probe {_e(str(n))} direction</th><td class=l>{', '.join(f'{v:.6f}' for v in d)}</td></tr>"
        )
    tilt, rot = session.machine.tilt_axis, session.machine.rot_axis
    rows.append(
        f"<tr><th class=l>Poses</th><td class=l>{len(setups)} ({len(b_meas)} {tilt} &times; {len(c_meas)} "
        f"{rot} positions, {len(set(setups.tolist()))} set-ups)</td></tr>"
    )
    rows.append(
        f"<tr><th class=l>{tilt} (deg)</th><td class=l>{', '.join(f'{b:g}' for b in b_meas)}</td></tr>"
    )
    rows.append(
        f"<tr><th class=l>{rot} (deg)</th><td class=l>{', '.join(f'{c:g}' for c in c_meas)}</td></tr>"
    )
    if session.noise_um is not None:
        rows.append(
            f"<tr><th class=l>Stated noise</th><td class=l>{session.noise_um:.3f} &micro;m</td></tr>"
        )
    parts.append(
        '<section id="setup"><h2>Machine and set-up</h2><table>'
        + "".join(rows)
        + "</table></section>"
    )

    parts.append('<section id="location-errors"><h2>Location errors (ISO 230-7), joint fit</h2>')
    parts.append(location_error_table(ident["location_errors"]))
    zeros = ", ".join(
        f"set-up {_e(k)}: ({', '.join(f'{v * 1e3:+.2f}' for v in z)}) &micro;m"
        for k, z in ident["probe_zeros"].items()
    )
    parts.append(
        f"<p>Residual RMS {ident['residual_rms_um']:.3f} &micro;m over {ident['n_samples']} poses "
        f"(3 readings each). Fitted probe zeros: {zeros}.</p>"
    )
    if ident["unobservable"]:
        parts.append(
            "<p class=warn>Not determined by this session's nests:</p><ul>"
            + "".join(f"<li>{_e(u)}</li>" for u in ident["unobservable"])
            + "</ul>"
        )
    parts.append(
        "<ul class=muted>" + "".join(f"<li>{_e(n)}</li>" for n in ident["notes"]) + "</ul>"
    )
    parts.append("</section>")

    map_csv = identification.error_map("csv", b_meas, c_meas)
    tilt, rot, tilt_map, rot_map = _map_words(model)
    parts.append(noise_budget_section(ident))
    parts.append(
        '<section id="error-map"><h2>Error map (Oyama &amp; Ibaraki Sec. 5.2)</h2>'
        f"<p>Position-dependent errors of the {tilt} axis (w_{tilt_map}, in front of the {tilt} "
        f"rotation) and of the {rot} axis (w_{rot_map}, in front of the {rot} rotation), beyond "
        "the rigid axis lines whose location errors are in the table above. Curves: the joint "
        "fit's smooth maps; bands: "
        "&plusmn;1&sigma; from the parameter covariance. "
        f"<a download='error_map.csv' href='data:text/csv;base64,"
        f"{base64.b64encode(map_csv.encode()).decode('ascii')}'>The map at the measured angles "
        "(CSV)</a>.</p>"
    )
    parts.append(
        img(
            rtest_b_map_plot(model, (b_meas[0], b_meas[-1])),
            f"{tilt}-axis errors against {tilt}",
            "error-map",
        )
    )
    parts.append(
        img(
            rtest_c_map_plot(model, b_meas),
            f"{rot}-axis errors against {rot} at each measured {tilt}",
            "error-map",
        )
    )
    parts.append("</section>")

    parts.append('<section id="residuals"><h2>Residuals</h2>')
    parts.append(
        img(
            rtest_residual_plot(setups, np.asarray(identification.raw.residuals)),
            "residual per pose and reading (measured - joint model)",
            "residuals",
        )
    )
    parts.append("</section>")

    if diagnosis is not None:
        parts.append(diagnosis_section(diagnosis.to_dict()))
    parts.extend(extra_sections)
    return write_page(path, parts, inputs)
