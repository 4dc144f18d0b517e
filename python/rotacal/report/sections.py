# SPDX-License-Identifier: BSD-3-Clause
"""The parts of a report every instrument's page shares: the words for the location errors
and the machine, the ISO 230-7 table, the effects fitted along, the noise model and
uncertainty budget, the diagnosis, and the residual and harmonic plots."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Iterable

import numpy as np

from .. import units
from ..diagnosis import group_text, model_text
from ..version import __version__
from .page import CSS, escape as _e, img, plot_text, png, plt

# Words for the ISO 230-7 location errors of a tilting-rotary table (Flynn et al., Table 1).
ERROR_WORDS = {
    "E_X0C": "position of C in X",
    "E_Y0C": "position of C in Y",
    "E_A0C": "orientation of C about X (squareness C to Y)",
    "E_B0C": "orientation of C about Y (squareness C to X)",
    "E_Y0A": "position of A in Y",
    "E_Z0A": "position of A in Z",
    "E_B0A": "orientation of A about Y (squareness A to Z)",
    "E_C0A": "orientation of A about Z (squareness A to Y)",
    "E_X0B": "position of B in X",
    "E_Z0B": "position of B in Z",
    "E_A0B": "orientation of B about X (squareness B to Z)",
    "E_C0B": "orientation of B about Z (squareness B to X)",
}

# Words for the location errors of a nutating axis R (formats.md: u, v perpendicular to it).
_UV_WORDS = {
    "E_U0": "position of {r} along its u",
    "E_V0": "position of {r} along its v",
    "E_DU0": "direction of {r} tilted towards its u",
    "E_DV0": "direction of {r} tilted towards its v",
}

# How the two rotary axes sit, by MachineType.configuration.
CONFIGURATION_WORDS = {
    "table-table": "tilting-rotary table",
    "head-table": "rotary table, tilting head",
    "head-head": "two-axis head",
}


def error_words(name: str) -> str:
    """Meaning of a location error name: ISO 230-7 words, or the nutating axis' u/v words."""
    if name in ERROR_WORDS:
        return ERROR_WORDS[name]
    for prefix, words in _UV_WORDS.items():
        if name.startswith(prefix) and len(name) == len(prefix) + 1:
            return words.format(r=name[-1])
    return ""


def machine_words(machine: Any) -> str:
    """'AC-head (two-axis head)' from a MachineType."""
    return (
        f"{machine.name} ({CONFIGURATION_WORDS.get(machine.configuration, machine.configuration)})"
    )


def _fmt(p: dict, scale: float) -> tuple[str, str]:
    if p.get("value") is None:
        return "unobservable", ""
    return f"{p['value'] * scale:+.2f}", f"{p['std'] * scale:.2f}"


def location_error_table(errors: dict, baseline: dict | None = None) -> str:
    """ISO 230-7 style table; positions in um, orientations in urad. With ``baseline`` (the
    location errors of the model without the diagnosis' findings), its value and the shift to
    ``errors`` stand beside each value, labelled as such."""
    extra = "<th>Baseline</th><th>Shift</th>" if baseline else ""
    rows = [
        "<table><tr><th class=l>Error</th><th class=l>Meaning</th><th>Value</th>"
        f"<th>1&sigma;</th>{extra}<th>Unit</th></tr>"
    ]
    for name, p in errors.items():
        scale, unit = (1e3, "&micro;m") if p["unit"] == "mm" else (1e6, "&micro;rad")
        v, s = _fmt(p, scale)
        cells = ""
        if baseline:
            b = baseline.get(name, {})
            bv, _ = _fmt(b, scale) if b else ("", "")
            shift = (
                f"{(p['value'] - b['value']) * scale:+.2f}"
                if p.get("value") is not None and b.get("value") is not None
                else ""
            )
            cells = f"<td>{bv}</td><td>{shift}</td>"
        rows.append(
            f"<tr><td class=l>{_e(name)}</td><td class=l>{_e(error_words(name))}</td>"
            f"<td>{v}</td><td>{s}</td>{cells}<td>{unit}</td></tr>"
        )
    rows.append("</table>")
    return "\n".join(rows)


def fitted_effects_table(effects: list[dict]) -> str:
    """The effects the fit carried along with the location errors (e.g. tool_offset_Z on a head
    machine: the error of pivot_length + tool_length), or '' when there are none."""
    if not effects:
        return ""
    rows = [
        "<p>Fitted along with the location errors:</p><table><tr><th class=l>Effect</th><th class=l>Cause</th>"
        "<th class=l>Parameter</th><th>Value</th><th>1&sigma;</th><th>Unit</th></tr>"
    ]
    for eff in effects:
        for pname, p in eff["params"].items():
            scale, unit = (
                (1e3, "&micro;m")
                if p["unit"] == "mm"
                else (1e6, "&micro;rad")
                if p["unit"] == "rad"
                else (1.0, _e(p["unit"]))
            )
            v, sd = _fmt(p, scale)
            rows.append(
                f"<tr><td class=l>{_e(eff['id'])}</td><td class=l>{_e(eff['cause'])}</td>"
                f"<td class=l>{_e(pname)}</td><td>{v}</td><td>{sd}</td><td>{unit}</td></tr>"
            )
    rows.append("</table>")
    return "\n".join(rows)


