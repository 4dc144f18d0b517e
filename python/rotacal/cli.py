"""The ``rotacal`` command line.

Exit codes: 0 success; 2 usage error; 3 invalid input (a malformed file, a bad parameter, a
degenerate geometry); 4 I/O error (cannot read or write a file or device); 5 any other
rotacal error.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Sequence

import numpy as np

from . import _core
from .ballbar import identify, predict, random_location_errors
from .diagnosis import diagnose
from .models import ballbar_model_from_dict, load_model, save_model
from .rtest import DEFAULT_DWELL_S, DEFAULT_NOISE_UM, DEFAULT_PROBE_ZERO_UM
from .sessions import load, save

EXIT_OK, EXIT_USAGE, EXIT_INPUT, EXIT_IO, EXIT_ERROR = 0, 2, 3, 4, 5

EPILOG = ("exit codes: 0 success, 2 usage error, 3 invalid input (malformed file, bad parameter, "
          "degenerate geometry), 4 I/O error, 5 other rotacal error")

# Flynn et al. 2016, Table 2, uncompensated: the machine of the paper's experiment.
TABLE2_ERRORS = {"E_Y0A": 0.0726, "E_Z0A": -0.0202, "E_B0A": 1.1284e-05, "E_C0A": -0.000113006,
                 "E_X0C": 0.0283, "E_Y0C": 0.1041, "E_A0C": 5.1954e-06, "E_B0C": -4.1544e-05}


def _say(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def _floats(text: str, n: int, what: str) -> list[float]:
    try:
        vals = [float(v) for v in text.split(",")]
    except ValueError:
        raise _core.InvalidArgument(f"{what}: '{text}' is not {n} comma-separated numbers") from None
    if len(vals) != n or not all(np.isfinite(vals)):
        raise _core.InvalidArgument(f"{what}: '{text}' must be {n} finite comma-separated numbers")
    return vals


# ------------------------------------------------------------------------- plan and set-up

def _add_setup_args(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("test set-up (Flynn et al. 2016, Table 1)")
    g.add_argument("--machine", default="AC-trt", help="AC-trt or BC-trt (default AC-trt)")
    g.add_argument("--length", type=float, default=100.0, help="calibrated ballbar length L0, mm")
    g.add_argument("--pivot", default="120,0,60", help="nominal pivot x,y,z on the table, mm (O_x, 0, O_z)")
    g.add_argument("--a-range", "--b-range", dest="tilt_range", default="-90,90",
                   help="tilt axis range, deg (A for AC-trt, B for BC-trt)")
    g.add_argument("--c-range", default="0,359", help="C range, deg")
    g.add_argument("--step", type=float, default=1.0, help="sample spacing, deg")
    g.add_argument("--feed", type=float, default=1000.0, help="linear feed, mm/min")
    g.add_argument("--rotary-feed", type=float, default=3600.0, help="rotary feed, deg/min")
    g.add_argument("--tests", default="", help="comma-separated test labels (default: all seven)")
    g.add_argument("--radial-c", default="outside", help="radial C tool circle outside or inside the pivot's")


def _setup(a: argparse.Namespace):
    s = _core.BallbarSetup()
    s.machine = _core.parse_machine_type(a.machine)
    s.ballbar_length = a.length
    s.pivot = np.array(_floats(a.pivot, 3, "--pivot"))
    s.tilt_range_deg = np.array(_floats(a.tilt_range, 2, "--a-range/--b-range"))
    s.rot_range_deg = np.array(_floats(a.c_range, 2, "--c-range"))
    s.step_deg = a.step
    s.feed_mm_per_min = a.feed
    s.feed_deg_per_min = a.rotary_feed
    if a.tests:
        s.tests = [_core.parse_ballbar_test(t.strip(), s.machine) for t in a.tests.split(",")]
    s.radial_c_side = _core.parse_radial_side(a.radial_c)
    return s


def cmd_plan(a: argparse.Namespace) -> int:
    setup = _setup(a)
    identified = None
    if a.compensate:
        model = ballbar_model_from_dict(load_model(a.compensate), a.compensate)
        if model.machine != setup.machine:
            raise _core.InvalidArgument(f"{a.compensate}: model is for {_core.machine_name(model.machine)}")
        identified = model.errors
    plan = _core.plan_ballbar_test(setup, identified)
    text = _core.write_nc_program(plan, _core.parse_nc_dialect(a.dialect))
    Path(a.output).write_text(text)
    _say(f"wrote {a.output}: {a.dialect} program, {plan.num_samples} points, {plan.duration:.0f} s"
         + (" (compensated)" if identified is not None else ""))
    if a.session:
        save(plan.commanded_session(), a.session)
        _say(f"wrote {a.session}: the commanded rows as a session template")
    return EXIT_OK


# ------------------------------------------------------------------------- simulate

def _truth(a: argparse.Namespace, machine) -> dict:
    names = list(_core.location_error_names(machine))
    rng = np.random.default_rng(a.seed)
    if a.errors == "random":
        errors = dict(zip(names, random_location_errors(machine, rng).tolist()))
    elif a.errors == "table2":
        if machine != _core.MachineType.AC_trt:
            raise _core.InvalidArgument("--errors table2 is the paper's AC-trt machine")
        errors = dict(TABLE2_ERRORS)
    elif a.errors == "zero":
        errors = {n: 0.0 for n in names}
    else:
        errors = {n: 0.0 for n in names}
        for item in a.errors.split(","):
            key, _, val = item.partition("=")
            if key.strip() not in names:
                raise _core.InvalidArgument(f"--errors: '{key}' is not a location error of {_core.machine_name(machine)}")
            errors[key.strip()] = _floats(val, 1, f"--errors {key}")[0]
    effects = {}
    for item in a.effect or []:
        key, _, val = item.partition("=")
        eff = _core.Effect(key.strip())
        effects[eff.id] = _floats(val, eff.num_params, f"--effect {key}")
    return {"errors": errors, "pivot_error": (rng.normal(0.0, a.pivot_error, 3)).tolist(),
            "effects": effects, "noise_um": a.noise, "seed": a.seed}


def machine_model(setup, truth: dict):
    """The simulated machine described by `truth` (errors, pivot error, effects)."""
    names = list(_core.location_error_names(setup.machine))
    ids = list(truth["effects"].keys())
    params = [v for i in ids for v in truth["effects"][i]]
    return _core.BallbarMachineModel(setup.machine, np.array([truth["errors"][n] for n in names]),
                                     np.asarray(setup.pivot) + np.array(truth["pivot_error"]), ids, params)


def simulate_session(setup, truth: dict):
    """Plan the test, run it on the machine described by `truth`, return (session, model)."""
    plan = _core.plan_ballbar_test(setup, None)
    model = machine_model(setup, truth)
    return _core.simulate_ballbar(plan.commanded_session(), model, truth["noise_um"], truth["seed"]), model


def cmd_simulate(a: argparse.Namespace) -> int:
    setup = _setup(a)
    truth = _truth(a, setup.machine)
    session, model = simulate_session(setup, truth)
    save(session, a.output)
    truth["pivot_actual"] = model.pivot.tolist()
    if a.truth:
        Path(a.truth).write_text(json.dumps(truth, indent=1) + "\n")
    _say(f"wrote {a.output}: {len(session)} samples on a simulated {a.machine}"
         + (f", truth in {a.truth}" if a.truth else ""))
    return EXIT_OK


def _named_values(text: str, names: list[str], what: str) -> dict[str, float]:
    """'NAME=VALUE,NAME=VALUE' -> dict, every NAME one of `names`."""
    out: dict[str, float] = {}
    for item in text.split(","):
        key, _, val = item.partition("=")
        if key.strip() not in names:
            raise _core.InvalidArgument(f"{what}: '{key}' is not one of {', '.join(names)}")
        out[key.strip()] = _floats(val, 1, f"{what} {key}")[0]
    return out


def _rtest_inputs(a: argparse.Namespace) -> dict:
    """The pattern and simulated machine of `simulate rtest` / `virtual rtest` / `record rtest`."""
    from . import rtest
    machine = _core.parse_machine_type(a.machine)
    b0, b1 = _floats(a.tilt_range, 2, "--b-range")
    c0, c1 = _floats(a.c_range, 2, "--c-range")
    out = {"machine": a.machine,
           "b_deg": rtest.angle_grid(b0, b1, a.b_step, "--b-range/--b-step"),
           "c_deg": rtest.angle_grid(c0, c1, a.c_step, "--c-range/--c-step", full_turn=True),
           "nests": [_floats(n, 3, "--nest") for n in a.nest] if a.nest else rtest.DEFAULT_NESTS,
           "dwell_s": a.dwell, "probe_dirs": None}
    if getattr(a, "errors", None) is not None:
        out["errors"] = a.errors if a.errors in ("random", "zero") else _named_values(
            a.errors, list(_core.location_error_names(machine)), "--errors")
        effects = {}
        for item in a.effect or []:
            key, _, val = item.partition("=")
            eff = _core.Effect(key.strip())
            effects[eff.id] = _floats(val, eff.num_params, f"--effect {key}")
        out["effects"] = effects
    if a.probe_dir:
        if len(a.probe_dir) != 3:
            raise _core.InvalidArgument(f"--probe-dir: give it 3 times (probes 1, 2, 3), got {len(a.probe_dir)}")
        dirs = np.array([_floats(d, 3, "--probe-dir") for d in a.probe_dir])
        out["probe_dirs"] = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
    return out


def cmd_simulate_rtest(a: argparse.Namespace) -> int:
    from . import rtest
    r = _rtest_inputs(a)
    b_deg, c_deg, nests, dirs = r["b_deg"], r["c_deg"], r["nests"], r["probe_dirs"]
    errors, effects = r["errors"], r["effects"]
    if dirs is None and a.raw_only:
        raise _core.InvalidArgument("--raw-only needs the probe directions (--probe-dir x3)")
    session, truth = rtest.simulate_rtest(errors, effects, machine=a.machine, b_deg=b_deg, c_deg=c_deg,
                                          nests=nests, noise_um=a.noise, probe_zero_um=a.probe_zero,
                                          probe_dirs=dirs, write_d=not a.raw_only, dwell_s=a.dwell,
                                          seed=a.seed)
    save(session, a.output)
    truth_path = Path(a.truth) if a.truth else Path(a.output).with_suffix(".truth.json")
    rtest.save_truth(truth, truth_path)
    _say(f"wrote {a.output}: {len(session)} poses ({len(b_deg)} B x {len(c_deg)} C x {len(nests)} nests) "
         f"on a simulated {a.machine}, truth in {truth_path}")
    return EXIT_OK


# ------------------------------------------------------------------------- analyse

def _ballbar(path: str):
    s = load(path)
    if not isinstance(s, _core.BallbarSession):
        raise _core.InvalidArgument(f"{path}: this command needs a rotacal-ballbar/1 session")
    return s


def _print_identification(d: dict) -> None:
    print(f"{d['method']} identification, {d['machine']}, {d['n_samples']} samples, "
          f"residual RMS {d['residual_rms_um']:.3f} um")
    for name, p in d["location_errors"].items():
        if p["value"] is None:
            print(f"  {name:6s}  unobservable")
        elif p["unit"] == "mm":
            print(f"  {name:6s} {p['value'] * 1e3:+9.3f} um  +- {p['std'] * 1e3:.3f}")
        else:
            print(f"  {name:6s} {p['value'] * 1e6:+9.3f} urad +- {p['std'] * 1e6:.3f}")
    for axis, p in d["pivot"].items():
        print(f"  pivot {axis}  " + ("unobservable" if p["value"] is None else f"{p['value']:.4f} mm +- {p['std'] * 1e3:.3f} um"))
    for u in d["unobservable"]:
        print(f"  not determined by these tests: {u}")
    mc = d.get("monte_carlo")
    if mc:
        print(f"Monte Carlo check of the 1-sigma, {mc['draws']} draws at {mc['noise_um']:.3f} um noise "
              "(ratio = Monte Carlo sigma / reported sigma):")
        for name, m in mc["parameters"].items():
            scale, unit = (1e6, "urad") if m["unit"] == "rad" else (1e3, "um")
            print(f"  {name:16s} reported {m['std_reported'] * scale:8.3f}  Monte Carlo {m['std_mc'] * scale:8.3f} "
                  f"{unit:4s}  ratio {m['ratio']:.2f}")


def cmd_identify(a: argparse.Namespace) -> int:
    s = load(a.file)
    result = identify(s, a.method, fit_length_offset=a.length_offset)
    d = result.to_dict()
    if a.monte_carlo:
        if not isinstance(s, _core.BallbarSession):
            raise _core.InvalidArgument("--monte-carlo: for ballbar sessions")
        from .ballbar import monte_carlo
        d["monte_carlo"] = monte_carlo(s, result, a.monte_carlo, seed=a.seed)
    if a.save_model:
        save_model(result.model_dict(), a.save_model)
        _say(f"wrote {a.save_model}")
    if a.json or isinstance(s, _core.RtestSession):
        print(json.dumps(d, indent=1))
    else:
        _print_identification(d)
    return EXIT_OK


def cmd_diagnose(a: argparse.Namespace) -> int:
    s = load(a.file)
    result = diagnose(s, max_harmonic=a.max_harmonic)
    d = result.to_dict()
    if a.report:
        from .report import ballbar_report, diagnosis_report
        if isinstance(s, _core.BallbarSession):
            ballbar_report(a.report, s, identify(s), result, source=a.file)
        else:
            diagnosis_report(a.report, d, title="R-test diagnosis", source=a.file)
        _say(f"wrote {a.report}")
    if a.json:
        print(json.dumps(d, indent=1))
        return EXIT_OK
    b = d["baseline"]
    print(f"baseline: residual RMS {b['residual_rms_um']:.3f} um, noise {b['noise_um']:.3f} um "
          f"({b['noise_source']}), chi2/dof {b['chi2_per_dof']:.2f}")
    if not d["findings"]:
        print("no effect of the catalogue is significant")
    for i, f in enumerate(d["findings"], 1):
        g = f["gain"]
        print(f"{i}. {f['effect']}: {f['cause']}")
        for name, p in f["parameters"].items():
            print(f"     {name} = " + ("unobservable" if p["value"] is None else f"{p['value']:.4g} +- {p['std']:.2g} {p['unit']}"))
        print(f"     RMS {g['rms_before_um']:.3f} -> {g['rms_after_um']:.3f} um, delta BIC {g['delta_bic']:.1f}, "
              f"CV RMS {g['cv_rms_before_um']:.3f} -> {g['cv_rms_after_um']:.3f} um")
    for amb in d["ambiguous"]:
        print(f"cannot be told apart with this data: {', '.join(amb['effects'])} ({amb['separating_test']})")
    if d["unexplained"]["present"]:
        print(f"unexplained structure remains: {d['unexplained']['signature']}")
    print(f"{len(d['unobservable'])} catalogue entries are invisible to this session's tests "
          "(--json lists them with reasons)")
    return EXIT_OK


def cmd_predict(a: argparse.Namespace) -> int:
    model_dict = load_model(a.model)
    s = load(a.session)
    if isinstance(s, _core.RtestSession):
        from . import rtest
        out = rtest.predict_rtest(model_dict, s, a.probe_zeros, source=a.model)
        if rtest._has_displacements(s) or s.probe_dirs:
            _say(f"measured - predicted: RMS {rtest.prediction_rms_um(model_dict, s, a.model):.3f} um over "
                 f"{len(s)} poses (one constant per set-up removed: its probe zero)")
    elif a.probe_zeros != "none":
        raise _core.InvalidArgument("predict: --probe-zeros is for R-test sessions")
    else:
        out = predict(ballbar_model_from_dict(model_dict, a.model), s)
        res = (s.length - out.length) * 1e3
        _say(f"measured - predicted: RMS {np.sqrt(np.mean(res ** 2)):.3f} um over {len(s)} samples")
    save(out, a.output)
    _say(f"wrote {a.output}")
    return EXIT_OK


def compensation_table(report) -> list[dict]:
    return [{"name": r.name, "unit": r.unit, "before": r.before, "after": r.after,
             "std_after": r.std_after, "change_percent": r.change_percent} for r in report.rows]


def _print_compensation(rows: list[dict]) -> None:
    print("error    uncompensated   compensated    change   (Flynn et al. Table 2 layout)")
    for r in rows:
        k, unit = (1e3, "um") if r["unit"] == "mm" else (1e6, "urad")
        print(f"{r['name']:6s} {r['before'] * k:+12.3f} {r['after'] * k:+12.3f} {unit:4s} {r['change_percent']:+8.1f} %")


def cmd_compensate(a: argparse.Namespace) -> int:
    setup = _setup(a)
    if a.model:
        model = ballbar_model_from_dict(load_model(a.model), a.model)
        plan = _core.plan_ballbar_test(setup, model.errors)
        Path(a.output).write_text(_core.write_nc_program(plan, _core.parse_nc_dialect(a.dialect)))
        _say(f"wrote {a.output}: compensated {a.dialect} program")
    if a.verify:
        truth = _truth(a, setup.machine)
        _, machine = simulate_session(setup, truth)
        commanded = _core.plan_ballbar_test(setup, None).commanded_session()
        _say("measuring, identifying, compensating and measuring again on the simulated machine ...")
        rep = _core.verify_compensation(commanded, machine, truth["noise_um"], truth["seed"])
        rows = compensation_table(rep)
        if a.json:
            print(json.dumps(rows, indent=1))
        else:
            _print_compensation(rows)
    if not a.model and not a.verify:
        raise _core.InvalidArgument("compensate: give --model MODEL.json (write a program) and/or --verify")
    return EXIT_OK


def cmd_report(a: argparse.Namespace) -> int:
    from .report import ballbar_report, rtest_report
    s = load(a.file)
    if isinstance(s, _core.RtestSession):
        from .rtest import identify_rtest, with_displacements
        if a.method != "joint":
            raise _core.InvalidArgument("report: an R-test report draws the joint fit's smooth maps; the paper "
                                        "method's per-angle map is in `rotacal identify --method paper`")
        s, _ = with_displacements(s)  # raw d1,d2,d3 with the file's probe.N.dir (identify notes it too)
        ident = identify_rtest(s, "joint")
        d = diagnose(s) if not a.no_diagnosis else None
        rtest_report(a.output, s, ident, d, source=a.file)
        print(Path(a.output).resolve())
        return EXIT_OK
    s = _ballbar(a.file)
    ident = identify(s, a.method)
    d = diagnose(s) if not a.no_diagnosis else None
    ballbar_report(a.output, s, ident, d, source=a.file)
    print(Path(a.output).resolve())
    return EXIT_OK


# ------------------------------------------------------------------------- demo (main job)

def cmd_demo(a: argparse.Namespace) -> int:
    """Simulate a machine with errors and one hidden effect, measure, identify, diagnose,
    compensate, and write a report."""
    from .report import ballbar_report
    out = Path(a.output)
    out.mkdir(parents=True, exist_ok=True)
    steps = 6
    t0 = time.monotonic()

    def step(i: int, what: str) -> None:
        _say(f"[{i}/{steps}] {what} ({time.monotonic() - t0:.1f} s)")

    step(1, "planning the single set-up ballbar test (AC-trt, L0 = 100 mm, pivot 120, 0, 60)")
    setup = _core.BallbarSetup()
    plan = _core.plan_ballbar_test(setup, None)
    (out / "ballbar_test.ngc").write_text(_core.write_nc_program(plan, _core.parse_nc_dialect("linuxcnc")))
    (out / "ballbar_test.h").write_text(_core.write_nc_program(plan, _core.parse_nc_dialect("heidenhain")))

    step(2, "simulating the machine of Flynn et al. Table 2 with a pivot set-up error and a hidden effect")
    truth = {"errors": dict(TABLE2_ERRORS), "pivot_error": [0.012, -0.008, 0.015],
             "effects": {"gravity_sag_A": [a.sag]}, "noise_um": 0.5, "seed": a.seed}
    session, machine = simulate_session(setup, truth)
    save(session, out / "session.csv")
    truth["pivot_actual"] = machine.pivot.tolist()
    (out / "truth.json").write_text(json.dumps(truth, indent=1) + "\n")

    step(3, "identifying the location errors (joint Ceres fit)")
    ident = identify(session)
    save_model(ident.model_dict(), out / "model.json")
    (out / "identification.json").write_text(json.dumps(ident.to_dict(), indent=1) + "\n")

    step(4, "diagnosing what the location-error model gets wrong")
    diag = diagnose(session, reference=plan.commanded_session())
    dd = diag.to_dict()
    (out / "diagnosis.json").write_text(json.dumps(dd, indent=1) + "\n")

    step(5, "compensating and measuring again (Table 2 experiment)")
    rows = compensation_table(_core.verify_compensation(plan.commanded_session(), machine, 0.5, a.seed))
    (out / "compensation.json").write_text(json.dumps(rows, indent=1) + "\n")

    step(6, "writing the report")
    comp_html = ["<section id='compensation'><h2>Compensation (Flynn et al. Table 2 experiment, simulated)</h2>"
                 "<table><tr><th class=l>Error</th><th>Uncompensated</th><th>Compensated</th><th>Change</th></tr>"]
    for r in rows:
        k, unit = (1e3, "&micro;m") if r["unit"] == "mm" else (1e6, "&micro;rad")
        comp_html.append(f"<tr><td class=l>{r['name']}</td><td>{r['before'] * k:+.2f} {unit}</td>"
                         f"<td>{r['after'] * k:+.2f} {unit}</td><td>{r['change_percent']:+.1f} %</td></tr>")
    comp_html.append("</table></section>")
    report = ballbar_report(out / "report.html", session, ident, diag, title="rotacal demo: single set-up ballbar test",
                            source=str(out / "session.csv"), extra_sections=["\n".join(comp_html)])

    print(f"hidden effect: gravity_sag_A, s = {a.sag * 1e3:.1f} um")
    if dd["findings"]:
        f = dd["findings"][0]
        p = next(iter(f["parameters"].values()))
        print(f"diagnosis found: {f['effect']} ({f['cause']}), "
              + (f"s = {p['value'] * 1e3:.2f} +- {p['std'] * 1e3:.2f} um" if p["value"] is not None else "unobservable"))
    else:
        print("diagnosis found nothing significant")
    worst = max(r["change_percent"] for r in rows)
    print(f"compensation reduced every location error by at least {-worst:.1f} %")
    print(f"report: {report.resolve()}")
    return EXIT_OK


# ------------------------------------------------------------------------- instruments

def _faults(a: argparse.Namespace):
    f = _core.FaultInjection()
    f.garbage_every, f.corrupt_every, f.drop_every = a.fault_garbage, a.fault_corrupt, a.fault_drop
    f.split_frames = a.fault_split
    f.close_after, f.silence_after = a.fault_unplug_after, a.fault_silence_after
    return f


def _serve(dev, what: str, a: argparse.Namespace, detail: str) -> int:
    """Print the device path, then serve until Ctrl-C (or the program's end with --exit-when-done)."""
    print(dev.port, flush=True)
    _say(f"virtual {what} on {dev.port} ({detail}); Ctrl-C to stop")
    try:
        while not (a.exit_when_done and dev.finished):
            time.sleep(0.05)
        time.sleep(0.5)  # let the host read the last bytes before the line goes away
    except KeyboardInterrupt:
        pass
    dev.stop()
    st = dev.stats()
    _say(f"virtual {what}: {st['frames_sent']} frames, {st['replies_sent']} replies, "
         f"{st['frames_dropped']} dropped and {st['frames_corrupted']} corrupted on purpose"
         + (", program finished" if st["finished"] else ""))
    return EXIT_OK


def cmd_virtual_ballbar(a: argparse.Namespace) -> int:
    from .instruments import virtual_ballbar
    setup = _setup(a)
    truth = _truth(a, setup.machine)
    plan = _core.plan_ballbar_test(setup, None)
    model = machine_model(setup, truth)
    truth["pivot_actual"] = model.pivot.tolist()
    if a.truth:
        Path(a.truth).write_text(json.dumps(truth, indent=1) + "\n")
    dev = virtual_ballbar(plan, model, noise_um=a.noise, seed=a.seed, rate_hz=a.rate, speed=a.speed,
                          baud=a.baud, faults=_faults(a))
    return _serve(dev, "ballbar", a, f"{plan.duration:.1f} s program at {a.rate:g} Hz, speed x{a.speed:g}")


def cmd_virtual_rtest(a: argparse.Namespace) -> int:
    from .instruments import virtual_rtest
    r = _rtest_inputs(a)
    dev, truth = virtual_rtest(r["errors"], r["effects"], machine=r["machine"], b_deg=r["b_deg"], c_deg=r["c_deg"],
                               nests=r["nests"], dwell_s=r["dwell_s"], noise_um=a.noise, probe_zero_um=a.probe_zero,
                               probe_dirs=r["probe_dirs"], seed=a.seed, mode=a.mode, rate_hz=a.rate,
                               speed=a.speed, baud=a.baud, faults=_faults(a))
    if a.truth:
        Path(a.truth).write_text(json.dumps(truth, indent=1) + "\n")
    return _serve(dev, "R-test", a, f"{a.mode} mode, {len(dev.program)} poses, speed x{a.speed:g}")


# Exit code of a recording by how it stopped: the data are in the file either way.
_RECORD_EXIT = {"end of program": EXIT_OK, "stopped": EXIT_OK, "device disconnected": EXIT_IO,
                "silence (timeout)": EXIT_IO, "no valid data": EXIT_IO}


def _report_recording(summary, path: str, json_out: bool) -> int:
    if json_out:
        print(json.dumps({k: getattr(summary, k) for k in ("rows", "frames", "lost", "crc_errors", "malformed",
                                                              "garbage_bytes", "over_range", "timeouts",
                                                              "reason", "detail")} | {"path": path}))
    _say(f"wrote {path}: {summary.describe()}")
    return _RECORD_EXIT[summary.reason]


def cmd_record_ballbar(a: argparse.Namespace) -> int:
    from .instruments import record_ballbar
    plan = _core.plan_ballbar_test(_setup(a), None)
    summary = record_ballbar(a.port, plan, a.output, baud=a.baud, rate_hz=a.rate, zero=a.zero,
                             silence_timeout_s=a.silence, progress=not a.no_progress)
    return _report_recording(summary, a.output, a.json)


def cmd_record_rtest(a: argparse.Namespace) -> int:
    from .instruments import record_rtest, rtest_program
    r = _rtest_inputs(a)
    program = rtest_program(r["machine"], r["b_deg"], r["c_deg"], r["nests"], r["dwell_s"])
    summary = record_rtest(a.port, program, a.output, mode=a.mode, dwell_s=r["dwell_s"], probe_dirs=r["probe_dirs"],
                           baud=a.baud, rate_hz=a.rate, speed=a.speed, silence_timeout_s=a.silence,
                           progress=not a.no_progress)
    return _report_recording(summary, a.output, a.json)


def _add_link_args(q: argparse.ArgumentParser, rate: float) -> None:
    g = q.add_argument_group("serial link")
    g.add_argument("--baud", type=int, default=115200, help="baud rate (default 115200)")
    g.add_argument("--rate", type=float, default=rate, help=f"stream sample rate, Hz (default {rate:g})")


def _add_virtual_args(q: argparse.ArgumentParser) -> None:
    q.add_argument("--speed", type=float, default=1.0, help="virtual seconds per real second (default 1: real time)")
    q.add_argument("--exit-when-done", action="store_true", help="stop serving when the program has run")
    q.add_argument("--truth", metavar="JSON", help="write the simulated machine here")
    g = q.add_argument_group("faults to act out (for testing recorders; 0 or -1: never)")
    g.add_argument("--fault-garbage", type=int, default=0, metavar="N", help="line noise after every Nth frame")
    g.add_argument("--fault-corrupt", type=int, default=0, metavar="N", help="flip a bit in every Nth frame")
    g.add_argument("--fault-drop", type=int, default=0, metavar="N", help="do not send every Nth frame")
    g.add_argument("--fault-split", action="store_true", help="send every frame in two writes")
    g.add_argument("--fault-unplug-after", type=int, default=-1, metavar="N", help="hang up after N frames")
    g.add_argument("--fault-silence-after", type=int, default=-1, metavar="N", help="go silent after N frames")


def _add_record_args(q: argparse.ArgumentParser) -> None:
    q.add_argument("--port", required=True, help="serial port, e.g. /dev/ttyUSB0, /dev/serial/by-id/..., /dev/pts/N")
    q.add_argument("--silence", type=float, default=3.0, help="stop after this many seconds without data")
    q.add_argument("--no-progress", action="store_true", help="no progress bar")
    q.add_argument("--json", action="store_true", help="print the recording summary as JSON")
    q.add_argument("-o", "--output", required=True)


# ------------------------------------------------------------------------- parser

def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="rotacal", description="Calibration of the rotary axes of 5-axis machine tools.",
                                epilog=EPILOG)
    sub = p.add_subparsers(dest="command", required=True)

    q = sub.add_parser("plan", help="plan a test and write its NC program", epilog=EPILOG)
    q.add_argument("kind", choices=["ballbar"])
    _add_setup_args(q)
    q.add_argument("--dialect", default="linuxcnc", help="linuxcnc (machine axes), heidenhain, siemens, fanuc")
    q.add_argument("--compensate", metavar="MODEL.json", help="emit the program compensated for a fitted model")
    q.add_argument("--session", metavar="CSV", help="also write the commanded rows as a session template")
    q.add_argument("-o", "--output", required=True)
    q.set_defaults(func=cmd_plan)

    q = sub.add_parser("simulate", help="simulate a measurement on a machine with errors", epilog=EPILOG)
    kinds = q.add_subparsers(dest="kind", required=True, metavar="{ballbar,rtest}")
    k = kinds.add_parser("ballbar", help="the single set-up ballbar test (Flynn et al. 2016)", epilog=EPILOG)
    _add_setup_args(k)
    _add_truth_args(k)
    k.add_argument("--truth", metavar="JSON", help="write the simulated machine here")
    k.add_argument("-o", "--output", required=True)
    k.set_defaults(func=cmd_simulate)
    k = kinds.add_parser("rtest", help="the R-test pattern of Oyama & Ibaraki Sec. 3.3 on a B/C table",
                         description="Writes a rotacal-rtest/1 session and, beside it, FILE.truth.json "
                                     "(the simulated machine, the probe zeros and the pattern).",
                         epilog=EPILOG)
    _add_rtest_sim_args(k)
    k.set_defaults(func=cmd_simulate_rtest)

    q = sub.add_parser("identify", help="identify location errors from a session", epilog=EPILOG)
    q.add_argument("file")
    q.add_argument("--method", default="joint", choices=["joint", "paper"])
    q.add_argument("--length-offset", action="store_true", help="also fit an offset of L0 (joint)")
    q.add_argument("--json", action="store_true", help="print the result as JSON")
    q.add_argument("--save-model", metavar="MODEL.json",
                   help="write the fitted model (ballbar, or R-test joint: location errors, maps, covariance)")
    q.add_argument("--monte-carlo", type=int, default=0, metavar="N",
                   help="check the 1-sigma by N simulated repeats of the session (ballbar; progress bar)")
    q.add_argument("--seed", type=int, default=1, help="seed of the Monte Carlo draws")
    q.set_defaults(func=cmd_identify)

    q = sub.add_parser("diagnose", help="find what the model gets wrong and why", epilog=EPILOG)
    q.add_argument("file")
    q.add_argument("--max-harmonic", type=int, default=4)
    q.add_argument("--json", action="store_true")
    q.add_argument("--report", metavar="OUT.html")
    q.set_defaults(func=cmd_diagnose)

    q = sub.add_parser("predict", help="predict a session with a fitted model", epilog=EPILOG)
    q.add_argument("session")
    q.add_argument("--model", required=True)
    q.add_argument("--probe-zeros", choices=["none", "fitted"], default="none",
                   help="R-test: add the probe zeros fitted for the same set-ups (same nests), or none "
                        "(default: a new set-up's zeros are unknown)")
    q.add_argument("-o", "--output", required=True,
                   help="the session with predicted lengths (ballbar) or dx,dy,dz and dx_std,dy_std,dz_std (R-test)")
    q.set_defaults(func=cmd_predict)

    q = sub.add_parser("compensate", help="compensated NC program, and its verification in simulation", epilog=EPILOG)
    _add_setup_args(q)
    _add_truth_args(q)
    q.add_argument("--model", metavar="MODEL.json", help="fitted model to compensate")
    q.add_argument("--dialect", default="linuxcnc")
    q.add_argument("-o", "--output", default="compensated.ngc")
    q.add_argument("--verify", action="store_true",
                   help="measure, identify, compensate and measure again on a simulated machine (--errors ...)")
    q.add_argument("--json", action="store_true")
    q.set_defaults(func=cmd_compensate)

    q = sub.add_parser("virtual", help="a virtual instrument on a pseudo-terminal (prints its path)",
                       epilog=EPILOG)
    kinds = q.add_subparsers(dest="kind", required=True)
    k = kinds.add_parser("ballbar", help="a ballbar on a simulated machine running the test program", epilog=EPILOG)
    _add_setup_args(k)
    _add_truth_args(k)
    _add_link_args(k, 1000.0)
    _add_virtual_args(k)
    k.set_defaults(func=cmd_virtual_ballbar)
    k = kinds.add_parser("rtest", help="an R-test on a simulated B/C table running the pattern", epilog=EPILOG)
    _add_rtest_pattern_args(k)
    _add_rtest_machine_args(k, "probe direction (give 3 times; default a 45-deg tripod)")
    k.add_argument("--mode", default="keyence", choices=["sylvac", "keyence", "stream"], help="probe protocol")
    _add_link_args(k, 100.0)
    _add_virtual_args(k)
    k.set_defaults(func=cmd_virtual_rtest)

    q = sub.add_parser("record", help="record a session from an instrument on a serial port",
                       epilog=EPILOG + "; a recording that ends by disconnect, silence or no valid data "
                                       "exits with 4, its rows kept in the file")
    kinds = q.add_subparsers(dest="kind", required=True)
    k = kinds.add_parser("ballbar", help="record a ballbar test (the same set-up options as plan)", epilog=EPILOG)
    _add_setup_args(k)
    _add_link_args(k, 1000.0)
    k.add_argument("--zero", action="store_true", help="zero the transducer before START (normally done in the calibrator)")
    _add_record_args(k)
    k.set_defaults(func=cmd_record_ballbar)
    k = kinds.add_parser("rtest", help="record an R-test (the same pattern options as simulate rtest)", epilog=EPILOG)
    _add_rtest_pattern_args(k)
    k.add_argument("--probe-dir", action="append", metavar="X,Y,Z",
                   help="calibrated probe direction (give 3 times; default a 45-deg tripod)")
    k.add_argument("--mode", default="keyence", choices=["sylvac", "keyence", "stream"], help="probe protocol")
    k.add_argument("--speed", type=float, default=1.0,
                   help="polled modes: the instrument's virtual seconds per real second (virtual instruments only)")
    _add_link_args(k, 100.0)
    _add_record_args(k)
    k.set_defaults(func=cmd_record_rtest)

    q = sub.add_parser("report", help="self-contained HTML report of a session", epilog=EPILOG)
    q.add_argument("file")
    q.add_argument("--method", default="joint", choices=["joint", "paper"])
    q.add_argument("--no-diagnosis", action="store_true")
    q.add_argument("-o", "--output", required=True)
    q.set_defaults(func=cmd_report)

    q = sub.add_parser("demo", help="the whole job on a simulated machine: plan, simulate, identify, "
                                    "diagnose, compensate, report", epilog=EPILOG)
    q.add_argument("-o", "--output", default="out/demo")
    q.add_argument("--seed", type=int, default=2016)
    q.add_argument("--sag", type=float, default=0.004, help="hidden gravity sag of the A table, mm")
    q.set_defaults(func=cmd_demo)
    return p


