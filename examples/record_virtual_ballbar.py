# SPDX-License-Identifier: BSD-3-Clause
"""Record a ballbar test from a virtual instrument and identify the machine it measured.

The virtual ballbar sits on a pseudo-terminal, exactly where a real transducer's USB-serial
port would be; the recorder neither knows nor cares. Run:

    python examples/record_virtual_ballbar.py [OUT.csv]

With a real instrument, skip the virtual part and pass its port (e.g. /dev/ttyUSB0) to
record_ballbar, or use `rotacal record ballbar --port ...`.
"""

import sys

import numpy as np

import rotacal
from rotacal import _core
from rotacal.instruments import record_ballbar, virtual_ballbar

out = sys.argv[1] if len(sys.argv) > 1 else "recorded_ballbar.csv"

# The test program (Flynn et al. 2016 single set-up) and a machine with known location errors.
setup = _core.BallbarSetup()
setup.step_deg = 2.0
plan = _core.plan_ballbar_test(setup, None)
names = list(_core.location_error_names(setup.machine))
errors = np.array([0.03, -0.02, 4e-5, -6e-5, 0.025, 0.04, 3e-5, -5e-5])  # mm, rad
truth = _core.BallbarMachineModel(
    setup.machine, errors, np.asarray(setup.pivot) + [0.01, -0.01, 0.02]
)

# 100 samples/s, 50x faster than real time so the example takes seconds, not minutes.
device = virtual_ballbar(plan, truth, noise_um=0.5, rate_hz=100, speed=50)
print(f"virtual ballbar on {device.port}")
summary = record_ballbar(device.port, plan, out, rate_hz=100, progress=False)
device.stop()
print(f"recorded {out}: {summary.describe()}")

ident = rotacal.identify(rotacal.load(out))
print(f"{'name':6s} {'truth':>10s} {'identified':>12s} {'1 sigma':>9s}")
for name, true in zip(names, errors):
    p = ident.parameter(name)
    scale, unit = (1e6, "urad") if p.unit == "rad" else (1e3, "um")
    print(f"{name:6s} {true * scale:10.3f} {p.value * scale:12.3f} {p.std * scale:9.3f}  {unit}")
