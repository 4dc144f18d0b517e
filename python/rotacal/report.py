"""Self-contained HTML reports (no network needed to open them): set-up, location errors in
an ISO 230-7 style table, ballbar polar plots of measured against model with the deviation
magnified, residual plots, and the diagnosis with before/after plots."""
from __future__ import annotations

import base64
import datetime as _dt
import html
import io
from pathlib import Path
from typing import Any, Iterable

import numpy as np

import matplotlib

matplotlib.use("Agg")  # files only, never a window
import matplotlib.pyplot as plt  # noqa: E402

from . import units  # noqa: E402

# Words for the ISO 230-7 location errors of a tilting-rotary table (Flynn et al., Table 1).
ERROR_WORDS = {
    "E_X0C": "position of C in X", "E_Y0C": "position of C in Y",
    "E_A0C": "orientation of C about X (squareness C to Y)",
    "E_B0C": "orientation of C about Y (squareness C to X)",
    "E_Y0A": "position of A in Y", "E_Z0A": "position of A in Z",
    "E_B0A": "orientation of A about Y (squareness A to Z)",
    "E_C0A": "orientation of A about Z (squareness A to Y)",
    "E_X0B": "position of B in X", "E_Z0B": "position of B in Z",
    "E_A0B": "orientation of B about X (squareness B to Z)",
    "E_C0B": "orientation of B about Z (squareness B to X)",
}

# Words for the location errors of a nutating axis R (formats.md: u, v perpendicular to it).
_UV_WORDS = {"E_U0": "position of {r} along its u", "E_V0": "position of {r} along its v",
             "E_DU0": "direction of {r} tilted towards its u", "E_DV0": "direction of {r} tilted towards its v"}

