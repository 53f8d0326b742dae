"""Ticks per second of the fleet with 5, 20 and 50 AGVs: over Zenoh and in process.

A 60 x 40 m warehouse (shelf rows, 3 m aisles, cross aisles) with AGVs
starting in docks on both sides and crossing to the other. Each run is cut
at ``--sim-time`` seconds of simulated time. Reported per fleet size:

- ticks/s of the lockstep clock, planning included (first to last tick), for
  the Zenoh mode (a world router and one process per AGV) and the in-process
  mode (the baseline: the same world and AGV step code, no bus);
- start-up: from the launch until the first tick is done (all AGV processes
  forked, connected and answering).

Target: 50 AGVs at >= 20 ticks/s (2x real time at 10 Hz), start-up < 5 s.

Run from the repository root: ``python benchmarks/fleet_bench.py``.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from fleet.runtime.inprocess import run_in_process
from fleet.runtime.launcher import FleetOptions, run_fleet
from fleet.scenario import load_scenario

WIDTH, HEIGHT = 60, 40


def warehouse_grid() -> str:
    rows = [["."] * WIDTH for _ in range(HEIGHT)]  # rows[0] is the bottom row
    for y0 in range(5, HEIGHT - 5, 5):
        for y in (y0, y0 + 1):
            for x in range(8, WIDTH - 8):
                if (x - 8) % 12 not in (9, 10, 11):  # cross aisles every 12 m
                    rows[y][x] = "#"
    return "\n".join("".join(r) for r in reversed(rows))


def scenario_text(agvs: int, sim_time: float) -> str:
    docks = [(x + 0.5, y + 0.5) for y in range(1, HEIGHT - 1, 2) for x in (1, 3, 5)]
    lines = [
        f'name = "bench-warehouse-{agvs}"',
        f"time_limit = {sim_time}",
        "[map]",
        f'grid = """\n{warehouse_grid()}\n"""',
    ]
    for i in range(agvs):
        x, y = docks[(i // 2) % len(docks)]
        start, goal = (
            ((x, y), (WIDTH - x, HEIGHT - y)) if i % 2 == 0 else ((WIDTH - x, y), (x, HEIGHT - y))
        )
        lines += [
            "[[agvs]]",
            f'name = "agv{i + 1}"',
            f"start = [{start[0]}, {start[1]}]",
            f"goal = [{goal[0]}, {goal[1]}]",
            f"heading = {0 if i % 2 == 0 else 180}",
        ]
    return "\n".join(lines) + "\n"


class Clock:
    """Records when the first and the last tick were done."""

    def __init__(self):
        self.start = time.monotonic()
        self.first = self.last = None
        self.ticks = 0

    def __call__(self, world) -> None:
        now = time.monotonic()
        if self.first is None:
            self.first = now
            self.first_tick = world.tick
        self.last, self.ticks = now, world.tick

    @property
    def ticks_per_s(self) -> float:
        span = self.last - self.first
        return (self.ticks - self.first_tick) / span if span > 0 else float("nan")

    @property
    def start_up(self) -> float:
        return self.first - self.start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="5,20,50")
    parser.add_argument("--sim-time", type=float, default=30.0, help="simulated seconds per run")
    args = parser.parse_args()
    print(f"fleet_bench: {WIDTH}x{HEIGHT} m warehouse, {args.sim_time:g} s simulated per run")
    header = (
        f"{'AGVs':>5}  {'in-process t/s':>14}  {'zenoh t/s':>9}  {'zenoh/in-process':>16}  "
        f"{'start-up s':>10}  arrived/collisions (zenoh)"
    )
    print(header)
    print("-" * len(header))
    verdicts = []
    with tempfile.TemporaryDirectory() as folder:
        for size in (int(s) for s in args.sizes.split(",")):
            path = Path(folder) / f"bench-{size}.toml"
            path.write_text(scenario_text(size, args.sim_time))
            scenario = load_scenario(path)
            local = Clock()
            run_in_process(scenario, progress=local)
            bus = Clock()
            summary = run_fleet(scenario, FleetOptions(scenario_arg=str(path)), progress=bus)
            arrived = sum(a.status == "arrived" for a in summary.agvs)
            print(
                f"{size:>5}  {local.ticks_per_s:>14.1f}  {bus.ticks_per_s:>9.1f}  "
                f"{bus.ticks_per_s / local.ticks_per_s:>16.2f}  {bus.start_up:>10.2f}  "
                f"{arrived}/{size} arrived by {args.sim_time:g} s, {summary.collisions} collisions"
            )
            if size == 50:
                verdicts.append(
                    ("50 AGVs over Zenoh >= 20 ticks/s", bus.ticks_per_s >= 20, bus.ticks_per_s)
                )
                verdicts.append(("start-up of 50 AGVs < 5 s", bus.start_up < 5, bus.start_up))
    for what, ok, value in verdicts:
        print(f"{'PASS' if ok else 'MISS'}  {what} ({value:.2f})")


if __name__ == "__main__":
    main()
