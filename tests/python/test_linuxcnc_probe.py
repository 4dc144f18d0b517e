# SPDX-License-Identifier: BSD-3-Clause
"""A real client of the probing program (issue 31, item 6): LinuxCNC runs it on a simulated
machine whose probe input is the simulated contact of the stylus with the sphere.

`rotacal plan probe` writes the G38.2 program and its session template; a headless LinuxCNC
runs it: the start of xyzac-trt-sim.ini that test_linuxcnc_kins.py shares, switched to
xyzac-trt-kins' identity type (as probe-sim.ini's trivkins: the program's machine axes are the
joints). The probe (tests/linuxcnc/probe.hal, loaded for the run) is a realtime HAL chain that compares the joints' X, Y, Z
with the sphere every servo period and drives motion.probe-input; a userspace component
(probe_contact.py) places the sphere where the simulated machine holds it at the current A, C,
with the independent reference simulator (tests/reference/refsim, no rotacal import): Flynn et
al.'s Table 2 location errors (from ../shared/data), a sphere set-up error, and a trigger
radius that scatters from touch to touch (AR(1), 0.5 um). LinuxCNC's log of the latched
#5061-#5063 is read back with `rotacal import probe` and identified with `rotacal identify`:
every location error within 3 sigma of the simulated machine's. On the same run: every touch
latched on its commanded line, at most one servo period's travel past the contact (the
pretravel, measured); no contact outside the G38.2 moves (counted in realtime; LinuxCNC stops
the program at one itself, as a program with a G1 into the sphere shows) and the traverses clear
of the sphere (polled).
"""

import json
import re
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from conftest import run_cli
from linuxcnc_session import CONFIG, hal_commands, requires_linuxcnc, shared

REFSIM = Path(__file__).resolve().parents[1] / "reference"
sys.path.insert(0, str(REFSIM))
import refsim  # noqa: E402
from refsim import noise  # noqa: E402

LINUXCNC_STARTS = {"xyzac-trt"}  # linuxcnc_session.shared

SERVO_PERIOD_S = 1e-3  # tests/linuxcnc/common.inc, [EMCMOT]SERVO_PERIOD
PROBE_FEED = 30.0  # mm/min: one servo period's travel is 0.5 um
POSITIONING_FEED = 6000.0  # mm/min, the G1 moves to and from each G38.2
APPROACH_MM = 0.3  # each G38.2 starts this far outside the nominal trigger sphere
SPHERE = (150.0, 0.0, 80.0)
SPHERE_D, STYLUS_D = 25.0, 6.0
SPHERE_ERROR_MM = 0.02  # 1 sigma per axis: the sphere set where the cycle's first touches found it
POSES = [(0, 0), (0, 120), (0, 240), (-90, 0), (45, 0), (90, 0)]  # A, C deg
NOISE_UM, RHO = 0.5, 0.5  # trigger radius, touch to touch
RUN_TIMEOUT = (
    240  # s, the display's bound (the program ran 80 s at F10 at a load average of 12, 44 s at F30)
)


def rotacal_cli(*args):
    r = run_cli(*args)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    return r.stdout


def probing_moves(program: str):
    """(start, target) of every G38.2 of the program: the position before it (modal X, Y, Z
    of the G0/G1 words) and its own words."""
    pos, moves = {}, []
    for line in program.splitlines():
        m = re.match(r"^(G0|G1|G38\.2) ", line)
        if not m:
            continue
        words = {k: float(v) for k, v in re.findall(r" ([XYZ])(-?[0-9.]+)", line)}
        if m.group(1) == "G38.2":
            moves.append((np.array([pos[k] for k in "XYZ"]), np.array([words[k] for k in "XYZ"])))
        pos.update(words)
    return moves


def sphere_centre(model, a_deg, c_deg, q):
    """Joint X, Y, Z of the stylus tip at the sphere's actual centre, machine at A, C (refsim)."""
    by_name = {"A": a_deg, "C": c_deg}
    angles = np.radians([[by_name[n] for n in model.machine.axis_names]])
    t = np.zeros(1)
    return model.p_table(q[None, :], angles, t)[0] - model.p_tool(np.zeros((1, 3)), angles, t)[0]


