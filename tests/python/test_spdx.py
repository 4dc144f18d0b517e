# SPDX-License-Identifier: BSD-3-Clause
"""Every source file we write names its licence in an SPDX line at its top (after a shebang):
what a vendor's licence scanner reads. The generated stub carries it too (_stubgen writes it)."""

import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SOURCES = ("*.cpp", "*.hpp", "*.h", "*.py", "*.pyi", "*.sh", "CMakeLists.txt", "*.cmake")
LINE = "SPDX-License-Identifier: BSD-3-Clause"


def test_every_source_file_has_an_spdx_line():
    files = subprocess.run(
        ["git", "-C", str(ROOT), "ls-files", "--", *SOURCES, *(f"**/{s}" for s in SOURCES)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    assert len(files) > 400
    missing = []
    for name in sorted(set(files)):
        head = (ROOT / name).read_text(errors="replace").splitlines()[:3]
        if not any(LINE in line for line in head):
            missing.append(name)
    assert not missing, f"no '{LINE}' in the first lines of: {missing}"
