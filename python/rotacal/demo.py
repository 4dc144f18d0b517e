# SPDX-License-Identifier: BSD-3-Clause
"""The whole job on a simulated machine: plan, simulate, identify, diagnose, compensate and report (``rotacal demo``)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Callable

from . import _core, jsontext
from .ballbar import identify, nc_program, verify_compensation
from .diagnosis import diagnose, held_effects
from .machines import ballbar_truth, simulate_ballbar_test
from .models import save_model
from .outputs import write_output
from .sessions import save

STEPS = 6


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

    Returns {"sag_mm", "finding" (the first finding's dict or None), "worst_change_percent",
    "report" (path)}.
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

    step(5, "compensating and measuring again (Table 2 experiment)")
    rows = verify_compensation(setup, truth)
    _write_json(out / "compensation.json", rows)

    step(6, "writing the report")
    report = ballbar_report(
        out / "report.html",
        session,
        ident,
        diag,
        title="rotacal demo: single set-up ballbar test",
        source=str(out / "session.csv"),
        extra_sections=[compensation_section(rows)],
    )
    return {
        "sag_mm": sag_mm,
        "finding": dd["findings"][0] if dd["findings"] else None,
        "worst_change_percent": max(r["change_percent"] for r in rows),
        "report": report,
    }
