"""Table 4 and the smoothness comparison over many walker timings, as a sweep.

One run of ``paper-dynamic`` proves little: when the walker starts decides whom it
meets. So the scenario (profile ``paper``) is swept with ``fleet.sweep`` over every
planner variant and ``WALKER_TIMINGS`` walker starts, each run recorded under the
paper's runs folder (``sweep/``; a run already recorded there is not redone), and
measured by ``recordings.analysis``. The report compares the variants timing by
timing: the % change of fusion against the hybrid at the same walker start, whose
distribution (``recordings.sweep_stats``) is what a verdict looks at.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from fleet.sweep.folder import sweep_entry, write_manifest
from fleet.sweep.grid import build_grid
from fleet.sweep.keys import Varied, parse_vary
from fleet.sweep.runner import SweepProgress, execute_sweep, local_pool
from planner.core.profiles import PAPER
from recordings.compare import percent_change
from recordings.sweep_report import SweepEntry
from recordings.sweep_stats import MetricStats, describe

SCENARIO = "paper-dynamic"
ALGORITHMS = ("fusion", "astar-dwa")  # what Table 4 and Fig. 11 compare
ALGORITHM_KEY = "planner.algorithm"
TIMING_KEY = "obstacles.walker.start_at"
WALKER_TIMINGS = f"{TIMING_KEY}=0:40:2"  # s: 21 starts, the shipped one (20 s) among them
QUICK_TIMINGS = f"{TIMING_KEY}=10:30:10"  # --quick (the tests): three


@dataclass
class TimingSweep:
    """Every run of the sweep, by (algorithm, walker start), measured at the run level."""

    folder: Path
    timings: tuple[float, ...]
    runs: dict[tuple[str, float], SweepEntry]

    def values(self, algorithm: str, metric: str) -> list[float]:
        """``metric`` of ``algorithm``'s runs, in the order of the timings (missing skipped)."""
        found = (self.runs[(algorithm, t)].run.get(metric) for t in self.timings)
        return [v for v in found if v is not None]

    def changes(self, metric: str, new: str = "fusion", old: str = "astar-dwa") -> list[float]:
        """The % change of ``new`` against ``old`` at each walker start where both have it."""
        out = []
        for t in self.timings:
            a, b = self.runs[(new, t)].run.get(metric), self.runs[(old, t)].run.get(metric)
            change = percent_change(a, b)
            if change is not None:
                out.append(change)
        return out

    def change_stats(self, metric: str) -> MetricStats | None:
        changes = self.changes(metric)
        return describe(changes) if changes else None

    def arrived_all(self, algorithm: str) -> int:
        """Of ``algorithm``'s runs, how many had every AGV arrive with no collision."""
        return sum(
            e.run.get("arrived") == 1 and e.run.get("collisions") == 0
            for (a, _), e in self.runs.items()
            if a == algorithm
        )


def record_timing_sweep(
    folder: Path, workers: int, log: Callable[[str], None], quick: bool = False
) -> TimingSweep:
    vary = [Varied("profile", (PAPER,)), Varied(ALGORITHM_KEY, ALGORITHMS)]
    over = [parse_vary(QUICK_TIMINGS if quick else WALKER_TIMINGS, "--over")]
    runs = build_grid(SCENARIO, vary, over)
    write_manifest(folder, SCENARIO, vary, over, runs)
    progress = SweepProgress(len(runs), _LogStream(log))
    measured: dict[tuple[str, float], SweepEntry] = {}

    def finished(done, rec) -> None:
        key = (done.run.variant[ALGORITHM_KEY], done.run.sample[TIMING_KEY])
        run = done.run
        measured[key] = sweep_entry(run.variant, run.sample, done.recording, rec, done.reused)
        progress(done)

    execute_sweep(runs, folder, local_pool(workers), finished)
    return TimingSweep(folder, tuple(over[0].values), measured)


class _LogStream:
    """The sweep's progress lines into the paper's log."""

    def __init__(self, log: Callable[[str], None]):
        self.log = log

    def write(self, text: str) -> None:
        if text.strip():
            self.log(text.strip())

    def flush(self) -> None:
        """Nothing is buffered."""
