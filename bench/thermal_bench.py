# SPDX-License-Identifier: BSD-3-Clause
"""Thermal test of a rotary axis (issue 53): accuracy, prediction, null sessions, two lags, time.

Data from the reference simulator's thermal extension (tests/reference/refsim/thermal.py), never
from rotacal's own simulator: an AC-trt touch probe, C at 300 rev/min for 4 h then at rest to
6 h, an epoch of 8 poses x 5 touches every 10 min (37 epochs, 1480 touches, as the shared
thermal_probe_ac.csv), its cold errors and sphere; each draw scales the shared truth's gains by
one factor, log-uniform in 0.5..2; 0.5 um white noise along each approach.

- accuracy: per gain and tau, the joint fit's RMSE over the draws against the Cramer-Rao bound
  (the Fisher information of the touches by finite differences of the REFERENCE simulator at
  the truth, per draw; RMS of error/CRB), against the per-epoch peer's RMSE, and the coverage of
  the fit's own 2-sigma intervals pooled over the gains and tau;
- prediction: identified from the heat-up epochs alone, each location error predicted at the
  middle of each cool-down epoch (rotacal predict's model file); RMS over those epochs of
  (prediction - truth) against 2x that error's median per-epoch sigma (each cool-down epoch
  identified alone, first draw);
- null: no drift; a session whose joint drift test (summary's drift_test: all gains against 0
  with the fit's covariance, F at the noise model's dof, level 1 %) finds a drift is a false
  finding; beside it the old rule (any gain beyond 3 sigma, one by one); null_ar1 (not in the
  default parts): the same with AR(1) 0.8 noise from touch to touch, identified with the noise
  model (noise "auto": GLS refit, the test's dof from its effective samples);
- detection: the same test on drifting sessions, the gains x 0.5-2 (the issue's), x 0.02-0.05 and x 0.003-0.01;
- two lags: tau2 = 4 tau1, K2 = 0.7 K1; named two-lag where BIC (n ln(RSS/n) + k ln n, k the
  observable parameters) of the two-lag fit is lower; one-lag sessions the same way;
- time: identification (fit, noise model, budget; the file load measured apart and taken
  off) of one 6 h session, and the peer's, in this process.

    python3 bench/thermal_bench.py [--draws N] [--draws-slow M] [--smoke]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "reference"))
import refsim  # noqa: E402
from refsim import thermal, writers  # noqa: E402

from rotacal import _core  # noqa: E402

SHARED = ROOT.parent / "shared" / "data"
NOISE_MM = 5e-4
DUTY = [(0.0, {"C": 300.0}), (14400.0, {"C": 0.0})]
POSES = [(0.0, c) for c in (0, 90, 180, 270)] + [(a, 0.0) for a in (-60, -30, 30, 60)]
POINT = ("q_x", "q_y", "q_z")


def shared_truth() -> dict:
    return json.loads((SHARED / "thermal_probe_ac.truth.json").read_text())


def pattern(interval_s: float = 600.0, end_s: float = 21600.0):
    """Rows of the test: pose number, time, angles (deg), approach direction, epoch."""
    dirs = refsim.poses.probe_directions()
    rows = []
    for e in range(int(end_s / interval_s) + 1):
        for k, (a, c) in enumerate(POSES):
            for j, d in enumerate(dirs):
                rows.append(
                    (len(POSES) * e + k + 1, interval_s * e + 16.0 * k + 2.0 * j, a, c, d, e + 1)
                )
    return rows


ROWS = pattern()


def latched(truth: dict, lags: list, rows=ROWS) -> np.ndarray:
    """Noise-free latched positions (N, 3) of the reference simulator."""
    time_s = np.array([r[1] for r in rows])
    epoch = np.array([r[5] for r in rows])
    errors, sphere = thermal.drifted(
        truth["errors"], truth["sphere_actual"], lags, DUTY, time_s, epoch
    )
    return refsim.probe_touches(
        refsim.Model("AC-trt", errors),
        sphere,
        np.array([150.0, 0.0, 80.0]),
        25.0,
        6.0,
        np.array([r[4] for r in rows]),
        np.radians(np.array([(r[2], r[3]) for r in rows])),
        time_s,
    )


def write_session(path: Path, touches: np.ndarray, rows=ROWS, duty=True) -> Path:
    s = {
        "pose": [r[0] for r in rows],
        "time": np.array([r[1] for r in rows]),
        "angles_deg": np.array([(r[2], r[3]) for r in rows]),
        "n": np.array([r[4] for r in rows]),
        "sphere": np.array([150.0, 0.0, 80.0]),
    }
    writers.write_probe(path, refsim.builtin("AC-trt"), s, touches, 25.0, 6.0, noise_um=0.5)
    if duty:
        thermal.add_thermal_columns(path, DUTY, [r[5] for r in rows])
    return path


def noisy(touches: np.ndarray, rng, rows=ROWS) -> np.ndarray:
    n = np.array([r[4] for r in rows])
    return touches + n * (NOISE_MM * rng.standard_normal(len(rows)))[:, None]


def scaled_lags(t: dict, factor: float, tau_s: float | None = None) -> list:
    lag = t["thermal"][0]
    return [
        {
            "axis": "C",
            "tau_s": tau_s or lag["tau_s"],
            "gains": {k: factor * v for k, v in lag["gains"].items()},
        }
    ]


def crb(truth: dict, lags: list, names: list[str]) -> dict[str, float]:
    """Cramer-Rao bound of each named parameter (gains, 'tau', cold errors, 'sphere.x'...) from the
    reference simulator: Fisher information of the touches along their approach directions."""
    n = np.array([r[4] for r in ROWS])
    base = latched(truth, lags)

    def moved(name: str, h: float) -> np.ndarray:
        t2 = json.loads(json.dumps(truth))
        l2 = json.loads(json.dumps(lags))
        if name == "tau":
            l2[0]["tau_s"] += h
        elif name.startswith("gain."):
            l2[0]["gains"][name[5:]] = l2[0]["gains"].get(name[5:], 0.0) + h
        elif name.startswith("sphere."):
            t2["sphere_actual"]["xyz".index(name[-1])] += h
        else:
            t2["errors"][name] += h
        return latched(t2, l2)

    cols = []
    for name in names:
        angle = name.split(".")[-1].startswith(("E_A", "E_B", "E_C"))  # rad, else mm
        h = 1.0 if name == "tau" else (1e-7 if angle else 1e-5)
        cols.append(np.sum((moved(name, h) - base) * n, axis=1) / h)
    J = np.column_stack(cols) / NOISE_MM
    scale = np.linalg.norm(J, axis=0)  # columns of mm, rad and s: scaled before the inverse
    Js = J / scale
    cov = np.linalg.inv(Js.T @ Js) / np.outer(scale, scale)
    return dict(zip(names, np.sqrt(np.diag(cov))))


def identify(path: Path, noise: str = "white", **kw) -> dict:
    return _core.identify_thermal(str(path), noise=noise, **kw)


def fit_parameters(ident: dict) -> list[str]:
    """The observable parameters of a one-lag fit in crb()'s names."""
    names = [c["name"] for c in ident["cold"] if c["observable"]]
    out = [n if n.startswith("E_") else "sphere." + n[-1] for n in names]
    out += ["gain." + g["name"] for g in ident["lags"][0]["gains"] if g["observable"]]
    return out + ["tau"]


