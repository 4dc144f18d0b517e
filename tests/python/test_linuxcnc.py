# SPDX-License-Identifier: BSD-3-Clause
"""The linuxcnc program through LinuxCNC's own interpreter.

`rs274 -t tool.tbl -g program.ngc` (Debian package linuxcnc-uspace) interprets the program
stand-alone and prints the canonical machining commands it would send to the motion
controller: STRAIGHT_TRAVERSE / STRAIGHT_FEED(x, y, z, a, b, c), ARC_FEED(first_end,
second_end, first_axis, second_axis, rotation, axis_end_point, a, b, c), SET_FEED_RATE(units
per minute, converted from G93 inverse time), SELECT_PLANE. Those moves are compared with the
planned toolpath (every sample, 1e-4 mm / 1e-4 deg) and with the ballbar geometry computed here
independently (|tool - pivot| = L0 at every block end and all along the arcs), and the block
times with the plan's time stamps.
"""

import json
import math
import re
import shutil
import subprocess

import numpy as np
import pytest

import rotacal
from conftest import truth

RS274 = shutil.which("rs274")
pytestmark = pytest.mark.skipif(
    RS274 is None,
    reason="rs274 (LinuxCNC stand-alone G-code interpreter) not on PATH: "
    "apt-get install linuxcnc-uspace",
)

TOL = 1e-4  # mm and deg: the program carries 4 decimals, rs274 prints 4
CANON = re.compile(r"^\s*\d+\s+N\.+\s+([A-Z_0-9]+)\((.*)\)\s*$")
# Canonical plane -> (first, second, normal) axis indices of ARC_FEED.
PLANES = {"CANON_PLANE_XY": (0, 1, 2), "CANON_PLANE_YZ": (1, 2, 0), "CANON_PLANE_XZ": (2, 0, 1)}


def rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


SLOT = {"A": 3, "B": 4, "C": 5}  # rs274 prints x, y, z, a, b, c


