#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Display job (serve_display.py) of tests/python/test_linuxcnc_probe.py, in the shared start of
xyzac-trt-sim.ini, or the [DISPLAY] program of probe-sim.ini (trivkins) run by hand.

In a served job, served.json gives the switchkins type of xyzac-trt-kins that is the identity
(the program is in machine axes: joints = X Y Z A C, as trivkins), the program's time bound and
the halcmd commands that load probe.hal's chain (after a move to 0, where probe-sim.ini
starts) and take it out again after the run (unloading probe-sim makes it write its record). After lcnc_display.Machine.bring_up it runs probe.ngc in AUTO mode to its end (M2) and writes
result.json: the program's run time and the counts of the realtime probe chain of probe.hal
(probe_touches: contacts; probe_strays: contacts outside probing), read with halcmd. Any
LinuxCNC error (a G38.2 that ends without contact, a probe already tripped at its start, a
limit) fails the run: {"error": ...}, exit 1.
"""

import json
import os
import subprocess
import time

import linuxcnc

from lcnc_display import RUN_TIMEOUT, Machine, run


def getp(name):
    return int(
        subprocess.run(["halcmd", "getp", name], capture_output=True, text=True, check=True).stdout
    )


def halcmd(*args):
    """halcmd with its output (and that of a loadusr component, which keeps it open while it
    runs: a pipe would never end) in halcmd.log."""
    with open("halcmd.log", "a") as log:
        subprocess.run(["halcmd", *args], stdout=log, stderr=log, check=True, timeout=30)


def switch_kins(m, kind):
    """Switch the kinematics type in joint mode; an MDI M66 makes the interpreter take the new
    position (as rotacal_kins_display.py does)."""
    m.set_mode(linuxcnc.MODE_MANUAL)
    m.c.teleop_enable(0)
    m.c.wait_complete(10)
    halcmd("setp", "motion.switchkins-type", str(kind))
    m.set_mode(linuxcnc.MODE_MDI)
    m.mdi("M66 E0 L0")


def main():
    served = json.load(open("served.json")) if os.path.exists("served.json") else None
    m = Machine()
    m.bring_up()
    if served is None:
        return run_program(m, RUN_TIMEOUT)
    switch_kins(m, served["identity_type"])
    m.mdi("G90 G0 X0 Y0 Z0 A0 C0")  # where probe-sim.ini starts: homed at 0
    m.wait_for("at 0", lambda: m.s.inpos and m.s.interp_state == linuxcnc.INTERP_IDLE)
    for args in served["hal"]:  # the probe chain, loaded once at 0, away from the sphere
        halcmd(*args)
    try:
        return run_program(m, served["timeout_s"])
    finally:
        m.c.abort()  # after an error: the program stopped, the machine stays on
        m.c.wait_complete(10)
        for args in served["cleanup"]:
            halcmd(*args)
        switch_kins(m, 0)


def run_program(m, timeout):
    s = m.s
    m.set_mode(linuxcnc.MODE_AUTO)
    m.c.program_open(os.path.abspath("probe.ngc"))
    t0 = time.monotonic()
    m.c.auto(linuxcnc.AUTO_RUN, 0)
    m.wait_for("the program to start", lambda: s.interp_state != linuxcnc.INTERP_IDLE)
    m.wait_for(
        "the program to end", lambda: s.interp_state == linuxcnc.INTERP_IDLE, timeout=timeout
    )
    return {
        "program_s": time.monotonic() - t0,
        "touches": getp("probe_touches.count"),
        "strays": getp("probe_strays.count"),
    }


if __name__ == "__main__":
    run(main, "result.json")
