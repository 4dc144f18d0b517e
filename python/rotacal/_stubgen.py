# SPDX-License-Identifier: BSD-3-Clause
"""Writes python/rotacal/_core.pyi from the built extension with the pinned pybind11-stubgen (``python -m rotacal._stubgen [--check]``)."""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

# The generator's output changes between versions: the stubs are generated with this one only
# (scripts/setup.sh installs it) so that regenerating never shows a difference the bindings did not make.
STUBGEN_VERSION = "2.5.5"
ENUMS = (
    "RadialSide",
    "BallbarTest",
    "NcDialect",
    "SegmentKind",
    "CircularPlane",
    "CircularDirection",
)
STUB = Path(__file__).with_name("_core.pyi")
SPDX = "# SPDX-License-Identifier: BSD-3-Clause\n"


def generate() -> str:
    """The stub text of the importable rotacal._core."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        found = version("pybind11-stubgen")
    except PackageNotFoundError:
        raise SystemExit(f"pybind11-stubgen=={STUBGEN_VERSION} is not installed") from None
    if found != STUBGEN_VERSION:
        raise SystemExit(
            f"pybind11-stubgen {found} found, the stubs are made with {STUBGEN_VERSION}"
        )
    with tempfile.TemporaryDirectory() as out:
        cmd = [sys.executable, "-m", "pybind11_stubgen", "rotacal._core", "-o", out]
        cmd += [f"--enum-class-locations={e}:rotacal._core" for e in ENUMS]
        # Defaults that are C++ objects (options structs) have no Python expression: the
        # generator logs them as errors and writes "...", which is what a stub shows.
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            raise SystemExit(f"pybind11-stubgen failed:\n{r.stderr}")
        # The licence line every source file of rotacal starts with, which the generator
        # does not write.
        return SPDX + (Path(out) / "rotacal" / "_core.pyi").read_text()


def main(argv: list[str]) -> int:
    text = generate()
    if "--check" in argv:
        if STUB.read_text() != text:
            print(
                f"{STUB} differs from the extension: run python -m rotacal._stubgen",
                file=sys.stderr,
            )
            return 1
        return 0
    STUB.write_text(text)
    print(f"wrote {STUB}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
