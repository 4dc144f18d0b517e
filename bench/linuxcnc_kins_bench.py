#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""rotacal-kins (linuxcnc/rotacal_kins.cpp) against its peer, LinuxCNC's xyzac-trt-kins, timed
where a controller runs them: in the servo thread of the headless LinuxCNC of
tests/linuxcnc/xyzac-trt-sim.ini (1 ms period), once with each kinematics, the same machine
(five joints XYZAC) and the same moves.

HAL's own timer of the motion controller's function (the pin motion-controller.time, CPU clocks
of rdtsc) is recorded every servo period by a `sampler` while the machine moves in world
coordinates (each period: one inverse and, for the position feedback, one forward), and turned
into us at the TSC's rate (the CPU's "cpu MHz" where /proc/cpuinfo says constant_tsc: the
kernel's TSC calibration on this computer; else the figures stay in clocks). The ratio needs no
rate. motion.servo.last-period, recorded beside, gives the servo period the thread kept. The median is the
figure; the 99.9th percentile on a busy 2-core computer measures preemption as much as code,
and the maximum is not reported. rotacal-kins runs a model with every catalogue term of AC-trt
(harmonics 1..2) and thermal gains. Run as root (LinuxCNC's headless runs as the tests run it,
tests/python/linuxcnc_session.py), under `flock /tmp/linuxcnc.lock`.
  linuxcnc_kins_bench.py [--build build/release] [--seconds 8]
"""

import argparse
import os
import shutil
import struct
import sys
import tempfile
import zlib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "python"))  # the headless LinuxCNC runner of the tests

SAMPLER_HAL = """# the motion controller's time and the servo period, in clocks, every period
loadrt sampler depth=4000 cfg=su
addf sampler.0 servo-thread
net mc-time motion-controller.time => sampler.0.pin.0
net servo-clocks motion.servo.last-period => sampler.0.pin.1
"""

DISPLAY = '''#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Moves in world coordinates while halsampler drains the sampler (servo_time.json)."""
import json, os, subprocess, time
import linuxcnc
from lcnc_display import Machine, run

def main():
    n = int(os.environ.get("ROTACAL_BENCH_SAMPLES", "8000"))
    m = Machine()
    m.bring_up()
    m.set_mode(linuxcnc.MODE_MDI)
    m.mdi("G21 G90 G17 G40 G49 G54 G94 G64")
    sampler = subprocess.Popen(["halsampler", "-n", str(n)], stdout=open("samples.txt", "w"))
    moves = 0
    while sampler.poll() is None:
        for x, a, c in ((80, 60, 170), (-80, -45, -170), (20, 10, 30)):
            m.c.mdi(f"G1 F6000 X{x} Y{x / 2} Z{-x / 4} A{a} C{c}")
            m.c.wait_complete(30)
            m.wait_for("the move", lambda: m.s.interp_state == linuxcnc.INTERP_IDLE, 30)
            moves += 1
            if sampler.poll() is not None:
                break
    return {"moves": moves}

if __name__ == "__main__":
    run(main, "servo_time.json")
