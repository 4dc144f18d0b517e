"""ISO 230-4 circular tests of the linear axes with the ballbar: plan, NC program, simulation,
G / G(b) / H and the diagnosis of their classic causes (include/rotacal/ballbar/circular_*.hpp,
include/rotacal/diagnose/circular_diagnosis.hpp), and the ``rotacal circular`` command.

The session is a plain ``rotacal-ballbar/1`` file whose tests are labelled
``circular_<XY|YZ|ZX>_<ccw|cw>[_f<feed>]``; every rotary axis is at 0 and the pivot is the
circle's centre, so the same instrument, set-up and files serve the 3-axis check before the
rotary-axis calibration.
"""
from __future__ import annotations

import argparse
import math
from typing import Any, Mapping, Sequence

import numpy as np

from . import _core, jsontext

AXES = "XYZ"
PLANES = ("XY", "YZ", "ZX")
# Display units of the catalogue's parameter units (the C++ side is in mm, rad, s).
_DISPLAY = {"mm": ("um", 1e3), "rad": ("urad", 1e6), "mm/mm": ("um/m", 1e6), "s": ("ms", 1e3)}


# ------------------------------------------------------------------------------ library

def plan(planes: Sequence[str] = PLANES, feeds_mm_per_min: Sequence[float] = (1000.0, 3000.0),
         directions: Sequence[str] = ("ccw", "cw"), *, machine: Any = None, radius: float = 100.0,
         centre: Sequence[float] = (120.0, 0.0, 60.0), start_deg: float = 0.0, span_deg: float = 360.0,
         run_in_deg: float = 45.0, overshoot_deg: float = 45.0, sample_rate_hz: float = 250.0) -> Any:
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


def errors(squareness_urad: Mapping[str, float] | None = None, scale_um_per_m: Mapping[str, float] | None = None,
           straightness_um: Mapping[str, float] | None = None, backlash_um: Mapping[str, float] | None = None,
           spike_um: Mapping[str, float] | None = None, spike_tau_ms: Mapping[str, float] | None = None,
           servo_lag_ms: Mapping[str, float] | None = None, cyclic_um: Mapping[str, Sequence[float]] | None = None,
           screw_pitch_mm: Mapping[str, float] | None = None) -> Any:
    """``_core.LinearAxisErrors`` from readable units: squareness by plane ("XY": x += s y),
    straightness by "DA" (error direction D, moving axis A: c2 at 100 mm from the centre),
    cyclic by axis as (cos, sin) amplitudes; every other entry by axis letter."""
    e = _core.LinearAxisErrors()

    def vec(field: str, values: Mapping[str, float] | None, keys: Sequence[str], scale: float) -> None:
        if not values:
            return
        v = np.array(getattr(e, field), dtype=float)
        for k, x in values.items():
            if k not in keys:
                raise _core.InvalidArgument(f"{field}: unknown key {k!r} (known: {', '.join(keys)})")
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
                raise _core.InvalidArgument(f"straightness: key {k!r} must be two different axes DA, e.g. 'YX'")
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


def simulation_options(machine_errors: Any = None, *, centring_error_mm: Sequence[float] = (0.0, 0.0, 0.0),
                       length_error_mm: float = 0.0, noise_um: float = 0.3, noise_rho: float = 0.9,
                       seed: int = 1) -> Any:
    """``_core.CircularSimulationOptions``: the machine (see ``errors``), its set-up and the
    ballbar's AR(1) noise (rho between successive readings, marginal sigma)."""
    o = _core.CircularSimulationOptions()
    if machine_errors is not None:
        o.errors = machine_errors
    o.centring_error = np.asarray(centring_error_mm, dtype=float)
    o.length_error = float(length_error_mm)
    o.noise_um, o.noise_rho, o.seed = float(noise_um), float(noise_rho), int(seed)
    return o


