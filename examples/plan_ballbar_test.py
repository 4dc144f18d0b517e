# SPDX-License-Identifier: BSD-3-Clause
"""Plan a single set-up ballbar test (Flynn et al. 2016) and write its NC programs.

    python examples/plan_ballbar_test.py [OUT_DIR]

Writes the program in each dialect (LinuxCNC machine axes, Heidenhain TCPM, Siemens TRAORI,
Fanuc G43.4) and the commanded session template, and prints what the operator needs to know:
the pivot position, the tests and how long the program runs.
"""

import sys
from pathlib import Path

import numpy as np

import rotacal
from rotacal import _core

out = Path(sys.argv[1] if len(sys.argv) > 1 else "plan_out")
out.mkdir(parents=True, exist_ok=True)

setup = _core.BallbarSetup()  # defaults: AC-trt, L0 = 100 mm, pivot (120, 0, 60)
setup.ballbar_length = 100.0
setup.pivot = np.array([120.0, 0.0, 60.0])
setup.step_deg = 1.0
plan = _core.plan_ballbar_test(setup, None)

print(f"pivot (table frame): {setup.pivot} mm, ballbar L0 = {setup.ballbar_length} mm")
print(f"{plan.num_samples} points, {plan.duration / 60:.1f} min at the set-up's feeds")
labels = np.array(plan.labels)
for test in dict.fromkeys(labels):
    if test != "transition":
        n = int(np.sum(labels == test))
        print(f"  {test:10s} {n:4d} points")

for dialect, suffix in (
    ("linuxcnc", "ngc"),
    ("heidenhain", "h"),
    ("siemens", "mpf"),
    ("fanuc", "nc"),
):
    path = out / f"ballbar_test.{suffix}"
    rotacal.write_output(
        path, _core.write_nc_program(plan, dialect)
    )  # never a half-written program
    print(f"wrote {path} ({dialect})")
template = out / "commanded.csv"
rotacal.save(plan.commanded_session(), template)
print(f"wrote {template}: the commanded rows, lengths to be measured")
