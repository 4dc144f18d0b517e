# SPDX-License-Identifier: BSD-3-Clause
"""What the headless [DISPLAY] programs of tests/linuxcnc share (tcp_display.py, probe_display.py).

LinuxCNC starts a display as `PROGRAM -ini FILE` from the INI's directory, after HAL and the
realtime parts are up, and shuts itself down when it exits. The displays run under Debian's
/usr/bin/python3, the only interpreter with the `linuxcnc` module. `Machine.bring_up` takes the
machine out of E-stop, switches it on and homes all joints (where they stand: HOME_SEARCH_VEL =
0). Every wait is bounded; `run` bounds the whole display by SIGALRM and writes any failure to
its result file as {"error": ...}, exiting 1.
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


class Machine:
    def __init__(self):
        self.s = linuxcnc.stat()
        self.c = linuxcnc.command()
        self.e = linuxcnc.error_channel()

    def poll(self):
        self.s.poll()
        err = self.e.poll()
        if err and err[0] in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR):
            raise RuntimeError(f"LinuxCNC error: {err[1]}")

    def wait_for(self, what, cond, timeout=WAIT):
        end = time.monotonic() + timeout
        while True:
            self.poll()
            if cond():
                return
            if time.monotonic() > end:
                raise TimeoutError(f"timed out after {timeout} s waiting for {what}")
            time.sleep(0.01)

    def mdi(self, line):
        self.c.mdi(line)
        if self.c.wait_complete(WAIT) == -1:
            raise TimeoutError(f"MDI {line!r} not complete after {WAIT} s")
        self.poll()
        if self.s.state == linuxcnc.RCS_ERROR:
            raise RuntimeError(f"MDI {line!r} failed")

    def set_mode(self, mode):
        self.c.mode(mode)
        self.c.wait_complete(WAIT)
        self.wait_for(f"mode {mode}", lambda: self.s.task_mode == mode)

    def bring_up(self):
        s, c = self.s, self.c
        self.wait_for("task to come up", lambda: s.task_state != 0)
        if s.task_state == linuxcnc.STATE_ON and all(s.homed[: s.joints]):
            return  # a served start (serve_display.py): up since an earlier job
        c.state(linuxcnc.STATE_ESTOP_RESET)
        self.wait_for("E-stop reset", lambda: s.task_state == linuxcnc.STATE_ESTOP_RESET)
        c.state(linuxcnc.STATE_ON)
        self.wait_for("machine on", lambda: s.task_state == linuxcnc.STATE_ON)
        self.set_mode(linuxcnc.MODE_MANUAL)
        c.teleop_enable(0)  # homing is done in joint mode
        c.wait_complete(WAIT)
        c.home(-1)
        self.wait_for("all joints homed", lambda: all(s.homed[: s.joints]))


def write_json(path, data):
    json.dump(data, open(path + ".tmp", "w"))
    os.replace(path + ".tmp", path)


def run(main, result):
    """main() -> dict, written to `result`; a failure is written there as {"error": ...}."""

    def on_alarm(signum, frame):
        raise TimeoutError(f"display ran longer than {RUN_TIMEOUT} s")

    signal.signal(signal.SIGALRM, on_alarm)
    signal.alarm(int(RUN_TIMEOUT))
    try:
        write_json(result, main())
    except BaseException as ex:  # noqa: BLE001 - reported to the test, then LinuxCNC shuts down
        traceback.print_exc()
        write_json(result, {"error": f"{type(ex).__name__}: {ex}"})
        sys.exit(1)
