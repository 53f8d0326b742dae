"""The fleet over Zenoh against in process, side by side: 50 to 200 AGVs on two maps.

``python benchmarks/fleet_bench.py [--maps sparse,dense] [--sizes 50,100,200]
[--sim-time 12] [--runs 1] [--zenoh-only] [--shared-memory]`` (from the repository root). The
maps are ``benchmarks/fleet_maps.py``'s: a sparse 128 x 80 m and a dense 64 x 40 m warehouse,
the AGVs crossing from docks on one side to the other. Each run is cut at ``--sim-time``
seconds of simulated time. Per map and fleet size, the same scenario:

- in process (the baseline: the same world and AGV step code, no bus) and over Zenoh (a
  world router and one process per AGV): *warm* ticks/s, from tick ``WARM_FROM`` to the
  last one, and their ratio; the cold start apart: start-up (from the launch until the
  first tick is done) and the time of the first ``WARM_FROM`` ticks;
- the floors (``bus_floor.py``): ticks/s over Zenoh of AGV processes that answer every
  tick at once without planning, with the project's messages (bus) and with their bytes
  neither decoded nor encoded (Zenoh: what zenoh-python itself allows). A run over Zenoh
  cannot be faster than its bus floor;
- bytes of the world's ticks per tick (the tick as each AGV receives it, summed over the
  AGVs) and the CPU to decode them (``bridge.bus.decode`` in this process, summed);
- CPU per warm tick, from /proc: in process the whole process; over Zenoh the AGV
  processes' main threads (the step and publishing its answer), their other threads
  (receiving and decoding the tick: the subscriber's Python thread and Zenoh's), and the
  world process. These are robust to other load on the machine, ticks/s are not;
- memory: PSS (``/proc/PID/smaps_rollup``: shared pages split between the processes that
  share them) per AGV of the AGV host and its AGV processes, and of the world, at tick
  ``PSS_AT_TICK``.

A run that fails says so in one line ("not measured: ...") and the bench goes on.
``--runs N`` repeats each Zenoh run N times and reports the median by warm ticks/s.

Targets (issue 42): warm Zenoh >= 1.5x in process at 50 and 100 AGVs on both maps; 200
AGVs run; start-up of 100 AGVs < 5 s; PSS <= 15 MiB per AGV; an AGV's whole step in
process <= 0.5 ms at 50 AGVs (its thread time in ``AgvNode.on_tick``, warm ticks).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.bus_floor import bus_floor_ticks_per_s
from benchmarks.fleet_maps import LAYOUTS, scenario_text
from bridge import keys
from bridge.bus import decode
from bridge.session import SHARED_MEMORY_ENV, shared_memory
from bridge.wire import to_wire
from fleet.runtime.agv_node import AgvNode
from fleet.runtime.inprocess import run_in_process
from fleet.runtime.launcher import FleetOptions, run_fleet
from fleet.runtime.world import World
from fleet.scenario import load_scenario
from planner.core.status import ARRIVED

WARM_FROM = 30  # ticks before this are the cold start: not in the warm ticks/s
PSS_AT_TICK = 40
TICKS_PER_S = os.sysconf("SC_CLK_TCK")
DECODE_REPEATS = 5


def pss_kib(pid: int) -> int:
    """The PSS of one process in KiB (0 if it is gone)."""
    try:
        with open(f"/proc/{pid}/smaps_rollup") as f:
            return sum(int(line.split()[1]) for line in f if line.startswith("Pss:"))
    except OSError:
        return 0


def descendants(pid: int) -> list[int]:
    """The children and grandchildren of ``pid`` (the AGV host and its AGV processes)."""
    parents = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    parents[int(entry)] = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                pass
    children = [p for p, pp in parents.items() if pp == pid]
    return children + [p for p, pp in parents.items() if pp in children]


def cpu_s(pid: int, tid: int | None = None) -> float:
    """CPU seconds (user + system) of a process, its exited threads included, or of one of
    its threads (0 if it is gone)."""
    path = f"/proc/{pid}/stat" if tid is None else f"/proc/{pid}/task/{tid}/stat"
    try:
        with open(path) as f:
            fields = f.read().rsplit(")", 1)[1].split()  # the name may hold spaces
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / TICKS_PER_S


CpuSnapshot = dict[int, tuple[float, float]]


def cpu_snapshot(world_pid: int) -> CpuSnapshot:
    """Per process (the world and its descendants): CPU seconds so far of the main thread and
    of the whole process. The whole counts threads that have exited, so that Zenoh's
    short-lived threads are not lost between two snapshots."""
    return {pid: (cpu_s(pid, pid), cpu_s(pid)) for pid in [world_pid, *descendants(world_pid)]}


def cpu_split(before: CpuSnapshot, after: CpuSnapshot, world_pid: int) -> tuple[float, ...]:
    """CPU seconds between two snapshots: the AGV processes' main threads, their other
    threads, the world. Only processes alive at both count."""
    agv_main = agv_other = world = 0.0
    for pid in before.keys() & after.keys():
        main = after[pid][0] - before[pid][0]
        whole = after[pid][1] - before[pid][1]
        if pid == world_pid:
            world = whole
        else:
            agv_main, agv_other = agv_main + main, agv_other + whole - main
    return agv_main, agv_other, world


def tick_load(world: World) -> tuple[float, float]:
    """KB and ms of decoding per tick: the tick as the AGVs receive it on the bus, over all
    of them."""
    tick = world.final_tick()
    tick.final = False
    payload = to_wire(keys.WORLD_TICK, tick)
    times = []
    for _ in range(DECODE_REPEATS):
        start = time.perf_counter()
        decode(keys.WORLD_TICK, payload)
        times.append(time.perf_counter() - start)
    receivers = len(world.live_agvs())
    return len(payload) * receivers / 1e3, statistics.median(times) * receivers * 1e3


@dataclass
class Clock:
    """What a run's progress callback sees: when ticks were done, CPU, memory."""

    zenoh: bool
    cpu_to: int  # the last tick before the time limit: every AGV process still runs
    start: float = field(default_factory=time.monotonic)
    times: dict[int, float] = field(default_factory=dict)
    last_tick: int = -1
    cpu: dict[int, CpuSnapshot] = field(default_factory=dict)
    process_cpu: dict[int, float] = field(default_factory=dict)
    world_pss: int = 0
    agvs_pss: int = 0
    load: tuple[float, float] | None = None  # KB and decode ms per tick

    def __call__(self, world: World) -> None:
        k = world.tick
        self.times.setdefault(k, time.monotonic())
        self.last_tick = k
        if k in (WARM_FROM, self.cpu_to):
            if self.zenoh:
                self.cpu[k] = cpu_snapshot(os.getpid())
            else:
                self.process_cpu[k] = time.process_time()
        if k == PSS_AT_TICK:
            self.world_pss = pss_kib(os.getpid())
            self.agvs_pss = sum(pss_kib(p) for p in descendants(os.getpid()))
            if not self.zenoh:
                self.load = tick_load(world)

    @property
    def start_up(self) -> float:
        return self.times[min(self.times)] - self.start

    @property
    def cold_s(self) -> float:
        return self.times[WARM_FROM] - self.times[min(self.times)]

    @property
    def warm_ticks_per_s(self) -> float:
        span = self.times[self.last_tick] - self.times[WARM_FROM]
        return (self.last_tick - WARM_FROM) / span if span > 0 else float("nan")

    def cpu_ms_per_tick(self) -> tuple[float, ...] | None:
        """Warm ticks: over Zenoh (AGV main threads, AGV other threads, world); in process
        (the whole process,). None: the run ended before ``cpu_to`` (every AGV arrived)."""
        span = self.cpu_to - WARM_FROM
        if self.zenoh and self.cpu_to in self.cpu:
            split = cpu_split(self.cpu[WARM_FROM], self.cpu[self.cpu_to], os.getpid())
        elif not self.zenoh and self.cpu_to in self.process_cpu:
            split = (self.process_cpu[self.cpu_to] - self.process_cpu[WARM_FROM],)
        else:
            return None
        return tuple(seconds * 1e3 / span for seconds in split)


