# SPDX-License-Identifier: BSD-3-Clause
"""BENCHMARKS.md, made from the benchmarks' own output: never edited by hand.

    python3 bench/report.py run NAME [NAME ...]   run those benchmarks, keep their output
    python3 bench/report.py run --all             every benchmark below
    python3 bench/report.py render                write BENCHMARKS.md from what was kept
    python3 bench/report.py list                  the benchmarks and their commands

`run` stores each benchmark's output, the command, the date, the wall time and the machine in
bench/results/NAME.json; `render` writes BENCHMARKS.md from those files alone (a test checks
that the committed BENCHMARKS.md is what `render` makes of them). A figure that changes is run
again and replaces the old one: its history is git's. Binaries are looked up in
build/release/bench (`--build DIR` for another build), the Python benchmarks run with the
interpreter that runs this script and need the rotacal package installed."""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import re
import shlex
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results"
OUTPUT = ROOT / "BENCHMARKS.md"

# name: (title, what it measures, command; "{bin}" is the benchmarks' build folder, "{py}" the
# Python interpreter). Ordered as BENCHMARKS.md lists them.
BENCHMARKS: dict[str, tuple[str, str, str]] = {
    "ballbar_accuracy": (
        "Ballbar: accuracy of the joint fit against its Cramer-Rao bound",
        "RMSE of the 8 location errors over Monte Carlo draws of the default single set-up "
        "test, divided by the Cramer-Rao bound, and the paper's chain beside it.",
        "{bin}/ballbar_accuracy --draws 1000",
    ),
    "ballbar_speed": (
        "Ballbar: speed against SciPy as its users run it",
        "rotacal's joint fit against scipy.optimize.least_squares on the same model and "
        "session, in one process; the ratio is the figure.",
        "{py} bench/ballbar_speed.py",
    ),
    "probe_accuracy": (
        "Touch probe: joint fit against the controllers' cycles method",
        "RMSE and Monte Carlo / reported sigma of the probe's joint fit and of the "
        "sphere-then-circle method of the cycles, on the same draws.",
        "{bin}/probe_accuracy",
    ),
    "rtest_bench": (
        "R-test: identification time and accuracy",
        "The R-test joint fit and the paper's method on simulated B/C-table sessions.",
        "{bin}/rtest_bench",
    ),
    "multi_bench": (
        "Several instruments: ballbar + probe of one machine",
        "Monte Carlo / reported sigma of the joint identification, and each session alone.",
        "{bin}/multi_bench --draws 1000",
    ),
    "any_machine_bench": (
        "Any 5-axis machine: accuracy on every built-in kinematics",
        "RMSE / Cramer-Rao bound of the location errors on each built-in machine.",
        "{bin}/any_machine_bench",
    ),
    "noise_mc_bench": (
        "Noise model: honest sigma on correlated noise",
        "Monte Carlo / reported sigma under AR noise, with and without the noise model.",
        "{bin}/noise_mc_bench",
    ),
    "ballbar_long": (
        "Long ballbar sessions: time and memory",
        "Identification of a long recording, time and peak memory.",
        "{bin}/ballbar_long",
    ),
    "long_session": (
        "Long ballbar sessions as a user runs them: identify and diagnose, time and memory",
        "`rotacal identify` with and without the uncertainty budget and `rotacal diagnose` on "
        "reference-simulator sessions of 90,000 and 1,000,000 readings (15 min and 2.8 h at "
        "100 Hz), each in its own process: wall and CPU time, peak memory and its bytes a "
        "reading above `import rotacal` (issue 56: 90,000 identify <= 1 s and 150 MB; "
        "1,000,000 identify <= 30 s, diagnose <= 10 min, <= 1 KB a reading).",
        "{py} bench/long_session_budget.py --samples 90000,1000000 --diagnose "
        "--keep /tmp/rotacal-long-sessions",
    ),
    "batch_throughput": (
        "Batch: a confusion-grid slice on 1 and 2 local workers",
        "The grid's first 2,000 sessions (AC-trt ballbar, white and pink noise) as a plain loop, "
        "then through rotacal.batch on 1 and 2 local workers, with the same records all three "
        "ways (issue 56: speed-up >= 1.8x on 2 cores, overhead per session <= 5 %). Needs an "
        "idle computer.",
        "{py} bench/batch_throughput.py --sessions 2000 --workers 1,2",
    ),
    "realtime_bench": (
        "Real-time kinematics: forward and inverse per call",
        "The header-only evaluation of a fitted model with every catalogue term (49 effects), "
        "1e6 calls each; the median is the figure, the 99.9th percentile on a busy computer "
        "measures the scheduler.",
        "{bin}/realtime_bench",
    ),
    "linuxcnc_kins_bench": (
        "Real-time kinematics in LinuxCNC's servo thread: rotacal-kins against xyzac-trt-kins",
        "The motion controller's own time per servo period (HAL's motion-controller.time) in "
        "the headless LinuxCNC, moving in world coordinates, with LinuxCNC's trt kinematics and "
        "with rotacal-kins running a model with every catalogue term; the median ratio is the "
        "figure. Needs root, LinuxCNC and the built module; run under flock /tmp/linuxcnc.lock.",
        "{py} bench/linuxcnc_kins_bench.py --build {bin}/..",
    ),
    "diagnosis_confusion": (
        "Diagnosis: named right, ambiguous, nothing, named wrong",
        "Reference-simulator sessions (tests/reference/refsim), one hidden catalogue effect "
        "beside random location errors, in white and coloured noise; null sessions count "
        "false findings.",
        "{py} bench/diagnosis_confusion.py --machines AC-trt --noise white,pink "
        "--amplitudes 3 --draws 1 --null 10 --seed 61 --jobs 2",
    ),
    "structure_null": (
        "Diagnosis: structure is not noise (unexplained structure, null rate)",
        "Reference-simulator sessions with nothing hidden in coloured noise (R-test, probe, "
        "ballbar): how often unexplained structure is reported (target <= 2 %) and a cause named "
        "(named wrong); and an R-test whose C angle is off by a Gaussian bump outside the "
        "catalogue: reported, and where.",
        "{py} bench/structure_null.py --draws 200 --bump-draws 20",
    ),
    "design_bench": (
        "Test design: predicted against Monte Carlo uncertainty",
        "The designed set-ups' predicted sigma against Monte Carlo draws.",
        "{py} bench/design_bench.py",
    ),
    "multi_diagnosis_pairs": (
        "Several sessions of one machine diagnosed together",
        "Two sessions of one table (ballbar + probe on an AC-trt, R-test + probe on a BC-trt), "
        "reference simulator, AR(1) 0.5 noise: one hidden machine effect, an instrument effect "
        "in one session, or nothing; the first finding of each session alone and of the two "
        "together.",
        "{py} bench/multi_diagnosis_pairs.py --figures --draws 20",
    ),
    "diagnosis_loop": (
        "The loop of an ambiguous diagnosis: the deciding test designed, measured and used",
        "A session of the reference simulator (AR(1) 0.5 noise of 0.5 um, one hidden effect) "
        "whose diagnosis gives a group holding the truth: the deciding test designed by "
        "`rotacal design KIND --separate X,Y --after S`, measured on the same machine and "
        "diagnosed with S; where no test of the instrument decides, the touch probe's standard "
        "poses on the same machine too. Counts per cell, nested members (no test can separate "
        "them, the model rule decides) apart.",
        "{py} bench/diagnosis_loop.py --draws 20",
    ),
    "table_residual_bench": (
        "Compensation tables: what each controller's tables leave over the travel",
        "A model with a worm-gear C, C run-out, face runout and wobble and a sagging A, exported "
        "with --tables for each controller and applied as the controller's documentation "
        "describes its tables: the residual of each held term against the interpolation error "
        "the table states (ratio <= 1 but for the slope of the error, about 1e-4), and the "
        "size of every term no table holds, at tilt 0 over a turn of C.",
        "{py} bench/table_residual_bench.py",
    ),
    "thermal_bench": (
        "Thermal test of a rotary axis: accuracy, prediction, null sessions, two lags, time",
        "Reference-simulator sessions (tests/reference/refsim/thermal.py) of a 6 h AC-trt probe "
        "test, the shared truth's gains scaled 0.5-2x, 0.5 um white noise: the joint fit's RMSE "
        "against the Cramer-Rao bound and the per-epoch peer, 2-sigma coverage, prediction of the "
        "cool-down from the heat-up, null sessions, two lags named by BIC, identification time.",
        "{py} bench/thermal_bench.py --draws 500 --draws-slow 100",
    ),
    "history_bench": (
        "Calibration history: store and read",
        "Time to store and read identifications in the SQLite history.",
        "{py} bench/history_bench.py",
    ),
}


