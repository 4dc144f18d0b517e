# SPDX-License-Identifier: BSD-3-Clause
"""ISO 230-4 circular tests of the linear axes with the ballbar: plan, NC program, simulation,
G / G(b) / H and the diagnosis of their classic causes (include/rotacal/ballbar/circular_*.hpp,
include/rotacal/diagnose/circular_diagnosis.hpp). The ``rotacal circular`` command is
rotacal.cli.circular.

The session is a plain ``rotacal-ballbar/1`` file whose tests are labelled
``circular_<XY|YZ|ZX>_<ccw|cw>[_f<feed>]``; every rotary axis is at 0 and the pivot is the
circle's centre, so the same instrument, set-up and files serve the 3-axis check before the
rotary-axis calibration.
"""

from __future__ import annotations

from typing import Any, Mapping, Sequence

import numpy as np

from . import _core

AXES = "XYZ"
PLANES = ("XY", "YZ", "ZX")
# Display units of the catalogue's parameter units (the C++ side is in mm, rad, s).
_DISPLAY = {"mm": ("um", 1e3), "rad": ("urad", 1e6), "mm/mm": ("um/m", 1e6), "s": ("ms", 1e3)}


def plan(
    planes: Sequence[str] = PLANES,
    feeds_mm_per_min: Sequence[float] = (1000.0, 3000.0),
    directions: Sequence[str] = ("ccw", "cw"),
    *,
    machine: Any = None,
    radius: float = 100.0,
    centre: Sequence[float] = (120.0, 0.0, 60.0),
    start_deg: float = 0.0,
    span_deg: float = 360.0,
    run_in_deg: float = 45.0,
    overshoot_deg: float = 45.0,
    sample_rate_hz: float = 250.0,
) -> Any:
    """The runs of an ISO 230-4 circular test (planes x feeds x directions), as
    ``_core.CircularPlanResult``; bad options raise InvalidArgument naming the option."""
    from .machines import load_machine

    p = _core.CircularTestPlan()
    if machine is not None:
        p.machine = load_machine(machine)
    p.radius = float(radius)
    p.centre = np.asarray(centre, dtype=float)
    p.planes = [_core.parse_circular_plane(str(x)) for x in planes]
    p.feeds_mm_per_min = [float(f) for f in feeds_mm_per_min]
    p.directions = [_core.parse_circular_direction(str(d)) for d in directions]
    p.start_deg, p.span_deg = float(start_deg), float(span_deg)
    p.run_in_deg, p.overshoot_deg = float(run_in_deg), float(overshoot_deg)
    p.sample_rate_hz = float(sample_rate_hz)
    return _core.plan_circular_test(p)


def nc_program(planned: Any, dialect: str = "linuxcnc") -> str:
    """NC program text of a planned circular test (linuxcnc, heidenhain, siemens, fanuc)."""
    return _core.write_circular_nc_program(planned, _core.parse_nc_dialect(dialect))


def errors(
    squareness_urad: Mapping[str, float] | None = None,
    scale_um_per_m: Mapping[str, float] | None = None,
    straightness_um: Mapping[str, float] | None = None,
    backlash_um: Mapping[str, float] | None = None,
    spike_um: Mapping[str, float] | None = None,
    spike_tau_ms: Mapping[str, float] | None = None,
    servo_lag_ms: Mapping[str, float] | None = None,
    cyclic_um: Mapping[str, Sequence[float]] | None = None,
    screw_pitch_mm: Mapping[str, float] | None = None,
) -> Any:
    """``_core.LinearAxisErrors`` from readable units: squareness by plane ("XY": x += s y),
    straightness by "DA" (error direction D, moving axis A: c2 at 100 mm from the centre),
    cyclic by axis as (cos, sin) amplitudes; every other entry by axis letter."""
    e = _core.LinearAxisErrors()

    def vec(
        field: str, values: Mapping[str, float] | None, keys: Sequence[str], scale: float
    ) -> None:
        if not values:
            return
        v = np.array(getattr(e, field), dtype=float)
        for k, x in values.items():
            if k not in keys:
                raise _core.InvalidArgument(
                    f"{field}: unknown key {k!r} (known: {', '.join(keys)})"
                )
            v[keys.index(k)] = float(x) * scale
        setattr(e, field, v)

    vec("squareness", squareness_urad, PLANES, 1e-6)
    vec("scale", scale_um_per_m, list(AXES), 1e-6)
    vec("backlash", backlash_um, list(AXES), 1e-3)
    vec("spike", spike_um, list(AXES), 1e-3)
    vec("spike_tau", spike_tau_ms, list(AXES), 1e-3)
    vec("servo_tau", servo_lag_ms, list(AXES), 1e-3)
    vec("screw_pitch", screw_pitch_mm, list(AXES), 1.0)
    if straightness_um:
        m = np.array(e.straightness, dtype=float)
        for k, x in straightness_um.items():
            if len(k) != 2 or k[0] not in AXES or k[1] not in AXES or k[0] == k[1]:
                raise _core.InvalidArgument(
                    f"straightness: key {k!r} must be two different axes DA, e.g. 'YX'"
                )
            m[AXES.index(k[0]), AXES.index(k[1])] = float(x) * 1e-3
        e.straightness = m
    if cyclic_um:
        c, s = np.array(e.cyclic_cos, dtype=float), np.array(e.cyclic_sin, dtype=float)
        for k, (a, b) in cyclic_um.items():
            if k not in AXES:
                raise _core.InvalidArgument(f"cyclic: unknown axis {k!r}")
            c[AXES.index(k)], s[AXES.index(k)] = float(a) * 1e-3, float(b) * 1e-3
        e.cyclic_cos, e.cyclic_sin = c, s
    return e


