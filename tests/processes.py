"""Finding the processes a test started, by PID through /proc (Linux).

The test session makes itself a child subreaper (``PR_SET_CHILD_SUBREAPER``),
so every process it started stays its descendant even when the parent in
between dies (a launcher killed with -9 leaves its AGVs to us, not to init).
"Ours" is then exactly the live descendants of this process: fleet runs
that other people start on the same machine are never counted.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal
import time
from pathlib import Path

_PR_SET_CHILD_SUBREAPER = 36


def become_subreaper() -> None:
    ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)


def _read(path: Path) -> str:
    try:
        return path.read_text(errors="replace")
    except OSError:
        return ""


def _parent_and_state(stat: str) -> tuple[int, str]:
    # "pid (comm) state ppid ...": comm may hold spaces and parentheses
    fields = stat.rsplit(")", 1)[-1].split()
    return int(fields[1]), fields[0]


def fleet_processes() -> dict[int, str]:
    """Every live (not zombie) descendant of this process: PID -> command line."""
    parents, commands = {}, {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        stat = _read(entry / "stat")
        if not stat:
            continue
        ppid, state = _parent_and_state(stat)
        if state == "Z":  # already dead, waiting to be reaped
            continue
        pid = int(entry.name)
        parents[pid] = ppid
        commands[pid] = _read(entry / "cmdline").replace("\0", " ").strip()
    me = os.getpid()
    found = {}
    for pid in parents:
        ancestor = parents.get(pid)
        while ancestor is not None and ancestor != me:
            ancestor = parents.get(ancestor)
        if ancestor == me:
            found[pid] = commands[pid]
    return found


def agv_pid(name: str, timeout: float = 30.0) -> int:
    """The PID of the process running AGV ``name`` (titled ``agv-fleet agv NAME``)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        for pid, command in fleet_processes().items():
            if command == f"agv-fleet agv {name}":
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
