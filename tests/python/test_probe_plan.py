# SPDX-License-Identifier: BSD-3-Clause
"""`rotacal plan probe` through LinuxCNC's own interpreter, and `rotacal import probe` of its log.

`rs274 -t tool.tbl -g probe.ngc` (linuxcnc-uspace; test_linuxcnc.run_rs274) interprets the program stand-alone and prints
its canonical commands: STRAIGHT_TRAVERSE / STRAIGHT_FEED / STRAIGHT_PROBE(x, y, z, a, b, c) and
LOG("text") with #5061..#5063 substituted (stand-alone, a probe move "latches" at its target).
The moves are checked against the reference simulator's nominal machine (tests/reference/refsim):
every probing move lies on the line through the sphere's nominal centre along its approach
direction, and no other move, nor any turn of the rotary axes, comes within the trigger radius of
the sphere. Then: plan -> latched points of a machine with errors by refsim -> a log in LinuxCNC's
LOG format -> import -> identify, every location error within 3 sigma.
"""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
import refsim  # noqa: E402
from refsim import noise  # noqa: E402
from refsim import poses as refposes  # noqa: E402

import rotacal  # noqa: E402
from conftest import run_cli as run  # noqa: E402
from test_linuxcnc import RS274, run_rs274  # noqa: E402  (the interpreter's canonical commands)

R = 0.5 * (25.0 + 6.0)  # trigger radius of the default sphere and stylus
SLOT = {"A": 3, "B": 4, "C": 5}


def nominal_centre(machine: str, angles_deg, sphere=(150.0, 0.0, 80.0)) -> np.ndarray:
    """The sphere's nominal centre in machine axes at a pose (tilt, rotary; deg) (refsim, as in its
    probe_touches)."""
    nominal = refsim.Model(machine).nominal()
    i_tilt, i_rot = refposes.rotary_roles(refsim.load_machine(machine))
    a = np.zeros((1, 2))
    a[0, i_tilt], a[0, i_rot] = np.radians(np.ravel(angles_deg))  # refsim's axis order
    c = nominal.p_table(np.atleast_2d(np.asarray(sphere, float)), a, np.zeros(1))
    return nominal.commanded_xyz(c, a)[0]


def segment_distance(c, a, b) -> float:
    ab = b - a
    t = 0.0 if ab @ ab == 0 else float(np.clip((c - a) @ ab / (ab @ ab), 0.0, 1.0))
    return float(np.linalg.norm(a + t * ab - c))


RS274_MISSING = (
    "rs274 (LinuxCNC stand-alone interpreter) not on PATH: apt-get install linuxcnc-uspace"
)


def check_in_rs274(tmp_path, machine: str, ngc: Path, plan, sphere=(150.0, 0.0, 80.0)) -> None:
    """The program through rs274 against refsim's nominal geometry: every probing move on the line
    through the sphere's nominal centre along the plan's direction, from outside to inside the
    trigger sphere; no other move and no turn of the rotary axes within it (turns 10 mm clear);
    the LOG lines numbered as the plan's poses and touches, with the latched position."""
    tilt, rot = machine[0], "C"
    canon = run_rs274(ngc.read_text(), tmp_path)
    assert canon[[n for n, _ in canon].index("LOGOPEN")][1] == '"rotacal_probe.log"'
    pos, probes, logs, after_probe = None, [], [], False
    cache = {}
    for name, args in canon:
        if name == "LOG":
            logs.append(args.strip('"').split())
            continue
        if name not in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "STRAIGHT_PROBE"):
            continue
        p = np.array([float(v) for v in args.split(",")])
        if pos is not None:
            ang0 = (pos[SLOT[tilt]], pos[SLOT[rot]])
            ang1 = (p[SLOT[tilt]], p[SLOT[rot]])
            if ang0 != ang1:  # a turn: the tool stays put, the sphere moves under it
                assert np.allclose(p[:3], pos[:3])
                for f in np.linspace(0.0, 1.0, 181):
                    a = (ang0[0] + f * (ang1[0] - ang0[0]), ang0[1] + f * (ang1[1] - ang0[1]))
                    assert np.linalg.norm(p[:3] - nominal_centre(machine, a, sphere)) > R + 10.0, (
                        a,
                        p,
                    )
            else:
                c = cache.setdefault(ang1, nominal_centre(machine, ang1, sphere))
                if name == "STRAIGHT_PROBE":
                    probes.append((pos[:3], p[:3], c, ang1))
                elif not after_probe:
                    assert segment_distance(c, pos[:3], p[:3]) > R, (name, pos, p)
        after_probe = name == "STRAIGHT_PROBE"
        pos = p
    n = np.asarray(plan.n)
    assert len(probes) == len(plan) == len(logs)
    for k, (start, end, c, ang) in enumerate(probes):
        assert np.allclose(ang, np.asarray(plan.angles_deg)[k], atol=1e-4)
        d = (end - start) / np.linalg.norm(end - start)
        assert np.allclose(d, n[k], atol=1e-4)  # along the approach direction...
        assert segment_distance(c, start - 100 * d, end + 100 * d) < 1e-3  # ...through the centre
        assert (
            np.linalg.norm(start - c) > R + 1.0 and np.linalg.norm(end - c) < R - 1.0
        )  # outside -> inside
        assert [int(v) for v in logs[k][:2]] == log_numbers(plan)[k]
        assert np.allclose(
            [float(v) for v in logs[k][2:]], end, atol=1e-5
        )  # #5061..#5063 of the latch


