#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Headless [DISPLAY] program that serves the checks of several tests from one LinuxCNC start
(tests/python/linuxcnc_session.py, `Start`).

A LinuxCNC start costs seconds of CPU (rtapi_app, motion, task, io, the interpreter); the
checks that use the same kinematics module share one. The test writes job N as
`$ROTACAL_LCNC_RUN/jobs/N.json`: {"display": module, "dir": job directory, "result": file name,
"timeout": s, "hal": [halcmd argument lists]}. This program runs the halcmd commands (the job's
pins: setp, net, unlinkp), then the display module's main() in the job directory (the
displays of tests/linuxcnc, which read their inputs from the current directory), writes what
it returns to the result file ({"error": ...} on a failure, after which the machine is
brought back up by the next job) and then `jobs/N.done`. {"stop": true} ends the program, and
with it LinuxCNC. Without a job for IDLE s it ends too: a test run that died does not leave
LinuxCNC running.
"""

import importlib
import json
import os
import signal
import subprocess
import time
import traceback
from pathlib import Path

from lcnc_display import write_json

SPOOL = Path(os.environ["ROTACAL_LCNC_RUN"]) / "jobs"
IDLE = float(os.environ.get("ROTACAL_LCNC_IDLE", "900"))  # s without a job: end


def next_job(n):
    path = SPOOL / f"{n}.json"
    end = time.monotonic() + IDLE
    while not path.exists():
        if time.monotonic() > end:
            return {"stop": True, "why": f"no job for {IDLE} s"}
        time.sleep(0.02)
    return json.loads(path.read_text())


def recover():
    """After a failed job: stop whatever moves, so that the next job starts from rest."""
    try:
        import linuxcnc

        c = linuxcnc.command()
        c.abort()
        c.wait_complete(10)
    except Exception:  # noqa: BLE001 - the next job's bring_up reports a machine that is down
        traceback.print_exc()


def run_job(job):
    def on_alarm(signum, frame):
        raise TimeoutError(f"job ran longer than {job['timeout']} s")

    os.chdir(job["dir"])
    signal.signal(signal.SIGALRM, on_alarm)
    signal.alarm(int(job["timeout"]))
    try:
        for args in job.get("hal", []):
            r = subprocess.run(["halcmd", *args], capture_output=True, text=True, timeout=30)
            if r.returncode != 0:
                raise RuntimeError(f"halcmd {' '.join(args)}: {r.stdout}{r.stderr}")
        data = importlib.import_module(job["display"]).main()
    except BaseException as ex:  # noqa: BLE001 - reported to the test; the next job still runs
        traceback.print_exc()
        data = {"error": f"{type(ex).__name__}: {ex}"}
        recover()
    finally:
        signal.alarm(0)
    write_json(job["result"], data)


def main():
    n = 0
    while True:
        job = next_job(n)
        if job.get("stop"):
            print(f"serve_display: stop ({job.get('why', 'asked')}) after {n} jobs", flush=True)
            return
        run_job(job)
        (SPOOL / f"{n}.done").write_text("")
        n += 1


if __name__ == "__main__":
    main()