def test_plan_probe_feeds_and_approach(tmp_path):
    # The options of the program (no LinuxCNC needed): each G38.2 starts --approach outside the
    # trigger sphere on the nominal machine and runs at --probe-feed, the G1 moves at
    # --positioning-feed; plan ballbar refuses them.
    ngc = tmp_path / "p.ngc"
    rotacal_cli(
        "plan",
        "probe",
        "--poses",
        "0,0;0,90",
        "--approach",
        0.25,
        "--probe-feed",
        7.5,
        "--positioning-feed",
        4000,
        "-o",
        ngc,
    )
    text = ngc.read_text()
    r = 0.5 * (25.0 + 6.0)  # the defaults: sphere 150, 0, 80; D 25; d 6
    centres = {
        0: np.array([150.0, 0.0, 80.0]),
        90: np.array([0.0, 150.0, 80.0]),
    }  # C turns the table (+Z)
    moves = probing_moves(text)
    assert len(moves) == 10
    for k, (start, target) in enumerate(moves):
        assert abs(np.linalg.norm(start - centres[0 if k < 5 else 90]) - (r + 0.25)) < 2e-4, (
            k,
            start,
        )
    assert re.findall(r"^G38\.2 .* F(\S+)$", text, re.M) == ["7.5"] * 10
    assert set(re.findall(r"^G1 .* F(\S+)$", text, re.M)) == {"4000.0"}
    bad = run_cli("plan", "ballbar", "--probe-feed", "7", "-o", tmp_path / "b.ngc")
    assert bad.returncode != 0 and "--probe-feed" in bad.stderr


def simulated_machine(shared_data):
    """(location errors, sphere's actual centre, trigger radius deviation per touch (mm)) of the
    simulated machine: Table 2 errors (../shared/data), a sphere set-up error, AR(1) noise."""
    errors = json.loads((shared_data / "probe_ac_table2.truth.json").read_text())["errors"]
    rng = np.random.default_rng(31)
    sphere_actual = np.array(SPHERE) + rng.normal(0.0, SPHERE_ERROR_MM, 3)
    eps = noise.ar1(
        ["touch"] * 5 * len(POSES), RHO, NOISE_UM * 1e-3, rng
    )  # five directions per pose
    return errors, sphere_actual, eps


def plan(tmp_path, poses, log):
    """`rotacal plan probe` of `poses`: (program text, session template path)."""
    # The stylus as calibrated on the machine, at the same feed: the mean pretravel (half a
    # period's travel) is part of its effective radius (docs/probe.md, "A real client").
    stylus_calibrated = STYLUS_D - PROBE_FEED / 60.0 * SERVO_PERIOD_S
    ngc, template = tmp_path / "probe.ngc", tmp_path / "template.csv"
    rotacal_cli(
        "plan",
        "probe",
        "--machine",
        "AC-trt",
        "--sphere",
        ",".join(map(str, SPHERE)),
        "--sphere-diameter",
        SPHERE_D,
        "--stylus-diameter",
        f"{stylus_calibrated:.7f}",
        "--poses",
        ";".join(f"{a},{c}" for a, c in poses),
        "--approach",
        APPROACH_MM,
        "--probe-feed",
        PROBE_FEED,
        "--positioning-feed",
        POSITIONING_FEED,
        "--log-file",
        log,
        "-o",
        ngc,
        "--session",
        template,
    )
    return ngc.read_text(), template


