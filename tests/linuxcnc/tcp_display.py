#!/usr/bin/python3
"""Headless [DISPLAY] program for xyzac-trt-sim.ini (tests/python/test_linuxcnc_kins.py).

LinuxCNC starts it as `tcp_display.py -ini FILE` from the INI's directory, after HAL and the
realtime parts are up, and shuts itself down when it exits. It runs under Debian's
/usr/bin/python3, the only interpreter with the `linuxcnc` module. It takes the machine out of
E-stop, switches it on, homes all joints (where they stand: HOME_SEARCH_VEL = 0), and in MDI
(world coordinates through xyzac-trt-kins: motion is in teleop/coordinated mode once all
joints are homed) moves to every pose of poses.json, [[x, y, z, a_deg, c_deg], ...], with G0.
When a move is done and the machine is in position it reads the joint positions (the
feedback after the simulated drives) and writes them, and the world position LinuxCNC
reports, to joints.json. Any failure is written to joints.json as {"error": ...} and exits 1.
Every wait is bounded; the whole run is bounded by SIGALRM.
"""
import json
import os
import signal
import sys
import time
import traceback

import linuxcnc

RUN_TIMEOUT = float(os.environ.get("ROTACAL_LCNC_RUN_TIMEOUT", "60"))  # s, whole display
WAIT = 10.0  # s, one state change / one move


def main():
    poses = json.load(open("poses.json"))
    s = linuxcnc.stat()
    c = linuxcnc.command()
    e = linuxcnc.error_channel()

    def poll():
        s.poll()
        err = e.poll()
        if err and err[0] in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR):
            raise RuntimeError(f"LinuxCNC error: {err[1]}")

    def wait_for(what, cond, timeout=WAIT):
        end = time.monotonic() + timeout
        while True:
            poll()
            if cond():
                return
            if time.monotonic() > end:
                raise TimeoutError(f"timed out after {timeout} s waiting for {what}")
            time.sleep(0.01)

    def mdi(line):
        c.mdi(line)
        if c.wait_complete(WAIT) == -1:
            raise TimeoutError(f"MDI {line!r} not complete after {WAIT} s")
        poll()
        if s.state == linuxcnc.RCS_ERROR:
            raise RuntimeError(f"MDI {line!r} failed")

    wait_for("task to come up", lambda: s.task_state != 0)
    c.state(linuxcnc.STATE_ESTOP_RESET)
    wait_for("E-stop reset", lambda: s.task_state == linuxcnc.STATE_ESTOP_RESET)
    c.state(linuxcnc.STATE_ON)
    wait_for("machine on", lambda: s.task_state == linuxcnc.STATE_ON)
    c.mode(linuxcnc.MODE_MANUAL)
    c.wait_complete(WAIT)
    c.teleop_enable(0)  # homing is done in joint mode
    c.wait_complete(WAIT)
    c.home(-1)
    wait_for("all joints homed", lambda: all(s.homed[:s.joints]))
    c.mode(linuxcnc.MODE_MDI)
    c.wait_complete(WAIT)
    wait_for("MDI mode", lambda: s.task_mode == linuxcnc.MODE_MDI)
    mdi("G21 G90 G17 G40 G49 G54 G94")
    poll()
    out = {"kinematics_type": s.kinematics_type, "motion_mode": s.motion_mode, "moves": []}
    if s.motion_mode != linuxcnc.TRAJ_MODE_COORD:
        raise RuntimeError(f"motion not in world (coordinated) mode: motion_mode={s.motion_mode}")
    for x, y, z, a, cc in poses:
        mdi(f"G0 X{x:.6f} Y{y:.6f} Z{z:.6f} A{a:.6f} C{cc:.6f}")
        wait_for("in position", lambda: s.inpos and s.interp_state == linuxcnc.INTERP_IDLE)
        time.sleep(0.01)  # a few more servo periods: the feedback is settled
        poll()
        out["moves"].append({"joints": list(s.joint_actual_position[:s.joints]),
                             "joints_cmd": [j["output"] for j in s.joint[:s.joints]],
                             "world": list(s.actual_position[:6])})
    json.dump(out, open("joints.json.tmp", "w"))
    os.replace("joints.json.tmp", "joints.json")


def on_alarm(signum, frame):
    raise TimeoutError(f"display ran longer than {RUN_TIMEOUT} s")


if __name__ == "__main__":
    signal.signal(signal.SIGALRM, on_alarm)
    signal.alarm(int(RUN_TIMEOUT))
    try:
        main()
    except BaseException as ex:  # noqa: BLE001 - reported to the test, then LinuxCNC shuts down
        traceback.print_exc()
        json.dump({"error": f"{type(ex).__name__}: {ex}"}, open("joints.json", "w"))
        sys.exit(1)
