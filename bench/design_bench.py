# SPDX-License-Identifier: BSD-3-Clause
"""Figures of the ballbar test design (docs/design.md) on the Table 2 machine (AC-trt, the
default set-up of Flynn et al. Table 1): the designed single set-up's largest expanded
uncertainty of the location errors against the default plan's at the same run time (target
<= 0.7), the design time (target <= 10 s), and whether the predicted 1-sigma is what simulated
tests of the designed set-up realise (Monte Carlo sigma / predicted, target 0.7-1.4).

After a session of that machine (simulated with hidden C error motions and AR(1) noise,
rho 0.5): the added test that separates axial_motion_C_h2 from tilt_motion_C_h2 (target:
correlation < 0.5 with one added test of <= 10 min, design <= 10 s), its Monte Carlo check
(session and added test simulated again and fitted jointly: realised / predicted sigma, target
0.7-1.4), and gravity_sag_A against radial_motion_A_h2 (target: reported inseparable).

R-test (Oyama and Ibaraki's B/C table and pattern): the designed nests and grid against the
default pattern at the same run time, the design time, and the Monte Carlo check of the
designed pattern under AR(1) noise (rho 0.4).

Touch probe: the designed poses, touch directions and sphere place against `plan probe`'s
default poses at the default sphere and the same 120 touches on the built-in machines (target
<= 0.7), and the design time (CPU and wall).

    PYTHONPATH=... python bench/design_bench.py            # the default grid, 100 draws
    PYTHONPATH=... python bench/design_bench.py --smoke    # a 2 x 2 grid, 3 draws: that it runs (CI)
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
    draws = 3 if a.smoke else a.draws  # smoke: the fewest a sigma (ddof 1) of is a figure
    t0 = time.perf_counter()
    d = design_ballbar(base, time_s=0.0, rate_hz=100.0, noise_um=0.5, **kw)
    elapsed = time.perf_counter() - t0
    print(f"design: {len(d.candidates)} set-ups in {elapsed:.2f} s (target <= 10 s)")
    for label, c in (("designed", d.best), ("default", d.baseline)):
        print(
            f"{label:9s} L0 {c.setup.ballbar_length:g} mm, pivot {tuple(float(v) for v in c.setup.pivot)}: "
            f"largest U (k=2) {c.worst_expanded_um:.4f} um ({c.worst_error}) at {d.time_budget_s:.0f} s"
        )
    print(f"ratio designed / default at the same run time: {d.ratio:.3f} (target <= 0.7)")

    # Monte Carlo at the plan's own sampling: the recorder rate that records the plan's samples.
    setup = d.best.setup
    plan = _core.plan_ballbar_test(setup, None)
    cmd = plan.commanded_session()
    t = np.asarray(cmd.time)
    tests = np.asarray(cmd.tests, dtype=object)
    t_tests = sum(t[tests == lab].max() - t[tests == lab].min() for lab in dict.fromkeys(tests))
    check = design_ballbar(
        setup,
        lengths=[setup.ballbar_length],
        pivot_x=[setup.pivot[0]],
        pivot_z=[setup.pivot[2]],
        rate_hz=len(cmd) / t_tests,
        noise_um=0.5,
    )
    predicted = np.asarray(check.best.sigma)[:8]
    names = list(_core.location_error_names(setup.machine))
    truth = _core.BallbarMachineModel(
        setup.machine, np.array([TABLE2_ERRORS[n] for n in names]), np.asarray(setup.pivot), [], []
    )
    est = []
    for k in range(draws):
        s = _core.simulate_ballbar(cmd, truth, 0.5, 100 + k, True)
        ident = _core.identify_joint(s)
        est.append([p.value for p in ident.parameters[:8]])
    realised = np.std(np.asarray(est), axis=0, ddof=1)
    ratio = realised / predicted
    print(
        f"Monte Carlo sigma / predicted over {draws} draws: {ratio.min():.2f}-{ratio.max():.2f} (target 0.7-1.4)"
    )
    separation(draws)
    rtest_design(draws)
    probe_design()


SEPARATE = ["axial_motion_C_h2", "tilt_motion_C_h2"]


def recorded(cmd, truth_of, rho: float, seed: int):
    """A session as a recorder gives it: the exact lengths of the machine plus AR(1) noise."""
    s = _core.simulate_ballbar(cmd, truth_of(cmd), 0.0, seed, False)
    e = _core.noise_ar1(list(s.tests), list(s.time), rho, 0.5e-3, seed)
    return s.with_lengths(np.asarray(s.length) + e)


def separation(draws: int) -> None:
    names = list(_core.location_error_names(_core.BallbarSetup().machine))
    errors = np.array([TABLE2_ERRORS[n] for n in names])

    def truth_of(cmd):  # the Table 2 machine with hidden C error motions (um, urad)
        return _core.BallbarMachineModel(
            cmd.machine,
            errors,
            np.asarray(cmd.pivot),
            SEPARATE,
            [1e-3, -0.6e-3, 0.0, 0.0, 3e-6, -2e-6],
        )

    base = _core.BallbarSetup()
    base.step_deg = 2.0
    cmd = _core.plan_ballbar_test(base, None).commanded_session()
    rho = 0.5
    session = recorded(cmd, truth_of, rho, 7)
    o = _core.SeparationOptions()
    o.added = base
    t0 = time.perf_counter()
    d = _core.design_ballbar_separation(session, SEPARATE, o)
    elapsed = time.perf_counter() - t0
    c = d.chosen
    print(
        f"separate {SEPARATE[0]} / {SEPARATE[1]} after a Table 2 session (AR(1) rho {rho}): "
        f"{d.candidates_tried} added tests in {elapsed:.2f} s (target <= 10 s)"
    )
    print(f"  {d.verdict}")
    print(
        f"  correlation {d.correlation_before:.2f} -> {c.correlation:.2f} (target < 0.5) with one added test of "
        f"{c.duration_s * c.slow_down:.0f} s (target <= 600 s)"
    )
    # Monte Carlo: the session and the added test (run slower: more readings) simulated again
    # and fitted jointly; the spread of every determined estimate against its prediction.
    added = c.setup
    added.step_deg = added.step_deg / c.slow_down
    add_cmd = _core.plan_ballbar_test(added, None).commanded_session()
    # The several-session identification, white; the pivot shared unless the design moved it.
    est = []
    for k in range(draws):
        f = _core.identify_multi(
            [
                ("session", recorded(cmd, truth_of, rho, 1000 + k)),
                ("added", recorded(add_cmd, truth_of, rho, 5000 + k)),
            ],
            noise="white",
            effects=SEPARATE,
            same_setup={} if c.new_pivot else {"added": "session"},
        )
        # the design's order: 8 location, the session's pivot, effects, the moved pivot
        moved = f.sessions[1].nuisances if c.new_pivot else []
        order = f.location_errors + f.sessions[0].nuisances + f.effects + moved
        est.append([e.value for e in order])
    realised = np.std(np.asarray(est), axis=0, ddof=1)
    predicted = np.asarray(d.sigma_after)
    ok = np.isfinite(predicted)
    ratio = realised[ok] / predicted[ok]
    print(
        f"  Monte Carlo sigma / predicted of the {ok.sum()} determined parameters over {draws} draws: "
        f"{ratio.min():.2f}-{ratio.max():.2f} (target 0.7-1.4)"
    )
    t0 = time.perf_counter()
    g = _core.design_ballbar_separation(session, ["gravity_sag_A", "radial_motion_A_h2"], o)
    print(
        f"gravity_sag_A / radial_motion_A_h2 in {time.perf_counter() - t0:.2f} s: "
        f"{'inseparable' if g.motion.same_motion else 'separable'} (target: inseparable)"
    )
    print(f"  {g.verdict}")


def rtest_design(draws: int) -> None:
    t0 = time.perf_counter()
    o = _core.RtestDesignOptions()
    o.noise_um, o.noise_rho = 0.3, 0.4
    d = _core.design_rtest_test(o)
    elapsed = time.perf_counter() - t0
    print(f"R-test design: {len(d.candidates)} patterns in {elapsed:.2f} s (target <= 10 s)")
    for label, c in (("designed", d.best), ("default", d.baseline)):
        p = c.pattern
        print(
            f"  {label:9s} nests {[tuple(float(v) for v in n) for n in p.nests]}, B {len(p.b_deg)} x C {len(p.c_deg)}, "
            f"{c.duration_s:.0f} s: largest U (k=2) {c.worst_expanded_um:.4f} um ({c.worst_error})"
        )
    print(f"  ratio designed / default at {d.time_budget_s:.0f} s: {d.ratio:.3f}")
    # Monte Carlo of the designed pattern at its own run time (no repeats), AR(1) noise.
    c = (
        _core.evaluate_rtest_design(d.best.pattern, o, 0.0)
        if hasattr(_core, "evaluate_rtest_design")
        else None
    )
    if c is None:
        return
    p = c.pattern
    est = []
    for k in range(draws):
        s, _ = rtest_session(p, k)
        e = _core.noise_ar1(
            np.repeat(s.setups, 3).tolist(),
            np.repeat(s.time, 3).tolist(),
            o.noise_rho,
            o.noise_um * 1e-3,
            900 + k,
        ).reshape(-1, 3)
        s = s.with_displacements(np.asarray(s.d) + e)
        ident = _core.identify_rtest_joint(s, noise="auto")  # GLS under the fitted AR model
        est.append([p_.value for p_ in ident.parameters[:8]])
    ratio = np.std(np.asarray(est), axis=0, ddof=1) / np.asarray(c.sigma)[:8]
    print(
        f"  Monte Carlo sigma / predicted of the designed pattern over {draws} draws: "
        f"{ratio.min():.2f}-{ratio.max():.2f} (target 0.7-1.4)"
    )
    # After an R-test session of the default pattern (noise 0.3 um): the nest that separates
    # axial from tilt motion of C, and gravity sag from the second radial harmonic of B.
    s, _ = rtest_session(o.base, 0)
    s = s.with_displacements(
        np.asarray(s.d) + np.random.default_rng(5).normal(0.0, 0.3e-3, np.asarray(s.d).shape)
    )
    for pair in (
        ["axial_motion_C_h2", "tilt_motion_C_h2"],
        ["gravity_sag_B", "radial_motion_B_h2"],
    ):
        t0 = time.perf_counter()
        sep = _core.design_rtest_separation(s, pair)
        took = f"{sep.candidates_tried} added nests in {time.perf_counter() - t0:.2f} s"
        if sep.motion.same_motion:
            print(f"R-test separate {pair[0]} / {pair[1]}: inseparable (same table motion), {took}")
        else:
            print(
                f"R-test separate {pair[0]} / {pair[1]}: {took}; correlation {sep.correlation_before:.2f} -> "
                f"{sep.chosen.correlation:.2f} with {sep.chosen.duration_s * sep.chosen.repeats:.0f} s"
            )
        print(f"  {sep.verdict[:200]}")


def probe_design() -> None:
    from rotacal.probe_design import design_probe
    from rotacal.machines import load_machine

    for name in ("AC-trt", "BC-trt", "B45C-trt", "B-head-C-table", "AC-head"):
        t0, c0 = time.perf_counter(), time.process_time()
        d = design_probe(load_machine(name))
        took, cpu = time.perf_counter() - t0, time.process_time() - c0
        b = d.baseline
        default = f"{b.worst_expanded_um:.3f} um ({b.worst_error})" if b.feasible else b.why_not
        sphere = ", ".join(f"{v:g}" for v in d.sphere)
        print(
            f"probe design {name}: {d.poses_tried} poses, {d.touches_tried} touches tried, {len(d.spheres)} sphere "
            f"places in {cpu:.2f} s CPU ({took:.2f} s wall); sphere at {sphere}; {d.touches} touches, designed "
            f"{d.best.worst_expanded_um:.3f} um ({d.best.worst_error}) / default {default}: ratio {d.ratio:.3f}"
        )


def rtest_session(p, k: int):
    from rotacal import rtest

    errors = {
        "E_X0B": 0.02,
        "E_Z0B": -0.015,
        "E_A0B": 3e-5,
        "E_C0B": -2e-5,
        "E_X0C": 0.01,
        "E_Y0C": 0.025,
        "E_A0C": 1.5e-5,
        "E_B0C": -4e-5,
    }
    return rtest.simulate_rtest(
        errors,
        {},
        machine="BC-trt",
        b_deg=list(p.b_deg),
        c_deg=list(p.c_deg),
        # the noise is added as AR(1) by the caller; 1e-6 um white here only
        # so that the session declares a noise level (the fit needs one)
        nests=[list(map(float, n)) for n in p.nests],
        noise_um=1e-6,
        probe_zero_um=20.0,
        probe_dirs=None,
        write_d=True,
        dwell_s=p.dwell_s,
        seed=100 + k,
    )


if __name__ == "__main__":
    main()