def run_probe(run_dir, program, errors, sphere_actual, eps):
    """LinuxCNC runs `program` on the simulated machine: (display's result, probe's record)."""
    truth = {
        "refsim": str(REFSIM),
        "machine": "AC-trt",
        "errors": errors,
        "sphere_actual": sphere_actual.tolist(),
        "sphere_diameter": SPHERE_D,
        "stylus_diameter": STYLUS_D,
        "trigger_noise_mm": eps.tolist(),
        "record": str(run_dir / "contact.json"),
    }
    # The shared start of xyzac-trt-kins (test_linuxcnc_kins.py), its switchkins type 1 the
    # identity (probe-sim.ini's trivkins); probe.hal loaded for this run and taken out after it.
    start = shared("xyzac-trt", "xyzac-trt-sim.ini", {"pins.hal": ""})
    chain = (
        (CONFIG / "probe.hal")
        .read_text()
        .replace("loadusr -Wn probe-sim /usr/bin/python3 probe_contact.py truth.json", "")
    )
    cmds = hal_commands(chain)
    existing = {f"J{j}-pos-fb" for j in range(5)}  # sim.hal's signals
    cleanup = [["unload", "probe-sim"]]
    cleanup += [["unloadrt", c[1]] for c in cmds if c[0] == "loadrt"]
    cleanup += [["delsig", c[1]] for c in cmds if c[0] == "net" and c[1] not in existing]
    contact = [
        "loadusr", "-Wn", "probe-sim", "/usr/bin/python3",
        str(start.run_dir / "probe_contact.py"), str(run_dir / "truth.json"),
    ]  # fmt: skip
    served = {
        "identity_type": 1,
        "timeout_s": RUN_TIMEOUT,
        "hal": [contact] + cmds,
        "cleanup": cleanup,
    }
    files = {
        "probe.ngc": program,
        "truth.json": json.dumps(truth),
        "served.json": json.dumps(served),
    }
    result = start.job("probe_display", run_dir, files, "result.json", RUN_TIMEOUT + 30)
    print(f"LinuxCNC: program {result['program_s']:.1f} s, session {result['elapsed']:.1f} s")
    return result, json.loads((run_dir / "contact.json").read_text())


@requires_linuxcnc
def test_a_contact_outside_probing_is_counted(shared_data, tmp_path):
    # The check of the next test can fail: one pose's program with a G1 (not G38.2) into the
    # sphere after the first touch, from its start to its target, is a stray contact.
    errors, sphere_actual, eps = simulated_machine(shared_data)
    run_dir = tmp_path / "lcnc"
    program, _ = plan(tmp_path, POSES[:1], run_dir / "probe.log")
    lines = program.splitlines()
    first = next(i for i, line in enumerate(lines) if line.startswith("G38.2 "))
    retract = first + 2  # G38.2, (LOG,...), then the G1 back to the start
    assert lines[retract].startswith("G1 X")
    crash = re.sub(r" F\S+$", f" F{POSITIONING_FEED:.1f}", lines[first].replace("G38.2 ", "G1 ", 1))
    lines[retract + 1 : retract + 1] = [crash, lines[retract]]
    # LinuxCNC stops the program itself, and the realtime count has it.
    with pytest.raises(AssertionError, match="Probe tripped during non-probe move"):
        run_probe(run_dir, "\n".join(lines) + "\n", errors, sphere_actual, eps)
    contact = json.loads((run_dir / "contact.json").read_text())
    assert contact["strays"] == 1 and len(contact["touches"]) == 2, contact