@dataclass
class Outcome:
    clock: Clock | None = None
    arrived: int = 0
    collisions: int = 0
    problem: str = ""  # why it was not measured


def measured(run, clock: Clock) -> Outcome:
    """``run(progress=clock)``; what went wrong in one line."""
    try:
        summary = run(progress=clock)
    except Exception as err:  # a bench reports any failure and goes on
        return Outcome(problem=f"{type(err).__name__}: {err}".splitlines()[0])
    if clock.last_tick <= WARM_FROM:
        return Outcome(problem=f"the run ended at tick {clock.last_tick}, before the warm ticks")
    arrived = sum(a.status == ARRIVED for a in summary.agvs)
    return Outcome(clock, arrived, summary.collisions)


class StepTimer:
    """The CPU (thread time) of every AGV's whole step (``AgvNode.on_tick``: planning, DWA,
    traffic) in an in-process run, from tick ``WARM_FROM`` on: the step alone, without the
    world, which the CPU per tick includes."""

    def __init__(self):
        self.seconds, self.steps = 0.0, 0

    @contextlib.contextmanager
    def timing(self):
        step = AgvNode.on_tick

        def timed(node, tick):
            start = time.thread_time()
            out = step(node, tick)
            if tick.tick >= WARM_FROM:
                self.seconds += time.thread_time() - start
                self.steps += 1
            return out

        AgvNode.on_tick = timed
        try:
            yield self
        finally:
            AgvNode.on_tick = step

    @property
    def ms_per_step(self) -> float | None:
        return self.seconds * 1e3 / self.steps if self.steps else None


