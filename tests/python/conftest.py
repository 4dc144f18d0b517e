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
