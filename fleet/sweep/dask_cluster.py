"""``agv-fleet sweep --cluster ADDRESS``: the same runs on a Dask distributed cluster.

A scheduler and workers are started by the user (``dask scheduler``, ``dask worker
tcp://HOST:PORT``) on machines that have agv-fleet installed; ``pip install
'agv-fleet[cluster]'`` brings Dask. Each run is one task of ``record_run``; its
recording comes back as bytes and is written under ``--out`` here, exactly as the
local pool's are.
"""

from __future__ import annotations

from collections.abc import Iterator

from fleet.sweep.grid import SweepRun
from fleet.sweep.runner import Executor, record_run, run_facts
from planner.core.errors import AgvFleetError, EnvironmentFailure

CONNECT_TIMEOUT_S = 10


class ClusterError(EnvironmentFailure):
    """Dask is missing, the scheduler cannot be reached, or a worker failed."""


def dask_cluster(address: str) -> Executor:
    """An executor that runs each task on the Dask cluster whose scheduler is ``address``."""
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise ClusterError(
            "--cluster needs Dask distributed: pip install 'agv-fleet[cluster]'"
        ) from None

    def execute(todo: list[tuple[int, SweepRun]]) -> Iterator[tuple[int, bytes]]:
        try:
            client = Client(address, timeout=CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError, ValueError) as err:
            raise ClusterError(f"cannot reach the Dask scheduler at {address}: {err}") from None
        futures: dict = {}
        try:
            for i, run in todo:
                future = client.submit(record_run, run.scenario, run_facts(run), pure=False)
                futures[future] = i
            for future in as_completed(futures):
                yield futures[future], _result(future, todo, futures[future])
        finally:
            client.cancel(list(futures))  # Ctrl-C or an error: nothing left queued
            client.close()

    return execute


def _result(future, todo, index: int) -> bytes:
    try:
        return future.result()
    except AgvFleetError:
        raise
    except Exception as err:  # whatever failed on the worker (a missing install, a crash)
        name = dict(todo)[index].name
        failure = f"{type(err).__name__}: {err}"
        raise ClusterError(f"a Dask worker failed run {name}: {failure}") from None
