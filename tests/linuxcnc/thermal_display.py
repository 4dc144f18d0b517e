#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Display job (serve_display.py) that turns an axis while the thermal HAL chain of
`rotacal export --thermal-chain` runs (tests/python/test_linuxcnc_kins.py,
test_linuxcnc_rotacal_kins.py).

The job's halcmd commands have loaded the chain and a `sampler` (channel 0) that logs, every
servo period in realtime, the joint's vel-cmd and the chain's signals scaled for halsampler's
six decimals. This program runs `halsampler -t` (the sample number tags each line: a lost
sample shows as a gap) into samples.txt, moves with the MDI lines of plan.json, waits in
position, rests plan["rest_s"] s, stops halsampler, and then runs plan["cleanup"] (halcmd
commands that take the chain out again: the start is shared). Its result: the number of lines
and the sampler's overruns.
"""

import json
import signal
import subprocess
import time

import linuxcnc

from lcnc_display import WAIT, Machine


def halcmd(*args):
    r = subprocess.run(["halcmd", *args], capture_output=True, text=True, timeout=WAIT)
    if r.returncode != 0 and args[0] == "unloadrt":
        # unloadrt sampler can report a failed rmmod while halsampler's detach is under way;
        # the component goes a moment later, or a second unloadrt takes it: what counts is
        # that it is gone
        for _ in range(20):
            time.sleep(0.25)
            if args[1] not in halcmd("list", "comp").split():
                return r.stdout
            r = subprocess.run(["halcmd", *args], capture_output=True, text=True, timeout=WAIT)
            if r.returncode == 0 or f"{args[1]}: not loaded" in r.stdout + r.stderr:
                return r.stdout  # unloaded by the first call after all (CI, 12-07)
    if r.returncode != 0:
        raise RuntimeError(f"halcmd {' '.join(args)}: {r.stdout}{r.stderr}")
    return r.stdout


def main():
    plan = json.load(open("plan.json"))
    m = Machine()
    s = m.s
    m.bring_up()
    m.set_mode(linuxcnc.MODE_MDI)
    m.mdi("G21 G90 G17 G40 G49 G54 G94")
    out = open("samples.txt", "w")
    sampler = subprocess.Popen(["halsampler", "-c", "0", "-t"], stdout=out)
    try:
        time.sleep(0.2)  # at rest: the first samples are the cold state
        for line in plan["moves"]:
            m.mdi(line)
            m.wait_for(
                "in position",
                lambda: s.inpos and s.interp_state == linuxcnc.INTERP_IDLE,
                timeout=plan["move_timeout_s"],
            )
        time.sleep(plan["rest_s"])
        overruns = int(halcmd("getp", "sampler.0.overruns"))
    finally:
        sampler.send_signal(signal.SIGINT)  # halsampler ends its loop and flushes
        sampler.wait(timeout=WAIT)
        out.close()
        for args in plan["cleanup"]:
            halcmd(*args)
    with open("samples.txt") as f:
        lines = sum(1 for _ in f)
    return {"lines": lines, "overruns": overruns, "halsampler_exit": sampler.returncode}
