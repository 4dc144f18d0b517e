# SPDX-License-Identifier: BSD-3-Clause
"""Writers (and a minimal reader) of the three session formats of formats.md, and truth JSON
like /work/shared/data/*.truth.json (keys errors, pivot_actual / sphere_actual / nests, effects,
noise_um; probe_zeros for an R-test)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np


def _header(fmt: str, machine, extra: list[str], noise_um: float | None) -> list[str]:
    lines = [f"# format: {fmt}", f"# machine: {machine.name}", "# units: mm, deg, s"]
    if machine.description is not None:  # formats.md: a machine that is not built in
        lines.append(
            "# machine_description: " + json.dumps(machine.description, separators=(",", ":"))
        )
    lines += extra
    if noise_um is not None:
        lines.append(f"# noise_um: {noise_um:.6g}")
    return lines


def _v(v, digits: int = 4) -> str:
    return ", ".join(f"{float(x):.{digits}f}" for x in v)


def _write(path, lines: list[str]) -> Path:
    path = Path(path)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def write_ballbar(path, machine, session: dict, length, noise_um: float | None = None) -> Path:
    """rotacal-ballbar/1: test,time,X,Y,Z,<rotary columns>,length."""
    extra = [
        f"# ballbar_length: {session['ballbar_length']:.4f}",
        f"# pivot: {_v(session['pivot'])}",
    ]
    lines = _header("rotacal-ballbar/1", machine, extra, noise_um)
    lines.append(",".join(["test", "time", "X", "Y", "Z", *machine.axis_names, "length"]))
    for lab, t, p, a, ln in zip(
        session["test"], session["time"], session["xyz"], session["angles_deg"], length
    ):
        lines.append(
            f"{lab},{t:.3f},{p[0]:.6f},{p[1]:.6f},{p[2]:.6f},{a[0]:.6f},{a[1]:.6f},{ln:.7f}"
        )
    return _write(path, lines)


def write_rtest(path, machine, session: dict, d, noise_um: float | None = None) -> Path:
    """rotacal-rtest/1: setup,time,<rotary columns>,X,Y,Z,dx,dy,dz."""
    extra = [f"# nest.{k}: {_v(v)}" for k, v in session["nests"].items()]
    lines = _header("rotacal-rtest/1", machine, extra, noise_um)
    lines.append(",".join(["setup", "time", *machine.axis_names, "X", "Y", "Z", "dx", "dy", "dz"]))
    for s, t, a, p, r in zip(
        session["setup"], session["time"], session["angles_deg"], session["xyz"], d
    ):
        lines.append(
            f"{s},{t:.3f},{a[0]:.6f},{a[1]:.6f},{p[0]:.6f},{p[1]:.6f},{p[2]:.6f},"
            f"{r[0]:.7f},{r[1]:.7f},{r[2]:.7f}"
        )
    return _write(path, lines)


def write_probe(
    path,
    machine,
    session: dict,
    latched,
    sphere_diameter: float,
    stylus_diameter: float,
    noise_um: float | None = None,
) -> Path:
    """rotacal-probe/1: pose,time,X,Y,Z,<rotary columns>,nx,ny,nz (X, Y, Z latched)."""
    extra = [
        f"# sphere: {_v(session['sphere'])}",
        f"# sphere_diameter: {sphere_diameter:.4f}",
        f"# stylus_diameter: {stylus_diameter:.4f}",
    ]
    lines = _header("rotacal-probe/1", machine, extra, noise_um)
    lines.append(",".join(["pose", "time", "X", "Y", "Z", *machine.axis_names, "nx", "ny", "nz"]))
    for k, t, p, a, n in zip(
        session["pose"], session["time"], latched, session["angles_deg"], session["n"]
    ):
        lines.append(
            f"{k},{t:.3f},{p[0]:.6f},{p[1]:.6f},{p[2]:.6f},{a[0]:.6f},{a[1]:.6f},"
            f"{n[0]:.6f},{n[1]:.6f},{n[2]:.6f}"
        )
    return _write(path, lines)


def write_truth(
    path, errors: dict, effects: dict | None = None, noise_um: float = 0.0, **extra
) -> Path:
    """Truth JSON: errors, effects, noise_um, and pivot_actual / sphere_actual / nests / probe_zeros."""
    doc = {
        "errors": {k: float(v) for k, v in errors.items()},
        **{k: np.asarray(v, float).tolist() for k, v in extra.items()},
        "effects": {
            k: (np.asarray(v, float).tolist() if np.ndim(v) else float(v))
            for k, v in (effects or {}).items()
        },
        "noise_um": float(noise_um),
    }
    path = Path(path)
    path.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    return path


def read_session(path) -> dict:
    """Metadata (key -> text) and columns (name -> list of text or float) of any of the formats."""
    meta, header, rows = {}, None, []
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        if not line.strip():
            continue
        if line.startswith("#"):
            key, _, value = line[1:].partition(":")
            meta[key.strip()] = value.strip()
        elif header is None:
            header = line.split(",")
        else:
            rows.append(line.split(","))
    cols = {}
    for i, name in enumerate(header):
        vals = [r[i] for r in rows]
        try:
            cols[name] = np.array([float(v) for v in vals])
        except ValueError:
            cols[name] = vals
    return {"meta": meta, "columns": cols}


def vector(text: str) -> np.ndarray:
    """'120.0, 0.0, 60.0' -> array (metadata vectors)."""
    return np.array([float(x) for x in text.split(",")])