def log_numbers(plan) -> list:
    """[pose number, touch number] of each row of the plan, as the program logs them."""
    out, last, touch = [], None, 0
    for pose in plan.poses:
        touch = 1 if pose != last else touch + 1
        last = pose
        out.append([int(pose), touch])
    return out


@pytest.mark.skipif(RS274 is None, reason=RS274_MISSING)
@pytest.mark.parametrize("machine", ["AC-trt", "BC-trt"])
def test_the_probing_program_runs_in_rs274_on_the_reference_geometry(tmp_path, machine):
    ngc, template = tmp_path / "probe.ngc", tmp_path / "plan.csv"
    r = run("plan", "probe", "--machine", machine, "--session", template, "-o", ngc)
    assert r.returncode == 0, r.stderr
    plan = rotacal.load(template)
    assert len(plan) == 120 and log_numbers(plan)[:6] == [
        [1, 1],
        [1, 2],
        [1, 3],
        [1, 4],
        [1, 5],
        [2, 1],
    ]
    check_in_rs274(tmp_path, machine, ngc, plan)


@pytest.mark.skipif(RS274 is None, reason=RS274_MISSING)
def test_the_designed_program_runs_in_rs274(tmp_path):
    """`design probe --json` -> `plan probe --design`: each touch along its own direction, the
    sphere where the design puts it (B-head-C-table: moved out on the table), through rs274."""
    machine = "B-head-C-table"
    r = run("design", "probe", "--machine", machine, "--json")
    assert r.returncode == 0, r.stderr
    design = tmp_path / "design.json"
    design.write_text(r.stdout)
    d = json.loads(r.stdout)
    ngc, template = tmp_path / "probe.ngc", tmp_path / "plan.csv"
    r = run(
        "plan", "probe", "--machine", machine, "--design", design, "--session", template, "-o", ngc
    )
    assert r.returncode == 0, r.stderr
    plan = rotacal.load(template)
    assert len(plan) == d["touches"] == 120
    assert np.allclose(plan.sphere, d["sphere"]) and not np.allclose(
        d["sphere"], [150.0, 0.0, 80.0]
    )
    dirs = np.concatenate([np.asarray(x) for x in d["best"]["pose_directions"]])
    assert np.allclose(
        np.asarray(plan.n), dirs / np.linalg.norm(dirs, axis=1, keepdims=True), atol=1e-9
    )
    check_in_rs274(tmp_path, machine, ngc, plan, d["sphere"])
    r = run("plan", "probe", "--machine", machine, "--design", design, "--poses", "0,0", "-o", ngc)
    assert r.returncode == 3 and "--design" in r.stderr


