# SPDX-License-Identifier: BSD-3-Clause
"""The whole job on a simulated machine: plan, simulate, identify, diagnose, compensate and report (``rotacal demo``)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

from . import _core, jsontext
from .ballbar import identify, nc_program, verify_compensation
from .diagnosis import diagnose, held_effects
from .machines import ballbar_truth, simulate_ballbar_test
from .models import save_model
from .outputs import write_output
from .sessions import save

STEPS = 7


def compensation_section(rows: list[dict]) -> str:
    """The report section of the Table 2 experiment (rows of ballbar.compensation_table)."""
    out = [
        "<section id='compensation'><h2>Compensation (Flynn et al. Table 2 experiment, simulated)</h2>"
        "<p>A separate experiment on the simulated machine, as in the paper: its own measurement, "
        "identification of the location errors, compensation and measurement again. Its "
        "'Uncompensated' column is that run's identification, not this session's: the values to load "
        "are those of the location-error section above.</p>"
        "<table><tr><th class=l>Error</th><th>Uncompensated</th><th>Compensated</th><th>Change</th></tr>"
    ]
    for r in rows:
        k, unit = (1e3, "&micro;m") if r["unit"] == "mm" else (1e6, "&micro;rad")
        out.append(
            f"<tr><td class=l>{r['name']}</td><td>{r['before'] * k:+.2f} {unit}</td>"
            f"<td>{r['after'] * k:+.2f} {unit}</td><td>{r['change_percent']:+.1f} %</td></tr>"
        )
    out.append("</table></section>")
    return "\n".join(out)


def loop_section(loop: dict) -> str:
    """The report section of the loop (issue 50 item 2): the group, the deciding test designed
    and simulated, the two sessions diagnosed together, the cause, the gain and the location
    errors of the final model."""
    from html import escape

    from . import units

    out = ["<section id='loop'><h2>The deciding test (the loop of an ambiguous diagnosis)</h2>"]
    out.append(f"<p>1. The session alone: one of {escape(', '.join(loop['group']))}.</p>")
    for t in loop["tried"]:
        out.append(
            f"<p>2. Design to separate {escape(' and '.join(t['pair']))}: {escape(t['verdict'])}</p>"
        )
    if not loop.get("added_test"):
        out.append("<p>No added test separates the members: the model rule decides.</p></section>")
        return "\n".join(out)
    a = loop["added_test"]
    out.append(
        f"<p>3. The added test ({escape(', '.join(a['tests']))}, pivot "
        f"{', '.join(f'{v:g}' for v in a['pivot'])} mm, {a['run_time_s']:.0f} s) simulated on the "
        f"same machine: {escape(a['session'])}.</p>"
    )
    f = loop["finding"]
    what = (
        f"{escape(f['effect'])} alone (weight {f['weight']:.2f})"
        if f["named"]
        else "still one of " + escape(", ".join(g["effect"] for g in f["group"]))
    )
    out.append(f"<p>4. Both sessions diagnosed together: {what}, for {escape(f['where'])}.</p>")
    out.append("<table><tr><th class=l>Session</th><th>RMS before</th><th>RMS after</th></tr>")
    for x in loop["sessions"]:
        out.append(
            f"<tr><td class=l>{escape(x['name'])}</td><td>{x['residual_rms_before_um']:.3f} &micro;m</td>"
            f"<td>{x['residual_rms_after_um']:.3f} &micro;m</td></tr>"
        )
    out.append(
        "</table><p>5. Location errors of the final model (both sessions, the cause in it):</p>"
    )
    out.append("<table><tr><th class=l>Error</th><th>Value</th></tr>")
    for name, p in loop["location_errors"].items():
        out.append(
            f"<tr><td class=l>{escape(name)}</td>"
            f"<td>{escape(units.estimate_text(p['value'], p['std'], p['unit']))}</td></tr>"
        )
    out.append("</table>")
    if loop.get("other_instrument"):
        out.append(_probe_step_html(loop["other_instrument"]))
    out.append("</section>")
    return "\n".join(out)


def _probe_step_html(o: dict) -> str:
    """The report's part of probe_step: the probe test, the three sessions together, the cause,
    each session's RMS and the location errors of the final model."""
    from html import escape

    from . import units

    f = o["finding"]
    if f is None:
        what = "nothing significant"
    elif f["named"]:
        what = f"{escape(f['effect'])} alone (weight {f['weight']:.2f}), for {escape(f['where'])}"
    else:
        what = "still one of " + escape(", ".join(g["effect"] for g in f["group"]))
    out = [
        f"<p>6. No added ballbar test separates what is left; the machine's other instrument: "
        f"{escape(o['test'])}, simulated on the same machine. The three sessions together: "
        f"{what}.</p>",
        "<table><tr><th class=l>Session</th><th>RMS before</th><th>RMS after</th></tr>",
    ]
    for x in o["sessions"]:
        out.append(
            f"<tr><td class=l>{escape(x['name'])}</td><td>{x['residual_rms_before_um']:.3f} &micro;m</td>"
            f"<td>{x['residual_rms_after_um']:.3f} &micro;m</td></tr>"
        )
    out.append("</table><p>7. Location errors of the final model (the three sessions):</p>")
    out.append("<table><tr><th class=l>Error</th><th>Value</th></tr>")
    for name, p in o["location_errors"].items():
        out.append(
            f"<tr><td class=l>{escape(name)}</td>"
            f"<td>{escape(units.estimate_text(p['value'], p['std'], p['unit']))}</td></tr>"
        )
    out.append("</table>")
    return "\n".join(out)


