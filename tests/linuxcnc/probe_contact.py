#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Userspace HAL component `probe-sim` of probe.hal: where the simulated machine holds the sphere.

Loaded by `loadusr -Wn probe-sim /usr/bin/python3 probe_contact.py truth.json` (Debian's python3:
it has the `hal` module and numpy). truth.json gives the simulated machine: `refsim` (the
directory holding the independent reference simulator tests/reference/refsim, which never
imports rotacal), `machine`, `errors` (location errors, mm and rad), `sphere_actual` (the
sphere's centre in the table frame, mm), `sphere_diameter`, `stylus_diameter` (mm),
`trigger_noise_mm` (the trigger radius' deviation per touch, in touch order) and `record`
(the file this component writes).

At the rotary joints' current A, C it sets `centre-x/y/z` to the joint X, Y, Z that put the
stylus tip at the sphere's actual centre (refsim: p_table of the errored machine minus its
tool-side offset), and `trigger-radius` to (D + d)/2 + trigger_noise_mm[k] for touch k. The
realtime chain of probe.hal compares every servo period; this component only follows the
rotary axes, which turn far above the sphere, and changes the radius for the next touch once
the stylus has left the sphere (never during an approach: each radius is set while the stylus
is retracting, and the record says whether it was in place before its touch).

The record (JSON, rewritten after every touch and on exit):
  touches: [{index, radius, centre, a, c, armed}] per trip counted by probe_touches;
           `armed`: the radius was set for this touch before it tripped
  strays: probe_strays.count, the contacts outside probing (realtime count)
  clearance_mm: {motion type: the smallest |tip - centre| - radius polled while that type
           moved, outside contact and outside the retract that follows each touch (until the
           stylus is LEFT_MM out)}
  extent:  {joint: [min, max]} of the polled X, Y, Z (mm), A, C (deg)
  poll_s:  {mean, max, over_10ms}: this loop's period, the latency a userspace trigger would
           have (why the contact is decided in realtime instead)
"""

import json
import math
import os
import signal
import sys
import time

import numpy as np

import hal

POLL_S = 0.0005
LEFT_MM = 0.05  # the stylus has left the sphere: this far outside the trigger radius
TYPES = {1: "traverse", 2: "feed", 3: "arc", 5: "probing"}


class Sphere:
    """The sphere as the errored machine holds it (refsim), in joint X, Y, Z of the tip."""

    def __init__(self, cfg):
        sys.path.insert(0, cfg["refsim"])
        import refsim  # noqa: E402 - the path comes from truth.json

        self.model = refsim.Model(cfg["machine"], cfg["errors"])
        self.names = self.model.machine.axis_names
        self.q = np.asarray(cfg["sphere_actual"], float)[None, :]

    def centre(self, a_deg, c_deg):
        by_name = {"A": a_deg, "C": c_deg}
        angles = np.radians([[by_name[n] for n in self.names]])
        t = np.zeros(1)
        p = self.model.p_table(self.q, angles, t)[0]
        return p - self.model.p_tool(np.zeros((1, 3)), angles, t)[0]


def main():
    cfg = json.load(open(sys.argv[1]))
    sphere = Sphere(cfg)
    r = 0.5 * (cfg["sphere_diameter"] + cfg["stylus_diameter"])
    noise = list(cfg["trigger_noise_mm"])
    c = hal.component("probe-sim")
    for name in ("x", "y", "z", "a", "c"):
        c.newpin(name, hal.HAL_FLOAT, hal.HAL_IN)
    for name in ("touches", "strays", "motion-type"):
        c.newpin(name, hal.HAL_S32, hal.HAL_IN)
    c.newpin("contact", hal.HAL_BIT, hal.HAL_IN)
    for name in ("centre-x", "centre-y", "centre-z", "trigger-radius"):
        c.newpin(name, hal.HAL_FLOAT, hal.HAL_OUT)
    running = [True]

    def stop(signum, frame):
        running[0] = False

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)

    record = {
        "touches": [],
        "strays": 0,
        "clearance_mm": {},
        "poll_s": {"mean": 0.0, "max": 0.0, "over_10ms": 0},
        "extent": {k: [math.inf, -math.inf] for k in "xyzac"},
    }
    polls, t_last, t_first = 0, None, None

    def save():
        record["strays"] = c["strays"]
        with open(cfg["record"] + ".tmp", "w") as f:
            json.dump(record, f)
        os.replace(cfg["record"] + ".tmp", cfg["record"])

    last_ac, centre = None, np.zeros(3)
    counted, armed_for, retracting = 0, 0, False
    c["trigger-radius"] = r + noise[0]
    c.ready()
    save()
    while running[0]:
        now = time.monotonic()
        if t_last is not None:
            dt, polls = now - t_last, polls + 1
            stats = record["poll_s"]
            stats["max"], stats["mean"] = max(stats["max"], dt), (now - t_first) / polls
            stats["over_10ms"] += dt > 0.01
        else:
            t_first = now
        t_last = now
        for k, (lo, hi) in record["extent"].items():
            record["extent"][k] = [min(lo, c[k]), max(hi, c[k])]
        ac = (c["a"], c["c"])
        if ac != last_ac:
            centre = sphere.centre(*ac)
            c["centre-x"], c["centre-y"], c["centre-z"] = centre
            last_ac = ac
        n = c["touches"]
        while counted < n:
            record["touches"].append(
                {
                    "index": counted,
                    "radius": c["trigger-radius"],
                    "centre": centre.tolist(),
                    "a": ac[0],
                    "c": ac[1],
                    "armed": armed_for == counted,
                }
            )
            counted += 1
            retracting = True
            save()
        gap = math.dist((c["x"], c["y"], c["z"]), centre) - c["trigger-radius"]
        if retracting and not c["contact"] and gap > LEFT_MM:
            retracting = False
            if counted < len(noise):
                c["trigger-radius"] = r + noise[counted]
                armed_for = counted
        kind = TYPES.get(c["motion-type"], str(c["motion-type"]))
        if not c["contact"] and not retracting and kind != "probing":
            record["clearance_mm"][kind] = min(record["clearance_mm"].get(kind, math.inf), gap)
        time.sleep(POLL_S)
    save()


if __name__ == "__main__":
    main()
