"""``agv-fleet run``: a world, one process per AGV, all on a fresh Zenoh bus.

The AGV processes are started first (they retry connecting), then this
process opens the router on a fresh endpoint and runs the world in it; so no
process ever forks after it opened a Zenoh session. Every child is ended by
PID on every way out: normal end, error, Ctrl-C or SIGTERM.

A recorder that ends before the run does is not a recording of the run: the run
goes on without it, and then ``RecordingLost`` says what the file holds.

Every run has its own credentials and access control (see bridge.trust): they
live in a private temporary folder (with the Unix socket) that the children
find through an environment variable, and that is removed at the end.
"""

from __future__ import annotations

import os
import queue
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from bridge.bus import Bus
from bridge.session import fresh_endpoint, new_run_id, open_router, run_prefix
from bridge.trust import CREDENTIALS_ENV, write_run_credentials
from fleet.runtime.interrupts import interrupts_raised
from fleet.runtime.summary import RunSummary
from fleet.runtime.world import World
from fleet.runtime.world_server import TICK_TIMEOUT_S, WorldServer
from fleet.runtime.world_watch import DEFAULT_GRACE_S
from fleet.scenario import Scenario
from planner.core.errors import EnvironmentFailure
from recordings.reader import held_seconds

EXIT_GRACE_S = 5.0


@dataclass
class FleetOptions:
    scenario_arg: str  # what the AGV processes load: a file path or a built-in name
    algorithm: str | None = None
    profile: str | None = None
    traffic: str | None = None
    realtime: float | None = None
    transport: str = "unix"
    zenoh_config: str | None = None
    tick_timeout: float = TICK_TIMEOUT_S
    grace: float = DEFAULT_GRACE_S
    record_path: Path | None = None  # None: no recorder
    say_waiting: bool = False  # tell on stderr when the AGVs are slow to come up


def agv_command(options: FleetOptions, names: list[str], endpoint: str, prefix: str) -> list[str]:
    """One host process that forks a process per AGV (see fleet.runtime.agv_host)."""
    # -P: import the same installed packages as this process, not a checkout in the cwd
    cmd = [sys.executable, "-P", "-m", "fleet.cli", "agv", options.scenario_arg]
    for name in names:
        cmd += ["--name", name]
    return cmd + _run_options(options, endpoint, prefix)


def recorder_command(options: FleetOptions, endpoint: str, prefix: str, run_id: str) -> list[str]:
    cmd = [sys.executable, "-P", "-m", "fleet.cli", "record", options.scenario_arg]
    cmd += ["--run-id", run_id, "-o", str(options.record_path)]
    return cmd + _run_options(options, endpoint, prefix)


def _run_options(options: FleetOptions, endpoint: str, prefix: str) -> list[str]:
    """What every child of the run is told alike: where the bus is, and the overrides."""
    args = ["--connect", endpoint, "--prefix", prefix, "--grace", str(options.grace)]
    for flag, value in (
        ("--algorithm", options.algorithm),
        ("--profile", options.profile),
        ("--traffic", options.traffic),
        ("--zenoh-config", options.zenoh_config),
    ):
        if value:
            args += [flag, value]
    return args


def run_fleet(
    scenario: Scenario,
    options: FleetOptions,
    progress: Callable[[World], None] | None = None,
    tap: Callable[[str, object], None] | None = None,
) -> RunSummary:
    """Run ``scenario`` with one process per AGV (and a recorder process when
    ``options.record_path`` is set), all on a fresh private bus. ``tap(key, msg)``
    sees every message of the bus, in this thread, after each tick (the live view)."""
    run_id = new_run_id()
    prefix = run_prefix(run_id)
    run_dir = tempfile.mkdtemp(prefix="agv-fleet-")  # 0700: this user's only
    endpoint = fresh_endpoint(options.transport, run_dir)
    children: list[subprocess.Popen] = []
    with _children_ended(children), interrupts_raised():
        try:
            names = [agv.name for agv in scenario.agvs]
            guard, child_files = write_run_credentials(run_dir, names, prefix)
            exits = AgvExits()
            command = [*agv_command(options, names, endpoint, prefix), "--exits-fd", exits.fd]
            children.append(_spawn(command, child_files["agvs"], pass_fds=(int(exits.fd),)))
            exits.start()
            recorder, ended = None, {}
            if options.record_path:
                recorder = _spawn(
                    recorder_command(options, endpoint, prefix, run_id), child_files["recorder"]
                )
                children.append(recorder)
                progress = _recorder_watched(recorder, progress, ended)
            with open_router(endpoint, options.zenoh_config, guard) as session:
                bus = Bus(session, prefix)
                if tap:
                    progress = _tapped(bus, tap, progress)
                server = WorldServer(
                    scenario,
                    bus,
                    tick_timeout=options.tick_timeout,
                    grace=options.grace,
                    realtime=options.realtime,
                    progress=progress,
                    abort_check=lambda: _exited_early(children),
                    recorder=options.record_path is not None,
                    say_waiting=options.say_waiting,
                    exits=exits.queue,
                )
                summary = server.run()
                if progress:
                    progress(server.world)  # the last messages, for the tap
            if recorder is not None:
                _check_recording(recorder, options.record_path, ended, summary)
            return summary
        finally:
            shutil.rmtree(run_dir, ignore_errors=True)