def simulate(planned: Any, machine_errors: Any = None, *, centring_error_mm: Sequence[float] = (0.0, 0.0, 0.0),
             length_error_mm: float = 0.0, noise_um: float = 0.3, noise_rho: float = 0.9, seed: int = 1) -> Any:
    """The session a ballbar records on a machine with ``machine_errors`` (see ``errors``), with
    AR(1) noise at the sample rate."""
    o = simulation_options(machine_errors, centring_error_mm=centring_error_mm, length_error_mm=length_error_mm,
                           noise_um=noise_um, noise_rho=noise_rho, seed=seed)
    return _core.simulate_circular(planned, o)


def virtual_ballbar(planned: Any, options: Any, *, rate_hz: float | None = None, speed: float = 1.0,
                    baud: int = 115200, faults: Any = None) -> Any:
    """Start a virtual ballbar on a pseudo-terminal that plays the circular program ``planned``
    on the machine of ``options`` (``simulation_options``); streams at ``rate_hz`` (default: the
    plan's sample rate) until the host asks for another. Returns the running instrument: open
    ``.port`` like a serial port; ``.stop()`` ends it."""
    rate = planned.plan.sample_rate_hz if rate_hz is None else float(rate_hz)
    dev = _core.VirtualCircularBallbar(planned, options, rate, float(speed), int(baud),
                                       faults or _core.FaultInjection())
    dev.start()
    return dev


def record_ballbar(port: str, planned: Any, path: str, *, baud: int = 115200, rate_hz: float | None = None,
                   zero: bool = False, silence_timeout_s: float = 3.0, progress: Any = True) -> Any:
    """Record the circular program ``planned`` from ``port`` into ``path`` (rotacal-ballbar/1):
    rows on a data arc get the run's label, the rest ``transition``, so ``analyze`` reads the
    file. ``rate_hz`` defaults to the plan's sample rate; ``progress`` as
    ``instruments.record_ballbar``'s; Ctrl-C stops cleanly."""
    from .instruments import _record
    rate = planned.plan.sample_rate_hz if rate_hz is None else float(rate_hz)
    return _record(lambda cb: _core.record_circular_ballbar(port, planned, str(path), baud, rate, zero,
                                                            silence_timeout_s, cb), progress)


def truth_dict(machine_errors: Any, centring_error_mm: Sequence[float], length_error_mm: float,
               noise_um: float, noise_rho: float, seed: int) -> dict:
    """The simulated machine as JSON-ready data (mm, rad, s: the catalogue's units)."""
    e = machine_errors
    return {"format": "rotacal-circular-truth/1", "units": "mm, rad, s",
            "squareness": dict(zip(PLANES, np.asarray(e.squareness).tolist())),
            "scale": dict(zip(AXES, np.asarray(e.scale).tolist())),
            "straightness": {f"{AXES[d]}{AXES[a]}": float(np.asarray(e.straightness)[d, a])
                             for d in range(3) for a in range(3) if d != a},
            "backlash": dict(zip(AXES, np.asarray(e.backlash).tolist())),
            "spike": dict(zip(AXES, np.asarray(e.spike).tolist())),
            "spike_tau": dict(zip(AXES, np.asarray(e.spike_tau).tolist())),
            "servo_tau": dict(zip(AXES, np.asarray(e.servo_tau).tolist())),
            "cyclic_cos": dict(zip(AXES, np.asarray(e.cyclic_cos).tolist())),
            "cyclic_sin": dict(zip(AXES, np.asarray(e.cyclic_sin).tolist())),
            "screw_pitch": dict(zip(AXES, np.asarray(e.screw_pitch).tolist())),
            "centring_error": [float(x) for x in centring_error_mm], "length_error": float(length_error_mm),
            "noise_um": float(noise_um), "noise_rho": float(noise_rho), "seed": int(seed)}