def simulation_options(
    machine_errors: Any = None,
    *,
    centring_error_mm: Sequence[float] = (0.0, 0.0, 0.0),
    length_error_mm: float = 0.0,
    noise_um: float = 0.3,
    noise_rho: float = 0.9,
    seed: int = 1,
) -> Any:
    """``_core.CircularSimulationOptions``: the machine (see ``errors``), its set-up and the
    ballbar's AR(1) noise (rho between successive readings, marginal sigma)."""
    o = _core.CircularSimulationOptions()
    if machine_errors is not None:
        o.errors = machine_errors
    o.centring_error = np.asarray(centring_error_mm, dtype=float)
    o.length_error = float(length_error_mm)
    o.noise_um, o.noise_rho, o.seed = float(noise_um), float(noise_rho), int(seed)
    return o


def simulate(
    planned: Any,
    machine_errors: Any = None,
    *,
    centring_error_mm: Sequence[float] = (0.0, 0.0, 0.0),
    length_error_mm: float = 0.0,
    noise_um: float = 0.3,
    noise_rho: float = 0.9,
    seed: int = 1,
) -> Any:
    """The session a ballbar records on a machine with ``machine_errors`` (see ``errors``), with
    AR(1) noise at the sample rate."""
    o = simulation_options(
        machine_errors,
        centring_error_mm=centring_error_mm,
        length_error_mm=length_error_mm,
        noise_um=noise_um,
        noise_rho=noise_rho,
        seed=seed,
    )
    return _core.simulate_circular(planned, o)


def virtual_ballbar(
    planned: Any,
    options: Any,
    *,
    rate_hz: float | None = None,
    speed: float = 1.0,
    baud: int = 115200,
    faults: Any = None,
) -> Any:
    """Start a virtual ballbar on a pseudo-terminal that plays the circular program ``planned``
    on the machine of ``options`` (``simulation_options``); streams at ``rate_hz`` (default: the
    plan's sample rate) until the host asks for another. Returns the running instrument: open
    ``.port`` like a serial port; ``.stop()`` ends it."""
    rate = planned.plan.sample_rate_hz if rate_hz is None else float(rate_hz)
    dev = _core.VirtualCircularBallbar(
        planned, options, rate, float(speed), int(baud), faults or _core.FaultInjection()
    )
    dev.start()
    return dev


def record_ballbar(
    port: str,
    planned: Any,
    path: str,
    *,
    baud: int = 115200,
    rate_hz: float | None = None,
    zero: bool = False,
    silence_timeout_s: float = 3.0,
    progress: Any = True,
) -> Any:
    """Record the circular program ``planned`` from ``port`` into ``path`` (rotacal-ballbar/1):
    rows on a data arc get the run's label, the rest ``transition``, so ``analyze`` reads the
    file. ``rate_hz`` defaults to the plan's sample rate; ``progress`` as
    ``instruments.record_ballbar``'s; Ctrl-C stops cleanly."""
    from .instruments import _record

    rate = planned.plan.sample_rate_hz if rate_hz is None else float(rate_hz)
    return _record(
        lambda cb: _core.record_circular_ballbar(
            port, planned, str(path), baud, rate, zero, silence_timeout_s, cb
        ),
        progress,
    )