def _add_rtest_pattern_args(q: argparse.ArgumentParser) -> None:
    g = q.add_argument_group("measurement pattern (Oyama & Ibaraki Sec. 3.3)")
    g.add_argument("--machine", default="BC-trt", help="BC-trt (the R-test model's machine) or AC-trt")
    g.add_argument("--b-range", dest="tilt_range", default="-90,90", help="tilt axis range, deg (inclusive)")
    g.add_argument("--b-step", type=float, default=30.0, help="tilt step, deg")
    g.add_argument("--c-range", default="0,360",
                   help="C range, deg (inclusive; an end one full turn after the start is left out)")
    g.add_argument("--c-step", type=float, default=30.0, help="C step, deg")
    g.add_argument("--nest", action="append", metavar="X,Y,Z",
                   help="nominal ball centre of a sensor nest, table frame, mm (repeatable; default "
                        "the paper's two: 100,0,60 and 0,-120,140)")
    g.add_argument("--dwell", type=float, default=DEFAULT_DWELL_S, help="time between readings, s")


def _add_rtest_machine_args(q: argparse.ArgumentParser, probe_dir_help: str) -> None:
    g = q.add_argument_group("simulated machine and instrument")
    g.add_argument("--errors", default="random",
                   help="location errors: random (seeded), zero, or NAME=VALUE,... (mm, rad)")
    g.add_argument("--effect", action="append", metavar="ID=P1,P2",
                   help="position-dependent error from the effects catalogue, e.g. gravity_sag_B=0.006 "
                        "or axial_motion_C_h2=0.002,-0.001 (repeatable)")
    g.add_argument("--noise", type=float, default=DEFAULT_NOISE_UM, help="1-sigma reading noise, um")
    g.add_argument("--probe-zero", type=float, default=DEFAULT_PROBE_ZERO_UM, help="1-sigma probe zero per set-up, um")
    g.add_argument("--probe-dir", action="append", metavar="X,Y,Z", help=probe_dir_help)
    g.add_argument("--seed", type=int, default=1)