def accuracy(draws: int, rng, tmp: Path) -> None:
    t = shared_truth()
    z, err, perr, crbs, names = [], [], [], [], None
    for d in range(draws):
        lags = scaled_lags(t, float(np.exp(rng.uniform(np.log(0.5), np.log(2.0)))))
        f = write_session(tmp / "acc.csv", noisy(latched(t, lags), rng))
        r = identify(f, peer=True)
        joint, peer = r["identification"], r["peer"]["identification"]
        est = {"tau": (joint["lags"][0]["tau_s"], joint["lags"][0]["tau_std_s"])}
        pest = {"tau": peer["lags"][0]["tau_s"]}
        for g, pg in zip(joint["lags"][0]["gains"], peer["lags"][0]["gains"]):
            if g["observable"]:
                est["gain." + g["name"]] = (g["value"], g["std"])
                pest["gain." + g["name"]] = pg["value"] if pg["observable"] else np.nan
        if names is None:
            names = list(est)
            bound_names = fit_parameters(joint)
        truth_v = {"tau": lags[0]["tau_s"], **{"gain." + k: v for k, v in lags[0]["gains"].items()}}
        bound = crb(t, lags, bound_names)
        err.append([est[k][0] - truth_v[k] for k in names])
        perr.append([pest[k] - truth_v[k] for k in names])
        z.append([(est[k][0] - truth_v[k]) / est[k][1] for k in names])
        crbs.append([bound[k] for k in names])
    err, perr, z, crbs = map(np.array, (err, perr, z, crbs))
    print(
        f"accuracy: {draws} draws, 1480 touches each, gains x 0.5-2 (log-uniform), 0.5 um white noise"
    )
    print("| parameter | joint RMSE/CRB | joint RMSE / peer RMSE | coverage 2 sigma |")
    print("|---|---|---|---|")
    worst = 0.0
    for i, k in enumerate(names):
        ratio = float(np.sqrt(np.mean((err[:, i] / crbs[:, i]) ** 2)))
        worst = max(worst, ratio)
        rel = float(np.sqrt(np.mean(err[:, i] ** 2)) / np.sqrt(np.nanmean(perr[:, i] ** 2)))
        print(f"| {k} | {ratio:.3f} | {rel:.3f} | {np.mean(np.abs(z[:, i]) <= 2):.1%} |")
    print(f"worst joint RMSE/CRB over the gains and tau: {worst:.3f}")
    print(
        f"coverage at 2 sigma, pooled over the gains and tau: {np.mean(np.abs(z) <= 2):.1%} of {z.size}"
    )