def truth_dict(
    machine_errors: Any,
    centring_error_mm: Sequence[float],
    length_error_mm: float,
    noise_um: float,
    noise_rho: float,
    seed: int,
) -> dict:
    """The simulated machine as JSON-ready data (mm, rad, s: the catalogue's units)."""
    e = machine_errors
    return {
        "format": "rotacal-circular-truth/1",
        "units": "mm, rad, s",
        "squareness": dict(zip(PLANES, np.asarray(e.squareness).tolist())),
        "scale": dict(zip(AXES, np.asarray(e.scale).tolist())),
        "straightness": {
            f"{AXES[d]}{AXES[a]}": float(np.asarray(e.straightness)[d, a])
            for d in range(3)
            for a in range(3)
            if d != a
        },
        "backlash": dict(zip(AXES, np.asarray(e.backlash).tolist())),
        "spike": dict(zip(AXES, np.asarray(e.spike).tolist())),
        "spike_tau": dict(zip(AXES, np.asarray(e.spike_tau).tolist())),
        "servo_tau": dict(zip(AXES, np.asarray(e.servo_tau).tolist())),
        "cyclic_cos": dict(zip(AXES, np.asarray(e.cyclic_cos).tolist())),
        "cyclic_sin": dict(zip(AXES, np.asarray(e.cyclic_sin).tolist())),
        "screw_pitch": dict(zip(AXES, np.asarray(e.screw_pitch).tolist())),
        "centring_error": [float(x) for x in centring_error_mm],
        "length_error": float(length_error_mm),
        "noise_um": float(noise_um),
        "noise_rho": float(noise_rho),
        "seed": int(seed),
    }


class CircularResult:
    """ISO 230-4 results of a session's circular runs and, unless skipped, the diagnosis."""

    def __init__(self, analysis: Any, diagnosis: Any | None, source: str = "") -> None:
        self.analysis = analysis
        self.diagnosis = diagnosis
        self.source = source

    def to_dict(self) -> dict:
        a = self.analysis
        out: dict[str, Any] = {
            "source": self.source,
            "standard": "ISO 230-4",
            "ballbar_length": a.ballbar_length,
            "runs": [
                {
                    "label": r.label,
                    "plane": r.plane.name,
                    "direction": r.direction.name,
                    "feed_mm_per_min": r.feed_mm_per_min,
                    "span_deg": r.span_deg,
                    "n": r.n,
                    "G_um": r.G_um,
                    "max_um": r.max_um,
                    "min_um": r.min_um,
                    "radius_deviation_um": r.radius_deviation_um,
                    "centre_um": [float(x) for x in r.centre_um],
                }
                for r in a.runs
            ],
            "pairs": [
                {
                    "plane": p.plane.name,
                    "feed_mm_per_min": p.feed_mm_per_min,
                    "ccw": p.ccw_label,
                    "cw": p.cw_label,
                    "G_b_um": p.G_b_um,
                    "H_um": p.H_um,
                    "H_angle_deg": p.H_angle_deg,
                    "common_span_deg": p.common_span_deg,
                }
                for p in a.pairs
            ],
            "ignored_tests": list(a.ignored_tests),
        }
        d = self.diagnosis
        if d is not None:
            out["diagnosis"] = {
                "n": d.n,
                "baseline_rms_um": d.baseline_rms_um,
                "final_rms_um": d.final_rms_um,
                "noise": d.noise.summary(),
                "noise_whitened": d.noise_whitened,
                "findings": [
                    {
                        "effect": f.effect,
                        "cause": f.cause,
                        "parameters": [
                            {"name": p.name, "value": p.value, "std": p.std, "unit": p.unit}
                            for p in f.parameters
                        ],
                        "gain": {
                            "rms_before_um": f.gain.rms_before_um,
                            "rms_after_um": f.gain.rms_after_um,
                            "delta_bic": f.gain.delta_bic,
                            "f_pvalue": f.gain.f_pvalue,
                            "cv_rms_before_um": f.gain.cv_rms_before_um,
                            "cv_rms_after_um": f.gain.cv_rms_after_um,
                        },
                    }
                    for f in d.findings
                ],
                "unobservable": [{"effect": u.effect, "reason": u.reason} for u in d.unobservable],
            }
        return out

    def text(self) -> str:
        a = self.analysis
        lines = [
            f"{self.source + ': ' if self.source else ''}{len(a.runs)} circular runs, L0 {a.ballbar_length:g} mm "
            "(ISO 230-4: centre of the least-squares circle)"
        ]
        lines.append(
            f"  {'run':28s} {'feed':>8s} {'span':>6s} {'G':>7s} {'radius':>8s} {'centre u, v':>17s}"
        )
        lines.append(f"  {'':28s} {'mm/min':>8s} {'deg':>6s} {'um':>7s} {'dev um':>8s} {'um':>17s}")
        for r in a.runs:
            lines.append(
                f"  {r.label:28s} {r.feed_mm_per_min:8.0f} {r.span_deg:6.1f} {r.G_um:7.2f} "
                f"{r.radius_deviation_um:8.2f} {r.centre_um[0]:8.2f},{r.centre_um[1]:8.2f}"
            )
        for p in a.pairs:
            lines.append(
                f"  {p.plane.name} at {p.feed_mm_per_min:.0f} mm/min: bidirectional G(b) {p.G_b_um:.2f} um, "
                f"hysteresis H {p.H_um:.2f} um at {p.H_angle_deg:.1f} deg"
            )
        if a.ignored_tests:
            lines.append(f"  not circular runs, ignored: {', '.join(a.ignored_tests)}")
        d = self.diagnosis
        if d is not None:
            lines.append(
                f"diagnosis: residual RMS {d.baseline_rms_um:.2f} um about each run's circle, "
                f"{d.final_rms_um:.2f} um with the findings; noise {d.noise.summary()}"
            )
            if not d.findings:
                lines.append("  no cause in the catalogue is supported by the data")
            for f in d.findings:
                vals = []
                for p in f.parameters:
                    unit, k = _DISPLAY.get(p.unit, (p.unit, 1.0))
                    vals.append(
                        f"{p.name.split('.')[-1]} = {p.value * k:.3g} +- {p.std * k:.2g} {unit}"
                    )
                lines.append(
                    f"  {f.effect}: {', '.join(vals)}  (RMS {f.gain.rms_before_um:.2f} -> "
                    f"{f.gain.rms_after_um:.2f} um, dBIC {f.gain.delta_bic:.0f})"
                )
                lines.append(f"      {f.cause}")
            if d.unobservable:
                lines.append("  not determined by these runs:")
                for u in d.unobservable:
                    lines.append(f"    {u.effect}: {u.reason}")
        return "\n".join(lines) + "\n"