def _add_rtest_sim_args(q: argparse.ArgumentParser) -> None:
    _add_rtest_pattern_args(q)
    _add_rtest_machine_args(q, "probe direction (give 3 times, normalised): also write raw d1,d2,d3 "
                               "with probe.N.dir")
    q.add_argument("--raw-only", action="store_true", help="with --probe-dir: write d1,d2,d3 but no dx,dy,dz")
    q.add_argument("--truth", metavar="JSON", help="where to write the truth (default: FILE.truth.json)")
    q.add_argument("-o", "--output", required=True)


def _add_truth_args(q: argparse.ArgumentParser) -> None:
    g = q.add_argument_group("simulated machine")
    g.add_argument("--errors", default="random",
                   help="random (seeded), table2 (Flynn et al.), zero, or NAME=VALUE,... (mm, rad)")
    g.add_argument("--effect", action="append", metavar="ID=P1,P2",
                   help="hide a catalogue effect, e.g. gravity_sag_A=0.004 (repeatable)")
    g.add_argument("--pivot-error", type=float, default=0.02, help="1-sigma pivot placement error, mm")
    g.add_argument("--noise", type=float, default=0.5, help="1-sigma reading noise, um")
    g.add_argument("--seed", type=int, default=1)


# Options whose values may start with '-' ("--a-range -90,90"): argparse would take the value
# for an option, so such pairs are joined as "--a-range=-90,90" before parsing.
_SIGNED_VALUE_OPTIONS = {"--a-range", "--b-range", "--c-range", "--pivot", "--errors", "--nest", "--probe-dir"}


def _join_signed_values(argv: Sequence[str]) -> list[str]:
    out: list[str] = []
    it = iter(argv)
    for tok in it:
        if tok in _SIGNED_VALUE_OPTIONS:
            nxt = next(it, None)
            out.append(tok if nxt is None else f"{tok}={nxt}")
        else:
            out.append(tok)
    return out


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    args = build_parser().parse_args(_join_signed_values(argv))
    try:
        return args.func(args)
    except (_core.ParseError, _core.InvalidArgument, _core.DegenerateGeometry) as e:
        _say(f"rotacal: error: {e}")
        return EXIT_INPUT
    except (_core.IoError, OSError) as e:
        _say(f"rotacal: error: {e}")
        return EXIT_IO
    except _core.Error as e:
        _say(f"rotacal: error: {e}")
        return EXIT_ERROR


if __name__ == "__main__":
    sys.exit(main())
