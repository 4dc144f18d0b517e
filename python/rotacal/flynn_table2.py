"""Flynn et al. (2016) Table 2 as a real-data case: what the simulation of the paper's
measure -> compensate -> measure-again chain predicts, which measured post-compensation values
it misses, and which effects (constant in both runs, or changed between the runs) of which
sizes explain them.

The experiment is modelled as it was run (Sec. 4): run 1 measures the machine with the nominal
program and identifies the 8 location errors by the paper's chain; the NC program is
compensated for them; run 2, some time later, runs the compensated program on the same machine
while the ballbar software holds the nominal one, and identifies again. A cause is a change of
the simulated machine in both runs ("constant") or in run 2 only ("between_runs"). Nothing of
the paper is used but Table 2 (data/flynn2016_table2.json); every other number is simulated.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Callable, Optional, Sequence

import numpy as np

from . import _core

TABLE2_PATH = Path(__file__).resolve().parent / "data" / "flynn2016_table2.json"
NAMES = ("E_Y0A", "E_Z0A", "E_B0A", "E_C0A", "E_X0C", "E_Y0C", "E_A0C", "E_B0C")
# Location errors in mm (positions) and rad (orientations), shown in um and urad.
_SCALE = np.array([1e3, 1e3, 1e6, 1e6, 1e3, 1e3, 1e6, 1e6])
_UNIT = ["um", "um", "urad", "urad", "um", "um", "urad", "urad"]


# ----------------------------------------------------------------------------- the table

def _printed_float(text: str, where: str) -> float:
    """A number as Table 2 prints it: '1.1284 E-5' (space before the exponent), '(183.231)'."""
    t = text.replace(" ", "").strip("()")
    try:
        v = float(t)
    except ValueError:
        raise _core.InvalidArgument(f"{where}: '{text}' is not a number as printed in Table 2") from None
    if not math.isfinite(v):
        raise _core.InvalidArgument(f"{where}: '{text}' is not finite")
    return v


def load_table2(path: str | Path | None = None, reading: str = "printed") -> dict:
    """Table 2 of Flynn et al. (2016): {"source": ..., "rows": [{"name", "unit", "before",
    "after", "printed": {...}}]} with values in mm and rad, in location_error_names order.

    reading : "printed" (default) takes every value as printed; "percent_consistent" takes,
        for the two rows whose printed values disagree with the paper's own '% Inc.' column
        (E_B0A, E_C0A; see the file's notes), the reading that reproduces that column.

    Raises rotacal.IoError if the file cannot be read, rotacal.ParseError if it is not the
    table, rotacal.InvalidArgument for a value that is not a number.
    """
    from .jsonfile import read_json
    p = Path(path) if path is not None else TABLE2_PATH
    d, _ = read_json(p)  # strict and bounded: deep nesting is a ParseError, not a RecursionError
    if not isinstance(d, dict):
        raise _core.ParseError(f"{p}: Table 2 is a JSON object with 'rows'")
    if reading not in ("printed", "percent_consistent"):
        raise _core.InvalidArgument(f"load_table2: reading must be 'printed' or 'percent_consistent', got {reading!r}")
    rows = d.get("rows")
    if not isinstance(rows, list) or [r.get("name") for r in rows] != list(NAMES):
        raise _core.ParseError(f"{p}: 'rows' must hold the 8 location errors in the order {', '.join(NAMES)}")
    out = []
    for i, r in enumerate(rows):
        where = f"{p}: rows[{i}] ({r['name']})"
        unit = "mm" if i % 4 < 2 else "rad"
        if r.get("unit") != unit:
            raise _core.ParseError(f"{where}: unit must be '{unit}', got {r.get('unit')!r}")
        alt = r.get("percent_consistent", {}) if reading == "percent_consistent" else {}
        out.append({"name": r["name"], "unit": unit,
                    "before": _printed_float(str(alt.get("uncompensated", r["uncompensated"])), where + " uncompensated"),
                    "after": _printed_float(str(alt.get("compensated", r["compensated"])), where + " compensated"),
                    "printed": {k: r[k] for k in ("uncompensated", "compensated", "change_percent")}})
    return {"source": d.get("source", {}), "machine": d.get("machine", "AC-trt"), "reading": reading,
            "notes": d.get("notes", []), "rows": out}


# ----------------------------------------------------------------------------- assumptions

@dataclass(frozen=True)
class Assumptions:
    """What the paper does not give. Defaults: rotacal's default single set-up test."""

    ballbar_length: float = 100.0          # mm
    pivot: tuple = (120.0, 0.0, 60.0)      # table frame, mm (O_x, 0, O_z)
    tilt_range_deg: tuple = (-90.0, 90.0)
    rot_range_deg: tuple = (0.0, 360.0)
    step_deg: float = 1.0
    noise_um: float = 0.5                  # marginal sigma of the ballbar reading
    noise_rho: float = 0.0                 # AR(1) correlation of successive samples
    hours_between_runs: float = 1.0
    thermal_time_constant_h: float = 1.0   # of the machine structure (1 - exp(-dt/tau))
    method: str = "paper"                  # identification of both runs, as in the paper

    def setup(self):
        s = _core.BallbarSetup()
        s.machine = _core.MachineType.AC_trt
        s.ballbar_length = float(self.ballbar_length)
        s.pivot = np.array(self.pivot, dtype=float)
        s.tilt_range_deg = np.array(self.tilt_range_deg, dtype=float)
        s.rot_range_deg = np.array(self.rot_range_deg, dtype=float)
        s.step_deg = float(self.step_deg)
        return s

    def check(self) -> None:
        if not (self.noise_um > 0 and math.isfinite(self.noise_um)):
            raise _core.InvalidArgument(f"assumptions.noise_um must be > 0, got {self.noise_um}")
        if not (0.0 <= self.noise_rho < 1.0):
            raise _core.InvalidArgument(f"assumptions.noise_rho must be in [0, 1), got {self.noise_rho}")
        if not (self.hours_between_runs >= 0 and math.isfinite(self.hours_between_runs)):
            raise _core.InvalidArgument(f"assumptions.hours_between_runs must be >= 0, got {self.hours_between_runs}")
        if not self.thermal_time_constant_h > 0:
            raise _core.InvalidArgument("assumptions.thermal_time_constant_h must be > 0")
        if self.method not in ("paper", "joint"):
            raise _core.InvalidArgument(f"assumptions.method must be 'paper' or 'joint', got {self.method!r}")


# Plausible sizes (half-widths of a rectangular distribution, as in GUM type B): the brief's
# table (squareness 20 urad, straightness 5 um over 300 mm, drift 2 um over the test, tool
# length 10 um, bar length calibration 1 um) and, for the rest, typical sizes of a
# machining centre stated here as assumptions. Keys are effect-id prefixes; values in the
# effect's own unit, except "*_over_test" (mm over the test duration).
PLAUSIBLE_CONSTANT = {
    "ballbar_length_offset": 0.001, "ballbar_thermal_drift_over_test": 0.002,
    "tool_offset_Z": 0.010, "tool_offset_X": 0.010, "tool_offset_Y": 0.010,
    "rotary_zero_offset": 50e-6, "angular_positioning": 25e-6,
    "radial_motion": 0.002, "axial_motion": 0.002, "tilt_motion": 5e-6,
    "gravity_sag": 0.005, "coning": 20e-6,
    "linear_squareness": 20e-6, "linear_scale": 20e-6,
    "thermal_drift_over_test": 0.002,
    "pivot": 0.010,
    "straightness_c2": 0.005 / 1.5 ** 2,   # 5 um at u = 1.5 (150 mm from the middle of 300 mm)
}
# Changes between the runs. Thermal ones reach these sizes after a full warm-up and scale with
# (1 - exp(-dt/tau)); set-up ones (tool, bar, drift rate) do not depend on dt.
PLAUSIBLE_CHANGE = {
    "axis_position": 0.010, "axis_orientation": 10e-6, "table_shift": 0.010,
    "tool_offset_Z": 0.010, "ballbar_length_offset": 0.001, "drift_over_test": 0.002, "pivot": 0.005,
    "linear_squareness": 5e-6, "linear_scale": 12e-6,
}
_THERMAL_CHANGES = {"axis_position", "axis_orientation", "table_shift", "linear_squareness", "linear_scale", "pivot"}


# ----------------------------------------------------------------------------- candidates

@dataclass
class Candidate:
    """One cause: how it changes the simulated machine in run 1 and run 2, for a size s."""

    id: str
    kind: str          # "constant" or "between_runs"
    cause: str
    unit: str          # display unit of the size
    display: float     # display value = display * size (internal unit)
    plausible: float   # half-width, internal unit
    family: str
    # (errors delta (8), {effect: params}, pivot delta (3)) of run 1 and run 2 for size s
    runs: Callable[[float], tuple] = field(repr=False)


def _effect_size(eid: str, duration: float) -> Optional[tuple]:
    """(plausible size, display factor, display unit) for a one-parameter effect or a
    parameter of a harmonic one; None if the table gives no size."""
    for key, val in PLAUSIBLE_CONSTANT.items():
        if key.endswith("_over_test"):
            prefix = key[: -len("_over_test")]
            if eid.startswith(prefix):
                return val / duration, 1e3 * duration, "um over the test"
        elif eid.startswith(key):
            unit = _core.Effect(eid).param_units[0]
            factor, disp = {"mm": (1e3, "um"), "rad": (1e6, "urad"), "mm/mm": (1e6, "um/m"),
                            "rad/rad": (1e6, "urad/rad")}.get(unit, (1.0, unit))
            return val, factor, disp
    return None


def _none(_size: float = 0.0) -> tuple:
    return np.zeros(8), {}, np.zeros(3)


def candidates(a: Assumptions, duration: float) -> list[Candidate]:
    """Every cause the analysis tries: each sized parameter of each catalogue effect that
    exists for AC-trt, constant in both runs; and the changes between the runs."""
    out: list[Candidate] = []
    for eff in _core.effect_catalogue(_core.MachineType.AC_trt, 2):
        eid = eff.id
        if eid.startswith("straightness_"):
            names = [n for n in eff.param_names]
            if "c2" not in names:
                continue
            sized = (PLAUSIBLE_CONSTANT["straightness_c2"], 1e3, "um at u = 1")
            params = ["c2"]
        else:
            sized = _effect_size(eid, duration)
            params = list(eff.param_names) if not eid.startswith("thermal_warmup") else []
        if sized is None or not params:
            continue
        plaus, disp, unit = sized
        for pname in params:
            k = list(eff.param_names).index(pname)

            def runs(s, eid=eid, k=k, n=eff.num_params):
                p = [0.0] * n
                p[k] = s
                return (np.zeros(8), {eid: p}, np.zeros(3)), (np.zeros(8), {eid: p}, np.zeros(3))
            cid = eid if eff.num_params == 1 else f"{eid}.{pname}"
            out.append(Candidate(f"constant:{cid}", "constant", eff.cause, unit, disp, plaus,
                                 family=eid.rsplit("_h", 1)[0] if "_h" in eid else eid, runs=runs))

    # The pivot ball placed off its nominal position (set-up), the same in both runs.
    for axis in "XYZ":
        piv = np.eye(3)["XYZ".index(axis)]
        out.append(Candidate(f"constant:pivot_{axis}", "constant", f"pivot placed off its nominal position along {axis}",
                             "um", 1e3, PLAUSIBLE_CONSTANT["pivot"], "pivot",
                             runs=lambda s, piv=piv: ((np.zeros(8), {}, piv * s),) * 2))

    f = 1.0 - math.exp(-a.hours_between_runs / a.thermal_time_constant_h)

    def change(cid, cause, family, unit, disp, plaus, run2):
        scale = f if family in _THERMAL_CHANGES else 1.0
        out.append(Candidate(f"between_runs:{cid}", "between_runs", cause, unit, disp, plaus * scale,
                             family, runs=lambda s: (_none(s), run2(s))))

    for k, n in enumerate(NAMES):
        pos = k % 4 < 2
        d = np.zeros(8)
        d[k] = 1.0
        change(n, f"{n} changed between the runs (thermal state of the rotary axes)",
               "axis_position" if pos else "axis_orientation", _UNIT[k], _SCALE[k],
               PLAUSIBLE_CHANGE["axis_position" if pos else "axis_orientation"],
               lambda s, d=d: (d * s, {}, np.zeros(3)))
    # The whole table (both rotary axes and the pivot on it) shifted in the machine frame:
    # X moves the C axis, Y both axes, Z the A axis (C's Z position is no location error).
    for axis, idx in (("X", [4]), ("Y", [0, 5]), ("Z", [1])):
        d = np.zeros(8)
        d[idx] = 1.0
        piv = np.eye(3)["XYZ".index(axis)]
        change(f"table_shift_{axis}", f"table (both rotary axes and the pivot) shifted along {axis} between the runs",
               "table_shift", "um", 1e3, PLAUSIBLE_CHANGE["table_shift"],
               lambda s, d=d, piv=piv: (d * s, {}, piv * s))
    # The pivot ball alone moved on the table (its stand warmed, or it was re-seated): run 2's
    # sphere arcs locate it again, so the chain should not see it; tried to show that.
    for axis in "XYZ":
        piv = np.eye(3)["XYZ".index(axis)]
        change(f"pivot_{axis}", f"pivot moved along {axis} on the table between the runs",
               "pivot", "um", 1e3, PLAUSIBLE_CHANGE["pivot"], lambda s, piv=piv: (np.zeros(8), {}, piv * s))
    change("tool_offset_Z", "tool length differs between the runs (re-measured, re-clamped, spindle growth)",
           "tool_offset_Z", "um", 1e3, PLAUSIBLE_CHANGE["tool_offset_Z"],
           lambda s: (np.zeros(8), {"tool_offset_Z": [s]}, np.zeros(3)))
    change("ballbar_length_offset", "ballbar length differs between the runs (bar temperature, recalibration)",
           "ballbar_length_offset", "um", 1e3, PLAUSIBLE_CHANGE["ballbar_length_offset"],
           lambda s: (np.zeros(8), {"ballbar_length_offset": [s]}, np.zeros(3)))
    for eid in ("thermal_drift_X", "thermal_drift_Y", "thermal_drift_Z", "ballbar_thermal_drift"):
        change(f"{eid}", f"drift during run 2 differs from run 1 ({_core.Effect(eid).cause})",
               "drift_over_test", "um over the test", 1e3 * duration, PLAUSIBLE_CHANGE["drift_over_test"] / duration,
               lambda s, eid=eid: (np.zeros(8), {eid: [s]}, np.zeros(3)))
    for eid in ("linear_squareness_XY", "linear_squareness_YZ", "linear_squareness_ZX"):
        change(eid, f"{_core.Effect(eid).cause}: changed between the runs (thermal bending)",
               "linear_squareness", "urad", 1e6, PLAUSIBLE_CHANGE["linear_squareness"],
               lambda s, eid=eid: (np.zeros(8), {eid: [s]}, np.zeros(3)))
    for eid in ("linear_scale_X", "linear_scale_Y", "linear_scale_Z"):
        change(eid, f"{_core.Effect(eid).cause}: changed between the runs (temperature of the scale)",
               "linear_scale", "um/m", 1e6, PLAUSIBLE_CHANGE["linear_scale"],
               lambda s, eid=eid: (np.zeros(8), {eid: [s]}, np.zeros(3)))
    return out


# ----------------------------------------------------------------------------- the chain

class _Chain:
    """Measure -> identify -> compensate -> measure again -> identify, on a simulated machine."""

    def __init__(self, a: Assumptions):
        a.check()
        self.a = a
        self.setup = a.setup()
        self.plan = _core.plan_ballbar_test(self.setup, None)
        self.cmd = self.plan.commanded_session()
        self.duration = float(self.cmd.time[-1] - self.cmd.time[0])
        self.pivot = np.asarray(self.setup.pivot, dtype=float)

    def _model(self, errors, effects: dict, pivot_delta):
        ids = list(effects.keys())
        return _core.BallbarMachineModel(_core.MachineType.AC_trt, np.asarray(errors, float),
                                         self.pivot + pivot_delta, ids, [v for i in ids for v in effects[i]])

    def _noise(self, rng, n: int) -> np.ndarray:
        """AR(1) noise of marginal sigma noise_um, in mm."""
        sig, rho = self.a.noise_um * 1e-3, self.a.noise_rho
        w = rng.normal(0.0, sig * math.sqrt(1.0 - rho * rho), n)
        if rho == 0.0:
            return w
        x = np.empty(n)
        x[0] = rng.normal(0.0, sig)
        for i in range(1, n):
            x[i] = rho * x[i - 1] + w[i]
        return x

    def _measure(self, program, model, rng):
        s = _core.simulate_ballbar(program, model, 0.0, 1, False)
        length = s.length + (self._noise(rng, len(s)) if rng is not None else 0.0)
        # The ballbar software holds the nominal program: its xyz, whatever the machine ran.
        return _core.BallbarSession(s.machine, s.ballbar_length, self.cmd.pivot, s.tests, s.time,
                                    self.cmd.xyz, s.angles_deg, length, self.a.noise_um)

    def _identify(self, session):
        from .ballbar import identify
        r = identify(session, self.a.method)
        return np.array([p.value for p in r.raw.parameters[:8]]), r

    def run(self, truth, run1: tuple, run2: tuple, rng=None, residuals: bool = False):
        """(before, after) identified location errors; run1/run2 = (errors delta, effects, pivot delta)."""
        m1 = self._model(truth + run1[0], run1[1], run1[2])
        m2 = self._model(truth + run2[0], run2[1], run2[2])
        s1 = self._measure(self.cmd, m1, rng)
        e1, _ = self._identify(s1)
        program = _core.plan_ballbar_test(self.setup, e1).commanded_session()
        s2 = self._measure(program, m2, rng)
        e2, r2 = self._identify(s2)
        if residuals:
            pred = _core.predict_session_lengths(r2.raw.model, s2)
            return e1, e2, (s2.length - pred) * 1e3, list(s2.tests)
        return e1, e2

    def truth_for(self, before: np.ndarray) -> np.ndarray:
        """Location errors whose noise-free run 1 identifies `before` (the chain's own bias
        removed by fixed-point iteration)."""
        truth = before.copy()
        for _ in range(3):
            e1, _ = self.run(truth, _none(0), _none(0))
            truth = truth - (e1 - before)
        return truth


# ----------------------------------------------------------------------------- analysis

def _chi2_95(df: int) -> float:
    """95 % quantile of chi2 with df degrees of freedom (Wilson-Hilferty)."""
    if df <= 0:
        return 0.0
    h = 2.0 / (9.0 * df)
    return df * (1.0 - h + 1.6449 * math.sqrt(h)) ** 3


def _box_lsq(R: np.ndarray, d: np.ndarray, w: np.ndarray, bounds: np.ndarray, iters: int = 200) -> np.ndarray:
    """min sum w (d - R s)^2 with |s_j| <= bounds_j, by cyclic coordinate descent (convex)."""
    s = np.zeros(R.shape[1])
    for _ in range(iters):
        old = s.copy()
        for j in range(R.shape[1]):
            r = R[:, j]
            res = d - R @ s + r * s[j]
            den = np.sum(w * r * r)
            s[j] = float(np.clip(np.sum(w * r * res) / den, -bounds[j], bounds[j])) if den > 0 else 0.0
        if np.max(np.abs(s - old) / np.maximum(bounds, 1e-300)) < 1e-9:
            break
    return s


def _scenario(a: Assumptions, before: np.ndarray, after: np.ndarray, draws: int, seed: int,
              max_causes: int, want_details: bool) -> dict:
    ch = _Chain(a)
    truth = ch.truth_for(before)
    cands = candidates(a, ch.duration)
    rng = np.random.default_rng(seed)
    const = [c for c in cands if c.kind == "constant"]

    # Prediction: noise in both runs and every constant effect at a random size within its
    # plausible half-width (rectangular), the same in both runs.
    sims = np.empty((draws, 8))
    for k in range(draws):
        errs, effs, piv = np.zeros(8), {}, np.zeros(3)
        for c in const:
            r = c.runs(rng.uniform(-c.plausible, c.plausible))[0]
            errs = errs + r[0]
            piv = piv + r[2]
            for eid, p in r[1].items():
                effs[eid] = [x + y for x, y in zip(effs.get(eid, [0.0] * len(p)), p)]
        sims[k] = ch.run(truth, (errs, effs, piv), (errs, effs, piv), rng)[1]
    mean = sims.mean(axis=0)
    std = sims.std(axis=0, ddof=1)
    # Coverage factor k = 2 (about 95 %); the draws are noise-dominated and near-Gaussian.
    lo, hi = mean - 2.0 * std, mean + 2.0 * std
    d = after - mean
    w = 1.0 / std ** 2

    # Response of the after-values (and of a repeated uncompensated run) to each cause, by a
    # central difference at its plausible size.
    R = np.empty((8, len(cands)))
    Rb = np.zeros((8, len(cands)))
    for j, c in enumerate(cands):
        h = c.plausible
        p1, p2 = c.runs(h)
        n1, n2 = c.runs(-h)
        ep = ch.run(truth, p1, p2)
        en = ch.run(truth, n1, n2)
        R[:, j] = (ep[1] - en[1]) / (2 * h)
        if want_details:
            # A repeated uncompensated run after the same interval: run 1 on run 2's machine,
            # minus run 1 (zero for a constant effect, the change itself otherwise).
            rp = ch.run(truth, p2, p2)[0] - ep[0]
            rn = ch.run(truth, n2, n2)[0] - en[0]
            Rb[:, j] = (rp - rn) / (2 * h)

    chi2_0 = float(np.sum(w * d * d))
    rows = []
    for j, c in enumerate(cands):
        r = R[:, j]
        den = float(np.sum(w * r * r))
        reach = np.abs(r) * c.plausible * _SCALE
        if den <= 0 or np.max(reach) < 1e-9:
            rows.append({"c": c, "j": j, "size": 0.0, "size_std": None, "chi2": chi2_0, "chi2_plausible": chi2_0,
                         "reach": reach})
            continue
        s = float(np.sum(w * r * d) / den)
        sp = float(np.clip(s, -c.plausible, c.plausible))
        rows.append({"c": c, "j": j, "size": s, "size_std": 1.0 / math.sqrt(den),
                     "chi2": float(np.sum(w * (d - s * r) ** 2)),
                     "chi2_plausible": float(np.sum(w * (d - sp * r) ** 2)), "reach": reach})
    # Rank by what the cause explains at a plausible size, then by what it needs.
    rows.sort(key=lambda x: (x["chi2_plausible"], x["chi2"]))

    # Extended model: greedy forward selection, sizes bounded by their plausible half-widths,
    # a cause kept while it lowers chi2 by more than ln(8) (BIC with 8 values).
    chosen: list[int] = []
    chi2 = chi2_0
    s_sel = np.zeros(0)
    while len(chosen) < max_causes:
        best = None
        for x in rows:
            j = x["j"]
            if j in chosen or x["size_std"] is None:
                continue
            idx = chosen + [j]
            sv = _box_lsq(R[:, idx], d, w, np.array([cands[i].plausible for i in idx]))
            c2 = float(np.sum(w * (d - R[:, idx] @ sv) ** 2))
            if best is None or c2 < best[0]:
                best = (c2, j, sv)
        # Stop when the deviations are already consistent with the predicted spread (chi2
        # below its 95 % quantile) or the next cause gains less than BIC's ln(8).
        if best is None or chi2 <= _chi2_95(8 - len(chosen)) or chi2 - best[0] <= math.log(8.0):
            break
        chi2, j, s_sel = best
        chosen.append(j)
    ext = R[:, chosen] @ s_sel if chosen else np.zeros(8)

    out = {"truth": truth, "mean": mean, "std": std, "lo": lo, "hi": hi, "d": d, "w": w, "chi2_0": chi2_0,
           "rows": rows, "chosen": chosen, "s_sel": s_sel, "ext": ext, "chi2_ext": chi2, "R": R, "Rb": Rb,
           "cands": cands, "duration": ch.duration, "chain": ch}
    return out


def _size_dict(c: Candidate, s: float, s_std: Optional[float]) -> dict:
    return {"size": float(s * c.display), "size_std": None if s_std is None else float(s_std * c.display),
            "unit": c.unit, "plausible": float(c.plausible * c.display),
            "size_over_plausible": float(abs(s) / c.plausible)}


def _vec(v: np.ndarray) -> dict:
    return {n: float(x) for n, x in zip(NAMES, v * _SCALE)}


def _separation(sc: dict, group: list[int]) -> dict:
    """Which test of run 2's raw data tells the causes of `group` apart: each cause at its
    fitted size, run 2's residuals after the paper's identification, RMS difference per test."""
    ch: _Chain = sc["chain"]
    res = {}
    for j in group:
        c = sc["cands"][j]
        s = next(x["size"] for x in sc["rows"] if x["j"] == j) or c.plausible
        p1, p2 = c.runs(s)
        res[j] = ch.run(sc["truth"], p1, p2, residuals=True)
    tests = res[group[0]][3]
    labels = sorted(set(tests), key=tests.index)
    best = {"test": None, "rms_difference_um": 0.0}
    per = {}
    for lab in labels:
        m = np.array([t == lab for t in tests])
        diffs = [float(np.sqrt(np.mean((res[i][2][m] - res[k][2][m]) ** 2)))
                 for ii, i in enumerate(group) for k in group[ii + 1:]]
        per[lab] = min(diffs) if diffs else 0.0
        if per[lab] > best["rms_difference_um"]:
            best = {"test": lab, "rms_difference_um": per[lab], "samples": int(m.sum())}
    return {"per_test_rms_difference_um": per, **best}


_FURTHER = {
    "axis_position": "log the temperatures and repeat the uncompensated test after the same interval",
    "axis_orientation": "log the temperatures and repeat the uncompensated test after the same interval",
    "table_shift": "log the temperatures and repeat the uncompensated test after the same interval",
    "tool_offset_Z": "measure the tool length (tool setter) before each run",
    "ballbar_length_offset": "calibrate the bar in its calibrator before each run",
    "drift_over_test": "repeat one test (e.g. radial_C) at the start and at the end of each run",
    "linear_squareness": "measure the linear axes (ballbar circles in XY, YZ, ZX, ISO 230-4) before each run",
    "linear_scale": "measure the linear axes' positioning (laser, ISO 230-2) before each run",
    "pivot": "fix the pivot stand rigidly and compare run 2's sphere-fit pivot with run 1's",
}


def analyse(table: dict | None = None, assumptions: Assumptions | None = None, *, draws: int = 200,
            seed: int = 1, sweep: Sequence[tuple[str, dict]] | None = None, sweep_draws: int = 60,
            max_causes: int = 6, top: int = 10) -> dict:
    """Analyse measured before/after identifications (default: Flynn et al. Table 2).

    Parameters
    ----------
    table : {"rows": [{"name", "unit", "before", "after"}]} in mm and rad in the order of
        location_error_names(AC-trt), e.g. load_table2(); default Table 2.
    assumptions : the unknowns of the experiment (Assumptions()).
    draws : Monte Carlo draws of the predicted chain (noise and constant effects).
    sweep : [(label, {field: value})] scenarios that change one assumption each; default
        DEFAULT_SWEEP. Each runs with sweep_draws draws.
    Returns a JSON-able dict (no NaN); render it with `render(result)`.
    """
    table = table if table is not None else load_table2()
    a = assumptions if assumptions is not None else Assumptions()
    if draws < 10:
        raise _core.InvalidArgument(f"analyse: draws must be at least 10, got {draws}")
    rows = table["rows"]
    if [r["name"] for r in rows] != list(NAMES):
        raise _core.InvalidArgument(f"analyse: table rows must be {', '.join(NAMES)} in this order")
    before = np.array([float(r["before"]) for r in rows])
    after = np.array([float(r["after"]) for r in rows])
    if not (np.all(np.isfinite(before)) and np.all(np.isfinite(after))):
        raise _core.InvalidArgument("analyse: before and after values must be finite")

    sc = _scenario(a, before, after, draws, seed, max_causes, True)
    cands = sc["cands"]
    std, mean, d = sc["std"], sc["mean"], sc["d"]

    prediction = {}
    for k, n in enumerate(NAMES):
        z = float(d[k] / std[k])
        prediction[n] = {"unit": _UNIT[k], "before": float(before[k] * _SCALE[k]),
                         "measured_after": float(after[k] * _SCALE[k]),
                         "predicted_mean": float(mean[k] * _SCALE[k]), "predicted_std": float(std[k] * _SCALE[k]),
                         "interval_k2": [float(sc["lo"][k] * _SCALE[k]), float(sc["hi"][k] * _SCALE[k])],
                         "z": z, "outside": bool(after[k] < sc["lo"][k] or after[k] > sc["hi"][k])}
    outside = [n for n in NAMES if prediction[n]["outside"]]

    ranked = []
    for x in sc["rows"][:top]:
        c = x["c"]
        j = x["j"]
        sp = float(np.clip(x["size"], -c.plausible, c.plausible))
        ranked.append({"id": c.id, "kind": c.kind, "cause": c.cause, **_size_dict(c, x["size"], x["size_std"]),
                       "plausible_size": bool(abs(x["size"]) <= c.plausible),
                       "chi2": x["chi2"], "chi2_at_plausible_size": x["chi2_plausible"],
                       "explains_at_fitted_size": _vec(x["size"] * sc["R"][:, j]),
                       "explains_at_plausible_size": _vec(sp * sc["R"][:, j]),
                       "repeat_uncompensated_shift": _vec(x["size"] * sc["Rb"][:, j])})

    # Per measured value: which kind can produce it, at a plausible size, alone.
    per_value = {}
    for k, n in enumerate(NAMES):
        dev = float(d[k] * _SCALE[k])
        tol = 2.0 * float(std[k] * _SCALE[k])
        best = {}
        for kind in ("constant", "between_runs"):
            reach = [(abs(float(sc["R"][k, j])) * c.plausible * _SCALE[k], c) for j, c in enumerate(cands)
                     if c.kind == kind]
            reach.sort(key=lambda t: -t[0])
            r0, c0 = reach[0]
            can = [c.id for r, c in reach if r >= abs(dev) - tol]
            best[kind] = {"largest_at_plausible_size": float(r0), "by": c0.id, "can_produce": can[:8],
                          "count": len(can)}
        if abs(dev) <= tol:
            verdict = "within the predicted spread"
        elif best["constant"]["count"] and best["between_runs"]["count"]:
            verdict = "either kind"
        elif best["between_runs"]["count"]:
            verdict = "only a change between the runs"
        elif best["constant"]["count"]:
            verdict = "only a constant effect"
        else:
            verdict = "no single cause at a plausible size"
        per_value[n] = {"unit": _UNIT[k], "deviation": dev, "two_sigma": tol, "verdict": verdict, **best}

    # Causes the 8 values cannot tell apart: responses nearly parallel in the chi2 metric.
    ambiguous = []
    W = np.sqrt(sc["w"])
    lead = [x for x in sc["rows"][:top] if x["size_std"] is not None]
    seen = set()
    for x in lead:
        j = x["j"]
        if j in seen:
            continue
        u = W * sc["R"][:, j]
        grp = [j]
        for y in sc["rows"]:
            k2 = y["j"]
            if k2 == j or y["size_std"] is None or abs(y["size"]) > 10 * cands[k2].plausible:
                continue
            v = W * sc["R"][:, k2]
            cos = float(abs(u @ v) / (np.linalg.norm(u) * np.linalg.norm(v)))
            if cos > 0.98:
                grp.append(k2)
        if len(grp) > 1:
            seen.update(grp)
            grp = grp[:4]
            sep = _separation(sc, grp)
            noise_se = a.noise_um / math.sqrt(max(sep.get("samples", 1), 1))
            ids = [cands[i].id for i in grp]
            fams = sorted({cands[i].family for i in grp})
            ambiguous.append({"candidates": ids, "separating_test": sep["test"],
                              "rms_difference_um": sep["rms_difference_um"],
                              "per_test_rms_difference_um": sep["per_test_rms_difference_um"],
                              "raw_data_separates": bool(sep["rms_difference_um"] > 3 * noise_se),
                              "further_measurement": [f"{f}: {_FURTHER[f]}" for f in fams if f in _FURTHER]})

    ext = sc["ext"]
    gain_rows = {}
    tot = {"um": [0.0, 0.0], "urad": [0.0, 0.0]}
    for k, n in enumerate(NAMES):
        meas = after[k] * _SCALE[k]
        basev = mean[k] * _SCALE[k]
        extv = (mean[k] + ext[k]) * _SCALE[k]
        gain_rows[n] = {"unit": _UNIT[k], "measured": float(meas), "baseline": float(basev),
                        "extended": float(extv), "unexplained_before": float(meas - basev),
                        "unexplained_after": float(meas - extv),
                        "inside_spread": bool(abs(meas - extv) <= 2 * std[k] * _SCALE[k])}
        tot[_UNIT[k]][0] += abs(meas - basev)
        tot[_UNIT[k]][1] += abs(meas - extv)
    extended = {"causes": [{"id": cands[j].id, "kind": cands[j].kind, "cause": cands[j].cause,
                            **_size_dict(cands[j], s, None)} for j, s in zip(sc["chosen"], sc["s_sel"])],
                "chi2_before": sc["chi2_0"], "chi2_after": sc["chi2_ext"], "per_value": gain_rows,
                "sum_abs_unexplained": {u: {"baseline": v[0], "extended": v[1], "accounted_for": v[0] - v[1]}
                                        for u, v in tot.items()}}

    constant_reach = {n: per_value[n]["constant"]["largest_at_plausible_size"] for n in NAMES}

    # Sweep of the assumptions: one change at a time.
    sweeps = []
    for label, changes in (DEFAULT_SWEEP if sweep is None else sweep):
        b = replace(a, **changes)
        s2 = _scenario(b, before, after, sweep_draws, seed, max_causes, False)
        out_n = [n for k, n in enumerate(NAMES) if after[k] < s2["lo"][k] or after[k] > s2["hi"][k]]
        top3 = [{"id": x["c"].id, **_size_dict(x["c"], x["size"], x["size_std"]),
                 "plausible_size": bool(abs(x["size"]) <= x["c"].plausible)} for x in s2["rows"][:3]]
        tot2 = {"um": [0.0, 0.0], "urad": [0.0, 0.0]}
        for k in range(8):
            tot2[_UNIT[k]][0] += abs(after[k] - s2["mean"][k]) * _SCALE[k]
            tot2[_UNIT[k]][1] += abs(after[k] - s2["mean"][k] - s2["ext"][k]) * _SCALE[k]
        sweeps.append({"scenario": label, "changes": {k: (list(v) if isinstance(v, tuple) else v)
                                                      for k, v in changes.items()},
                       "outside": out_n, "predicted_std": _vec(s2["std"]), "top_causes": top3,
                       "extended_causes": [s2["cands"][j].id for j in s2["chosen"]],
                       "sum_abs_unexplained": {u: {"baseline": v[0], "extended": v[1]} for u, v in tot2.items()}})

    result = {
        "source": table.get("source", {}),
        "assumptions": {**{k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(a).items()},
                        "test_duration_s": sc["duration"], "draws": draws, "seed": seed,
                        "thermal_change_fraction": 1.0 - math.exp(-a.hours_between_runs / a.thermal_time_constant_h),
                        "plausible_constant": dict(PLAUSIBLE_CONSTANT), "plausible_change_full_warmup": dict(PLAUSIBLE_CHANGE)},
        "simulated_truth": _vec(sc["truth"]),
        "prediction": prediction,
        "outside": outside,
        "constant_effects_largest_after_value": constant_reach,
        "per_value": per_value,
        "ranked_causes": ranked,
        "ambiguous": ambiguous,
        "extended_model": extended,
        "sweep": sweeps,
    }
    result["conclusions"] = _conclusions(result)
    _check_finite(result, "result")
    return result


DEFAULT_SWEEP = (
    ("bar 150 mm", {"ballbar_length": 150.0}),
    ("pivot O_x 80, O_z 40", {"pivot": (80.0, 0.0, 40.0)}),
    ("A range -60..60", {"tilt_range_deg": (-60.0, 60.0)}),
    ("noise 1 um, AR(1) 0.9", {"noise_um": 1.0, "noise_rho": 0.9}),
    ("15 min between runs", {"hours_between_runs": 0.25}),
    ("8 h between runs", {"hours_between_runs": 8.0}),
)


def _check_finite(x, path: str) -> None:
    if isinstance(x, float) and not math.isfinite(x):
        raise _core.Error(f"flynn_table2: non-finite value at {path}")
    if isinstance(x, dict):
        for k, v in x.items():
            _check_finite(v, f"{path}.{k}")
    elif isinstance(x, (list, tuple)):
        for i, v in enumerate(x):
            _check_finite(v, f"{path}[{i}]")


def _conclusions(r: dict) -> list[str]:
    out = []
    n_out = len(r["outside"])
    out.append(f"{n_out} of 8 measured post-compensation values fall outside the simulated interval (mean +- 2 std)"
               + (f": {', '.join(r['outside'])}." if n_out else "."))
    cmax = max(r["constant_effects_largest_after_value"].items(), key=lambda t: t[1])
    out.append("Effects that stay the same in both runs cancel in the chain: the largest post-compensation value "
               f"any of them produces at its plausible size is {cmax[1]:.2f} {r['prediction'][cmax[0]]['unit']} "
               f"({cmax[0]}).")
    for n, v in r["per_value"].items():
        if v["verdict"] != "within the predicted spread":
            out.append(f"{n}: deviation {v['deviation']:+.2f} {v['unit']}: {v['verdict']}"
                       + (f" (largest change between runs at a plausible size: {v['between_runs']['largest_at_plausible_size']:.2f}"
                          f" {v['unit']}, {v['between_runs']['by']})" if v["verdict"] == "no single cause at a plausible size" else "")
                       + ".")
    for g in r["ambiguous"]:
        out.append(f"Not told apart by the 8 values: {', '.join(g['candidates'])}; "
                   + (f"run 2's raw {g['separating_test']} data would separate them." if g["raw_data_separates"]
                      else "no test of the session separates them; " + "; ".join(g["further_measurement"]) + "."))
    if any(c["kind"] == "between_runs" for c in r["ranked_causes"][:1]):
        out.append("A repeated uncompensated run after the same interval tells every change between the runs "
                   "from a constant effect: a change moves its before-values by the size it adds after compensation "
                   "(ranked_causes[].repeat_uncompensated_shift), a constant effect does not move them.")
    e = r["extended_model"]
    for u, t in e["sum_abs_unexplained"].items():
        out.append(f"Extended model ({len(e['causes'])} causes at plausible sizes) accounts for {t['accounted_for']:.2f} "
                   f"of {t['baseline']:.2f} {u} (sum of |measured - predicted| over the {u} values); "
                   f"{t['extended']:.2f} {u} remain.")
    if not r["sweep"]:
        return out
    stable = [s["scenario"] for s in r["sweep"] if set(s["outside"]) == set(r["outside"])]
    out.append(f"The same values fall outside in {len(stable)} of {len(r['sweep'])} swept scenarios"
               + (f" (differs in: {', '.join(s['scenario'] for s in r['sweep'] if s['scenario'] not in stable)})."
                  if len(stable) < len(r["sweep"]) else "."))
    return out


# ----------------------------------------------------------------------------- rendering

def render(r: dict) -> str:
    """Plain-text rendering of analyse()'s result."""
    L = []
    a = r["assumptions"]
    L.append("Flynn et al. (2016) Table 2: measured before/after compensation vs the simulated chain")
    L.append(f"assumed: bar {a['ballbar_length']:g} mm, pivot {a['pivot']}, A {a['tilt_range_deg']}, "
             f"C {a['rot_range_deg']}, step {a['step_deg']:g} deg, noise {a['noise_um']:g} um AR(1) {a['noise_rho']:g}, "
             f"{a['hours_between_runs']:g} h between runs (tau {a['thermal_time_constant_h']:g} h), "
             f"method {a['method']}, {a['draws']} draws")
    L.append("")
    L.append("error   unit   before   measured after   predicted (mean +- std)   interval (k=2)       z   outside")
    for n, p in r["prediction"].items():
        L.append(f"{n:6s} {p['unit']:5s} {p['before']:+9.2f} {p['measured_after']:+12.2f}   "
                 f"{p['predicted_mean']:+9.2f} +- {p['predicted_std']:6.2f}     "
                 f"[{p['interval_k2'][0]:+7.2f}, {p['interval_k2'][1]:+7.2f}] {p['z']:+8.1f}   {'yes' if p['outside'] else 'no'}")
    L.append("")
    L.append("which kind of cause can produce each value alone, at a plausible size:")
    for n, v in r["per_value"].items():
        L.append(f"  {n}: {v['verdict']}; constant effects reach {v['constant']['largest_at_plausible_size']:.2f} {v['unit']}, "
                 f"changes between runs {v['between_runs']['largest_at_plausible_size']:.2f} {v['unit']} "
                 f"({v['between_runs']['by']})")
    L.append("")
    L.append("causes ranked (one at a time; size fitted to the 8 deviations, checked against its plausible size):")
    for i, c in enumerate(r["ranked_causes"], 1):
        sd = f" +- {c['size_std']:.2f}" if c["size_std"] is not None else ""
        L.append(f"  {i:2d}. {c['id']:40s} {c['size']:+9.2f}{sd} {c['unit']} (plausible {c['plausible']:.2f}, "
                 f"x{c['size_over_plausible']:.1f}{'' if c['plausible_size'] else ' TOO LARGE'}) chi2 {c['chi2']:.0f}")
    if r["ambiguous"]:
        L.append("")
        L.append("causes these 8 values cannot tell apart:")
        for g in r["ambiguous"]:
            how = (f"raw data of test {g['separating_test']} separates them ({g['rms_difference_um']:.2f} um RMS)"
                   if g["raw_data_separates"] else "no test of the session separates them")
            L.append(f"  {', '.join(g['candidates'])}: {how}; " + "; ".join(g["further_measurement"]))
    e = r["extended_model"]
    L.append("")
    L.append("extended model (causes at plausible sizes, greedy):")
    for c in e["causes"]:
        L.append(f"  {c['id']:40s} {c['size']:+9.2f} {c['unit']} (plausible {c['plausible']:.2f})")
    L.append("error   unit   measured   baseline   extended   unexplained before -> after")
    for n, g in e["per_value"].items():
        L.append(f"{n:6s} {g['unit']:5s} {g['measured']:+9.2f} {g['baseline']:+9.2f} {g['extended']:+9.2f}   "
                 f"{g['unexplained_before']:+9.2f} -> {g['unexplained_after']:+9.2f}")
    L.append("")
    L.append("sweep of the assumptions:")
    for s in r["sweep"]:
        t = s["top_causes"][0]
        L.append(f"  {s['scenario']:24s} outside: {','.join(s['outside']) or '-':48s} first cause {t['id']} "
                 f"{t['size']:+.2f} {t['unit']}; unexplained um {s['sum_abs_unexplained']['um']['baseline']:.1f}"
                 f"->{s['sum_abs_unexplained']['um']['extended']:.1f}, urad "
                 f"{s['sum_abs_unexplained']['urad']['baseline']:.1f}->{s['sum_abs_unexplained']['urad']['extended']:.1f}")
    L.append("")
    L += [f"- {c}" for c in r["conclusions"]]
    return "\n".join(L)