def analyze(
    session: Any,
    *,
    diagnose: bool = True,
    screw_pitch_mm: Sequence[float] = (10.0, 10.0, 10.0),
    source: str = "",
) -> CircularResult:
    """ISO 230-4 G per run, G(b) and H per cw/ccw pair, and (``diagnose``) the classic causes."""
    from .sessions import BALLBAR, require

    require(session, BALLBAR, "circular analyze")
    analysis = _core.analyze_circular(session)
    diag = None
    if diagnose:
        o = _core.CircularDiagnosisOptions()
        o.screw_pitch = np.asarray(screw_pitch_mm, dtype=float)
        diag = _core.diagnose_circular(session, o)
    return CircularResult(analysis, diag, source)


def is_circular(session: Any) -> bool:
    """True for a ballbar session whose tests are ISO 230-4 circular runs (``circular_*``
    labels), beside at most the ``transition`` rows of a recording: the linear axes' test,
    which the rotary-axis commands cannot analyse."""
    from .sessions import BALLBAR, kind

    tests = set(session.tests) if kind(session) == BALLBAR else set()
    runs = {str(t) for t in tests if str(t).startswith("circular_")}
    return bool(runs) and tests <= runs | {"transition"}


def polar_figure(result: CircularResult) -> Any:
    """The polar plot of every run's radial deviation (one panel per plane), as ballbar software
    shows it: the path about the least-squares centre with the deviation magnified."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = result.analysis.runs
    planes = [p for p in PLANES if any(r.plane.name == p for r in runs)]
    fig, axes = plt.subplots(
        1, len(planes), subplot_kw={"projection": "polar"}, figsize=(4.6 * len(planes), 4.8)
    )
    axes = np.atleast_1d(axes)
    for ax, plane in zip(axes, planes):
        rs = [r for r in runs if r.plane.name == plane]
        lo = min(float(np.min(r.radial_um)) for r in rs)
        hi = max(float(np.max(r.radial_um)) for r in rs)
        span = max(hi - lo, 1e-3)
        for r in rs:
            order = np.argsort(r.angle_deg) if r.span_deg >= 359.0 else np.arange(len(r.angle_deg))
            ax.plot(
                np.radians(r.angle_deg[order]),
                r.radial_um[order],
                lw=0.8,
                label=f"{r.direction.name} {r.feed_mm_per_min:.0f}",
            )
        ax.set_rorigin(lo - 1.5 * span)
        ax.set_rlim(lo - 0.1 * span, hi + 0.1 * span)
        pair = [p for p in result.analysis.pairs if p.plane.name == plane]
        title = f"{plane}: G {max(r.G_um for r in rs):.1f} um"
        if pair:
            title += f", H {max(p.H_um for p in pair):.1f} um"
        ax.set_title(title + "\nradial deviation, um", fontsize=9)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.15, -0.15))
    fig.tight_layout()
    return fig


def polar_plot(result: CircularResult, path: str, inputs: Sequence[str] = ()) -> None:
    """polar_figure as a PNG file, written by the output rule."""
    import io

    import matplotlib.pyplot as plt

    from .outputs import write_output

    fig = polar_figure(result)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    write_output(path, buf.getvalue(), list(inputs))