class CircularResult:
    """ISO 230-4 results of a session's circular runs and, unless skipped, the diagnosis."""

    def __init__(self, analysis: Any, diagnosis: Any | None, source: str = "") -> None:
        self.analysis = analysis
        self.diagnosis = diagnosis
        self.source = source

    def to_dict(self) -> dict:
        a = self.analysis
        out: dict[str, Any] = {
            "source": self.source, "standard": "ISO 230-4", "ballbar_length": a.ballbar_length,
            "runs": [{"label": r.label, "plane": r.plane.name, "direction": r.direction.name,
                      "feed_mm_per_min": r.feed_mm_per_min, "span_deg": r.span_deg, "n": r.n,
                      "G_um": r.G_um, "max_um": r.max_um, "min_um": r.min_um,
                      "radius_deviation_um": r.radius_deviation_um,
                      "centre_um": [float(x) for x in r.centre_um]} for r in a.runs],
            "pairs": [{"plane": p.plane.name, "feed_mm_per_min": p.feed_mm_per_min, "ccw": p.ccw_label,
                       "cw": p.cw_label, "G_b_um": p.G_b_um, "H_um": p.H_um, "H_angle_deg": p.H_angle_deg,
                       "common_span_deg": p.common_span_deg} for p in a.pairs],
            "ignored_tests": list(a.ignored_tests),
        }
        d = self.diagnosis
        if d is not None:
            out["diagnosis"] = {
                "n": d.n, "baseline_rms_um": d.baseline_rms_um, "final_rms_um": d.final_rms_um,
                "noise": d.noise.summary(), "noise_whitened": d.noise_whitened,
                "findings": [{"effect": f.effect, "cause": f.cause,
                              "parameters": [{"name": p.name, "value": p.value, "std": p.std, "unit": p.unit}
                                             for p in f.parameters],
                              "gain": {"rms_before_um": f.gain.rms_before_um, "rms_after_um": f.gain.rms_after_um,
                                       "delta_bic": f.gain.delta_bic, "f_pvalue": f.gain.f_pvalue,
                                       "cv_rms_before_um": f.gain.cv_rms_before_um,
                                       "cv_rms_after_um": f.gain.cv_rms_after_um}} for f in d.findings],
                "unobservable": [{"effect": u.effect, "reason": u.reason} for u in d.unobservable],
            }
        return out

    def text(self) -> str:
        a = self.analysis
        lines = [f"{self.source + ': ' if self.source else ''}{len(a.runs)} circular runs, L0 {a.ballbar_length:g} mm "
                 "(ISO 230-4: centre of the least-squares circle)"]
        lines.append(f"  {'run':28s} {'feed':>8s} {'span':>6s} {'G':>7s} {'radius':>8s} {'centre u, v':>17s}")
        lines.append(f"  {'':28s} {'mm/min':>8s} {'deg':>6s} {'um':>7s} {'dev um':>8s} {'um':>17s}")
        for r in a.runs:
            lines.append(f"  {r.label:28s} {r.feed_mm_per_min:8.0f} {r.span_deg:6.1f} {r.G_um:7.2f} "
                         f"{r.radius_deviation_um:8.2f} {r.centre_um[0]:8.2f},{r.centre_um[1]:8.2f}")
        for p in a.pairs:
            lines.append(f"  {p.plane.name} at {p.feed_mm_per_min:.0f} mm/min: bidirectional G(b) {p.G_b_um:.2f} um, "
                         f"hysteresis H {p.H_um:.2f} um at {p.H_angle_deg:.1f} deg")
        if a.ignored_tests:
            lines.append(f"  not circular runs, ignored: {', '.join(a.ignored_tests)}")
        d = self.diagnosis
        if d is not None:
            lines.append(f"diagnosis: residual RMS {d.baseline_rms_um:.2f} um about each run's circle, "
                         f"{d.final_rms_um:.2f} um with the findings; noise {d.noise.summary()}")
            if not d.findings:
                lines.append("  no cause in the catalogue is supported by the data")
            for f in d.findings:
                vals = []
                for p in f.parameters:
                    unit, k = _DISPLAY.get(p.unit, (p.unit, 1.0))
                    vals.append(f"{p.name.split('.')[-1]} = {p.value * k:.3g} +- {p.std * k:.2g} {unit}")
                lines.append(f"  {f.effect}: {', '.join(vals)}  (RMS {f.gain.rms_before_um:.2f} -> "
                             f"{f.gain.rms_after_um:.2f} um, dBIC {f.gain.delta_bic:.0f})")
                lines.append(f"      {f.cause}")
            if d.unobservable:
                lines.append("  not determined by these runs:")
                for u in d.unobservable:
                    lines.append(f"    {u.effect}: {u.reason}")
        return "\n".join(lines) + "\n"