@requires_linuxcnc
def test_linuxcnc_runs_the_probing_program_and_the_log_identifies_the_machine(
    shared_data, tmp_path
):
    t_start = time.monotonic()
    errors, sphere_actual, eps = simulated_machine(shared_data)
    n = len(eps)
    period_travel = PROBE_FEED / 60.0 * SERVO_PERIOD_S  # mm
    run_dir = tmp_path / "lcnc"
    log = run_dir / "probe.log"
    program, template = plan(tmp_path, POSES, log)
    assert program.count("G38.2 ") == n and f"F{PROBE_FEED:.1f}" in program
    result, contact = run_probe(run_dir, program, errors, sphere_actual, eps)

    # Every touch a G38.2 contact, none elsewhere; the traverses clear of the sphere.
    assert result["touches"] == n and len(contact["touches"]) == n, (
        result,
        len(contact["touches"]),
    )
    assert result["strays"] == 0 and contact["strays"] == 0, (
        "the stylus touched the sphere outside a G38.2 move"
    )
    assert all(t["armed"] for t in contact["touches"]), (
        "a touch began before its trigger radius was set"
    )
    clearance = contact["clearance_mm"]
    assert min(clearance.values()) > 0.0, clearance
    print(
        "smallest polled clearance outside the touches (mm): "
        + ", ".join(f"{k} {v:.3f}" for k, v in sorted(clearance.items()))
    )
    # Within the machine's travel (its built-in description) and the poses' A, C all along.
    travel = json.loads(rotacal_cli("machines", "show", "AC-trt", "--json"))["description"][
        "travel_mm"
    ]
    extent = contact["extent"]
    for k, (lo, hi) in zip("xyz", travel):
        assert lo <= extent[k][0] <= extent[k][1] <= hi, (k, extent[k], (lo, hi))
    for k, i in (("a", 0), ("c", 1)):
        angles = [p[i] for p in POSES] + [0.0]  # the machine starts homed at 0
        assert min(angles) - 1e-9 <= extent[k][0] <= extent[k][1] <= max(angles) + 1e-9, (
            k,
            extent[k],
        )
    print(
        "polled extent: " + ", ".join(f"{k} {lo:.3f}..{hi:.3f}" for k, (lo, hi) in extent.items())
    )

    # Each latched position on its commanded line, past the contact by at most one period's travel.
    model = refsim.Model("AC-trt", errors)
    r = 0.5 * (SPHERE_D + STYLUS_D)
    rows = [line.split() for line in log.read_text().splitlines() if line.strip()]
    assert len(rows) == n
    pretravel = []
    for k, ((start, target), row, rec) in enumerate(
        zip(probing_moves(program), rows, contact["touches"])
    ):
        a, c = POSES[k // 5]
        centre = sphere_centre(model, a, c, sphere_actual)
        assert (
            np.abs(centre - rec["centre"]).max() < 1e-9
            and abs(rec["radius"] - (r + eps[k])) < 1e-12
        )
        u = (target - start) / np.linalg.norm(target - start)
        w = start - centre
        lam_contact = -w @ u - np.sqrt(
            (w @ u) ** 2 - w @ w + (r + eps[k]) ** 2
        )  # entry into the trigger sphere
        latched = np.array([float(v) for v in row[2:]])
        lam = (latched - start) @ u
        assert np.linalg.norm(start + lam * u - latched) < 2e-6, (
            k,
            row,
        )  # on the line (log: 6 decimals)
        pretravel.append(lam - lam_contact)
    pretravel = np.array(pretravel)
    print(
        f"pretravel over {n} touches: mean {pretravel.mean() * 1e3:.4f} um, max {pretravel.max() * 1e3:.4f} um, "
        f"min {pretravel.min() * 1e3:.4f} um (one servo period at F{PROBE_FEED:g}: {period_travel * 1e3:.4f} um)"
    )
    assert pretravel.min() > -2e-6 and pretravel.max() < period_travel + 2e-6
    poll = contact["poll_s"]
    print(
        f"userspace loop: mean {poll['mean'] * 1e3:.2f} ms, max {poll['max'] * 1e3:.1f} ms, "
        f"{poll['over_10ms']} periods over 10 ms: a trigger decided there would latch up to "
        f"{poll['max'] * PROBE_FEED / 60.0 * 1e3:.1f} um late"
    )

    # The log read back and identified: every location error within 3 sigma of the machine's.
    session = tmp_path / "probe.csv"
    rotacal_cli("import", "probe", log, "--plan", template, "-o", session)
    d = json.loads(rotacal_cli("identify", session, "--json"))
    fitted = d["location_errors"]
    assert set(fitted) == set(errors)
    for name, true in errors.items():
        p = fitted[name]
        assert p["value"] is not None and p["std"] is not None, name
        z = (p["value"] - true) / p["std"]
        print(f"  {name}: {p['value']:+.7f} +- {p['std']:.7f}, truth {true:+.7f} ({z:+.2f} sigma)")
        assert abs(z) < 3.0, (name, p, true)
    # The check can fail: the nominal machine (no errors) is far outside 3 sigma.
    assert max(abs(fitted[k]["value"]) / fitted[k]["std"] for k in errors) > 100
    print(f"residual RMS {d['residual_rms_um']:.3f} um; test {time.monotonic() - t_start:.1f} s")
