# SPDX-License-Identifier: BSD-3-Clause
"""Identify the location errors of a ballbar session and diagnose what the model misses.

Usage: python examples/identify_session.py SESSION.csv
"""

import sys

import rotacal

session = rotacal.load(sys.argv[1])
result = rotacal.identify(session)  # joint fit of the exact model (Gauss-Newton, Ceres Jets)
for name, p in result.to_dict()["location_errors"].items():
    print(
        name,
        "unobservable" if p["value"] is None else f"{p['value']:.6g} +- {p['std']:.2g} {p['unit']}",
    )

diagnosis = rotacal.diagnose(session)
for finding in diagnosis.to_dict()["findings"]:
    print("found:", finding["effect"], "-", finding["cause"])
