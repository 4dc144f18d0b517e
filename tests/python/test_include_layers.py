# SPDX-License-Identifier: BSD-3-Clause
"""The C++ layer order of the README, checked on every #include of include/ and src/.

core < kinematics < realtime (the controller's evaluation, on kinematics alone) < fit < session < io < design < instrument problems (ballbar, rtest, probe) <
circular (the ballbar's tests of the linear axes) < diagnose < multi < hw.

A file may include its own layer and the layers below it, never one above, and no instrument
includes another instrument. Adapters live with their instrument but belong to the engine they
adapt: a file named *diagnosis* in an instrument folder, or under its diagnosis/ folder, is at
the diagnose layer."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
ORDER = [
    "core",
    "kinematics",
    "realtime",
    "fit",
    "session",
    "io",
    "design",
    "instrument",
    "circular",
    "diagnose",
    "multi",
    "compensation",
    "hw",
]
INSTRUMENTS = {"ballbar", "rtest", "probe"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"(?:rotacal/)?([^"]+)"', re.M)


def _folder_of(path: Path) -> str:
    """The folder of include/rotacal/X/... or src/X/..."""
    parts = path.relative_to(ROOT).parts
    return parts[2] if parts[0] == "include" else parts[1]


def _layer(folder: str, path: Path) -> str:
    if folder in INSTRUMENTS or folder == "circular":
        if "diagnosis" in path.name or "diagnosis" in path.parent.name:
            return "diagnose"
        return "instrument" if folder in INSTRUMENTS else "circular"
    return folder


def _sources():
    for base in (ROOT / "include" / "rotacal", ROOT / "src"):
        for p in sorted(base.rglob("*")):
            if p.suffix in (".hpp", ".cpp", ".h"):
                yield p


def _resolve(src: Path, target: str) -> Path | None:
    for base in (ROOT / "include" / "rotacal", src.parent):
        cand = (base / target).resolve()
        if cand.exists():
            return cand
    return None


def _edges():
    for src in _sources():
        for target in INCLUDE.findall(src.read_text()):
            dst = _resolve(src, target)
            if dst is None or not (
                dst.is_relative_to(ROOT / "include") or dst.is_relative_to(ROOT / "src")
            ):
                continue
            yield src, dst


def test_every_folder_has_a_layer():
    folders = {
        _folder_of(p)
        for p in _sources()
        if len(p.relative_to(ROOT).parts) > 3 or p.relative_to(ROOT).parts[0] == "src"
    }
    unknown = {f for f in folders if f not in ORDER and f not in INSTRUMENTS}
    assert not unknown, f"folders without a place in the layer order: {sorted(unknown)}"


def test_no_include_runs_against_the_layer_order():
    bad = []
    for src, dst in _edges():
        a, b = _folder_of(src), _folder_of(dst)
        la, lb = _layer(a, src), _layer(b, dst)
        if ORDER.index(lb) > ORDER.index(la):
            bad.append(f"{src.relative_to(ROOT)} ({la}) includes {dst.relative_to(ROOT)} ({lb})")
    assert not bad, "\n".join(bad)


def test_no_instrument_includes_another():
    bad = [
        f"{s.relative_to(ROOT)} -> {d.relative_to(ROOT)}"
        for s, d in _edges()
        if _folder_of(s) in INSTRUMENTS
        and _folder_of(d) in INSTRUMENTS
        and _folder_of(s) != _folder_of(d)
    ]
    assert not bad, "\n".join(bad)