'''


def model_with_every_term(path: Path) -> None:
    import rotacal
    from rotacal import _core

    rng = np.random.default_rng(55)
    machine = _core.MachineType.AC_trt
    names = list(_core.location_error_names(machine))
    fx = []
    for f in _core.effect_catalogue(machine, 2):
        if f.id.startswith("ballbar_"):  # the instrument's, not the machine's
            continue
        fx.append(
            {
                "id": f.id,
                "params": {
                    n: {"value": (0.01 if u == "mm" else 0.3 if u == "1" else 2e-5) * rng.normal()}
                    for n, u in zip(f.param_names, f.param_units)
                },
            }
        )
    doc = {
        "format": "rotacal-model/1",
        "kind": "ballbar",
        "machine": "AC-trt",
        "location_errors": {
            n: {"value": (1e-4 if n[2] in "ABC" else 0.05) * rng.normal()} for n in names
        },
        "pivot": {k: {"value": 0.0} for k in "xyz"},
        "effects": fx,
        "source": {"session": "bench"},
    }
    rotacal.save_model(doc, path)


def blob_with_thermal_gains(blob: bytes) -> bytes:
    """Thermal gains on E_Y0A (y1) and E_X0C (y2) (realtime/blob.hpp's layout), CRC renewed."""
    b = bytearray(blob)
    off = 20 + 18 + 2 * 195 + 8 * 8
    struct.pack_into("<d", b, off + 8 * 0, 0.003)
    struct.pack_into("<d", b, off + 8 * (8 + 4), -0.002)
    struct.pack_into("<I", b, 16, zlib.crc32(bytes(b[20:])))
    return bytes(b)


def tsc_mhz() -> float | None:
    """The TSC's rate (clocks per us) where it is constant, else None."""
    info = Path("/proc/cpuinfo").read_text()
    if " constant_tsc" not in info:
        return None
    return float(info.split("cpu MHz")[1].split(":")[1].split()[0])


def one_run(kins: str, workdir: Path, blob: Path | None, samples: int) -> dict:
    from linuxcnc_session import run_linuxcnc

    ini = (ROOT / "tests/linuxcnc/xyzac-trt-sim.ini").read_text()
    ini = ini.replace("DISPLAY = ./tcp_display.py", "DISPLAY = ./servo_time_display.py")
    ini = ini.replace("HALFILE = pins.hal", "HALFILE = pins.hal\nHALFILE = servo_time.hal")
    files = {"servo_time.hal": SAMPLER_HAL, "servo_time_display.py": DISPLAY, "pins.hal": ""}
    if kins == "rotacal-kins":
        ini = ini.replace(
            "KINEMATICS = xyzac-trt-kins",
            f"KINEMATICS = rotacal-kins model={blob} coordinates=XYZAC",
        )
        files["trt-tool-offset.hal"] = (
            "net tool-offset motion.tooloffset.z => rotacal-kins.tool-offset\n"
        )
        files["pins.hal"] = "setp rotacal-kins.y1 0.4\nsetp rotacal-kins.y2 -0.2\n"
    files["xyzac-trt-sim.ini"] = ini
    os.environ["ROTACAL_BENCH_SAMPLES"] = str(samples)
    run_dir = workdir / kins
    out = run_linuxcnc(run_dir, "xyzac-trt-sim.ini", files, "servo_time.json", 120)
    s = np.loadtxt(run_dir / "samples.txt")
    rate = tsc_mhz() or 1.0
    t = s[:, 0] / rate
    return {
        "median": float(np.median(t)),
        "p999": float(np.quantile(t, 0.999)),
        "period": float(np.mean(s[:, 1]) / rate),
        "periods": len(t),
        "moves": out["moves"],
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", type=Path, default=ROOT / "build/release")
    ap.add_argument("--seconds", type=float, default=8.0)
    a = ap.parse_args()
    so = a.build / "linuxcnc/rotacal-kins.so"
    if not so.exists():
        raise SystemExit(f"{so}: build the target rotacal_kins first")
    module = Path("/usr/lib/linuxcnc/modules/rotacal-kins.so")
    work = Path(tempfile.mkdtemp(prefix="rotacal-kins-bench-"))
    os.chmod(work, 0o755)  # rtapi_app reads the blob as RTAPI_UID
    shutil.copyfile(so, module.with_suffix(".tmp"))
    os.replace(module.with_suffix(".tmp"), module)
    try:
        model = work / "model.json"
        model_with_every_term(model)
        from rotacal import realtime

        blob = work / "model.rtb"
        m = realtime.load_realtime(model)  # the blob `rotacal export --controller realtime` writes
        blob.write_bytes(blob_with_thermal_gains(m.blob()))
        os.chmod(blob, 0o644)
        n = int(a.seconds * 1000)
        res = {k: one_run(k, work, blob, n) for k in ("xyzac-trt-kins", "rotacal-kins")}
    finally:
        module.unlink(missing_ok=True)
        shutil.rmtree(work, ignore_errors=True)
    unit = "us" if tsc_mhz() else "TSC clocks"
    print(f"motion-controller time per servo period ({n} periods, moving), {unit}:")
    print(
        f"{'kinematics':<16} {'median':>8} {'99.9%':>8} {'periods':>8} {'moves':>6} {'period':>8}"
    )
    for k, r in res.items():
        print(
            f"{k:<16} {r['median']:8.2f} {r['p999']:8.2f} {r['periods']:8d} {r['moves']:6d} "
            f"{r['period']:8.1f}"
        )
    t, r = res["xyzac-trt-kins"], res["rotacal-kins"]
    print(f"ratio rotacal-kins / xyzac-trt-kins, median: {r['median'] / t['median']:.2f}")
    print(f"rotacal-kins adds, median: {r['median'] - t['median']:.2f} {unit} per servo period")


if __name__ == "__main__":
    main()