def test_other_dialects_and_limits_are_refused(tmp_path):
    out = tmp_path / "p.ngc"
    for dialect in ("heidenhain", "siemens", "fanuc"):
        r = run("plan", "probe", "--dialect", dialect, "-o", out)
        assert (
            r.returncode == 3 and "no checkable probing words" in r.stderr and dialect in r.stderr
        )
    r = run("plan", "probe", "--machine", "B-head-C-table", "--poses", "0,0;-150,0", "-o", out)
    assert r.returncode == 3 and "outside the axis limits" in r.stderr
    r = run("plan", "probe", "--sphere", "150,0,380", "-o", out)
    assert r.returncode == 3 and "travel" in r.stderr
    r = run("plan", "probe", "--length", "150", "-o", out)
    assert r.returncode == 3 and "--length" in r.stderr
    r = run("plan", "ballbar", "--sphere", "1,2,3", "-o", out)
    assert r.returncode == 3 and "--sphere belong to plan probe" in r.stderr
    assert not out.exists()


def write_linuxcnc_log(path: Path, plan, latched: np.ndarray) -> None:
    """What (LOG,pose touch #5061 #5062 #5063) writes: the parameters as %f."""
    lines = [
        f"{plan.pose_names[k // 5]} {k % 5 + 1} {x:f} {y:f} {z:f}"
        for k, (x, y, z) in enumerate(latched)
    ]
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("machine,seed", [("AC-trt", 31), ("BC-trt", 32)])
def test_plan_log_import_identify_within_3_sigma(tmp_path, machine, seed):
    poses = "0,0;0,45;0,90;0,135;0,180;0,225;0,270;0,315;-60,0;-30,0;30,0;60,0;-45,90;45,90;-45,270;45,270"
    ngc, template = tmp_path / "probe.ngc", tmp_path / "plan.csv"
    r = run(
        "plan", "probe", "--machine", machine, "--poses", poses, "--session", template, "-o", ngc
    )
    assert r.returncode == 0, r.stderr
    plan = rotacal.load(template)
    assert len(plan) == 16 * 5
    rng = np.random.default_rng(seed)
    names = refsim.builtin(machine).error_names()
    errors = {
        nm: (rng.normal(0, 0.03) if k % 4 < 2 else rng.normal(0, 4e-5))
        for k, nm in enumerate(names)
    }
    sphere_actual = np.array([150.0, 0.0, 80.0]) + np.array([0.021, -0.013, 0.008])
    model = refsim.Model(machine, errors, {})
    latched = refsim.probe_touches(
        model,
        sphere_actual,
        np.array([150.0, 0.0, 80.0]),
        25.0,
        6.0,
        np.asarray(plan.n),
        np.radians(np.asarray(plan.angles_deg)),
        np.asarray(plan.time),
    )
    latched = latched + np.column_stack(
        [noise.ar1(["t"] * len(plan), 0.3, 0.5e-3, rng) for _ in range(3)]
    )
    log, session = tmp_path / "rotacal_probe.log", tmp_path / "session.csv"
    write_linuxcnc_log(log, plan, latched)
    r = run("import", "probe", log, "--plan", template, "-o", session)
    assert r.returncode == 0, r.stderr
    s = rotacal.load(session)
    assert np.allclose(np.asarray(s.xyz), latched, atol=1e-6) and np.array_equal(
        np.asarray(s.n), np.asarray(plan.n)
    )
    r = run("identify", session, "--json", "--no-budget")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    bad = [
        f"{k}: {d['location_errors'][k]} truth {v}"
        for k, v in errors.items()
        if abs(d["location_errors"][k]["value"] - v) > 3 * d["location_errors"][k]["std"]
    ]
    assert not bad, bad
    # A log with a touch missing is refused naming the line; the session is not written.
    lines = log.read_text().splitlines()
    log.write_text("\n".join(lines[:3] + lines[4:]) + "\n")
    other = tmp_path / "other.csv"
    r = run("import", "probe", log, "--plan", template, "-o", other)
    assert r.returncode == 3 and "rotacal_probe.log:4" in r.stderr and not other.exists()