def noise_budget_section(ident: dict) -> str:
    """The noise model the 1-sigma rests on and the uncertainty budget (GUM / ISO/TR 230-9) of
    each location error, from an identification's to_dict() (docs/json_schema.md)."""
    out = ['<section id="uncertainty"><h2>Noise model and uncertainty budget</h2>']
    nm = ident.get("noise_model")
    if nm:
        from ..results import noise_handling_words

        how = (
            noise_handling_words(nm)
            if "gls_refit" in nm
            else "the readings are taken as independent"
        )
        out.append(f"<p>Noise model of the residuals: {_e(nm['summary'])}; {_e(how)}.</p>")
        walk = any(st.get("random_walk_step_um", 0.0) > 0.0 for st in nm["streams"])
        out.append(
            "<table><tr><th class=l>Stream</th><th>n</th><th>AR order</th><th>&sigma; (&micro;m)</th>"
            + ("<th>random-walk step (&micro;m per reading)</th>" if walk else "")
            + "<th>correlation (readings)</th><th>correlation time (s)</th><th>effective samples</th></tr>"
        )
        for st in nm["streams"]:
            name = st["group"] + (f" ch {st['channel']}" if st["channel"] else "")
            out.append(
                f"<tr><td class=l>{_e(name)}</td><td>{st['n']}</td><td>{st['order']}</td>"
                f"<td>{st['sigma_um']:.3f}</td>"
                + (f"<td>{st.get('random_walk_step_um', 0.0):.4f}</td>" if walk else "")
                + f"<td>{st['correlation_samples']:.1f}</td>"
                f"<td>{st['correlation_time_s']:.3g}</td><td>{st['effective_samples']:.0f}</td></tr>"
            )
        out.append("</table>")
    b = ident.get("uncertainty_budget")
    if b:
        out.append(
            f"<p>Uncertainty budget, coverage {b['coverage'] * 100:.0f} %: type A from the noise model, "
            "type B from each catalogue effect the model leaves out (its bias at the session's bound or a "
            "default plausible size, rectangular). Values in &micro;m or &micro;rad.</p>"
        )
        out.append(
            "<table><tr><th class=l>Error</th><th>Value</th><th>Type A</th><th>u<sub>c</sub></th>"
            "<th>U</th><th>k</th><th>&nu;<sub>eff</sub></th><th class=l>Dominant left-out effects</th></tr>"
        )
        for name, e in b["location_errors"].items():
            if not e["observable"]:
                out.append(
                    f"<tr><td class=l>{_e(name)}</td><td colspan=7 class=l>unobservable</td></tr>"
                )
                continue
            f = 1e6 if e["unit"] == "rad" else 1e3
            nu = "&infin;" if e["nu_eff"] is None else f"{e['nu_eff']:.0f}"
            dom = ", ".join(_e(x) for x in e["dominant"]) or "none"
            out.append(
                f"<tr><td class=l>{_e(name)}</td><td>{e['value'] * f:+.3f}</td><td>{e['u_a'] * f:.3f}</td>"
                f"<td>{e['u_c'] * f:.3f}</td><td>{e['expanded'] * f:.3f}</td><td>{e['k']:.2f}</td>"
                f"<td>{nu}</td><td class=l>{dom}</td></tr>"
            )
        out.append("</table>")
        from ..results import budget_why

        why = budget_why(b)
        if why:
            out.append(f"<p>{_e(why)}</p>")
    out.append("</section>")
    return "".join(out) if (nm or b) else ""


def with_budget(identification: Any, session: Any, diagnosis: Any) -> None:
    """Attach the budget of a given diagnosis to a joint identification that has none."""
    if (
        diagnosis is None
        or getattr(identification, "budget", "none") is not None
        or identification.raw.method != "joint"
    ):
        return
    from ..diagnosis import uncertainty_budget

    identification.budget = uncertainty_budget(session, diagnosis)


def residual_plot(tests: np.ndarray, residuals: list[tuple[str, np.ndarray]]) -> str:
    """Residual per sample, tests side by side, for one or more models."""
    fig, ax = plt.subplots(figsize=(9, 3))
    x = np.arange(len(tests))
    for label, r in residuals:
        ax.plot(x, r * 1e3, ".", ms=2, label=label)
    for t in dict.fromkeys(tests):
        idx = np.flatnonzero(tests == t)
        ax.axvline(idx[0], color="#ccc", lw=0.8)
        ax.text(idx.mean(), ax.get_ylim()[1], plot_text(t), ha="center", va="bottom", fontsize=7)
    ax.set_xlabel("sample")
    ax.set_ylabel("residual (\u00b5m)")
    ax.legend(fontsize=7, loc="lower right")
    return png(fig)


