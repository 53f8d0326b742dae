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


@pytest.fixture(autouse=True)
def no_process_left_behind():
    """After every test, no process of the fleet that the test started is alive (by PID)."""
    from tests.processes import fleet_processes, wait_gone

    before = set(fleet_processes())
    yield
    left = wait_gone(set(fleet_processes()) - before)
    assert not left, f"processes left behind: {sorted(left)}"
