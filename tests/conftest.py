"""Shared test fixtures: where the public data sets are."""

from __future__ import annotations

from pathlib import Path

import pytest

SHARED_DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    if not SHARED_DATA.is_dir():
        pytest.fail(f"public data sets not found at {SHARED_DATA} (../shared/data)")
    return SHARED_DATA
