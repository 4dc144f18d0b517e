"""Fixtures shared by the Python tests: the shared sessions beside the repository and their truth files."""
import json
from pathlib import Path

import pytest

# The independent implementation's sessions, beside the repository (../shared/data).
SHARED = Path(__file__).resolve().parents[3] / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    if not SHARED.is_dir():
        pytest.fail(f"shared data not found at {SHARED} (expected ../shared beside the repository)")
    return SHARED


def truth(path: Path) -> dict:
    return json.loads(path.with_suffix(".truth.json").read_text())


def split_by_c(path, step):
    """Two files from one session: rows with C on multiples of `step` deg, and the others."""
    lines = path.read_text().splitlines()
    meta = [ln for ln in lines if ln.startswith("#")]
    header, *rows = [ln for ln in lines if ln and not ln.startswith("#")]
    c_col = header.split(",").index("C")
    on = [r for r in rows if float(r.split(",")[c_col]) % step == 0]
    off = [r for r in rows if float(r.split(",")[c_col]) % step != 0]
    out = []
    for name, part in (("fit", on), ("held", off)):
        p = path.with_name(f"{path.stem}.{name}.csv")
        p.write_text("\n".join(meta + [header] + part) + "\n")
        out.append(p)
    return out
