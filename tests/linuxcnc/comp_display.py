#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Headless [DISPLAY] program for a COMP_FILE run of xyzac-trt-sim.ini (tests/python/
test_comp_tables.py): after lcnc_display.Machine.bring_up, in MDI, it turns C to every angle of
poses.json ([c_deg, ...], through a turn up and back down), waits until the move is done and
the correction has ramped in (control.c ramps it through backlash_filt), and reads
joint.4.motor-pos-cmd, joint.4.pos-cmd and joint.4.motor-offset as doubles (hal.get_value:
halcmd prints 7 significant digits); written to comp.json (a failure: {"error": ...}, exit 1)."""

import json
import time

import hal
import linuxcnc

from lcnc_display import Machine, run


def pin(name):
    return float(hal.get_value(name))


def main():
    poses = json.load(open("poses.json"))
    reader = hal.component("rotacal-comp-reader")  # attaches this process to HAL
    reader.ready()
    m = Machine()
    s = m.s
    m.bring_up()
    m.set_mode(linuxcnc.MODE_MDI)
    m.mdi("G21 G90 G17 G40 G49 G54 G94")
    out = {"readings": []}
    for c in poses:
        m.mdi(f"G0 C{c:.6f}")
        m.wait_for("in position", lambda: s.inpos and s.interp_state == linuxcnc.INTERP_IDLE)
        # At rest the trim of the last moving servo cycle stays; backlash_filt reaches it
        # within a few cycles at 0.5 x the joint's acceleration. Read until two agree.
        last = None
        for _ in range(100):
            time.sleep(0.02)
            now = pin("joint.4.motor-pos-cmd")
            if now == last:
                break
            last = now
        out["readings"].append(
            {
                "commanded": c,
                "motor_pos_cmd": now,
                "pos_cmd": pin("joint.4.pos-cmd"),
                "motor_offset": pin("joint.4.motor-offset"),
            }
        )
    return out


if __name__ == "__main__":
    run(main, "comp.json")