def analyze(session: Any, *, diagnose: bool = True, screw_pitch_mm: Sequence[float] = (10.0, 10.0, 10.0),
            source: str = "") -> CircularResult:
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
    fig, axes = plt.subplots(1, len(planes), subplot_kw={"projection": "polar"}, figsize=(4.6 * len(planes), 4.8))
    axes = np.atleast_1d(axes)
    for ax, plane in zip(axes, planes):
        rs = [r for r in runs if r.plane.name == plane]
        lo = min(float(np.min(r.radial_um)) for r in rs)
        hi = max(float(np.max(r.radial_um)) for r in rs)
        span = max(hi - lo, 1e-3)
        for r in rs:
            order = np.argsort(r.angle_deg) if r.span_deg >= 359.0 else np.arange(len(r.angle_deg))
            ax.plot(np.radians(r.angle_deg[order]), r.radial_um[order],
                    lw=0.8, label=f"{r.direction.name} {r.feed_mm_per_min:.0f}")
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


# ------------------------------------------------------------------------------ command line

def _axis_values(option: str, keys: Sequence[str], lo: float, hi: float, per_key: int = 1) -> Any:
    """argparse type: KEY=V[,KEY=V...] (per_key 2: KEY=A:B) with KEY in keys, each V in [lo, hi]."""
    from .cli import OptionError

    def parse(text: str) -> dict:
        out: dict = {}
        for item in text.split(","):
            key, eq, val = item.partition("=")
            key = key.strip().upper() if all(c.isalpha() for c in key.strip()) else key.strip()
            if not eq or key not in keys:
                raise OptionError(f"{option}: '{item[:40]}' must be KEY=VALUE with KEY in {', '.join(keys)}")
            try:
                vals = [float(v) for v in val.split(":")]
            except ValueError:
                raise OptionError(f"{option}: '{item[:40]}' is not a number") from None
            if len(vals) != per_key or not all(math.isfinite(v) and lo <= v <= hi for v in vals):
                form = "A:B" if per_key == 2 else "V"
                raise OptionError(f"{option}: '{item[:40]}': {key}={form}, each in [{lo:g}, {hi:g}]")
            out[key] = vals if per_key > 1 else vals[0]
        return out
    return parse


def _names(option: str, known: Sequence[str]) -> Any:
    from .cli import OptionError

    def parse(text: str) -> list[str]:
        vals = [v.strip() for v in text.split(",") if v.strip()]
        bad = [v for v in vals if v not in known and v.upper() not in known]
        if not vals or bad:
            raise OptionError(f"{option}: '{text[:40]}': a comma-separated list of {', '.join(known)}")
        return vals
    return parse


