# SPDX-License-Identifier: BSD-3-Clause
"""The loop of a diagnosis that cannot decide (docs/multi_diagnosis.md): a touch-probe session
leaves "one of these"; the added poses that separate two of its members are designed, measured
(here simulated on the same machine) and diagnosed together with the session.

Usage: python examples/diagnose_with_added_test.py
"""

import numpy as np

import rotacal
from rotacal.probe_design import design_probe_separation


def first(d: dict) -> str:
    f = d["findings"][0] if d["findings"] else None
    if f is None:
        return "nothing"
    where = f" (for {f['where']})" if "where" in f else ""
    if f["named"]:
        return f"{f['effect']}, weight {f['weight']:.2f}{where}"
    return "one of: " + ", ".join(f"{g['effect']} ({g['weight']:.2f})" for g in f["group"]) + where


machine = rotacal._core.parse_machine_type("AC-trt")
errors = rotacal.random_location_errors(machine, np.random.default_rng(3))
hidden = {"gravity_sag_A": [0.005]}  # the table sags 5 um at A = 90 deg
offset = (0.02, -0.01, 0.015)  # where the sphere is, against where it was meant to be
session, _ = rotacal.simulate_probe(
    machine, errors, hidden, sphere_offset=offset, ar1_rho=0.5, seed=2
)
print("1. the session alone:", first(rotacal.diagnose(session).to_dict()))

# The sag and radial_motion_A_h2 no test separates (the sag is a special case of it); the sag
# and the tilt motion an A sweep at C 180 deg does.
pair = ["gravity_sag_A", "tilt_motion_A_h2"]
design = design_probe_separation(session, pair)
poses = np.asarray(design.chosen.poses_deg)
print(f"2. designed: {len(poses)} added poses to separate {pair[0]} and {pair[1]}")
added, _ = rotacal.simulate_probe(
    machine, errors, hidden, sphere_offset=offset, ar1_rho=0.5, seed=102,
    poses_deg=poses, directions=np.asarray(design.chosen.directions),
)  # fmt: skip
j = rotacal.diagnose([("session", session), ("added", added)]).to_dict()
print("3. both together:", first(j))
for s in j["sessions"]:
    print(
        f"   {s['name']}: residual RMS {s['residual_rms_before_um']:.3f} -> "
        f"{s['residual_rms_after_um']:.3f} um"
    )
for e in j["final_model"]["effects"]:
    print(
        f"   the extended model holds {e['id']}: "
        + ", ".join(
            f"{k} = {v['value']:.3g} +- {v['std']:.2g} {v['unit']}" for k, v in e["params"].items()
        )
    )
