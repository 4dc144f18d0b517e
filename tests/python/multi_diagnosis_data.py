# SPDX-License-Identifier: BSD-3-Clause
"""Sessions of ONE simulated machine for the diagnosis of several sessions (issue 50 item 1),
made by the independent reference simulator (tests/reference/refsim, never rotacal's own): a
ballbar single set-up and a touch-probe pose set on the same location errors and effects, each
with its own set-up error and AR(1) noise."""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
import refsim  # noqa: E402
from refsim import noise, poses, writers  # noqa: E402

import rotacal  # noqa: E402


def machine_errors(machine: str, seed: int) -> dict:
    """Location errors of the machine: tens of um and tens of urad."""
    rng = np.random.default_rng(seed)
    names = refsim.builtin(machine).error_names()
    return {
        n: (rng.normal(0, 0.02) if k % 4 < 2 else rng.normal(0, 4e-5)) for k, n in enumerate(names)
    }


def ballbar(
    tmp_path, machine, errors, effects, seed, rho=0.5, noise_um=0.5, pivot=(110.0, 10.0, 70.0)
):
    """The single set-up ballbar tests; `effects`: the machine's and this session's own."""
    rng = np.random.default_rng(seed)
    m = refsim.builtin(machine)
    s = poses.ballbar_single_setup(m, pivot=pivot)
    model = refsim.Model(m, errors, effects)
    actual = np.asarray(pivot) + rng.normal(0, 10e-3, 3)  # the set-up error
    length = refsim.ballbar_lengths(model, actual, s["xyz"], np.radians(s["angles_deg"]), s["time"])
    length = length + noise.ar1(s["test"], rho, noise_um * 1e-3, rng)
    path = writers.write_ballbar(tmp_path / f"ballbar_{seed}.csv", m, s, length, noise_um=noise_um)
    return rotacal.load(path), path


def probe(
    tmp_path,
    machine,
    errors,
    effects,
    seed,
    rho=0.5,
    noise_um=0.5,
    sphere=(140.0, -10.0, 75.0),
    poses_of=None,
    actual=None,
    name=None,
):
    """refsim's 24 poses x 5 touches about `sphere`, or the poses of `poses_of` (pose, time,
    angles_deg, n, sphere: a session template read by template_poses); the sphere where it
    actually is, `actual`, else the nominal one moved by a set-up error; the trigger's noise
    along the approach."""
    rng = np.random.default_rng(seed)
    m = refsim.builtin(machine)
    s = poses_of if poses_of is not None else poses.probe_poses(m, sphere=sphere)
    set_up = s["sphere"] + rng.normal(0, 0.02, 3)
    actual = set_up if actual is None else np.asarray(actual, float)
    latched = refsim.probe_touches(
        refsim.Model(m, errors, effects),
        actual,
        s["sphere"],
        25.0,
        6.0,
        s["n"],
        np.radians(s["angles_deg"]),
        s["time"],
    )
    one = ["touches"] * len(latched)
    e = noise.ar1(one, rho, noise_um * 1e-3, rng)
    n = s["n"] / np.linalg.norm(s["n"], axis=1, keepdims=True)
    path = writers.write_probe(
        tmp_path / (name or f"probe_{machine}_{seed}.csv"),
        m,
        s,
        latched + e[:, None] * n,
        25.0,
        6.0,
        noise_um=noise_um,
    )
    return rotacal.load(path), path


def template_poses(path) -> dict:
    """The commanded poses of a rotacal-probe/1 session template (`design probe --separate ...
    -o added.ngc` writes added.csv): pose, time, rotary angles, approach n and nominal sphere,
    read as a user's recorder would, from the file's text."""
    lines = Path(path).read_text().splitlines()
    sphere = next(ln for ln in lines if ln.startswith("# sphere:")).split(":", 1)[1]
    rows = [ln.split(",") for ln in lines if ln and not ln.startswith("#")]
    head, body = rows[0], np.array(rows[1:], float)
    col = {c: i for i, c in enumerate(head)}
    rot = [c for c in head[5:] if c not in ("nx", "ny", "nz")]
    return {
        "pose": [int(p) for p in body[:, col["pose"]]],
        "time": body[:, col["time"]],
        "angles_deg": body[:, [col[c] for c in rot]],
        "n": body[:, [col["nx"], col["ny"], col["nz"]]],
        "sphere": np.array([float(v) for v in sphere.split(",")]),
    }