def _add_plan_args(q: argparse.ArgumentParser) -> None:
    from .cli import number, number_list, numbers
    g = q.add_argument_group("the test (ISO 230-4)")
    g.add_argument("--machine", default=None, help="built-in machine or rotacal-machine/1 file (default AC-trt); rotary axes stay at 0")
    g.add_argument("--length", type=number("--length", 0.0, 1e4, "mm", lo_open=True), default=100.0, help="bar length L0 = radius, mm")
    g.add_argument("--pivot", type=numbers("--pivot", 3, 1e5, "mm"), default=[120.0, 0.0, 60.0],
                   help="centre pivot, table frame at rotary zero, mm (default 120,0,60: the rotary test's)")
    g.add_argument("--planes", type=_names("--planes", PLANES), default=list(PLANES), help="XY,YZ,ZX (default all)")
    g.add_argument("--feeds", type=number_list("--feeds", 1.0, 1e5, "mm/min", most=8), default=[1000.0, 3000.0],
                   help="path feeds, mm/min (default 1000,3000)")
    g.add_argument("--directions", type=_names("--directions", ("ccw", "cw")), default=["ccw", "cw"], help="ccw,cw (default both)")
    g.add_argument("--start", type=number("--start", -3600.0, 3600.0, "deg"), default=0.0, help="start of the data arc, deg (--start=-20 for a negative one)")
    g.add_argument("--span", type=number("--span", 0.0, 360.0, "deg", lo_open=True), default=360.0, help="data arc, deg (e.g. 220 for a partial arc)")
    g.add_argument("--run-in", type=number("--run-in", 0.0, 360.0, "deg"), default=45.0, help="arc before the data arc, deg")
    g.add_argument("--overshoot", type=number("--overshoot", 0.0, 360.0, "deg"), default=45.0, help="arc after the data arc, deg")
    g.add_argument("--rate", type=number("--rate", 0.0, 1e5, "Hz", lo_open=True), default=250.0, help="ballbar sample rate, Hz")


def _add_machine_args(k: argparse.ArgumentParser) -> None:
    from .cli import number, numbers
    g = k.add_argument_group("simulated machine (units as named; default: no error)")
    g.add_argument("--squareness", type=_axis_values("--squareness", PLANES, -1e4, 1e4), metavar="XY=S,...",
                   help="urad; XY: x += s y, YZ: y += s z, ZX: z += s x")
    g.add_argument("--scale", type=_axis_values("--scale", AXES, -1e4, 1e4), metavar="X=K,...", help="um/m")
    g.add_argument("--straightness", type=_axis_values("--straightness", ["XY", "XZ", "YX", "YZ", "ZX", "ZY"], -1e3, 1e3),
                   metavar="YX=C,...", help="um at 100 mm from the centre (DA: error direction D, moving axis A)")
    g.add_argument("--backlash", type=_axis_values("--backlash", AXES, 0.0, 1e3), metavar="X=B,...", help="lost motion, um")
    g.add_argument("--spike", type=_axis_values("--spike", AXES, 0.0, 1e3), metavar="X=H,...", help="reversal spike height, um")
    g.add_argument("--spike-tau", type=_axis_values("--spike-tau", AXES, 0.1, 1e4), metavar="X=T,...",
                   help="reversal spike decay time, ms (default 15)")
    g.add_argument("--servo-lag", type=_axis_values("--servo-lag", AXES, 0.0, 1e3), metavar="X=T,...",
                   help="position-loop time constant 1/Kv, ms")
    g.add_argument("--cyclic", type=_axis_values("--cyclic", AXES, -1e3, 1e3, per_key=2), metavar="X=C:S,...",
                   help="cyclic error, um: cos and sin amplitudes over the screw lead")
    g.add_argument("--pitch", type=_axis_values("--pitch", AXES, 0.01, 1e4), metavar="X=P,...", help="screw leads, mm (default 10)")
    g.add_argument("--centring-error", type=numbers("--centring-error", 3, 10.0, "mm"), default=None,
                   help="pivot ball off the commanded centre, mm (default: random, 5 um 1-sigma, seeded)")
    g.add_argument("--length-error", type=number("--length-error", -1e4, 1e4, "um"), default=0.0, help="bar calibration error, um")
    g.add_argument("--noise", type=number("--noise", 0.0, 1000.0, "um"), default=0.3, help="1-sigma reading noise, um")
    g.add_argument("--rho", type=number("--rho", 0.0, 0.999, ""), default=0.9, help="AR(1) correlation between readings")
    g.add_argument("--seed", type=number("--seed", 0, 2**32 - 1, integer=True), default=1)


