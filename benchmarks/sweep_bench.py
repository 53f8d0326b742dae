"""How a sweep scales: 16 in-process runs on 1 worker against 2, and Dask's cost per run.

- Speed-up: the same 16 runs (the built-in warehouse at 16 time limits, ``SCENARIO``)
  with the local pool of 1 process and of 2, each into a fresh folder, wall time from the first
  task to the last recording written (starting the pool included). Target on a 2-core
  machine: >= 1.7x.
- Overhead per run: 16 runs that end at their first tick (the AGV starts on its goal),
  on the local pool of 2 and on a real Dask cluster of 2 single-threaded workers
  (``dask scheduler`` / ``dask worker`` subprocesses, started before the clock): the
  difference over 16 is what Dask costs a run beyond the local pool (sending the
  scenario, the scheduler's round trips, the recording's bytes back). Starting the
  local pool (a pool started for one empty run) is measured alone and left out of the
  local pool's time per run, as the Dask workers' start is.

Run from the repository root: ``python benchmarks/sweep_bench.py`` (about 2-3 minutes).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

if __package__ in (None, ""):
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.dask_processes import DaskProcesses
from fleet.sweep.dask_cluster import dask_cluster
from fleet.sweep.grid import build_grid
from fleet.sweep.keys import parse_vary
from fleet.sweep.runner import Executor, execute_sweep, local_pool

RUNS = 16
TARGET_SPEEDUP = 1.7
SCENARIO = "warehouse"
"""The built-in 8-AGV warehouse, cut at 16 time limits (30 to 45 s): runs of one to two
seconds each, as a sweep's runs are, against a pool start of about a second (each worker
loads the planner's compiled kernels once). Runs much shorter than that measure the
pool's start, not the sweep."""
TIMINGS = "time_limit=30:{last}:1"
EMPTY = """name = "sweep-bench-empty"
dt = 0.1
time_limit = 40

[map]
resolution = 1.0
grid = \"\"\"
..........
..........
\"\"\"

[[agvs]]
name = "a1"
start = [0.5, 0.5]
goal = [0.5, 0.5]
"""


def timed(executor: Executor, runs, out: Path) -> float:
    t0 = time.perf_counter()
    execute_sweep(runs, out, executor, lambda finished, rec: None)
    return time.perf_counter() - t0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=RUNS, help=f"runs per sweep (default {RUNS})")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="sweep-bench-") as folder:
        root = Path(folder)
        empty = root / "empty.toml"
        empty.write_text(EMPTY)
        runs = build_grid(SCENARIO, [], [parse_vary(TIMINGS.format(last=29 + args.runs))])
        empties = build_grid(str(empty), [], [parse_vary(f"time_limit=30:{29 + args.runs}:1")])

        one = timed(local_pool(1), runs, root / "one")
        two = timed(local_pool(2), runs, root / "two")
        print(f"{len(runs)} runs, local pool: 1 worker {one:.1f} s, 2 workers {two:.1f} s")
        speedup = one / two
        verdict = "meets" if speedup >= TARGET_SPEEDUP else "misses"
        print(f"  speed-up {speedup:.2f}x ({verdict} the target >= {TARGET_SPEEDUP}x)")

        start = timed(local_pool(1), empties[:1], root / "start")
        local = timed(local_pool(2), empties, root / "empty-local")
        with DaskProcesses(root, workers=2) as address:
            remote = timed(dask_cluster(address), empties, root / "empty-dask")
        # the Dask workers were up before the clock: the pool's start-up is left out of its
        # runs too (``start`` is a pool started for one run, so the run's own time is in it)
        per_local = max(local - start, 0.0) / len(empties)
        per_dask = remote / len(empties)
        print(
            f"{len(empties)} runs of one tick: local pool of 2 {local:.2f} s, of which starting "
            f"the pool (with one run) {start:.2f} s: {per_local * 1000:.0f} ms a run; "
            f"Dask with 2 workers {remote:.2f} s: {per_dask * 1000:.0f} ms a run"
        )
        overhead = (per_dask - per_local) * 1000
        print(f"  Dask's overhead against the local pool: {overhead:+.0f} ms a run")
    return 0


if __name__ == "__main__":
    sys.exit(main())