def truth_at(t: dict, lags: list, t_mid: float) -> dict:
    time_s = np.r_[[r[1] for r in ROWS], t_mid]
    epoch = np.r_[[r[5] for r in ROWS], -1]
    errs, _ = thermal.drifted(t["errors"], t["sphere_actual"], lags, DUTY, time_s, epoch)
    return {k: v[-1] for k, v in errs.items()}


def per_epoch_sigma(touches: np.ndarray, epochs: list[int], tmp: Path) -> dict[str, float]:
    import rotacal

    sig: dict[str, list] = {}
    for e in epochs:
        rows = [r for r in ROWS if r[5] == e]
        idx = [i for i, r in enumerate(ROWS) if r[5] == e]
        f = write_session(tmp / "epoch.csv", touches[idx], rows, duty=False)
        ident = rotacal.probe.identify_probe(rotacal.load(str(f)), noise="white")
        for name, p in ident.to_dict()["location_errors"].items():
            if p.get("std") is not None:
                sig.setdefault(name, []).append(p["std"])
    return {k: float(np.median(v)) for k, v in sig.items()}


def prediction(draws: int, rng, tmp: Path) -> None:
    t = shared_truth()
    heat_rows = [r for r in ROWS if r[1] < 14400.0]
    cool = sorted({r[5] for r in ROWS if r[1] >= 14400.0})
    span = {e: [r[1] for r in ROWS if r[5] == e] for e in cool}
    mids = {e: 0.5 * (min(v) + max(v)) for e, v in span.items()}
    sigma, ok, ratios = None, [], []
    for d in range(draws):
        lags = scaled_lags(t, float(np.exp(rng.uniform(np.log(0.5), np.log(2.0)))))
        touches = noisy(latched(t, lags), rng)
        if sigma is None:
            sigma = per_epoch_sigma(touches, cool, tmp)
        f = write_session(tmp / "heat.csv", touches[: len(heat_rows)], heat_rows)
        r = identify(f, model=True)
        model = tmp / "model.json"
        model.write_text(json.dumps(r["model"]))
        full = write_session(tmp / "full.csv", touches)
        p = _core.predict_thermal(str(model), str(full), [mids[e] for e in cool])
        worst = 0.0
        for e_pred in p["errors"]:
            name = e_pred["name"]
            if not e_pred["observable"] or name not in sigma:
                continue
            truth_v = np.array([truth_at(t, lags, mids[e])[name] for e in cool])
            rms = float(np.sqrt(np.mean((np.array(e_pred["value"]) - truth_v) ** 2)))
            worst = max(worst, rms / (2.0 * sigma[name]))
        ratios.append(worst)
        ok.append(worst <= 1.0)
    print(
        f"prediction from the heat-up alone: {draws} draws, {len(cool)} cool-down epochs predicted"
    )
    print(
        f"worst error's RMS(prediction - truth) / (2 x median per-epoch sigma): median {np.median(ratios):.3f}, max {np.max(ratios):.3f}"
    )
    print(f"draws where every error is within 2x its per-epoch sigma: {np.mean(ok):.1%}")


def null(draws: int, rng, tmp: Path, rho: float = 0.0) -> None:
    t = shared_truth()
    found, one_by_one, pvals = 0, 0, []
    base = latched(t, [])
    n = np.array([r[4] for r in ROWS])
    for d in range(draws):
        touches = (
            base + n * refsim.noise.ar1(["t"] * len(ROWS), rho, NOISE_MM, rng)[:, None]
            if rho
            else noisy(base, rng)
        )
        f = write_session(tmp / "null.csv", touches)
        # coloured noise: the noise model and its GLS refit (the CLI's default), else white
        s = identify(f, "auto" if rho else "white", tolerance_mm=0.005)["summary"]
        found += s["drift_test"]["drift_found"]
        one_by_one += any(e.get("significant", False) for e in s["drifts"])
        pvals.append(s["drift_test"]["p_value"])
    level = s["drift_test"]["level"]
    noise = f"AR(1) {rho:g} from touch to touch" if rho else "white"
    print(
        f"null sessions (no drift, {noise} noise): the joint drift test (F, level {level:g}) finds a drift in "
        f"{found}/{draws} ({found / draws:.1%}); a gain beyond 3 sigma, one by one: {one_by_one}/{draws}"
    )
    p = np.sort(pvals)
    print(
        "p-values under the null: fraction below 0.01 / 0.05 / 0.5: "
        + " / ".join(f"{np.mean(p < x):.3f}" for x in (0.01, 0.05, 0.5))
    )