def _machine_options(a: argparse.Namespace) -> tuple[Any, Any]:
    """The simulated machine of the options (``errors``, ``simulation_options``) and its truth JSON."""
    e = errors(squareness_urad=a.squareness, scale_um_per_m=a.scale, straightness_um=a.straightness,
               backlash_um=a.backlash, spike_um=a.spike, spike_tau_ms=a.spike_tau, servo_lag_ms=a.servo_lag,
               cyclic_um=a.cyclic, screw_pitch_mm=a.pitch)
    rng = np.random.default_rng(a.seed)
    centring = (a.centring_error if a.centring_error is not None
                else (rng.normal(0.0, 0.005, 3)).tolist())  # a pivot set by hand: ~5 um
    o = simulation_options(e, centring_error_mm=centring, length_error_mm=a.length_error * 1e-3,
                           noise_um=a.noise, noise_rho=a.rho, seed=a.seed)
    return o, truth_dict(e, centring, a.length_error * 1e-3, a.noise, a.rho, a.seed)


def _planned(a: argparse.Namespace) -> Any:
    return plan(a.planes, a.feeds, a.directions, machine=a.machine, radius=a.length, centre=a.pivot,
                start_deg=a.start, span_deg=a.span, run_in_deg=a.run_in, overshoot_deg=a.overshoot,
                sample_rate_hz=a.rate)


def _cmd_plan(a: argparse.Namespace) -> int:
    from .cli import EXIT_OK, _say
    from .outputs import write_output
    from .sessions import save
    planned = _planned(a)
    write_output(a.output, nc_program(planned, a.dialect), [], [a.session] if a.session else [])
    last = planned.runs[-1]
    _say(f"wrote {a.output}: {a.dialect} program, {len(planned.runs)} runs, "
         f"{planned.num_samples()} readings, {last.time[-1]:.0f} s of data and moves")
    if a.session:
        save(_core.circular_commanded_session(planned), a.session, [], [a.output])
        _say(f"wrote {a.session}: the commanded rows as a session template")
    return EXIT_OK


def _cmd_simulate(a: argparse.Namespace) -> int:
    from .cli import EXIT_OK, _say
    from .outputs import write_output
    from .sessions import save
    planned = _planned(a)
    o, data = _machine_options(a)
    session = _core.simulate_circular(planned, o)
    save(session, a.output, [], [a.truth] if a.truth else [])
    _say(f"wrote {a.output}: {len(planned.runs)} circular runs, {planned.num_samples()} readings")
    if a.truth:
        write_output(a.truth, jsontext.dumps(data) + "\n", [], [a.output])
        _say(f"wrote {a.truth}: the simulated machine")
    return EXIT_OK


def _cmd_virtual(a: argparse.Namespace) -> int:
    from .cli import _faults, _serve
    from .outputs import write_output
    planned = _planned(a)
    o, data = _machine_options(a)
    if a.truth:
        write_output(a.truth, jsontext.dumps(data) + "\n")
    dev = virtual_ballbar(planned, o, speed=a.speed, baud=a.baud, faults=_faults(a))
    last = planned.runs[-1]
    return _serve(dev, "ballbar", a, f"circular program, {len(planned.runs)} runs, {last.time[-1]:.0f} s, "
                                     f"{a.rate:g} Hz, speed x{a.speed:g}")


def _cmd_record(a: argparse.Namespace) -> int:
    from .cli import _report_recording
    planned = _planned(a)
    summary = record_ballbar(a.port, planned, a.output, baud=a.baud, zero=a.zero, silence_timeout_s=a.silence,
                             progress=not a.no_progress)
    return _report_recording(summary, a.output, a.json)


def _cmd_analyze(a: argparse.Namespace) -> int:
    from .cli import EXIT_OK, _say
    from .sessions import load
    session = load(a.file)
    pitch = [10.0, 10.0, 10.0]
    for k, v in (a.pitch or {}).items():
        pitch[AXES.index(k)] = v
    result = analyze(session, diagnose=not a.no_diagnose, screw_pitch_mm=pitch, source=a.file)
    if a.json:
        print(jsontext.dumps(result.to_dict()))
    else:
        print(result.text(), end="")
    if a.plot:
        polar_plot(result, a.plot, [a.file])
        _say(f"wrote {a.plot}: polar plot of the radial deviations")
    return EXIT_OK


