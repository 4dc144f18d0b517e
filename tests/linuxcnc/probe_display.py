#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Headless [DISPLAY] program for probe-sim.ini (tests/python/test_linuxcnc_probe.py).

After lcnc_display.Machine.bring_up it runs probe.ngc in AUTO mode to its end (M2) and writes
result.json: the program's run time and the counts of the realtime probe chain of probe.hal
(probe_touches: contacts; probe_strays: contacts outside probing), read with halcmd. Any
LinuxCNC error (a G38.2 that ends without contact, a probe already tripped at its start, a
limit) fails the run: {"error": ...}, exit 1.
"""

import os
import subprocess
import time

import linuxcnc

from lcnc_display import RUN_TIMEOUT, Machine, run


def getp(name):
    return int(
        subprocess.run(["halcmd", "getp", name], capture_output=True, text=True, check=True).stdout
    )


def main():
    m = Machine()
    s = m.s
    m.bring_up()
    m.set_mode(linuxcnc.MODE_AUTO)
    m.c.program_open(os.path.abspath("probe.ngc"))
    t0 = time.monotonic()
    m.c.auto(linuxcnc.AUTO_RUN, 0)
    m.wait_for("the program to start", lambda: s.interp_state != linuxcnc.INTERP_IDLE)
    m.wait_for(
        "the program to end", lambda: s.interp_state == linuxcnc.INTERP_IDLE, timeout=RUN_TIMEOUT
    )
    return {
        "program_s": time.monotonic() - t0,
        "touches": getp("probe_touches.count"),
        "strays": getp("probe_strays.count"),
    }


if __name__ == "__main__":
    run(main, "result.json")
