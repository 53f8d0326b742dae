"""Running a sweep's runs: a local process pool or a Dask cluster, resumable.

Each run is one task, ``record_run``: the checked scenario goes to a worker (pickled,
map included, so a worker on another machine needs no scenario or map file), which
runs it in process into a temporary recording and sends the recording's bytes back.
Here they are written to ``<out>/<run name>.mcap`` under a temporary name and renamed
when whole, so a recording under its own name is a finished run: on the next sweep
into the same folder, a recording of the same scenario text that finished is not
redone, and Ctrl-C (which stops the pool) loses only the runs in flight.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from fleet.runtime.inprocess import run_recorded
from fleet.scenario import Scenario
from fleet.sweep.grid import SweepRun
from recordings.reader import Recording, RecordingError, open_recording

PARTIAL_SUFFIX = ".partial"


@dataclass(frozen=True)
class Finished:
    """A run whose recording is whole under ``recording``."""

    run: SweepRun
    recording: Path
    reused: bool  # recorded by an earlier sweep into the same folder


def run_facts(run: SweepRun) -> dict:
    """What the recording says about the run: how it was made and its sweep values."""
    configs = {a.config.algorithm for a in run.scenario.agvs}
    profiles = {a.config.profile for a in run.scenario.agvs}
    return {
        "mode": "in-process",
        "algorithm": configs.pop() if len(configs) == 1 else "scenario's",
        "profile": profiles.pop() if len(profiles) == 1 else "scenario's",
        "experiment": "agv-fleet sweep",
        "sweep": {"variant": run.variant, "sample": run.sample},
    }


def record_run(scenario: Scenario, facts: dict) -> bytes:
    """The task a worker runs: ``scenario`` in process, its whole recording as bytes."""
    with tempfile.TemporaryDirectory(prefix="agv-fleet-sweep-") as folder:
        path = Path(folder) / "run.mcap"
        run_recorded(scenario, path, facts)
        return path.read_bytes()


def recording_path(out: Path, run: SweepRun) -> Path:
    return out / f"{run.name}.mcap"


def finished_recording(path: Path, run: SweepRun) -> Recording | None:
    """The recording at ``path`` if it is a finished run of exactly ``run``'s scenario."""
    if not path.is_file():
        return None
    try:
        rec = open_recording(path)
    except RecordingError:
        return None
    whole = rec.result is not None and not rec.truncated
    return rec if whole and rec.scenario_text == run.scenario.source else None


def save_recording(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` whole or not at all (a temporary name, then a rename)."""
    partial = path.with_name(path.name + PARTIAL_SUFFIX)
    partial.write_bytes(data)
    os.replace(partial, path)


Executor = Callable[[list[tuple[int, SweepRun]]], Iterator[tuple[int, bytes]]]


def local_pool(workers: int) -> Executor:
    """An executor of ``workers`` processes on this machine (spawned: no state copied)."""

    def execute(todo: list[tuple[int, SweepRun]]) -> Iterator[tuple[int, bytes]]:
        context = multiprocessing.get_context("spawn")
        pool = context.Pool(min(workers, len(todo)) or 1, initializer=_worker_start)
        try:
            tasks = [(i, run.scenario, run_facts(run)) for i, run in todo]
            yield from pool.imap_unordered(_numbered_run, tasks)
            pool.close()
        finally:
            pool.terminate()  # Ctrl-C or an error: stop the runs in flight
            pool.join()

    return execute


def _worker_start() -> None:
    """A pool worker leaves Ctrl-C to the sweep, which stops the pool."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _numbered_run(task: tuple[int, Scenario, dict]) -> tuple[int, bytes]:
    index, scenario, facts = task
    return index, record_run(scenario, facts)


def execute_sweep(
    runs: list[SweepRun],
    out: Path,
    executor: Executor,
    on_finished: Callable[[Finished, Recording], None],
) -> list[Finished]:
    """Every run of ``runs`` recorded under ``out`` (those already there reused), each
    handed to ``on_finished`` with its recording as it becomes whole."""
    out.mkdir(parents=True, exist_ok=True)
    for stale in out.glob(f"*.mcap{PARTIAL_SUFFIX}"):  # left by a sweep that was killed
        stale.unlink()
    done: dict[int, Finished] = {}
    todo = []
    for i, run in enumerate(runs):
        path = recording_path(out, run)
        rec = finished_recording(path, run)
        if rec is None:
            todo.append((i, run))
        else:
            done[i] = Finished(run, path, reused=True)
            on_finished(done[i], rec)
    if todo:
        for i, data in executor(todo):
            path = recording_path(out, runs[i])
            save_recording(path, data)
            done[i] = Finished(runs[i], path, reused=False)
            on_finished(done[i], open_recording(path))
    return [done[i] for i in range(len(runs))]


class SweepProgress:
    """Lines on stderr: runs done of all, how many were reused, and the time left at the
    pace of the runs made since the first one (starting the workers is not a run's time)."""

    def __init__(self, total: int, stream, quiet: bool = False):
        self.total = total
        self.stream = stream
        self.quiet = quiet
        self.done = 0
        self.reused = 0
        self.first_made: float | None = None

    def __call__(self, finished: Finished) -> None:
        self.done += 1
        self.reused += finished.reused
        now = time.perf_counter()
        made = self.done - self.reused
        if made == 1 and not finished.reused:
            self.first_made = now
        if self.quiet:
            return
        left = self.total - self.done
        eta = ""
        if made > 1 and left and self.first_made is not None:
            eta = f", ETA {_duration((now - self.first_made) / (made - 1) * left)}"
        reused = f" ({self.reused} already recorded)" if self.reused else ""
        print(
            f"sweep: {self.done}/{self.total} done{reused}{eta}: {finished.recording.name}",
            file=self.stream,
            flush=True,
        )


def _duration(seconds: float) -> str:
    minutes, secs = divmod(round(seconds), 60)
    return f"{minutes} min {secs:02d} s" if minutes else f"{secs} s"