def read_template(path) -> tuple[dict, dict]:
    """A session template as a user's recorder reads it, from the file's text: its metadata
    ("# key: value") and its columns by name (floats where they parse, else strings)."""
    lines = Path(path).read_text().splitlines()
    meta = dict(ln[2:].split(":", 1) for ln in lines if ln.startswith("# ") and ":" in ln)
    meta = {k.strip(): v.strip() for k, v in meta.items()}
    rows = [ln.split(",") for ln in lines if ln and not ln.startswith("#")]
    cols: dict = {}
    for i, name in enumerate(rows[0]):
        values = [r[i] for r in rows[1:]]
        try:
            cols[name] = np.array(values, float)
        except ValueError:
            cols[name] = values
    return meta, cols


def vector(text: str) -> np.ndarray:
    return np.array([float(v) for v in text.split(",")])


def ballbar_template(path) -> dict:
    """The commanded rows of a rotacal-ballbar/1 session template (`design ballbar --separate
    ... -o added.ngc` writes added.csv) as refsim's poses.ballbar_single_setup gives them."""
    meta, c = read_template(path)
    return {
        "test": [str(t) for t in c["test"]],
        "time": c["time"],
        "xyz": np.stack([c["X"], c["Y"], c["Z"]], axis=1),
        "angles_deg": np.stack([c[k] for k in list(c)[5:7]], axis=1),
        "pivot": vector(meta["pivot"]),
        "ballbar_length": float(meta["ballbar_length"]),
    }


def rtest_template(path) -> dict:
    """The commanded rows of a rotacal-rtest/1 session template (`design rtest --separate ...
    --session added.csv` writes it) as refsim's poses.rtest_grid gives them."""
    meta, c = read_template(path)
    return {
        "setup": [str(int(v)) if not isinstance(v, str) else v for v in c["setup"]],
        "time": c["time"],
        "xyz": np.stack([c["X"], c["Y"], c["Z"]], axis=1),
        "angles_deg": np.stack([c[k] for k in list(c)[2:4]], axis=1),
        "nests": {k[5:]: vector(v) for k, v in meta.items() if k.startswith("nest.")},
    }


def ballbar_from(tmp_path, machine, errors, effects, seed, template, name, rho=0.5, noise_um=0.5):
    """The test of a session template measured on the machine: the ballbar's pivot where it is,
    the nominal one moved by a set-up error."""
    rng = np.random.default_rng(seed)
    m = refsim.builtin(machine)
    actual = template["pivot"] + rng.normal(0, 10e-3, 3)
    model = refsim.Model(m, errors, effects)
    length = refsim.ballbar_lengths(
        model, actual, template["xyz"], np.radians(template["angles_deg"]), template["time"]
    )
    length = length + noise.ar1(template["test"], rho, noise_um * 1e-3, rng)
    path = writers.write_ballbar(tmp_path / name, m, template, length, noise_um=noise_um)
    return rotacal.load(path), path


def rtest(tmp_path, machine, errors, effects, seed, rho=0.5, noise_um=0.5, pattern=None, name=None):
    """refsim's tilt x C grid with two nests, or the poses of `pattern` (rtest_template); the
    probe zeros are the session's own."""
    rng = np.random.default_rng(seed)
    m = refsim.builtin(machine)
    s = pattern if pattern is not None else poses.rtest_grid(m)
    d = refsim.rtest_displacements(
        refsim.Model(m, errors, effects),
        s["nests"],
        s["setup"],
        s["xyz"],
        np.radians(s["angles_deg"]),
        s["time"],
    )
    d = d + np.stack([noise.ar1(s["setup"], rho, noise_um * 1e-3, rng) for _ in range(3)], axis=1)
    d = d + np.array([0.2, -0.1, 0.05])
    path = writers.write_rtest(
        tmp_path / (name or f"rtest_{machine}_{seed}.csv"), m, s, d, noise_um=noise_um
    )
    return rotacal.load(path), path
