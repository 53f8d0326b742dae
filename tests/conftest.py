"""Shared test fixtures: the public data sets (``tests/data``) and the process check."""

from __future__ import annotations

import signal
from pathlib import Path

import pytest

# A suite started in the background by a shell without job control (`(bash -c 'pytest' &)`,
# `nohup ... &`) inherits SIGINT ignored, and so does every process it starts: the Ctrl-C
# tests then fail with runs that never see their Ctrl-C. Children get the default back.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

# copies of public maps with their sources (tests/data/README.md): a plain clone needs nothing else
PUBLIC_DATA = Path(__file__).resolve().parent / "data"


@pytest.fixture(scope="session")
def public_data() -> Path:
    if not PUBLIC_DATA.is_dir():
        pytest.fail(f"public data sets not found at {PUBLIC_DATA}")
    return PUBLIC_DATA


@pytest.fixture(scope="session", autouse=True)
def _own_descendants():
    from tests.processes import become_subreaper

    become_subreaper()


@pytest.fixture(autouse=True)
def no_process_left_behind():
    """After every test, no process that the test started is alive (by PID)."""
    from tests.processes import fleet_processes, wait_gone

    before = set(fleet_processes())
    yield
    left = wait_gone(set(fleet_processes()) - before)
    assert not left, f"processes left behind: {sorted(left)}"
