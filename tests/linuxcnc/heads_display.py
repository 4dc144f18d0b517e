#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Headless [DISPLAY] program for maxkins-sim.ini and 5axiskins-sim.ini
(tests/python/test_linuxcnc_heads.py).

After lcnc_display.Machine.bring_up, in MDI (world coordinates through the head kinematics:
motion is in coordinated mode once all joints are homed) it moves to every pose of poses.json,
[[x, y, z, b_deg, c_deg], ...], with G0. In position, it reads the joint positions (the module's
inverse kinematics of the commanded pose, after the simulated drives) and the world position
LinuxCNC reports from them (the module's forward kinematics of the joints), and writes both to
joints.json (a failure: {"error": ...}, exit 1).
"""

import json
import time

import linuxcnc

from lcnc_display import Machine, run


def main():
    poses = json.load(open("poses.json"))
    m = Machine()
    s = m.s
    m.bring_up()
    m.set_mode(linuxcnc.MODE_MDI)
    m.mdi("G21 G90 G17 G40 G49 G54 G94")
    m.poll()
    out = {"motion_mode": s.motion_mode, "moves": []}
    if s.motion_mode != linuxcnc.TRAJ_MODE_COORD:
        raise RuntimeError(f"motion not in world (coordinated) mode: motion_mode={s.motion_mode}")
    for x, y, z, b, cc in poses:
        m.mdi(f"G0 X{x:.6f} Y{y:.6f} Z{z:.6f} B{b:.6f} C{cc:.6f}")
        m.wait_for("in position", lambda: s.inpos and s.interp_state == linuxcnc.INTERP_IDLE)
        time.sleep(0.01)  # a few more servo periods: the feedback is settled
        m.poll()
        out["moves"].append(
            {
                "joints": list(s.joint_actual_position[: s.joints]),
                "joints_cmd": [j["output"] for j in s.joint[: s.joints]],
                "world": list(s.actual_position[:9]),
                "world_cmd": list(s.position[:9]),
            }
        )
    return out


if __name__ == "__main__":
    run(main, "joints.json")