# How the two rotary axes sit, by MachineType.configuration.
CONFIGURATION_WORDS = {"table-table": "tilting-rotary table", "head-table": "rotary table, tilting head",
                       "head-head": "two-axis head"}


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
    return f"{machine.name} ({CONFIGURATION_WORDS.get(machine.configuration, machine.configuration)})"


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:2em auto;max-width:1100px;color:#222}
h1{font-size:1.6em;border-bottom:2px solid #246;padding-bottom:.3em}
h2{font-size:1.25em;color:#246;margin-top:1.6em}
table{border-collapse:collapse;margin:.6em 0}
td,th{border:1px solid #bbb;padding:.25em .6em;text-align:right}
th{background:#eef2f7} td.l,th.l{text-align:left}
.muted{color:#777}.warn{color:#a40}.ok{color:#270}
figure{display:inline-block;margin:.5em;text-align:center}
figcaption{font-size:.85em;color:#555}
"""


def _e(text: Any) -> str:
    """HTML-escaped text: everything that may come from a file (labels, names, notes)."""
    return html.escape(str(text), quote=True)


def _plot_text(text: Any, limit: int = 60) -> str:
    """A label from a file as matplotlib text: cut to ``limit`` characters, and '$' escaped so
    that it is never read as mathtext (an unbalanced '$' would stop the report)."""
    t = str(text)
    t = t if len(t) <= limit else t[:limit - 1] + "\u2026"
    return t.replace("$", r"\$")


def _png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _img(src: str, caption: str, section: str) -> str:
    return (f'<figure data-section="{_e(section)}"><img src="{src}" alt="{_e(caption)}">'
            f"<figcaption>{_e(caption)}</figcaption></figure>")


def _fmt(p: dict, scale: float) -> tuple[str, str]:
    if p.get("value") is None:
        return "unobservable", ""
    return f"{p['value'] * scale:+.2f}", f"{p['std'] * scale:.2f}"


def location_error_table(errors: dict, baseline: dict | None = None) -> str:
    """ISO 230-7 style table; positions in um, orientations in urad. With ``baseline`` (the
    location errors of the model without the diagnosis' findings), its value and the shift to
    ``errors`` stand beside each value, labelled as such."""
    extra = "<th>Baseline</th><th>Shift</th>" if baseline else ""
    rows = ["<table><tr><th class=l>Error</th><th class=l>Meaning</th><th>Value</th>"
            f"<th>1&sigma;</th>{extra}<th>Unit</th></tr>"]
    for name, p in errors.items():
        scale, unit = (1e3, "&micro;m") if p["unit"] == "mm" else (1e6, "&micro;rad")
        v, s = _fmt(p, scale)
        cells = ""
        if baseline:
            b = baseline.get(name, {})
            bv, _ = _fmt(b, scale) if b else ("", "")
            shift = (f"{(p['value'] - b['value']) * scale:+.2f}"
                     if p.get("value") is not None and b.get("value") is not None else "")
            cells = f"<td>{bv}</td><td>{shift}</td>"
        rows.append(f"<tr><td class=l>{_e(name)}</td><td class=l>{_e(error_words(name))}</td>"
                    f"<td>{v}</td><td>{s}</td>{cells}<td>{unit}</td></tr>")
    rows.append("</table>")
    return "\n".join(rows)


def extended_identification(session: Any, identification: Any, diagnosis: Any) -> Any | None:
    """The joint identification of the model the diagnosis extended (its findings' effects
    fitted along), or None when there is nothing to extend: no finding, or a paper-method
    identification. Where the diagnosis found an effect, this is the result a user loads
    (the baseline's location errors carry the effect's bias); issue 29, one value per quantity."""
    if diagnosis is None or not diagnosis.findings or identification.raw.method != "joint":
        return None
    from .ballbar import identify
    effects = list(diagnosis.raw.final_fit.effects)
    noise = "white" if identification.raw.noise.white else "auto"
    return identify(session, "joint", effects=effects, noise=noise)


def location_errors_section(ident: dict, baseline: dict | None, diagnosis: Any) -> list[str]:
    """The location-error section: the result, and where the diagnosis extended the model,
    which model that is and the baseline's values beside it."""
    if baseline is None:
        parts = [f'<section id="location-errors"><h2>Location errors (ISO 230-7), method: {_e(ident["method"])}</h2>',
                 location_error_table(ident["location_errors"])]
    else:
        found = [f.effect for f in diagnosis.findings]
        parts = [f'<section id="location-errors"><h2>Location errors (ISO 230-7) of the extended model: '
                 f'location errors + {_e(", ".join(found))}</h2>',
                 "<p>These are the values to load into the controller: the diagnosis found "
                 f"{_e(', '.join(found))} in this session, and a model without it biases the location errors "
                 "(Baseline: the fit of the location errors alone, shown for comparison; Shift: result - baseline). "
                 "The uncertainty budget below is of this model too.</p>",
                 location_error_table(ident["location_errors"], baseline["location_errors"])]
        for f in diagnosis.findings:
            if not f.named_alone:
                others = ", ".join(r.effect for r in f.rivals if r.in_group)
                parts.append(f"<p class=warn>{_e(f.effect)} is one of a group this session cannot separate "
                             f"({_e(others)}); with another member of the group the location errors above would "
                             "differ. `rotacal design ballbar --separate` proposes the test that decides.</p>")
    return parts


def fitted_effects_table(effects: list[dict]) -> str:
    """The effects the fit carried along with the location errors (e.g. tool_offset_Z on a head
    machine: the error of pivot_length + tool_length), or '' when there are none."""
    if not effects:
        return ""
    rows = ["<p>Fitted along with the location errors:</p><table><tr><th class=l>Effect</th><th class=l>Cause</th>"
            "<th class=l>Parameter</th><th>Value</th><th>1&sigma;</th><th>Unit</th></tr>"]
    for eff in effects:
        for pname, p in eff["params"].items():
            scale, unit = (1e3, "&micro;m") if p["unit"] == "mm" else (1e6, "&micro;rad") if p["unit"] == "rad" \
                else (1.0, _e(p["unit"]))
            v, sd = _fmt(p, scale)
            rows.append(f"<tr><td class=l>{_e(eff['id'])}</td><td class=l>{_e(eff['cause'])}</td>"
                        f"<td class=l>{_e(pname)}</td><td>{v}</td><td>{sd}</td><td>{unit}</td></tr>")
    rows.append("</table>")
    return "\n".join(rows)


def noise_budget_section(ident: dict) -> str:
    """The noise model the 1-sigma rests on and the uncertainty budget (GUM / ISO/TR 230-9) of
    each location error, from an identification's to_dict() (docs/json_schema.md)."""
    out = ['<section id="uncertainty"><h2>Noise model and uncertainty budget</h2>']
    nm = ident.get("noise_model")
    if nm:
        from .results import noise_handling_words
        how = noise_handling_words(nm) if "gls_refit" in nm else "the readings are taken as independent"
        out.append(f"<p>Noise model of the residuals: {_e(nm['summary'])}; {_e(how)}.</p>")
        walk = any(st.get("random_walk_step_um", 0.0) > 0.0 for st in nm["streams"])
        out.append("<table><tr><th class=l>Stream</th><th>n</th><th>AR order</th><th>&sigma; (&micro;m)</th>"
                   + ("<th>random-walk step (&micro;m per reading)</th>" if walk else "")
                   + "<th>correlation (readings)</th><th>correlation time (s)</th><th>effective samples</th></tr>")
        for st in nm["streams"]:
            name = st["group"] + (f" ch {st['channel']}" if st["channel"] else "")
            out.append(f"<tr><td class=l>{_e(name)}</td><td>{st['n']}</td><td>{st['order']}</td>"
                       f"<td>{st['sigma_um']:.3f}</td>"
                       + (f"<td>{st.get('random_walk_step_um', 0.0):.4f}</td>" if walk else "")
                       + f"<td>{st['correlation_samples']:.1f}</td>"
                       f"<td>{st['correlation_time_s']:.3g}</td><td>{st['effective_samples']:.0f}</td></tr>")
        out.append("</table>")
    b = ident.get("uncertainty_budget")
    if b:
        out.append(f"<p>Uncertainty budget, coverage {b['coverage'] * 100:.0f} %: type A from the noise model, "
                   "type B from each catalogue effect the model leaves out (its bias at the session's bound or a "
                   "default plausible size, rectangular). Values in &micro;m or &micro;rad.</p>")
        out.append("<table><tr><th class=l>Error</th><th>Value</th><th>Type A</th><th>u<sub>c</sub></th>"
                   "<th>U</th><th>k</th><th>&nu;<sub>eff</sub></th><th class=l>Dominant left-out effects</th></tr>")
        for name, e in b["location_errors"].items():
            if not e["observable"]:
                out.append(f"<tr><td class=l>{_e(name)}</td><td colspan=7 class=l>unobservable</td></tr>")
                continue
            f = 1e6 if e["unit"] == "rad" else 1e3
            nu = "&infin;" if e["nu_eff"] is None else f"{e['nu_eff']:.0f}"
            dom = ", ".join(_e(x) for x in e["dominant"]) or "none"
            out.append(f"<tr><td class=l>{_e(name)}</td><td>{e['value'] * f:+.3f}</td><td>{e['u_a'] * f:.3f}</td>"
                       f"<td>{e['u_c'] * f:.3f}</td><td>{e['expanded'] * f:.3f}</td><td>{e['k']:.2f}</td>"
                       f"<td>{nu}</td><td class=l>{dom}</td></tr>")
        out.append("</table>")
        from .results import budget_why
        why = budget_why(b)
        if why:
            out.append(f"<p>{_e(why)}</p>")
    out.append("</section>")
    return "".join(out) if (nm or b) else ""


def _with_budget(identification: Any, session: Any, diagnosis: Any) -> None:
    """Attach the budget of a given diagnosis to a joint identification that has none."""
    if diagnosis is None or getattr(identification, "budget", "none") is not None \
            or identification.raw.method != "joint":
        return
    from .diagnosis import uncertainty_budget
    identification.budget = uncertainty_budget(session, diagnosis)


def _swept_angle(angles_deg: np.ndarray) -> tuple[np.ndarray, int]:
    span = angles_deg.max(axis=0) - angles_deg.min(axis=0)
    k = int(np.argmax(span))
    return np.radians(angles_deg[:, k]), k


def polar_plots(tests: np.ndarray, angles_deg: np.ndarray, measured: np.ndarray,
                model: np.ndarray, nominal: float, axis_names: tuple[str, str]) -> list[str]:
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
        ax.set_title(f"{_plot_text(t)}: deviation from L0 against {axis_names[k]}\n"
                     f"scale: ring spacing {span / 2:.2g} \u00b5m", fontsize=8)
        ax.legend(loc="lower right", fontsize=7)
        figs.append((_png(fig), f"{_plot_text(t)}: measured and model, deviation magnified"))
    return figs


def residual_plot(tests: np.ndarray, residuals: list[tuple[str, np.ndarray]]) -> str:
    """Residual per sample, tests side by side, for one or more models."""
    fig, ax = plt.subplots(figsize=(9, 3))
    x = np.arange(len(tests))
    for label, r in residuals:
        ax.plot(x, r * 1e3, ".", ms=2, label=label)
    for t in dict.fromkeys(tests):
        idx = np.flatnonzero(tests == t)
        ax.axvline(idx[0], color="#ccc", lw=0.8)
        ax.text(idx.mean(), ax.get_ylim()[1], _plot_text(t), ha="center", va="bottom", fontsize=7)
    ax.set_xlabel("sample")
    ax.set_ylabel("residual (\u00b5m)")
    ax.legend(fontsize=7, loc="lower right")
    return _png(fig)


def harmonic_plot(structure: list[dict], title: str) -> str | None:
    groups = [g for g in structure if g["harmonic_um"]]
    if not groups:
        return None
    fig, ax = plt.subplots(figsize=(6, 3))
    w = 0.8 / len(groups)
    for i, g in enumerate(groups):
        orders = np.arange(1, len(g["harmonic_um"]) + 1)
        ax.bar(orders + i * w, g["harmonic_um"], width=w, label=_plot_text(f"{g['group']} ({g['angle_axis']})"))
    ax.set_xlabel("harmonic order in the swept rotary angle")
    ax.set_ylabel("amplitude (\u00b5m)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=6)
    return _png(fig)


def ballbar_report(path: str | Path, session: Any, identification: Any,
                   diagnosis: Any | None = None, title: str | None = None,
                   source: str = "", extra_sections: Iterable[str] = (), inputs: Iterable[str] = ()) -> Path:
    """Write the HTML report of a ballbar session (by the output rule; ``inputs`` are refused
    as the target). Every text from a file is escaped. Returns the path written."""
    from . import _core

    path = Path(path)
    baseline, location_only = None, identification
    extended = extended_identification(session, identification, diagnosis)
    if extended is not None:
        baseline, identification = identification.to_dict(), extended
    _with_budget(identification, session, diagnosis)
    ident = identification.to_dict()
    tests = np.asarray(session.tests, dtype=object)  # object: a long label must not widen every row
    angles = np.asarray(session.angles_deg)
    measured = np.asarray(session.length)
    model = _core.predict_session_lengths(identification.raw.model, session)
    machine = session.machine
    # session.angles_deg holds (tilt, rotary) on every machine, whatever their chain order.
    axis_names = (machine.tilt_axis, machine.rot_axis)
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{_e(title or 'rotacal report')}</title>"
             f"<style>{_CSS}</style></head><body>"]
    parts.append(f"<h1>{_e(title or 'Single set-up ballbar test')}</h1>")
    parts.append(f"<p class=muted>rotacal {_e(_version())} &middot; "
                 f"{_dt.datetime.now().strftime('%Y-%m-%d %H:%M')} &middot; {_e(source)}</p>")

    pv = ident["pivot"]
    pivot_txt = ", ".join("unobservable" if pv[a]["value"] is None else f"{pv[a]['value']:.4f}" for a in "xyz")
    parts.append('<section id="setup"><h2>Machine and set-up</h2><table>'
                 f"<tr><th class=l>Machine</th><td class=l>{_e(machine_words(machine))}</td></tr>"
                 f"<tr><th class=l>Ballbar length L0</th><td class=l>{session.ballbar_length:.4f} mm</td></tr>"
                 f"<tr><th class=l>Nominal pivot (table frame)</th><td class=l>{', '.join(f'{v:.4f}' for v in session.pivot)} mm</td></tr>"
                 f"<tr><th class=l>Identified pivot</th><td class=l>{pivot_txt} mm</td></tr>"
                 f"<tr><th class=l>Samples / tests</th><td class=l>{len(tests)} / {_e(', '.join(dict.fromkeys(tests)))}</td></tr>"
                 "</table></section>")

    parts.extend(location_errors_section(ident, baseline, diagnosis))
    parts.append(f"<p>Residual RMS {ident['residual_rms_um']:.3f} &micro;m over {ident['n_samples']} samples.</p>")
    parts.append(fitted_effects_table(ident.get("effects", [])))
    if ident["unobservable"]:
        parts.append("<p class=warn>Not determined by this session's tests:</p><ul>" +
                     "".join(f"<li>{_e(u)}</li>" for u in ident["unobservable"]) + "</ul>")
    if ident.get("notes"):
        parts.append("<ul class=muted>" + "".join(f"<li>{_e(n)}</li>" for n in ident["notes"]) + "</ul>")
    parts.append("</section>")
    parts.append(noise_budget_section(ident))

    parts.append('<section id="polar"><h2>Ballbar plots: measured against model</h2>')
    for src, cap in polar_plots(tests, angles, measured, model, session.ballbar_length, axis_names):
        parts.append(_img(src, cap, "polar"))
    parts.append("</section>")

    residuals = [("location-error model", np.asarray(location_only.residuals))]
    if diagnosis is not None and diagnosis.findings:
        residuals.append(("extended model", np.asarray(diagnosis.raw.final_fit.residuals)))
    parts.append('<section id="residuals"><h2>Residuals</h2>')
    parts.append(_img(residual_plot(tests, residuals), "residual per sample (measured - model)", "residuals"))
    parts.append("</section>")

    if diagnosis is not None:
        parts.append(diagnosis_section(diagnosis.to_dict()))
    parts.extend(extra_sections)
    return _write_page(path, parts, inputs)


# Records on load how many figures decoded, so a browser test can check they render.
_IMAGE_CHECK = ("<script>window.addEventListener('load',function(){var im=document.images,ok=0;"
                "for(var i=0;i<im.length;i++){if(im[i].complete&&im[i].naturalWidth>0)ok++;}"
                "document.body.setAttribute('data-images',im.length);"
                "document.body.setAttribute('data-images-rendered',ok);});</script>")


def _write_page(path: Path, parts: list[str], inputs: Iterable[str] = ()) -> Path:
    """Close the page (with the image check) and write it by the output rule."""
    from .outputs import write_output
    parts = parts + [_IMAGE_CHECK, "</body></html>"]
    write_output(path, "\n".join(parts), [str(i) for i in inputs])
    return path


def diagnosis_report(path: str | Path, d: dict, title: str, source: str = "", inputs: Iterable[str] = ()) -> Path:
    """A report with the diagnosis alone (e.g. of an R-test session)."""
    from .outputs import write_output
    path = Path(path)
    page = (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{_e(title)}</title>"
            f"<style>{_CSS}</style></head><body><h1>{_e(title)}</h1>"
            f"<p class=muted>rotacal {_e(_version())} &middot; {_e(source)}</p>"
            f"{diagnosis_section(d)}</body></html>")
    write_output(path, page, [str(i) for i in inputs])
    return path


def diagnosis_section(d: dict) -> str:
    b = d["baseline"]
    out = ['<section id="diagnosis"><h2>Diagnosis</h2>',
           f"<p>Baseline (location errors and pivot): residual RMS {b['residual_rms_um']:.3f} &micro;m, "
           f"noise {b['noise_um']:.3f} &micro;m ({_e(b['noise_source'])}), "
           f"&chi;&sup2;/dof {b['chi2_per_dof']:.2f} (p = {b['p_value']:.2g}).</p>"]
    if not d["findings"]:
        out.append("<p class=ok>No effect of the catalogue is significant: the location-error model "
                   "explains the data to the noise.</p>")
    else:
        out.append("<table><tr><th class=l>#</th><th class=l>Effect</th><th>Weight</th><th class=l>Cause</th>"
                   "<th class=l>Parameters</th><th>RMS before</th><th>RMS after</th><th>&Delta;BIC</th>"
                   "<th>CV RMS before</th><th>CV RMS after</th></tr>")
        for i, f in enumerate(d["findings"], 1):
            params = "<br>".join(f"{_e(k)} = {_e(units.estimate_text(v['value'], v['std'], v['unit']))}"
                                 for k, v in f["parameters"].items())
            if f["named"]:
                effect = _e(f["effect"])
            else:  # the group the data cannot separate, with the parameters of its best
                effect = "one of: " + ", ".join(
                    f"{_e(m['effect'])} ({'aliased' if m.get('aliased') else format(m['weight'], '.2f')})"
                    for m in f["group"])
                params = f"if {_e(f['effect'])}:<br>" + params
            g = f["gain"]
            out.append(f"<tr><td class=l>{i}</td><td class=l>{effect}</td><td>{f['weight']:.2f}</td>"
                       f"<td class=l>{_e(f['cause'])}</td>"
                       f"<td class=l>{params}</td><td>{g['rms_before_um']:.3f}</td><td>{g['rms_after_um']:.3f}</td>"
                       f"<td>{g['delta_bic']:.1f}</td><td>{g['cv_rms_before_um']:.3f}</td><td>{g['cv_rms_after_um']:.3f}</td></tr>")
        out.append("</table><p class=muted>RMS in &micro;m; CV: blocked cross-validation. Weight: the BIC "
                   "weight of the effect against the candidates that explain the same signal; below 0.9 the "
                   "finding is the group the data cannot separate, not one name.</p>")
    for a in d["ambiguous"]:
        out.append(f"<p class=warn>Cannot be told apart with this data: {_e(', '.join(a['effects']))} "
                   f"({_e(a['separating_test'])}).</p>")
    if d["unexplained"]["present"]:
        out.append(f"<p class=warn>Unexplained structure remains (&chi;&sup2;/dof "
                   f"{d['unexplained']['chi2_per_dof']:.2f}): {_e(d['unexplained']['signature'])}</p>")
    for title, key in (("before", "before"), ("after", "after")):
        src = harmonic_plot(d["residual_structure"][key], f"residual harmonics {title} the diagnosis")
        if src:
            out.append(_img(src, f"residual harmonics {title}", "diagnosis"))
    notes = {g["harmonic_note"] for g in d["residual_structure"]["before"] if g.get("harmonic_note")}
    for note in sorted(notes):
        out.append(f"<p class=muted>{_e(note)}</p>")
    if d["unobservable"]:
        out.append("<details><summary>Effects this session cannot see</summary><ul>" +
                   "".join(f"<li>{_e(u['effect'])}: {_e(u['reason'])}</li>" for u in d["unobservable"]) +
                   "</ul></details>")
    out.append("</section>")
    return "\n".join(out)


def _version() -> str:
    from . import __version__
    return __version__


# ------------------------------------------------------------------------- R-test

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
    from . import _core
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
            ax.text(0.5, 0.5, "not fitted: a head axis' rotations\nonly move the one sphere", ha="center",
                    va="center", transform=ax.transAxes, fontsize=8, color="#777")
        ax.axhline(0, color="#999", lw=0.6)
        ax.set_title(f"{_COMPONENTS[k]}_{tilt_map} ({unit})"
                     + ("" if k >= fitted or np.all(np.isfinite(s[:, k])) else ", not determined (dashed)"),
                     fontsize=9)
        ax.tick_params(labelsize=7)
        if k >= 3:
            ax.set_xlabel(f"{tilt} (deg)", fontsize=8)
    fig.suptitle(f"{tilt}-axis errors beyond its location errors, joint fit (band: 1\u03c3)", fontsize=10)
    fig.tight_layout()
    return _png(fig)


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
            _band(axes.flat[k], c, v[:, k] * scale, s[:, k] * scale, colors[bi], f"{tilt} = {b:g}\u00b0")
    for k, ax in enumerate(axes.flat):
        scale, unit = _component_scale(k)
        ax.set_title(f"{_COMPONENTS[k]}_{rot_map} ({unit})", fontsize=9)
        ax.tick_params(labelsize=7)
        if k >= 3:
            ax.set_xlabel(f"{rot} (deg)", fontsize=8)
        if k >= fitted:
            why = ("assumed 0\n(Oyama Sec. 4.2)" if k == 5 and fitted == 5
                   else "a head axis' rotations\nonly move the one sphere")
            ax.text(0.5, 0.5, "not fitted: " + why, ha="center", va="center",
                    transform=ax.transAxes, fontsize=8, color="#777")
        ax.axhline(0, color="#999", lw=0.6)
    axes.flat[0].legend(fontsize=6, ncol=2)
    fig.suptitle(f"{rot}-axis errors beyond its location errors, joint fit (bands: 1\u03c3)", fontsize=10)
    fig.tight_layout()
    return _png(fig)


def rtest_residual_plot(setups: np.ndarray, residuals: np.ndarray) -> str:
    """Residual (measured - model) of each reading component per pose."""
    labels = np.array([f"set-up {s}" for s in setups], dtype=object)
    return residual_plot(labels, [(f"d{a}", residuals[:, k]) for k, a in enumerate("xyz")])


def rtest_report(path: str | Path, session: Any, identification: Any, diagnosis: Any | None = None,
                 title: str | None = None, source: str = "", inputs: Iterable[str] = (),
                 extra_sections: Iterable[str] = ()) -> Path:
    """Write the HTML report of an R-test session: set-up, location errors (ISO 230-7 table),
    the error map against B and C with uncertainty bands, residuals and the diagnosis."""
    from . import _core

    path = Path(path)
    _with_budget(identification, session, diagnosis)
    ident = identification.to_dict()
    if ident["method"] != "joint":
        raise _core.InvalidArgument("rtest_report: needs the joint identification (its model draws the map)")
    model = identification.raw.model
    setups = np.asarray(session.setups, dtype=object)
    angles = np.asarray(session.angles_deg)
    b_meas = sorted(set(np.round(angles[:, 0], 6).tolist()))
    c_meas = sorted(set(np.round(angles[:, 1], 6).tolist()))
    heading = title or "R-test: location errors and error map of the rotary axes"
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{_e(heading)}</title>"
             f"<style>{_CSS}</style></head><body>", f"<h1>{_e(heading)}</h1>",
             f"<p class=muted>rotacal {_e(_version())} &middot; "
             f"{_dt.datetime.now().strftime('%Y-%m-%d %H:%M')} &middot; {_e(source)}</p>"]

    rows = [f"<tr><th class=l>Machine</th><td class=l>{_e(machine_words(session.machine))}</td></tr>"]
    for label, q in sorted(session.nests.items()):
        rows.append(f"<tr><th class=l>Nest {_e(label)} (table frame)</th>"
                    f"<td class=l>{', '.join(f'{v:.4f}' for v in q)} mm</td></tr>")
    for n, d in sorted(session.probe_dirs.items()):
        rows.append(f"<tr><th class=l>Probe {_e(str(n))} direction</th><td class=l>{', '.join(f'{v:.6f}' for v in d)}</td></tr>")
    tilt, rot = session.machine.tilt_axis, session.machine.rot_axis
    rows.append(f"<tr><th class=l>Poses</th><td class=l>{len(setups)} ({len(b_meas)} {tilt} &times; {len(c_meas)} "
                f"{rot} positions, {len(set(setups.tolist()))} set-ups)</td></tr>")
    rows.append(f"<tr><th class=l>{tilt} (deg)</th><td class=l>{', '.join(f'{b:g}' for b in b_meas)}</td></tr>")
    rows.append(f"<tr><th class=l>{rot} (deg)</th><td class=l>{', '.join(f'{c:g}' for c in c_meas)}</td></tr>")
    if session.noise_um is not None:
        rows.append(f"<tr><th class=l>Stated noise</th><td class=l>{session.noise_um:.3f} &micro;m</td></tr>")
    parts.append('<section id="setup"><h2>Machine and set-up</h2><table>' + "".join(rows) + "</table></section>")

    parts.append('<section id="location-errors"><h2>Location errors (ISO 230-7), joint fit</h2>')
    parts.append(location_error_table(ident["location_errors"]))
    zeros = ", ".join(f"set-up {_e(k)}: ({', '.join(f'{v * 1e3:+.2f}' for v in z)}) &micro;m"
                      for k, z in ident["probe_zeros"].items())
    parts.append(f"<p>Residual RMS {ident['residual_rms_um']:.3f} &micro;m over {ident['n_samples']} poses "
                 f"(3 readings each). Fitted probe zeros: {zeros}.</p>")
    if ident["unobservable"]:
        parts.append("<p class=warn>Not determined by this session's nests:</p><ul>" +
                     "".join(f"<li>{_e(u)}</li>" for u in ident["unobservable"]) + "</ul>")
    parts.append("<ul class=muted>" + "".join(f"<li>{_e(n)}</li>" for n in ident["notes"]) + "</ul>")
    parts.append("</section>")

    map_csv = identification.error_map("csv", b_meas, c_meas)
    tilt, rot, tilt_map, rot_map = _map_words(model)
    parts.append(noise_budget_section(ident))
    parts.append('<section id="error-map"><h2>Error map (Oyama &amp; Ibaraki Sec. 5.2)</h2>'
                 f"<p>Position-dependent errors of the {tilt} axis (w_{tilt_map}, in front of the {tilt} "
                 f"rotation) and of the {rot} axis (w_{rot_map}, in front of the {rot} rotation), beyond "
                 "the rigid axis lines whose location errors are in the table above. Curves: the joint "
                 "fit's smooth maps; bands: "
                 "&plusmn;1&sigma; from the parameter covariance. "
                 f"<a download='error_map.csv' href='data:text/csv;base64,"
                 f"{base64.b64encode(map_csv.encode()).decode('ascii')}'>The map at the measured angles "
                 "(CSV)</a>.</p>")
    parts.append(_img(rtest_b_map_plot(model, (b_meas[0], b_meas[-1])), f"{tilt}-axis errors against {tilt}",
                      "error-map"))
    parts.append(_img(rtest_c_map_plot(model, b_meas), f"{rot}-axis errors against {rot} at each measured {tilt}",
                      "error-map"))
    parts.append("</section>")

    parts.append('<section id="residuals"><h2>Residuals</h2>')
    parts.append(_img(rtest_residual_plot(setups, np.asarray(identification.raw.residuals)),
                      "residual per pose and reading (measured - joint model)", "residuals"))
    parts.append("</section>")

    if diagnosis is not None:
        parts.append(diagnosis_section(diagnosis.to_dict()))
    parts.extend(extra_sections)
    return _write_page(path, parts, inputs)


# ------------------------------------------------------------------------- ISO 230-4 circular tests

def circular_report(path: str | Path, result: Any, title: str | None = None, source: str = "",
                    inputs: Iterable[str] = (), extra_sections: Iterable[str] = ()) -> Path:
    """The HTML report of a session of ISO 230-4 circular tests (rotacal.circular.analyze):
    G per run, G(b) and H per cw/ccw pair, the polar plot and the named causes."""
    from .circular import polar_figure

    path = Path(path)
    d = result.to_dict()
    heading = title or "Circular tests of the linear axes (ISO 230-4)"
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{_e(heading)}</title>"
             f"<style>{_CSS}</style></head><body>", f"<h1>{_e(heading)}</h1>",
             f"<p class=muted>rotacal {_e(_version())} &middot; "
             f"{_dt.datetime.now().strftime('%Y-%m-%d %H:%M')} &middot; {_e(source)}</p>"]
    rows = ["<table><tr><th class=l>Run</th><th class=l>Plane</th><th class=l>Direction</th>"
            "<th>Feed (mm/min)</th><th>Span (deg)</th><th>Readings</th><th>G (&micro;m)</th>"
            "<th>Radius deviation (&micro;m)</th></tr>"]
    for r in d["runs"]:
        rows.append(f"<tr><td class=l>{_e(r['label'])}</td><td class=l>{_e(r['plane'])}</td>"
                    f"<td class=l>{_e(r['direction'])}</td><td>{r['feed_mm_per_min']:.0f}</td>"
                    f"<td>{r['span_deg']:.1f}</td><td>{r['n']}</td><td>{r['G_um']:.2f}</td>"
                    f"<td>{r['radius_deviation_um']:.2f}</td></tr>")
    rows.append("</table>")
    parts.append(f'<section id="circular-deviation"><h2>Circular deviation G per run (bar length '
                 f'{d["ballbar_length"]:g} mm)</h2><p>G: the radial separation of the two circles about the '
                 "least-squares centre that enclose the path (ISO 230-4).</p>" + "".join(rows))
    if d["pairs"]:
        prs = ["<table><tr><th class=l>Plane</th><th>Feed (mm/min)</th><th>G(b) (&micro;m)</th>"
               "<th>H (&micro;m)</th><th>at (deg)</th></tr>"]
        for q in d["pairs"]:
            prs.append(f"<tr><td class=l>{_e(q['plane'])}</td><td>{q['feed_mm_per_min']:.0f}</td>"
                       f"<td>{q['G_b_um']:.2f}</td><td>{q['H_um']:.2f}</td><td>{q['H_angle_deg']:.1f}</td></tr>")
        prs.append("</table>")
        parts.append("<p>Bidirectional circular deviation G(b) and circular hysteresis H of each "
                     "clockwise / counter-clockwise pair:</p>" + "".join(prs))
    if d["ignored_tests"]:
        parts.append(f"<p class=warn>Not circular runs, ignored: {_e(', '.join(d['ignored_tests']))}</p>")
    parts.append("</section>")
    parts.append('<section id="polar"><h2>Polar plot</h2>')
    parts.append(_img(_png(polar_figure(result)), "radial deviation of every run about its least-squares centre",
                      "polar"))
    parts.append("</section>")
    diag = d.get("diagnosis")
    if diag is not None:
        parts.append('<section id="diagnosis"><h2>Causes (catalogue of docs/effects.md, circular tests)</h2>'
                     f"<p>Residual RMS about each run's circle {diag['baseline_rms_um']:.2f} &micro;m; with the "
                     f"findings {diag['final_rms_um']:.2f} &micro;m. Noise: {_e(diag['noise'])}.</p>")
        if not diag["findings"]:
            parts.append("<p>No cause in the catalogue is supported by the data.</p>")
        else:
            fr = ["<table><tr><th class=l>Cause</th><th class=l>Parameters (1&sigma;)</th>"
                  "<th>RMS before (&micro;m)</th><th>after</th></tr>"]
            for f in diag["findings"]:
                ps = "; ".join(f"{_e(p['name'].split('.')[-1])} = {p['value']:.4g} &plusmn; {p['std']:.2g} "
                               f"{_e(p['unit'])}" for p in f["parameters"])
                fr.append(f"<tr><td class=l><b>{_e(f['effect'])}</b><br>{_e(f['cause'])}</td><td class=l>{ps}</td>"
                          f"<td>{f['gain']['rms_before_um']:.2f}</td><td>{f['gain']['rms_after_um']:.2f}</td></tr>")
            fr.append("</table>")
            parts.append("".join(fr))
        if diag["unobservable"]:
            parts.append("<p>Not determined by these runs:</p><ul>" +
                         "".join(f"<li>{_e(u['effect'])}: {_e(u['reason'])}</li>" for u in diag["unobservable"]) +
                         "</ul>")
        parts.append("</section>")
    parts.extend(extra_sections)
    return _write_page(path, parts, inputs)