def detection(draws: int, rng, tmp: Path) -> None:
    """The joint test on drifting sessions: the issue's gains (x 0.5-2) and smaller ones."""
    t = shared_truth()
    for lo, hi in ((0.5, 2.0), (0.02, 0.05), (0.003, 0.01)):
        found = 0
        for d in range(draws):
            lags = scaled_lags(t, float(np.exp(rng.uniform(np.log(lo), np.log(hi)))))
            f = write_session(tmp / "det.csv", noisy(latched(t, lags), rng))
            found += identify(f)["summary"]["drift_test"]["drift_found"]
        print(
            f"drifting sessions, gains x {lo:g}-{hi:g} of the shared truth: drift found in "
            f"{found}/{draws} ({found / draws:.1%})"
        )


def bic(ident: dict) -> float:
    n = ident["n_samples"]
    k = sum(c["observable"] for c in ident["cold"])
    k += sum(
        lag["tau_observable"] + sum(g["observable"] for g in lag["gains"]) for lag in ident["lags"]
    )
    rss = n * (ident["residual_rms_um"] * 1e-3) ** 2
    return n * np.log(rss / n) + k * np.log(n)


def two_lags(draws: int, rng, tmp: Path) -> None:
    t = shared_truth()
    k1 = t["thermal"][0]["gains"]
    named2, named2_one = 0, 0
    for d in range(draws):
        f_ = float(np.exp(rng.uniform(np.log(0.5), np.log(2.0))))
        two = [
            {"axis": "C", "tau_s": 1200.0, "gains": {k: f_ * v for k, v in k1.items()}},
            {"axis": "C", "tau_s": 4800.0, "gains": {k: 0.7 * f_ * v for k, v in k1.items()}},
        ]
        f = write_session(tmp / "two.csv", noisy(latched(t, two), rng))
        named2 += bic(identify(f, lags=2)["identification"]) < bic(identify(f)["identification"])
        f = write_session(tmp / "one.csv", noisy(latched(t, scaled_lags(t, f_)), rng))
        named2_one += bic(identify(f, lags=2)["identification"]) < bic(
            identify(f)["identification"]
        )
    print(f"two lags (tau2 = 4 tau1 = 4800 s, K2 = 0.7 K1, 6 h): named two-lag in {named2}/{draws}")
    print(f"one-lag sessions named two-lag: {named2_one}/{draws}")


def timing(rng, tmp: Path, repeats: int) -> None:
    t = shared_truth()
    f = write_session(tmp / "time.csv", noisy(latched(t, t["thermal"]), rng))

    def best(fn) -> float:
        out = []
        for _ in range(repeats):
            c0 = time.process_time()
            fn()
            out.append(time.process_time() - c0)
        return float(np.median(out))

    load = best(lambda: _core.read_instrument_session(str(f)))
    joint = best(lambda: identify(f, "auto")) - load
    both = best(lambda: identify(f, "auto", peer=True)) - load
    peer = both - joint
    print(
        f"time of a 6 h probe test (1480 touches), CPU, median of {repeats}: file load {load * 1e3:.1f} ms; "
        f"joint fit, noise model and budget {joint * 1e3:.1f} ms; per-epoch peer {peer * 1e3:.1f} ms; "
        f"joint/peer {joint / peer:.2f}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=100, help="draws of accuracy and null")
    ap.add_argument(
        "--draws-slow",
        type=int,
        default=None,
        help="draws of prediction and two_lags (default --draws)",
    )
    ap.add_argument("--seed", type=int, default=53)
    ap.add_argument("--parts", default="accuracy,prediction,null,detection,two_lags,time")
    ap.add_argument("--smoke", action="store_true", help="2 draws of each part (CI)")
    a = ap.parse_args()
    draws = 2 if a.smoke else a.draws
    slow = 2 if a.smoke else (a.draws_slow or a.draws)
    rng = np.random.default_rng(a.seed)
    parts = {
        "accuracy": accuracy,
        "prediction": prediction,
        "null": null,
        "null_ar1": lambda k, rng, tmp: null(k, rng, tmp, rho=0.8),
        "detection": detection,
        "two_lags": two_lags,
    }
    with tempfile.TemporaryDirectory(prefix="thermal-bench-") as d:
        for p in a.parts.split(","):
            c0 = time.process_time()
            if p == "time":
                timing(rng, Path(d), 3 if a.smoke else 15)
            else:
                parts[p](
                    slow if p in ("prediction", "detection", "two_lags", "null_ar1") else draws,
                    rng,
                    Path(d),
                )
            print(f"({p}: {time.process_time() - c0:.1f} CPU-s)\n")


if __name__ == "__main__":
    main()
