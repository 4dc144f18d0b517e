# SPDX-License-Identifier: BSD-3-Clause
"""The thermal test of a rotary axis (formats.md "Thermal test of a rotary axis", effects.md
`thermal_location_R`), written from the spec text only.

- duty: `# duty.N: TIME, AXIS=SPEED, ...` -> [(TIME, {axis: rev/min})], an axis not named is at
  rest from TIME, every axis at rest before the first entry;
- heat input u(t) = |omega_R(t)| / (100 rev/min), 0 during an epoch (first to last row time);
- lag state tau dy/dt = u - y, y = 0 at the session's first row, solved exactly on each interval
  where u is constant: y(t + h) = u + (y(t) - u) exp(-h / tau);
- every location error E -> E + sum_k K_k,E y_k(t); the table-side point (probe sphere, each
  R-test nest) q -> q + sum_k (K_k,qx, K_k,qy, K_k,qz) y_k(t).
Gains are keyed as in the shared truth files: the error names, and q_x, q_y, q_z.
"""

from __future__ import annotations

import numpy as np


def parse_duty(meta: dict) -> list[tuple[float, dict]]:
    """`duty.N` metadata (N = 1, 2, ...) -> [(time_s, {axis: rev/min})]."""
    out, n = [], 1
    while f"duty.{n}" in meta:
        fields = [f.strip() for f in meta[f"duty.{n}"].split(",")]
        speeds = {}
        for f in fields[1:]:
            axis, _, speed = f.partition("=")
            speeds[axis.strip()] = float(speed)
        out.append((float(fields[0]), speeds))
        n += 1
    return out


def epoch_spans(time, epoch) -> list[tuple[float, float]]:
    """(first row time, last row time) of each epoch, in file order."""
    time, epoch = np.asarray(time, float), np.asarray(epoch)
    return [(time[epoch == e].min(), time[epoch == e].max()) for e in dict.fromkeys(epoch.tolist())]


def heat_input_pieces(duty, axis: str, spans, t0: float, t1: float):
    """[(start, end, u)] covering [t0, t1]: u = |speed| / 100 from the duty, 0 inside an epoch."""
    cuts = {t0, t1}
    cuts.update(t for t, _ in duty if t0 < t < t1)
    for a, b in spans:
        cuts.update(x for x in (a, b) if t0 < x < t1)
    cuts = sorted(cuts)
    pieces = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        mid = 0.5 * (a + b)
        u = 0.0
        for t, speeds in duty:  # the last entry at or before the piece applies
            if t <= mid:
                u = abs(speeds.get(axis, 0.0)) / 100.0
        if any(s <= mid <= e for s, e in spans):
            u = 0.0
        pieces.append((a, b, u))
    return pieces


def lag_state(duty, axis: str, tau_s: float, time, epoch) -> np.ndarray:
    """y(t) at each row's time (exact for piecewise-constant u), 0 at the first row."""
    time = np.asarray(time, float)
    t0, t1 = float(time.min()), float(time.max())
    pieces = heat_input_pieces(duty, axis, epoch_spans(time, epoch), t0, t1)
    starts, y_start, y = [], [], 0.0
    for a, b, u in pieces:
        starts.append((a, b, u))
        y_start.append(y)
        y = u + (y - u) * np.exp(-(b - a) / tau_s)
    out = np.empty_like(time)
    for i, t in enumerate(time):
        k = max(j for j, (a, _, _) in enumerate(starts) if a <= t) if t > t0 else 0
        a, _, u = starts[k]
        out[i] = u + (y_start[k] - u) * np.exp(-(t - a) / tau_s)
    return out


def drifted(errors: dict, table_point, lags, duty, time, epoch):
    """Per-row errors {name: (N,)} and table-side point (N, 3) of a thermal model.

    lags: [{"axis": "C", "tau_s": ..., "gains": {name or q_x/q_y/q_z: K}}] (the truth's `thermal`)."""
    time = np.asarray(time, float)
    errs = {k: np.full(len(time), float(v)) for k, v in errors.items()}
    q = np.tile(np.asarray(table_point, float), (len(time), 1))
    for lag in lags:
        y = lag_state(duty, lag["axis"], float(lag["tau_s"]), time, epoch)
        for name, k in lag["gains"].items():
            if name in ("q_x", "q_y", "q_z"):
                q[:, "xyz".index(name[2])] += k * y
            else:
                errs[name] = errs.get(name, np.zeros(len(time))) + k * y
    return errs, q


def add_thermal_columns(path, duty, epoch) -> None:
    """Turn a probe or R-test file written by writers.py into a thermal session: `# duty.N:`
    lines after the metadata, and the `epoch` column last (formats.md)."""
    from pathlib import Path

    lines = Path(path).read_text(encoding="utf-8").splitlines()
    head = [ln for ln in lines if ln.startswith("#")]
    body = [ln for ln in lines if not ln.startswith("#")]
    for n, (t, speeds) in enumerate(duty, start=1):
        head.append(f"# duty.{n}: {t:g}, " + ", ".join(f"{a}={v:g}" for a, v in speeds.items()))
    body = [body[0] + ",epoch"] + [f"{r},{int(e)}" for r, e in zip(body[1:], epoch)]
    Path(path).write_text("\n".join(head + body) + "\n", encoding="utf-8")