# The README's table of headline figures: (figure, benchmark, pattern whose first group is the
# value shown), each value taken from that benchmark's kept output by `render`.
HEADLINES: list[tuple[str, str, str]] = [
    (
        "Ballbar joint fit: worst RMSE / Cramer-Rao bound of the 8 location errors",
        "ballbar_accuracy",
        r"worst RMSE/CRB of the 8 location errors: ([\d.]+)",
    ),
    (
        "Ballbar joint fit against SciPy least_squares, one call",
        "ballbar_speed",
        r"one call each in turn: ([\d.]+x wall, [\d.]+x CPU)",
    ),
    ("Touch-probe joint fit, 120 touches", "probe_accuracy", r"joint fit: ([\d.]+ ms CPU) per fit"),
    ("R-test joint fit, 2 x 84 poses", "rtest_bench", r"poses: .*?, ([\d.]+ ms CPU) median"),
    (
        "Diagnosis named the hidden cause alone, white noise, 3x its detection amplitude (AC-trt)",
        "diagnosis_confusion",
        r"\| white \| 3x \| \d+ \| (\d+%) \|",
    ),
    (
        "The same in 1/f-like noise (the others: 'one of these', or nothing found)",
        "diagnosis_confusion",
        r"\| pink \| 3x \| \d+ \| (\d+%) \|",
    ),
    (
        "Diagnosis named a wrong cause first, 1/f-like noise, sessions",
        "diagnosis_confusion",
        r"\| pink \| (\d+/\d+) \(\d+%\) \|",
    ),
    (
        "Ballbar + probe of one AC-trt diagnosed together: coning of A named alone (each alone)",
        "multi_diagnosis_pairs",
        r"coning_A 2\.5e-05[\s\S]*?named first: first alone (\d+, probe alone \d+, joint \d+ of \d+)",
    ),
    (
        "Real-time kinematics with every model term, AC-trt: forward, median us",
        "realtime_bench",
        r"AC-trt\s+\d+\s+([\d.]+)\s",
    ),
    (
        "The same, inverse (5 fixed Newton steps), median us",
        "realtime_bench",
        r"AC-trt\s+\d+\s+[\d.]+\s+[\d.]+\s+([\d.]+)\s",
    ),
]
HEADLINE_START = "<!-- headlines: made by `python3 bench/report.py render` -->"
HEADLINE_END = "<!-- /headlines -->"