def in_process(scenario, timer: StepTimer, progress):
    with timer.timing():
        return run_in_process(scenario, progress=progress)


def last_tick_before_the_limit(scenario) -> int:
    return round(scenario.time_limit / scenario.dt) - 1


def zenoh_median(scenario, path: Path, runs: int) -> Outcome:
    """The median of ``runs`` Zenoh runs by warm ticks/s (each run's rate printed when
    there are several); a failed run counts as the slowest."""
    outcomes = [
        measured(
            partial(run_fleet, scenario, FleetOptions(str(path))),
            Clock(True, last_tick_before_the_limit(scenario)),
        )
        for _ in range(runs)
    ]
    outcomes.sort(key=lambda o: o.clock.warm_ticks_per_s if o.clock else -1.0)
    if runs > 1:
        rates = ", ".join(f"{o.clock.warm_ticks_per_s:.1f}" if o.clock else "-" for o in outcomes)
        print(f"  {scenario.name}: {runs} Zenoh runs, warm ticks/s {rates}")
    return outcomes[(runs - 1) // 2]  # of an even N, the slower middle one


def floor_rates(scenario) -> tuple[tuple[float | None, float | None], str]:
    """The bus floor and the Zenoh floor (see ``bus_floor``), and why either was not measured."""
    rates, problems = [], []
    for raw in (False, True):
        try:
            rates.append(bus_floor_ticks_per_s(World(scenario).first_tick(), scenario.dt, raw=raw))
        except Exception as err:  # a bench reports any failure and goes on
            rates.append(None)
            problems.append(f"{type(err).__name__}: {err}".splitlines()[0])
    return (rates[0], rates[1]), "; ".join(problems)


def fmt(value: float | None, width: int, digits: int = 1) -> str:
    return f"{'-':>{width}}" if value is None else f"{value:>{width}.{digits}f}"


HEADER = (
    f"{'map':>6} {'AGVs':>4}  {'in-proc t/s':>11}  {'zenoh t/s':>9}  {'zenoh/in-proc':>13}  "
    f"{'bus floor':>9}  {'zenoh floor':>11}  {'start-up s':>10}  {'cold s':>6}  "
    f"{'PSS/AGV MiB':>11}  {'world MiB':>9}  {'KB/tick':>8}  {'decode ms/tick':>14}"
)


def report(map_name, size, local: Outcome, bus: Outcome, floors, floor_problem, verdicts):
    lc, bc = local.clock, bus.clock
    local_rate = lc.warm_ticks_per_s if lc else None
    bus_rate = bc.warm_ticks_per_s if bc else None
    ratio = bus_rate / local_rate if lc and bc else None
    load = lc.load if lc and lc.load else (None, None)
    print(
        f"{map_name:>6} {size:>4}  {fmt(local_rate, 11)}  {fmt(bus_rate, 9)}  "
        f"{fmt(ratio, 13, 2)}  {fmt(floors[0], 9)}  {fmt(floors[1], 11)}  "
        f"{fmt(bc and bc.start_up, 10, 2)}  "
        f"{fmt(bc and bc.cold_s, 6)}  {fmt(bc and bc.agvs_pss / size / 1024, 11)}  "
        f"{fmt(bc and bc.world_pss / 1024, 9)}  {fmt(load[0], 8)}  {fmt(load[1], 14, 2)}"
    )
    for mode, outcome in (("in process", local), ("over Zenoh", bus)):
        if outcome.problem:
            print(f"{'':>12}{mode}: not measured: {outcome.problem}")
    if floor_problem:
        print(f"{'':>12}floors: not measured: {floor_problem}")
    if lc and bc and lc.cpu_ms_per_tick() and bc.cpu_ms_per_tick():
        (whole,) = lc.cpu_ms_per_tick()
        steps, receiving, world = bc.cpu_ms_per_tick()
        print(
            f"{'':>12}CPU per warm tick: in process {whole:.1f} ms; over Zenoh AGV main "
            f"threads {steps:.1f} ms ({steps / size:.2f} per AGV), AGV receiving "
            f"{receiving:.1f} ms, world {world:.1f} ms, sum {steps + receiving + world:.1f} ms"
        )
        cores = os.cpu_count() or 1
        print(
            f"{'':>12}so over Zenoh at most {cores * whole / (steps + receiving + world):.2f}x "
            f"in process, with all {cores} cores busy all the time"
        )
    elif lc and bc:
        print(f"{'':>12}CPU per warm tick: not measured (the run ended before the time limit)")
    if lc and bc:
        print(
            f"{'':>12}arrived by the cut: in process {local.arrived}/{size}, over Zenoh "
            f"{bus.arrived}/{size}; collisions {local.collisions} / {bus.collisions}"
        )
    if size in (50, 100):
        ok = ratio is not None and ratio >= 1.5
        verdicts.append((ok, f"{map_name} {size} AGVs: warm Zenoh/in process >= 1.5", ratio))
    if size == 200:
        verdicts.append((bc is not None, f"{map_name} 200 AGVs run over Zenoh", bus_rate))
    if size == 100 and bc:
        verdicts.append((bc.start_up < 5, f"{map_name} start-up of 100 AGVs < 5 s", bc.start_up))
    if bc:
        pss = bc.agvs_pss / size / 1024
        verdicts.append((pss <= 15, f"{map_name} {size} AGVs: PSS <= 15 MiB per AGV", pss))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--maps", default="sparse,dense")
    parser.add_argument("--sizes", default="50,100,200")
    parser.add_argument("--zenoh-only", action="store_true", help="skip the in-process runs")
    parser.add_argument("--sim-time", type=float, default=12.0, help="simulated s per run")
    parser.add_argument(
        "--runs", type=int, default=1, help="Zenoh runs per size; the median run is reported"
    )
    parser.add_argument(
        "--shared-memory", action="store_true", help="Zenoh's shared memory on (floor and runs)"
    )
    args = parser.parse_args()
    if args.shared_memory:  # inherited by every process the runs start
        os.environ[SHARED_MEMORY_ENV] = "1"
    maps = args.maps.split(",")
    if args.runs < 1 or any(m not in LAYOUTS for m in maps):
        parser.error(f"--runs must be at least 1; --maps among {', '.join(LAYOUTS)}")
    started = time.monotonic()
    layouts = ", ".join(f"{m} {LAYOUTS[m].width}x{LAYOUTS[m].height} m" for m in maps)
    memory = "on" if shared_memory() else "off"
    print(
        f"fleet_bench: {layouts}; {args.sim_time:g} s simulated, warm from tick {WARM_FROM}; "
        f"Zenoh shared memory {memory}"
    )
    print(HEADER)
    print("-" * len(HEADER))
    verdicts: list = []
    with tempfile.TemporaryDirectory() as folder:
        for map_name in maps:
            for size in (int(s) for s in args.sizes.split(",")):
                path = Path(folder) / f"bench-{map_name}-{size}.toml"
                path.write_text(scenario_text(map_name, size, args.sim_time))
                scenario = load_scenario(path)
                local = Outcome(problem="skipped (--zenoh-only)")
                timer = StepTimer()
                if not args.zenoh_only:
                    local = measured(
                        partial(in_process, scenario, timer),
                        Clock(False, last_tick_before_the_limit(scenario)),
                    )
                floors, floor_problem = floor_rates(scenario)
                bus = zenoh_median(scenario, path, args.runs)
                report(map_name, size, local, bus, floors, floor_problem, verdicts)
                step = timer.ms_per_step
                if step is not None:
                    print(f"{'':>12}in process, an AGV's whole step: {step:.3f} ms (warm)")
                    if size == 50:
                        what = f"{map_name} 50 AGVs: step in process <= 0.5 ms"
                        verdicts.append((step <= 0.5, what, step))
    for ok, what, value in verdicts:
        print(f"{'PASS' if ok else 'MISS'}  {what} ({fmt(value, 0, 2).strip()})")
    print(f"fleet_bench took {time.monotonic() - started:.0f} s")


if __name__ == "__main__":
    main()
