"""Figures of the ballbar test design (docs/design.md) on the Table 2 machine (AC-trt, the
default set-up of Flynn et al. Table 1): the designed single set-up's largest expanded
uncertainty of the location errors against the default plan's at the same run time (target
<= 0.7), the design time (target <= 10 s), and whether the predicted 1-sigma is what simulated
tests of the designed set-up realise (Monte Carlo sigma / predicted, target 0.7-1.4).

    PYTHONPATH=... python bench/design_bench.py            # the default grid, 100 draws
    PYTHONPATH=... python bench/design_bench.py --smoke    # a 2 x 2 grid, 10 draws
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from rotacal import _core
from rotacal.design import design_ballbar
from rotacal.machines import TABLE2_ERRORS


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--smoke", action="store_true")
    ap.add_argument("--draws", type=int, default=100)
    a = ap.parse_args()
    base = _core.BallbarSetup()
    kw = {"pivot_x": [90.0, 150.0], "pivot_z": [40.0, 90.0]} if a.smoke else {}
    draws = 10 if a.smoke else a.draws
    t0 = time.perf_counter()
    d = design_ballbar(base, time_s=0.0, rate_hz=100.0, noise_um=0.5, **kw)
    elapsed = time.perf_counter() - t0
    print(f"design: {len(d.candidates)} set-ups in {elapsed:.2f} s (target <= 10 s)")
    for label, c in (("designed", d.best), ("default", d.baseline)):
        print(f"{label:9s} L0 {c.setup.ballbar_length:g} mm, pivot {tuple(float(v) for v in c.setup.pivot)}: "
              f"largest U (k=2) {c.worst_expanded_um:.4f} um ({c.worst_error}) at {d.time_budget_s:.0f} s")
    print(f"ratio designed / default at the same run time: {d.ratio:.3f} (target <= 0.7)")

    # Monte Carlo at the plan's own sampling: the recorder rate that records the plan's samples.
    setup = d.best.setup
    plan = _core.plan_ballbar_test(setup, None)
    cmd = plan.commanded_session()
    t = np.asarray(cmd.time)
    tests = np.asarray(cmd.tests, dtype=object)
    t_tests = sum(t[tests == lab].max() - t[tests == lab].min() for lab in dict.fromkeys(tests))
    check = design_ballbar(setup, lengths=[setup.ballbar_length], pivot_x=[setup.pivot[0]],
                           pivot_z=[setup.pivot[2]], rate_hz=len(cmd) / t_tests, noise_um=0.5)
    predicted = np.asarray(check.best.sigma)[:8]
    names = list(_core.location_error_names(setup.machine))
    truth = _core.BallbarMachineModel(setup.machine, np.array([TABLE2_ERRORS[n] for n in names]),
                                      np.asarray(setup.pivot), [], [])
    est = []
    for k in range(draws):
        s = _core.simulate_ballbar(cmd, truth, 0.5, 100 + k, True)
        ident = _core.identify_joint(s)
        est.append([p.value for p in ident.parameters[:8]])
    realised = np.std(np.asarray(est), axis=0, ddof=1)
    ratio = realised / predicted
    print(f"Monte Carlo sigma / predicted over {draws} draws: {ratio.min():.2f}-{ratio.max():.2f} (target 0.7-1.4)")


if __name__ == "__main__":
    main()
