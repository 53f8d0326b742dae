"""Finding the fleet's processes by PID through /proc (Linux), for the tests.

Only processes of this test session count: they inherit ``TEST_SESSION_ENV``
from it (even once reparented), so a test never sees, or kills, the processes
of another test session or run on the same machine.
"""

from __future__ import annotations

import contextlib
import os
import signal
import time
import uuid
from pathlib import Path

TEST_SESSION_ENV = "AGV_FLEET_TEST_SESSION"
os.environ.setdefault(TEST_SESSION_ENV, uuid.uuid4().hex)
_MARK = f"{TEST_SESSION_ENV}={os.environ[TEST_SESSION_ENV]}".encode()


def _read(path: Path) -> str:
    try:
        return path.read_text(errors="replace")
    except OSError:
        return ""


def fleet_processes() -> dict[int, str]:
    """Every live process of ours: AGV hosts and AGVs (``fleet.cli`` in the command
    line; forked AGVs keep their host's command line and are named ``agv <name>``)."""
    found = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        cmdline = _read(entry / "cmdline").replace("\0", " ")
        stat = _read(entry / "stat")
        if "fleet.cli" in cmdline and ") Z " not in stat and _ours(entry):
            found[int(entry.name)] = _read(entry / "comm").strip()  # zombies are already dead
    return found


def _ours(entry: Path) -> bool:
    try:
        return _MARK in (entry / "environ").read_bytes().split(b"\0")
    except OSError:
        return False


def agv_pid(name: str, timeout: float = 30.0) -> int:
    """The PID of the process running AGV ``name``, once it exists."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        for pid, comm in fleet_processes().items():
            if comm == f"agv {name}"[:15]:
                return pid
        time.sleep(0.05)
    raise AssertionError(f"no process for AGV {name!r} within {timeout} s")


def wait_gone(pids, timeout: float = 10.0) -> set[int]:
    """The PIDs still alive after ``timeout`` (killed then, so tests stay independent)."""
    deadline = time.monotonic() + timeout
    alive = set(pids)
    while alive and time.monotonic() < deadline:
        alive &= set(fleet_processes())
        time.sleep(0.05)
    for pid in alive:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    return alive
