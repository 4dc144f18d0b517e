#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Headless [DISPLAY] program for rotacal-kins-sim.ini (tests/python/test_linuxcnc_rotacal_kins.py).

For each model of plan.json (switchkins type k = the k-th blob rotacal-kins loaded), it sets
motion.switchkins-type and rotacal-kins' pins (tool-offset, y1, y2) with halcmd, then
- in joint mode jogs every joint to each commanded joint position (JOG_INCREMENT from where it
  stands) and reads the joints and the world position motion computes from them with
  kinematicsForward (the feedback: POSITION_FEEDBACK = ACTUAL);
- in MDI (world coordinates, through kinematicsInverse) moves with G0 to each world pose and
  reads the joints and the world position again.
It writes everything to rotacal_kins.json (a failure: {"error": ...}, exit 1).
"""

import json
import os
import subprocess
import time
from pathlib import Path

import linuxcnc

from lcnc_display import WAIT, Machine, run

LETTERS = "XYZABC"


def setp(pin, value):
    subprocess.run(["halcmd", "setp", pin, repr(float(value))], check=True, timeout=WAIT)


def settle(m):
    """In position and idle; a few more servo periods so the feedback is the last command's."""
    s = m.s
    m.wait_for("in position", lambda: s.inpos and s.interp_state == linuxcnc.INTERP_IDLE)
    time.sleep(0.02)
    m.poll()
    return {
        "joints": list(s.joint_actual_position[: s.joints]),
        "joints_cmd": [j["output"] for j in s.joint[: s.joints]],
        "world": list(s.actual_position[:6]),
    }


def joint_mode(m):
    m.set_mode(linuxcnc.MODE_MANUAL)
    m.c.teleop_enable(0)
    m.c.wait_complete(WAIT)
    m.wait_for("joint mode", lambda: m.s.motion_mode == linuxcnc.TRAJ_MODE_FREE)


def jog_to(m, target):
    for j, v in enumerate(target):
        m.poll()
        step = v - m.s.joint[j]["output"]
        if step != 0.0:
            m.c.jog(linuxcnc.JOG_INCREMENT, True, j, 5000.0, step)
            m.wait_for(f"joint {j} at {v}", lambda: m.s.joint[j]["inpos"] and m.s.inpos)


def lcnc_cpu_seconds():
    """CPU seconds LinuxCNC's processes (which leave the test's process tree) have used so far:
    the cost of a run, reported by the test."""
    total = 0.0
    for p in Path("/proc").iterdir():
        try:
            stat = (p / "stat").read_text() if p.name.isdigit() else ""
        except OSError:
            continue
        if stat and stat[stat.index("(") + 1 : stat.rindex(")")] in (
            "rtapi_app",
            "milltask",
            "linuxcncsvr",
            "io",
        ):
            fields = stat[stat.rindex(")") + 2 :].split()
            total += (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    return total


def main():
    plan = json.load(open("plan.json"))
    m = Machine()
    m.bring_up()
    out = {"models": []}
    for k, p in enumerate(plan["models"]):
        joint_mode(m)
        setp("motion.switchkins-type", k)
        for pin in ("tool-offset", "y1", "y2"):
            setp(f"rotacal-kins.{pin}", p[pin])
        time.sleep(0.05)
        res = {"joint_moves": [], "world_moves": []}
        for target in p["joints"]:
            jog_to(m, target)
            res["joint_moves"].append(settle(m))
        m.set_mode(linuxcnc.MODE_MDI)
        m.mdi("G21 G90 G17 G40 G49 G54 G94")
        m.mdi("M66 E0 L0")  # the interpreter takes the position of the switched kinematics
        m.poll()
        if m.s.motion_mode != linuxcnc.TRAJ_MODE_COORD:
            raise RuntimeError(f"not in world mode: motion_mode={m.s.motion_mode}")
        for pose in p["world"]:
            m.mdi("G0 " + " ".join(f"{a}{v:.6f}" for a, v in zip(LETTERS, pose)))
            res["world_moves"].append(settle(m))
        out["models"].append(res)
    out["lcnc_cpu_s"] = lcnc_cpu_seconds()
    return out


if __name__ == "__main__":
    run(main, "rotacal_kins.json")
