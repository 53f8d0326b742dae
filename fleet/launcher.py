"""``agv-fleet run``: a world, one process per AGV, all on a fresh Zenoh bus.

The AGV processes are started first (they retry connecting), then this
process opens the router on a fresh endpoint and runs the world in it; so no
process ever forks after it opened a Zenoh session. Every child is ended by
PID on every way out: normal end, error, Ctrl-C or SIGTERM.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass

from bridge.bus import Bus
from bridge.session import fresh_endpoint, new_run_id, open_router, run_prefix
from fleet.scenario import Scenario
from fleet.summary import RunSummary
from fleet.world import World
from fleet.world_process import WorldServer

EXIT_GRACE_S = 5.0


@dataclass
class FleetOptions:
    scenario_arg: str  # what the AGV processes load: a file path or a built-in name
    algorithm: str | None = None
    realtime: float | None = None
    transport: str = "unix"
    zenoh_config: str | None = None
    tick_timeout: float = 2.0


def agv_command(options: FleetOptions, names: list[str], endpoint: str, prefix: str) -> list[str]:
    """One host process that forks a process per AGV (see fleet.agv_host)."""
    # -P: import the same installed packages as this process, not a checkout in the cwd
    cmd = [sys.executable, "-P", "-m", "fleet.cli", "agv", options.scenario_arg]
    for name in names:
        cmd += ["--name", name]
    cmd += ["--connect", endpoint, "--prefix", prefix]
    if options.algorithm:
        cmd += ["--algorithm", options.algorithm]
    if options.zenoh_config:
        cmd += ["--zenoh-config", options.zenoh_config]
    return cmd


def run_fleet(
    scenario: Scenario,
    options: FleetOptions,
    progress: Callable[[World], None] | None = None,
    extra_children: Callable[[str, str], list[list[str]]] | None = None,
) -> RunSummary:
    """Run ``scenario`` with one process per AGV; ``extra_children(endpoint, prefix)``
    gives more commands to start on the same bus (the recorder)."""
    run_id = new_run_id()
    prefix = run_prefix(run_id)
    endpoint = fresh_endpoint(options.transport)
    children: list[subprocess.Popen] = []
    with _children_ended(children), _sigterm_as_interrupt():
        try:
            names = [agv.name for agv in scenario.agvs]
            children.append(_spawn(agv_command(options, names, endpoint, prefix)))
            for cmd in extra_children(endpoint, prefix) if extra_children else []:
                children.append(_spawn(cmd))
            with open_router(endpoint, options.zenoh_config) as session:
                server = WorldServer(
                    scenario,
                    Bus(session, prefix),
                    tick_timeout=options.tick_timeout,
                    realtime=options.realtime,
                    progress=progress,
                    abort_check=lambda: _exited_early(children),
                )
                return server.run()
        finally:
            if endpoint.startswith("unixsock-stream/"):
                shutil.rmtree(os.path.dirname(endpoint.split("/", 1)[1]), ignore_errors=True)


def _exited_early(children: list[subprocess.Popen]) -> str | None:
    """Why the run cannot start: a child process that already ended with an error."""
    for child in children:
        code = child.poll()
        if code:
            what = " ".join(child.args[4:6])
            return f"the process of '{what}' ended with status {code} before the run started"
    return None


def _spawn(cmd: list[str]) -> subprocess.Popen:
    # own process group: a Ctrl-C in the terminal reaches only the launcher, which
    # ends the children itself, in order
    return subprocess.Popen(cmd, stdin=subprocess.DEVNULL, start_new_session=True)


@contextmanager
def _children_ended(children: list[subprocess.Popen]):
    """On the way out, give children a grace period to exit, then end them by PID."""
    try:
        yield
    finally:
        deadline = time.monotonic() + EXIT_GRACE_S
        for child in children:
            try:
                child.wait(timeout=max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                child.terminate()
        for child in children:
            try:
                child.wait(timeout=1.0)
            except subprocess.TimeoutExpired:
                child.kill()
                child.wait()


@contextmanager
def _sigterm_as_interrupt():
    """SIGTERM ends the run like Ctrl-C, so the children are cleaned up."""

    def handler(signum, frame):
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
