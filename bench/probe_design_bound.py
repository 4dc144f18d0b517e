# SPDX-License-Identifier: BSD-3-Clause
"""The lower bound of the touch probe's largest expanded uncertainty (k = 2) of the location
errors at 120 touches on B-head-C-table (docs/design.md, "Touch probe": why the design cannot
reach 0.7 of the default poses there), from the reference simulator alone
(tests/python/probe_bound.py): for each candidate set (pose grid, sphere position, touch
directions shared by every pose or chosen touch by touch) the value a continuous design reaches
and the certified bound no design of 120 touches can beat, against the default poses at the
default sphere (0.5 um per touch; the candidate directions of `rotacal design probe`, contact
points within 80 deg of the stylus axis, as a third set), and on the 15 / 30 deg grid the continuous design rounded
to 120 touches (whole pose visits, or single touches when each has its own direction).

    python bench/probe_design_bound.py            # ~15 min on the loaded 2-core machine
    python bench/probe_design_bound.py --quick    # the default sphere on the 15 / 30 deg grid, 1 min
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "python"))
import probe_bound as pb  # noqa: E402
from refsim import poses as refposes  # noqa: E402

MACHINE = "B-head-C-table"
SPHERE = (150.0, 0.0, 80.0)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--machine", default=MACHINE)
    a = ap.parse_args()
    m = a.machine
    Gd, names = pb.sensitivities(m, pb.default_poses(m), SPHERE)
    u0, worst0 = pb.largest_u_um(pb.pattern_information(Gd, refposes.probe_directions()), names)
    print(f"{m}: default poses at sphere {SPHERE}, 120 touches: largest U {u0:.4f} um ({worst0})")
    grids = [(15.0, 30.0, 90.0)] + ([] if a.quick else [(5.0, 15.0, 110.0)])
    spheres = [SPHERE] + (
        []
        if a.quick
        else [(250.0, 0.0, 80.0), (300.0, 0.0, 40.0), (150.0, 0.0, 200.0), (0.0, 150.0, 80.0)]
    )
    print(
        "| poses | sphere | directions | reached U (um) | bound U (um) | bound / default | 120 touches / default |"
    )
    print("|---|---|---|---|---|---|---|")
    for tilt_step, rot_step, limit in grids:
        for sphere in spheres if tilt_step == 15.0 else [SPHERE]:
            G, _ = pb.sensitivities(m, pb.grid(m, tilt_step, rot_step, limit), sphere)
            where = f"tilt +-{limit:g} every {tilt_step:g}, rotary every {rot_step:g} ({len(G)})"
            contact = [
                pb.contact_directions(m, t, r) for t, r in pb.grid(m, tilt_step, rot_step, limit)
            ]
            for label, dirs in (
                ("default 5, every pose", refposes.probe_directions()),
                ("any, touch by touch", None),
                ("contact within 80 deg of the stylus, touch by touch", "contact"),
            ):
                if isinstance(dirs, str) and len(G) > 200:
                    continue  # the design's grid only (27,000 candidate touches on the fine one)
                if isinstance(
                    dirs, str
                ):  # the design's candidate directions (rounded: rotacal design probe)
                    up, low, w = pb.minimax_bound(
                        G, names, 120, iterations=60, touch_directions=contact
                    )
                    whole = ""
                else:
                    up, low, w = pb.minimax_bound(G, names, 120, dirs)
                    whole = (
                        f"{pb.rounded_u_um(G, names, 120, w, dirs) / u0:.3f}"
                        if len(G) < 200
                        else ""
                    )
                print(
                    f"| {where} | {sphere} | {label} | {up:.4f} | {low:.4f} | {low / u0:.3f} | {whole} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