def close_the_loop(
    setup: Any, session: Any, truth: dict, finding: dict, seed: int, out: Path
) -> dict:
    """Design the test that decides between members of `finding`'s group, simulate it on the
    machine of `truth` (a new pivot: a new set-up error), diagnose both sessions together."""
    from .deciding_test import design_deciding_test, group_members
    from .design import added_setup

    design, tried = design_deciding_test(session, finding, setup)
    loop: dict = {"group": group_members(finding), "tried": tried}
    if design is None:
        return loop
    added = added_setup(design)
    plan, text = nc_program(added, "linuxcnc")
    write_output(out / "added_test.ngc", text)
    rng = np.random.default_rng(seed + 1)
    truth_added = dict(truth, seed=seed + 1)
    if design.chosen.new_pivot:  # the bar mounted again: a set-up error of its own
        truth_added["pivot_error"] = rng.normal(0.0, 0.01, 3).tolist()
    added_session, _ = simulate_ballbar_test(added, truth_added)
    save(added_session, out / "added_test.csv")
    joint = diagnose([("session", session), ("added_test", added_session)]).to_dict()
    _write_json(out / "loop_diagnosis.json", joint)
    f = joint["findings"][0] if joint["findings"] else None
    loop["added_test"] = {
        "tests": [_core.test_label(t, added.machine) for t in added.tests],
        "pivot": list(map(float, added.pivot)),
        "run_time_s": plan.duration,
        "session": str(out / "added_test.csv"),
    }
    loop["finding"] = f
    loop["sessions"] = joint["sessions"]
    loop["location_errors"] = joint["final_model"]["location_errors"]
    loop["final_model"] = joint["final_model"]
    if f is not None and not f["named"] and _separable_left(f, tried):
        sessions = [("session", session), ("added_test", added_session)]
        loop["other_instrument"] = probe_step(setup, truth, sessions, seed, out)
    return loop


def _separable_left(finding: dict, tried: list[dict]) -> bool:
    """True where the group still holds a pair not known to be nested (no ballbar design said
    their table motions are the same): another instrument may separate it."""
    from .deciding_test import group_members

    nested = {frozenset(t["pair"]) for t in tried if t["same_motion"]}
    members = group_members(finding)
    return any(
        frozenset((a, b)) not in nested for i, a in enumerate(members) for b in members[i + 1 :]
    )


def probe_step(setup: Any, truth: dict, sessions: list, seed: int, out: Path) -> dict:
    """The machine's other instrument where no added ballbar test separates what is left (issue
    50 item 2): a machine effect is shared by every session of the machine, so the touch probe's
    standard poses (`rotacal plan probe`: its default cross, a sphere of its own set-up) are
    simulated on the same machine and diagnosed with the ballbar sessions."""
    from .probe import simulate_probe

    m = setup.machine
    poses, _ = _core.default_probe_poses_deg(m)
    sphere = (150.0, 0.0, 80.0)  # plan probe's default sphere position
    write_output(out / "probe_test.ngc", _core.write_probe_nc_program(m, "linuxcnc", poses, sphere))
    names = list(_core.location_error_names(m))
    rng = np.random.default_rng(seed + 2)
    probe_session, _ = simulate_probe(
        m,
        [truth["errors"][n] for n in names],
        truth["effects"],
        sphere_offset=rng.normal(0.0, 0.01, 3),  # the sphere's own set-up error
        noise_um=truth["noise_um"],
        seed=seed + 2,
        sphere=sphere,
    )
    save(probe_session, out / "probe_test.csv")
    joint = diagnose([*sessions, ("probe_test", probe_session)]).to_dict()
    _write_json(out / "loop_probe_diagnosis.json", joint)
    f = joint["findings"][0] if joint["findings"] else None
    return {
        "test": f"touch probe, {len(poses)} poses (plan probe's default), sphere "
        + ", ".join(f"{v:g}" for v in sphere)
        + " mm",
        "session": str(out / "probe_test.csv"),
        "finding": f,
        "sessions": joint["sessions"],
        "location_errors": joint["final_model"]["location_errors"],
    }


