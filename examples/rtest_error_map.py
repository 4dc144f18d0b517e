# SPDX-License-Identifier: BSD-3-Clause
"""R-test error map of a B/C table (Oyama & Ibaraki): identify the location errors and the
position-dependent errors, print the map and save it with the fitted model.

Usage: python examples/rtest_error_map.py [SESSION.csv] [-o OUT_DIR]
Without a session, a machine with gravity sag and coning of its B axis is simulated.
"""

import argparse
from pathlib import Path

import numpy as np

import rotacal

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("session", nargs="?", help="a rotacal-rtest/1 file (default: simulate one)")
parser.add_argument(
    "-o", "--output", default=".", help="directory for error_map.csv/.json and model.json"
)
args = parser.parse_args()

if args.session:
    session = rotacal.load(args.session)
else:
    # 6 um of gravity sag at B = +-90 deg and 145 urad/rad of coning, as in the paper's Sec. 5.3.
    session, truth = rotacal.rtest.simulate_rtest(
        "random", {"gravity_sag_B": 0.006, "coning_B": 1.45e-4}, seed=3
    )
    print("simulated:", ", ".join(f"{k} = {v}" for k, v in truth["effects"].items()))

result = rotacal.identify(session)  # joint fit: location errors + smooth maps + probe zeros
d = result.to_dict()
print(f"{len(session)} poses, residual RMS {d['residual_rms_um']:.3f} um")
for name, p in d["location_errors"].items():
    scale, unit = (1e3, "um") if p["unit"] == "mm" else (1e6, "urad")
    print(
        f"  {name}  "
        + (
            "unobservable"
            if p["value"] is None
            else f"{p['value'] * scale:+8.2f} +- {p['std'] * scale:.2f} {unit}"
        )
    )
for u in d["unobservable"]:
    print("  not determined:", u)

# The B-axis map: gravity sag shows in dz_BY, coning in alpha_BY (C = 0 rows of the map).
print("   B    dz_BY (um)        alpha_BY (urad)")
for e in d["error_map"]["entries"]:
    if e["C"] == 0:
        print(
            f"{e['B']:+5.0f}  {e['BY'][2] * 1e3:+7.2f} +- {e['BY_std'][2] * 1e3:.2f}"
            f"   {e['BY'][3] * 1e6:+8.2f} +- {e['BY_std'][3] * 1e6:.2f}"
        )

out = Path(args.output)
out.mkdir(parents=True, exist_ok=True)
rotacal.write_output(out / "error_map.csv", result.error_map("csv"))
rotacal.write_output(out / "error_map.json", result.error_map("json"))
rotacal.save_model(result.model_dict(), out / "model.json")
# The model predicts the table's error at any (B, C) for any table point, with 1 sigma.
model = rotacal.load_model(out / "model.json")
m, _, _ = rotacal.models.rtest_model_from_dict(model)
err, std = m.table_errors(np.array([50.0, 50.0, 0.0]), np.radians([[45.0, 15.0]]))
print(
    "error of table point (50, 50, 0) at B = 45, C = 15 deg:",
    ", ".join(f"{v * 1e3:+.2f} +- {s * 1e3:.2f}" for v, s in zip(err[0], std[0])),
    "um",
)
print("wrote", ", ".join(str(out / f) for f in ("error_map.csv", "error_map.json", "model.json")))