def headline_table(results: dict[str, dict]) -> str:
    rows = ["| figure | value | in BENCHMARKS.md |", "|---|---|---|"]
    for label, name, pattern in HEADLINES:
        if name not in results:
            continue
        m = re.search(pattern, results[name]["output"])
        if not m:
            raise SystemExit(f"report: headline '{label}': no match for {pattern!r} in {name}")
        anchor = re.sub(r"[^a-z0-9 -]", "", BENCHMARKS[name][0].lower()).replace(" ", "-")
        rows.append(f"| {label} | {m.group(1)} | [{name}](BENCHMARKS.md#{anchor}) |")
    return "\n".join(rows)


def with_headlines(readme: str, results: dict[str, dict]) -> str:
    """The README with the table between the headline markers made from `results`."""
    start, end = readme.find(HEADLINE_START), readme.find(HEADLINE_END)
    if start < 0 or end < start:
        raise SystemExit("report: README.md has no headline markers")
    head = readme[: start + len(HEADLINE_START)]
    return head + "\n" + headline_table(results) + "\n" + readme[end:]


def machine() -> dict:
    """What ran the benchmark: processor, cores, memory, system, compiler."""
    cpu = ""
    try:
        m = re.search(r"^model name\s*:\s*(.+)$", Path("/proc/cpuinfo").read_text(), re.M)
        cpu = m.group(1).strip() if m else ""
    except OSError:
        pass
    mem = ""
    try:
        kb = int(re.search(r"MemTotal:\s*(\d+)", Path("/proc/meminfo").read_text()).group(1))
        mem = f"{kb / 1024**2:.0f} GiB"
    except (OSError, AttributeError):
        pass
    cxx = subprocess.run(["c++", "--version"], capture_output=True, text=True).stdout
    return {
        "cpu": cpu or platform.processor(),
        "cores": os.cpu_count(),
        "memory": mem,
        "system": f"{platform.system()} {platform.release()}",
        "compiler": cxx.splitlines()[0] if cxx else "",
        "python": platform.python_version(),
    }