def harmonic_plot(structure: list[dict], title: str) -> str | None:
    groups = [g for g in structure if g["harmonic_um"]]
    if not groups:
        return None
    fig, ax = plt.subplots(figsize=(6, 3))
    w = 0.8 / len(groups)
    for i, g in enumerate(groups):
        orders = np.arange(1, len(g["harmonic_um"]) + 1)
        ax.bar(
            orders + i * w,
            g["harmonic_um"],
            width=w,
            label=plot_text(f"{g['group']} ({g['angle_axis']})"),
        )
    ax.set_xlabel("harmonic order in the swept rotary angle")
    ax.set_ylabel("amplitude (\u00b5m)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=6)
    return png(fig)


def diagnosis_report(
    path: str | Path, d: dict, title: str, source: str = "", inputs: Iterable[str] = ()
) -> Path:
    """A report with the diagnosis alone (e.g. of an R-test session)."""
    from ..outputs import write_output

    path = Path(path)
    page = (
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{_e(title)}</title>"
        f"<style>{CSS}</style></head><body><h1>{_e(title)}</h1>"
        f"<p class=muted>rotacal {_e(__version__)} &middot; {_e(source)}</p>"
        f"{diagnosis_section(d)}</body></html>"
    )
    write_output(path, page, [str(i) for i in inputs])
    return path


def diagnosis_section(d: dict) -> str:
    b = d["baseline"]
    out = [
        '<section id="diagnosis"><h2>Diagnosis</h2>',
        f"<p>Baseline (location errors and pivot): residual RMS {b['residual_rms_um']:.3f} &micro;m, "
        f"noise {b['noise_um']:.3f} &micro;m ({_e(b['noise_source'])}), "
        f"&chi;&sup2;/dof {b['chi2_per_dof']:.2f} (p = {b['p_value']:.2g}).</p>",
    ]
    if not d["findings"]:
        out.append(
            "<p class=ok>No effect of the catalogue is significant: the location-error model "
            "explains the data to the noise.</p>"
        )
    else:
        out.append(
            "<table><tr><th class=l>#</th><th class=l>Effect</th><th>Weight</th><th class=l>Cause</th>"
            "<th class=l>Parameters</th><th>RMS before</th><th>RMS after</th><th>&Delta;BIC</th>"
            "<th>CV RMS before</th><th>CV RMS after</th></tr>"
        )
        for i, f in enumerate(d["findings"], 1):
            params = "<br>".join(
                f"{_e(k)} = {_e(units.estimate_text(v['value'], v['std'], v['unit']))}"
                for k, v in f["parameters"].items()
            )
            if f["named"]:
                effect = _e(f["effect"])
            elif f.get("lack_of_fit"):  # a local defect outside the catalogue fits as well
                effect = f"not named: {_e(f['effect'])} ({_e(f['lack_of_fit'])})"
                params = f"if {_e(f['effect'])}:<br>" + params
            else:  # the group the data cannot separate, with the parameters of the held one
                effect = "one of: " + _e(group_text(f))
                params = f"if {_e(f['effect'])}:<br>" + params
            effect += f"<br><span class=muted>{_e(model_text(f))}</span>"
            g = f["gain"]
            out.append(
                f"<tr><td class=l>{i}</td><td class=l>{effect}</td><td>{f['weight']:.2f}</td>"
                f"<td class=l>{_e(f['cause'])}</td>"
                f"<td class=l>{params}</td><td>{g['rms_before_um']:.3f}</td><td>{g['rms_after_um']:.3f}</td>"
                f"<td>{g['delta_bic']:.1f}</td><td>{g['cv_rms_before_um']:.3f}</td><td>{g['cv_rms_after_um']:.3f}</td></tr>"
            )
        out.append(
            "</table><p class=muted>RMS in &micro;m; CV: blocked cross-validation. Weight: the BIC "
            "weight of the effect against the candidates that explain the same signal; below 0.9 the "
            "finding is the group the data cannot separate, not one name.</p>"
        )
    for a in d["ambiguous"]:
        out.append(
            f"<p class=warn>Cannot be told apart with this data: {_e(', '.join(a['effects']))} "
            f"({_e(a['separating_test'])}).</p>"
        )
    if d["unexplained"]["present"]:
        out.append(
            f"<p class=warn>Unexplained structure remains (&chi;&sup2;/dof "
            f"{d['unexplained']['chi2_per_dof']:.2f}): {_e(d['unexplained']['signature'])}</p>"
        )
    for title, key in (("before", "before"), ("after", "after")):
        src = harmonic_plot(
            d["residual_structure"][key], f"residual harmonics {title} the diagnosis"
        )
        if src:
            out.append(img(src, f"residual harmonics {title}", "diagnosis"))
    notes = {
        g["harmonic_note"] for g in d["residual_structure"]["before"] if g.get("harmonic_note")
    }
    for note in sorted(notes):
        out.append(f"<p class=muted>{_e(note)}</p>")
    if d["unobservable"]:
        out.append(
            "<details><summary>Effects this session cannot see</summary><ul>"
            + "".join(f"<li>{_e(u['effect'])}: {_e(u['reason'])}</li>" for u in d["unobservable"])
            + "</ul></details>"
        )
    out.append("</section>")
    return "\n".join(out)