class RecordingLost(EnvironmentFailure):
    """The run completed, its recording did not: ``summary`` is the run's."""

    def __init__(self, message: str, summary: RunSummary):
        super().__init__(message)
        self.summary = summary


def _recorder_watched(recorder: subprocess.Popen, progress, ended: dict):
    """A progress callback that also notes (in ``ended["at"]``) the simulated time at
    which the recorder process was first seen ended."""

    def on_tick(world: World) -> None:
        if "at" not in ended and recorder.poll() is not None:
            ended["at"] = world.time
        if progress:
            progress(world)

    return on_tick


def _check_recording(recorder: subprocess.Popen, path: Path, ended: dict, summary) -> None:
    """Raise RecordingLost unless the recorder stored the whole run and exited with 0."""
    try:
        code = recorder.wait(timeout=EXIT_GRACE_S)
    except subprocess.TimeoutExpired:
        code = None
    if code == 0:
        return
    if code is None:
        how = "did not finish"
    else:
        how = f"was killed by signal {-code}" if code < 0 else f"ended with status {code}"
    when = f" at t = {ended['at']:.1f} s" if "at" in ended else ""
    held = held_seconds(path)
    holds = "nothing readable" if held is None else f"{held:.1f} of {summary.sim_time:.1f} s"
    raise RecordingLost(f"the recorder {how}{when}: {path} holds {holds}", summary)


def _tapped(bus: Bus, tap, progress):
    """A progress callback that also hands every message seen on the bus to ``tap``."""
    messages = bus.subscribe("**")

    def on_tick(world: World) -> None:
        while not messages.empty():
            received = messages.get_nowait()
            tap(received.key, received.msg)
        if progress:
            progress(world)

    return on_tick


def _exited_early(children: list[subprocess.Popen]) -> str | None:
    """Why the run cannot start: a child process that already ended with an error."""
    for child in children:
        code = child.poll()
        if code:
            what = " ".join(child.args[4:6])  # the command and the scenario
            return f"the process of '{what}' ended with status {code} before the run started"
    return None


class AgvExits:
    """The pipe on which the AGV host tells which AGV process ended abnormally and how
    (``agv_host.tell_exit``), read by a thread into ``queue`` as (name, why)."""

    def __init__(self):
        self._read, write = os.pipe()
        self.fd = str(write)
        self.queue: queue.Queue[tuple[str, str]] = queue.Queue()

    def start(self) -> None:
        """After the host has its copy of the write end: close ours and read."""
        os.close(int(self.fd))
        threading.Thread(target=self._pump, daemon=True).start()

    def _pump(self) -> None:
        with os.fdopen(self._read, "r", errors="replace") as lines:
            for line in lines:
                name, _, why = line.rstrip("\n").partition("\t")
                if name and why:
                    self.queue.put((name, why))


def _spawn(cmd: list[str], credentials_file: str, pass_fds=()) -> subprocess.Popen:
    # own process group: a Ctrl-C in the terminal reaches only the launcher, which
    # ends the children itself, in order
    env = {**os.environ, CREDENTIALS_ENV: credentials_file}
    return subprocess.Popen(
        cmd, stdin=subprocess.DEVNULL, start_new_session=True, env=env, pass_fds=pass_fds
    )


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
