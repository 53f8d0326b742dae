"""A real Dask cluster on this machine for tests and benchmarks: ``dask scheduler`` and
``dask worker`` as subprocesses on free 127.0.0.1 ports, always stopped on the way out.

Not a LocalCluster and not an in-process client: the scheduler and the workers are
separate processes started as a user starts them, so a sweep reaches them as it would
reach a cluster of other machines.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

BIN = Path(sys.executable).parent
START_TIMEOUT_S = 60


class DaskProcesses:
    """``with DaskProcesses(folder, workers=2) as address:`` a scheduler and ``workers``
    single-threaded worker processes; logs and the scheduler file go into ``folder``."""

    def __init__(self, folder: Path, workers: int = 2):
        self.folder = folder
        self.workers = workers
        self.file = folder / "scheduler.json"
        self.processes: list[subprocess.Popen] = []

    def __enter__(self) -> str:
        from distributed import Client

        common = ["--no-dashboard", "--scheduler-file", str(self.file)]
        self._start("scheduler", "--host", "127.0.0.1", "--port", "0", *common)
        try:
            deadline = time.monotonic() + START_TIMEOUT_S
            while not self.file.is_file() and time.monotonic() < deadline:
                time.sleep(0.2)
            address = json.loads(self.file.read_text())["address"]
            workers = ["--nworkers", str(self.workers), "--nthreads", "1", "--host", "127.0.0.1"]
            self._start("worker", *workers, *common)
            with Client(address, timeout=START_TIMEOUT_S) as client:
                client.wait_for_workers(self.workers, timeout=START_TIMEOUT_S)
            return address
        except BaseException:
            self.__exit__()
            raise

    def _start(self, role: str, *args: str) -> None:
        with (self.folder / f"dask-{role}.log").open("w") as log:
            command = [str(BIN / "dask"), role, *args]
            self.processes.append(subprocess.Popen(command, stdout=log, stderr=log))

    def __exit__(self, *exc) -> None:
        for process in reversed(self.processes):  # the workers first, then the scheduler
            process.terminate()
            try:
                process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