def rodrigues(n, a):
    n = np.asarray(n, float) / np.linalg.norm(n)
    K = np.array([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
    return np.eye(3) + math.sin(a) * K + (1 - math.cos(a)) * K @ K


class Chain:
    """The nominal kinematics of formats.md ("Any 5-axis machine") written out here from the
    machine's description, independently of rotacal's: p_table = Rot(T1) Rot(T2) q,
    p_tool = (X, Y, Z) + Rot(H1) Rot(H2) t, each Rot about the axis line through its point."""

    def __init__(self, machine):
        d = json.loads(machine.description_json)
        self.table = [
            (np.array(a.get("point", [0, 0, 0]), float), np.array(a["direction"], float), a["name"])
            for a in d["table_axes"]
        ]
        self.head = [
            (np.array(a.get("point", [0, 0, 0]), float), np.array(a["direction"], float), a["name"])
            for a in d["head_axes"]
        ]
        self.t = np.array([0.0, 0.0, -(d["pivot_length"] + d["tool_length"])])

    @staticmethod
    def _turn(axes, p6, x):
        for p0, n, letter in reversed(axes):  # the outermost axis turns first
            x = p0 + rodrigues(n, math.radians(p6[SLOT[letter]])) @ (x - p0)
        return x

    def ballbar_length(self, p6, pivot):
        """|tool ball - pivot ball| at the rs274 pose p6 (x, y, z, a, b, c; mm, deg)."""
        p_tool = np.asarray(p6[:3]) + self._turn(self.head, p6, self.t)
        return np.linalg.norm(p_tool - self._turn(self.table, p6, pivot))


def run_rs274(text, tmp_path):
    """Canonical commands [(name, args)] of a program; any other output line is an error."""
    ngc = tmp_path / "ballbar.ngc"
    ngc.write_text(text)
    tbl = tmp_path / "tool.tbl"
    tbl.write_text("T1 P1 Z0 D0 ;ballbar tool cup\n")
    out = subprocess.run(
        [RS274, "-t", str(tbl), "-g", str(ngc)],
        capture_output=True,
        text=True,
        stdin=subprocess.DEVNULL,
        timeout=300,
    )
    canon = []
    for line in (out.stdout + out.stderr).splitlines():
        m = CANON.match(line)
        if m:
            canon.append((m.group(1), m.group(2)))
        elif line.strip() not in ("", "executing"):
            raise AssertionError(f"rs274: {line}")
    assert any(name == "PROGRAM_END" for name, _ in canon), "rs274 did not reach M2"
    return canon


def numbers(args):
    return [float(v) for v in args.replace(" ", ",").split(",") if v]


def canonical_moves(canon):
    """Approach point and feed moves: ('line'|'arc', start(6), end(6), feed, arc data)."""
    pos = np.zeros(6)
    approach = None
    plane = "CANON_PLANE_XY"
    feed = None
    moves = []
    for name, args in canon:
        if name == "SELECT_PLANE":
            plane = args.strip()
        elif name == "SET_FEED_RATE":
            feed = numbers(args)[0]
        elif name == "STRAIGHT_TRAVERSE":
            pos = np.array(numbers(args)[:6])
            approach = pos.copy()
        elif name == "STRAIGHT_FEED":
            end = np.array(numbers(args)[:6])
            moves.append(("line", pos, end, feed, None))
            pos = end
        elif name == "ARC_FEED":
            v = numbers(args)
            f, s, n = PLANES[plane]
            end = pos.copy()
            end[f], end[s], end[n] = v[0], v[1], v[5]
            end[3:6] = v[6:9]
            centre = np.zeros(3)
            centre[f], centre[s], centre[n] = v[2], v[3], pos[n]
            moves.append(("arc", pos, end, feed, (plane, centre, int(v[4]))))
            pos = end
    return approach, moves


def arc_angle(p, centre, plane, rotation, start):
    """Angle swept from `start` to `p` in the arc's direction, in [0, 2 pi)."""
    f, s, _ = PLANES[plane]
    a0 = math.atan2(start[s] - centre[s], start[f] - centre[f])
    a = math.atan2(p[s] - centre[s], p[f] - centre[f])
    return ((a - a0) if rotation > 0 else (a0 - a)) % (2 * math.pi)


def arc_points(start, centre, plane, rotation, sweep, k=64):
    f, s, _ = PLANES[plane]
    r = math.hypot(start[f] - centre[f], start[s] - centre[s])
    a0 = math.atan2(start[s] - centre[s], start[f] - centre[f])
    pts = []
    for t in np.linspace(0, sweep, k):
        a = a0 + (t if rotation > 0 else -t)
        p = start[:3].copy()
        p[f], p[s] = centre[f] + r * math.cos(a), centre[s] + r * math.sin(a)
        pts.append(p)
    return pts


def check_program(plan, text, tmp_path, actual_errors=None):
    """Assert that LinuxCNC runs `text` exactly along `plan`. Returns the numbers of line and
    arc blocks and the worst pose (mm, deg), ballbar length (mm) and block time (s) errors.

    The ballbar length is checked against the pivot as the machine carries it: the nominal
    table (rotations written out here), or a machine with `actual_errors` (rotacal.forward)."""
    machine = plan.setup.machine
    ac = machine == rotacal.MachineType.AC_trt
    tilt_slot, rot_slot = SLOT[machine.tilt_axis], SLOT[machine.rot_axis]
    chain = Chain(machine)
    pivot = np.asarray(plan.setup.pivot)
    L0 = plan.setup.ballbar_length
    # Planned poses as rs274 prints them: x, y, z, a, b, c (machine_axes: X, Y, Z, tilt, rotary).
    ax = plan.machine_axes
    P = np.zeros((len(ax), 6))
    P[:, :3] = ax[:, :3]
    P[:, tilt_slot] = ax[:, 3]
    P[:, rot_slot] = ax[:, 4]
    T = plan.time
    kinds = [plan.segments[i].kind.name for i in plan.segment_index]
    arc_kind = "arc_transition"

    def ballbar_length(p6):
        if actual_errors is None:
            if machine in (rotacal.MachineType.AC_trt, rotacal.MachineType.BC_trt):
                tilt, c = (
                    math.radians(p6[tilt_slot]),
                    math.radians(p6[5]),
                )  # Flynn's two tables, by hand
                return np.linalg.norm(p6[:3] - (rx(tilt) if ac else ry(tilt)) @ rz(c) @ pivot)
            return chain.ballbar_length(p6, pivot)
        assert not machine.has_head, "actual_errors: table machines only (rotacal.forward)"
        tilt, c = math.radians(p6[tilt_slot]), math.radians(p6[rot_slot])
        pivot_m = rotacal.forward(machine, actual_errors, np.array([[tilt, c]]), pivot[None, :])[0]
        return np.linalg.norm(p6[:3] - pivot_m)

    approach, moves = canonical_moves(run_rs274(text, tmp_path))
    assert approach is not None and np.abs(approach - P[0]).max() < TOL, (approach, P[0])
    j, t_prev = 1, T[0]
    n_lines = n_arcs = 0
    worst = {"pose": 0.0, "length": 0.0, "time": 0.0}
    for kind, start, end, feed, arc in moves:
        assert j < len(P), "the program moves beyond the plan"
        if kind == "line":
            n_lines += 1
            assert np.abs(end - P[j]).max() < TOL, (j, end, P[j])
            j_end, length = j, np.linalg.norm(end[:3] - start[:3])
        else:
            n_arcs += 1
            plane, centre, rotation = arc
            f, s, n = PLANES[plane]
            r = math.hypot(start[f] - centre[f], start[s] - centre[s])
            sweep = arc_angle(end, centre, plane, rotation, start) or 2 * math.pi
            # Planned points of the arc transition lie on this arc, in order along it.
            k, last = j, 0.0
            while k < len(P) and kinds[k] == arc_kind:
                p = P[k]
                assert abs(math.hypot(p[f] - centre[f], p[s] - centre[s]) - r) < TOL, (k, p)
                assert abs(p[n] - centre[n]) < TOL and np.abs(p[3:] - start[3:]).max() < TOL
                t = arc_angle(p, centre, plane, rotation, start)
                assert last < t <= sweep + 1e-6, (k, t, sweep)
                last = t
                k += 1
            if k > j and np.abs(end - P[k - 1]).max() < TOL:
                j_end = k - 1  # the arc's own end point was planned (a rotary move follows)
            else:
                assert np.abs(end - P[k]).max() < TOL, (k, end, P[k])  # next test's first point
                j_end = k
            length = r * sweep
            for q in arc_points(start, centre, plane, rotation, sweep):
                assert abs(ballbar_length(np.r_[q, start[3:]]) - L0) < TOL
        # The ballbar keeps L0 at every block end, and the block takes the planned time.
        assert abs(ballbar_length(end) - L0) < TOL, (j_end, end, ballbar_length(end))
        worst["pose"] = max(worst["pose"], np.abs(end - P[j_end]).max())
        worst["length"] = max(worst["length"], abs(ballbar_length(end) - L0))
        if length > 1e-6:
            dt_rs, dt_plan = 60.0 * length / feed, T[j_end] - t_prev
            assert abs(dt_rs - dt_plan) <= 1e-3 * dt_plan + 1e-4, (j_end, dt_rs, dt_plan)
            worst["time"] = max(worst["time"], abs(dt_rs - dt_plan))
        j, t_prev = j_end + 1, T[j_end]
    assert j == len(P), f"{len(P) - j} planned samples never reached"
    print(
        f"rs274: {n_lines} lines, {n_arcs} arcs; worst pose {worst['pose']:.2g}, "
        f"|L - L0| {worst['length']:.2g} mm, block time {worst['time']:.2g} s"
    )
    return n_lines, n_arcs


def test_default_ac_program_runs_the_plan(tmp_path):
    plan = rotacal.plan_ballbar_test()
    n_lines, n_arcs = check_program(plan, rotacal.write_nc_program(plan, "linuxcnc"), tmp_path)
    # Counted by hand in test_ballbar_nc_program.cpp: 2695 G1 blocks, 4 G2/G3 arcs.
    assert (n_lines, n_arcs) == (2695, 4)


def test_compensated_program_runs_the_plan(shared_data, tmp_path):
    t = truth(shared_data / "ballbar_ac_table2.csv")
    names = rotacal.location_error_names(rotacal.MachineType.AC_trt)
    errors = np.array([t["errors"][n] for n in names])
    plan = rotacal.plan_ballbar_test(identified=errors)
    text = rotacal.write_nc_program(plan, "linuxcnc")
    # On the Table 2 machine the compensated program keeps the ballbar at L0 (pivot at its
    # nominal place) ...
    assert check_program(plan, text, tmp_path, actual_errors=errors) == (2695, 4)
    # ... the nominal program does not, and the compensated one is not the nominal plan.
    nominal = rotacal.plan_ballbar_test()
    with pytest.raises(AssertionError):
        check_program(
            nominal, rotacal.write_nc_program(nominal, "linuxcnc"), tmp_path, actual_errors=errors
        )
    with pytest.raises(AssertionError):
        check_program(nominal, text, tmp_path)


@pytest.mark.parametrize(
    "machine,pivot,side,step",
    [
        (rotacal.MachineType.BC_trt, (0.0, 120.0, 60.0), rotacal.RadialSide.outside, 1.0),
        (rotacal.MachineType.AC_trt, (95.0, 40.0, 75.0), rotacal.RadialSide.inside, 2.5),
        (rotacal.MachineType.BC_trt, (-80.0, 60.0, 90.0), rotacal.RadialSide.inside, 3.0),
    ],
)
def test_other_layouts_run_the_plan(machine, pivot, side, step, tmp_path):
    setup = rotacal.BallbarSetup(
        machine=machine,
        pivot=np.array(pivot),
        radial_c_side=side,
        step_deg=step,
        ballbar_length=110.0,
    )
    plan = rotacal.plan_ballbar_test(setup)
    n_lines, n_arcs = check_program(plan, rotacal.write_nc_program(plan, "linuxcnc"), tmp_path)
    assert n_lines > 0


def test_the_check_catches_a_wrong_program(tmp_path):
    plan = rotacal.plan_ballbar_test()
    text = rotacal.write_nc_program(plan, "linuxcnc")
    lines = text.splitlines()
    # One coordinate 2e-4 mm off in the middle of radial_A.
    i = next(k for k, l in enumerate(lines) if l.startswith("(TEST radial_A")) + 90
    x = float(re.search(r" Y(-?[0-9.]+)", lines[i]).group(1))
    bad = lines.copy()
    bad[i] = re.sub(r" Y-?[0-9.]+", f" Y{x + 2e-4:.4f}", lines[i])
    with pytest.raises(AssertionError):
        check_program(plan, "\n".join(bad) + "\n", tmp_path)
    # An arc run the other way round (G2 for G3): its end is right, its path is not.
    bad = [l.replace("G17 G3", "G17 G2", 1) for l in lines]
    with pytest.raises(AssertionError):
        check_program(plan, "\n".join(bad) + "\n", tmp_path)
    # A block time off by 1 %.
    j = next(k for k, l in enumerate(lines) if l.startswith("(TEST axial_C")) + 10
    f = float(re.search(r" F([0-9.]+)", lines[j]).group(1))
    bad = lines.copy()
    bad[j] = re.sub(r" F[0-9.]+", f" F{f * 1.01:.4f}", lines[j])
    with pytest.raises(AssertionError):
        check_program(plan, "\n".join(bad) + "\n", tmp_path)
    # An interpreter error (unknown word) is an error, not silently ignored.
    with pytest.raises(AssertionError, match="rs274"):
        check_program(plan, text.replace("G93", "G93 Q7", 1), tmp_path)