def _write_json(path: Path, data: object) -> None:
    write_output(path, jsontext.dumps(data) + "\n")


def run_demo(
    output: str | Path,
    seed: int = 2016,
    sag_mm: float = 0.004,
    say: Callable[[str], None] = lambda _: None,
) -> dict:
    """Simulate the machine of Flynn et al. Table 2 with a pivot set-up error and a hidden
    gravity sag, measure, identify, diagnose, compensate and write every file and the report
    into ``output`` (created, with its parents: the one output folder a command makes). ``say`` receives one progress line per step.

    Where the diagnosis gives a group, the loop (close_the_loop): the deciding test designed,
    simulated on the same machine and diagnosed with the session.

    Returns {"sag_mm", "finding" (the first finding's dict or None), "worst_change_percent",
    "report" (path), "loop" (close_the_loop's dict, None where the diagnosis named its cause)}.
    """
    from .report import ballbar_report, extended_identification  # draws

    out = Path(output)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()

    def step(i: int, what: str) -> None:
        say(f"[{i}/{STEPS}] {what} ({time.monotonic() - t0:.1f} s)")

    step(1, "planning the single set-up ballbar test (AC-trt, L0 = 100 mm, pivot 120, 0, 60)")
    setup = _core.BallbarSetup()
    for name, dialect in (("ballbar_test.ngc", "linuxcnc"), ("ballbar_test.h", "heidenhain")):
        plan, text = nc_program(setup, dialect)
        write_output(out / name, text)

    step(
        2,
        "simulating the machine of Flynn et al. Table 2 with a pivot set-up error and a hidden effect",
    )
    truth = ballbar_truth(
        setup.machine, "table2", {"gravity_sag_A": [sag_mm]}, noise_um=0.5, seed=seed
    )
    truth["pivot_error"] = [0.012, -0.008, 0.015]  # fixed, as in the paper's set-up
    session, machine = simulate_ballbar_test(setup, truth)
    save(session, out / "session.csv")
    truth["pivot_actual"] = machine.pivot.tolist()
    _write_json(out / "truth.json", truth)

    step(3, "identifying the location errors (joint fit of the exact model)")
    ident = identify(session)

    step(4, "diagnosing what the location-error model gets wrong")
    diag = diagnose(session, reference=plan.commanded_session())
    dd = diag.to_dict()
    _write_json(out / "diagnosis.json", dd)
    # One value per quantity: where the diagnosis extended the model, its fit is the result
    # (model.json, identification.json); the location errors alone are kept beside it, labelled.
    extended = extended_identification(session, ident, diag)
    result = extended if extended is not None else ident
    model = result.model_dict()
    why = {h["id"]: h["held_because"] for h in held_effects(diag)} if extended else {}
    for entry in model.get("effects", []):  # which member of its group, and why (issue 50)
        entry["held_because"] = why[entry["id"]]
    save_model(model, out / "model.json")
    _write_json(out / "identification.json", result.to_dict())
    if extended is not None:
        _write_json(out / "identification_location_errors_only.json", ident.to_dict())

    f = dd["findings"][0] if dd["findings"] else None
    loop = None
    if f is not None and not f["named"]:
        step(
            5,
            "the diagnosis gives a group: designing the deciding test, simulating it, "
            "diagnosing both sessions",
        )
        loop = close_the_loop(setup, session, truth, f, seed, out)
        _write_json(out / "loop.json", {k: v for k, v in loop.items() if k != "final_model"})
    else:
        step(5, "the diagnosis names its cause alone (or nothing): no deciding test needed")

    step(6, "compensating and measuring again (Table 2 experiment)")
    rows = verify_compensation(setup, truth)
    _write_json(out / "compensation.json", rows)

    step(7, "writing the report")
    report = ballbar_report(
        out / "report.html",
        session,
        ident,
        diag,
        title="rotacal demo: single set-up ballbar test",
        source=str(out / "session.csv"),
        extra_sections=([loop_section(loop)] if loop else []) + [compensation_section(rows)],
    )
    return {
        "sag_mm": sag_mm,
        "finding": dd["findings"][0] if dd["findings"] else None,
        "worst_change_percent": max(r["change_percent"] for r in rows),
        "report": report,
        "loop": loop,
    }