def add_cli(sub: Any) -> None:
    """Register ``rotacal circular plan|simulate|virtual|record|analyze`` on the CLI's subparsers."""
    from .cli import EPILOG, _add_record_args, _add_virtual_args, number, path
    q = sub.add_parser("circular", help="ISO 230-4 circular tests of the linear axes with the ballbar",
                       description="Circular tests of the linear axes (ISO 230-4) with the same ballbar, set-up and "
                                   "rotacal-ballbar/1 files as the rotary test: plan writes the NC program, simulate a "
                                   "session with circular_* tests, virtual serves a simulated ballbar playing the "
                                   "program on a pseudo-terminal, record reads a ballbar into a session, analyze "
                                   "prints G, G(b), H and the named causes.",
                       epilog=EPILOG)
    acts = q.add_subparsers(dest="action", required=True)

    k = acts.add_parser("plan", help="write the NC program of the circular tests", epilog=EPILOG)
    _add_plan_args(k)
    k.add_argument("--dialect", default="linuxcnc", help="linuxcnc, heidenhain, siemens, fanuc")
    k.add_argument("--session", metavar="CSV", type=path("--session"), help="also write the commanded rows as a session template")
    k.add_argument("-o", "--output", required=True, type=path("--output"))
    k.set_defaults(func=_cmd_plan)

    k = acts.add_parser("simulate", help="simulate the ballbar on a machine with linear-axis errors", epilog=EPILOG)
    _add_plan_args(k)
    _add_machine_args(k)
    k.add_argument("--truth", metavar="JSON", type=path("--truth"), help="write the simulated machine here")
    k.add_argument("-o", "--output", required=True, type=path("--output"))
    k.set_defaults(func=_cmd_simulate)

    # The two ends of a serial line: the plan's options (and --rate as the stream's rate) and a baud rate.
    for name, summary, text in (
            ("virtual", "a virtual ballbar on a pseudo-terminal playing the circular program",
             "Serves the ballbar protocol (docs/protocols.md) on a pseudo-terminal while a simulated machine with the "
             "given linear-axis errors runs the planned circular program (the options of plan and simulate); prints "
             "the port. Record it with `rotacal circular record --port PORT` and the same plan options."),
            ("record", "record a circular test from a ballbar on a serial port",
             "Reads the ballbar on --port while the machine runs the planned circular program (the same plan options "
             "as `plan`; --rate is the requested sample rate) and writes a rotacal-ballbar/1 file as it goes: rows on "
             "a data arc labelled with their run (circular_XY_ccw, ...), the others 'transition'. `rotacal circular "
             "analyze` reads it.")):
        k = acts.add_parser(name, help=summary, description=text, epilog=EPILOG)
        _add_plan_args(k)
        k.add_argument("--baud", type=number("--baud", 50, 4_000_000, integer=True), default=115200,
                       help="baud rate (default 115200)")
        if name == "virtual":
            _add_machine_args(k)
            _add_virtual_args(k)
            k.set_defaults(func=_cmd_virtual)
        else:
            k.add_argument("--zero", action="store_true", help="send ZERO before START")
            _add_record_args(k)
            k.set_defaults(func=_cmd_record)

    k = acts.add_parser("analyze", help="G, G(b), H per plane and the causes the data support", epilog=EPILOG)
    k.add_argument("file", type=path("FILE"))
    k.add_argument("--pitch", type=_axis_values("--pitch", AXES, 0.01, 1e4), metavar="X=P,...",
                   help="screw leads for the cyclic-error entries, mm (default 10)")
    k.add_argument("--no-diagnose", action="store_true", help="the ISO 230-4 results only")
    k.add_argument("--json", action="store_true")
    k.add_argument("--plot", metavar="PNG", type=path("--plot"), help="polar plot of the radial deviations")
    k.set_defaults(func=_cmd_analyze)