def commit(rev: str | None = None) -> str:
    """The commit the benchmarks were built from: `rev` where given (a build older than the
    checkout), else HEAD, marked where tracked files have changed since."""
    if rev:
        r = subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", rev],
            capture_output=True,
            text=True,
            check=True,
        )
        return r.stdout.strip()
    r = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    )
    dirty = subprocess.run(
        # what this script writes itself does not count as a change of what was measured
        ["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no", "--", "."]
        + [":!bench/results", ":!BENCHMARKS.md", ":!README.md"],
        capture_output=True,
        text=True,
    ).stdout.strip()
    return (r.stdout.strip() or "unknown") + ("+changes" if dirty else "")


def command_of(name: str, build: Path) -> str:
    return BENCHMARKS[name][2].format(bin=os.path.relpath(build, ROOT), py="python3")


def run(name: str, build: Path, built_from: str | None = None) -> dict:
    cmd = command_of(name, build)
    argv = [sys.executable if a == "python3" else a for a in shlex.split(cmd)]
    load = os.getloadavg()[0]
    t0 = time.monotonic()
    r = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True)
    wall = time.monotonic() - t0
    if r.returncode != 0:
        raise SystemExit(f"report: {name} failed (exit {r.returncode}):\n{r.stderr[-4000:]}")
    return {
        "name": name,
        "command": cmd,
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "commit": commit(built_from),
        "wall_s": round(wall, 1),
        "load_before": round(load, 1),
        "machine": machine(),
        "output": r.stdout.rstrip(),
    }


def render(results: dict[str, dict]) -> str:
    out = [
        "# Benchmarks",
        "",
        "Made by `python3 bench/report.py render` from the benchmarks' own output in",
        "`bench/results/`; do not edit by hand. Re-run a figure with",
        "`python3 bench/report.py run NAME` and render again. Each section gives the command,",
        "when and on what it ran, and what the benchmark printed.",
        "",
    ]
    missing = [n for n in BENCHMARKS if n not in results]
    for name, (title, what, _) in BENCHMARKS.items():
        if name not in results:
            continue
        r = results[name]
        m = r["machine"]
        out += [
            f"## {title}",
            "",
            what,
            "",
            f"- command: `{r['command']}`",
            f"- run: {r['date']}, commit {r['commit']}, {r['wall_s']} s wall, "
            f"load {r['load_before']} at the start",
            f"- machine: {m['cpu']}, {m['cores']} cores, {m['memory']}, {m['system']}, "
            f"{m['compiler']}, Python {m['python']}",
            "",
            "```",
            r["output"],
            "```",
            "",
        ]
    if missing:
        out += [
            "## Not run yet",
            "",
            *[f"- `{n}`: `{command_of(n, ROOT / 'build/release/bench')}`" for n in missing],
            "",
        ]
    return "\n".join(out)


def load_results() -> dict[str, dict]:
    return {p.stem: json.loads(p.read_text()) for p in sorted(RESULTS.glob("*.json"))}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run benchmarks and keep their output")
    r.add_argument("names", nargs="*", metavar="NAME", help="from `list`")
    r.add_argument("--all", action="store_true")
    r.add_argument("--build", type=Path, default=ROOT / "build" / "release" / "bench")
    r.add_argument(
        "--built-from", metavar="REV", help="the commit the build was made from (default HEAD)"
    )
    sub.add_parser("render", help="write BENCHMARKS.md from bench/results")
    sub.add_parser("list", help="the benchmarks and their commands")
    a = ap.parse_args(argv)
    if a.cmd == "list":
        for n in BENCHMARKS:
            print(f"{n:22s} {command_of(n, ROOT / 'build/release/bench')}")
    elif a.cmd == "run":
        names = list(BENCHMARKS) if a.all else a.names
        unknown = [n for n in names if n not in BENCHMARKS]
        if not names or unknown:
            ap.error(f"run: name benchmarks of `list` or give --all (unknown: {unknown})")
        RESULTS.mkdir(exist_ok=True)
        for n in names:
            print(f"report: running {n}: {command_of(n, a.build)}", file=sys.stderr, flush=True)
            res = run(n, a.build.resolve(), a.built_from)
            (RESULTS / f"{n}.json").write_text(json.dumps(res, indent=1) + "\n")
    else:
        results = load_results()
        OUTPUT.write_text(render(results))
        readme = ROOT / "README.md"
        readme.write_text(with_headlines(readme.read_text(), results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
