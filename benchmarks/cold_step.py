"""One AGV's control step with its caches warm and cold, in one process.

Over Zenoh each AGV is a process, and 50 of them take turns on 2 cores: between
two steps of one AGV the 49 others run, and on a machine whose last-level cache
is smaller than what they touch together, every step starts cold. This runs
the ``fleet_bench`` warehouse in process (one World, one AgvNode per AGV, no bus)
and, on alternate ticks, evicts the caches before each AGV's step by writing
``--evict-mb`` of memory (default: twice the last-level cache). Warm and cold
ticks alternate within the same run, so the machine's own drift (often a fifth
on a shared 2-core VM) cancels out of their ratio.

It prints the step's CPU time (thread time of ``AgvNode.on_tick``) per AGV,
warm and cold, and where the cold step's extra time goes: compiled (numba)
kernels against the Python around them, from a profile of every numba
dispatcher's calls. The cold step predicts the AGV main threads' cost over
Zenoh (``fleet_bench``'s "AGV main threads ... per AGV") without 50 processes.

Run from the repository root: ``python benchmarks/cold_step.py``.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from numba.core.registry import CPUDispatcher

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.fleet_maps import warehouse_text as scenario_text
from fleet.runtime.agv_node import AgvNode
from fleet.runtime.lockstep import run_lockstep
from fleet.runtime.world import World
from fleet.scenario import load_scenario

FIRST_TICK = 50  # the first ticks plan the routes: not a step's usual work
CACHE_LINE = 64


def last_level_cache_bytes() -> int | None:
    """The largest CPU cache of cpu0 in bytes (Linux sysfs), or None when unknown."""
    sizes = []
    for index in Path("/sys/devices/system/cpu/cpu0/cache").glob("index*"):
        try:
            text = (index / "size").read_text().strip()
        except OSError:
            continue
        scale = {"K": 1024, "M": 1024**2}.get(text[-1:], 1)
        sizes.append(int(text.rstrip("KM")) * scale)
    return max(sizes) if sizes else None


class Evictor:
    """Writes one byte in every cache line of a buffer larger than the caches."""

    def __init__(self, megabytes: int):
        self.buffer = np.zeros(megabytes * 1024 * 1024, dtype=np.uint8)

    def __call__(self) -> None:
        self.buffer[::CACHE_LINE] += 1


class StepTimes:
    """CPU seconds of the AGV steps, warm and cold ticks apart."""

    def __init__(self):
        self.seconds = {"warm": 0.0, "cold": 0.0}
        self.steps = {"warm": 0, "cold": 0}

    def add(self, kind: str, seconds: float) -> None:
        self.seconds[kind] += seconds
        self.steps[kind] += 1

    def ms_per_step(self, kind: str) -> float:
        return 1e3 * self.seconds[kind] / max(self.steps[kind], 1)


def compiled_functions() -> set[tuple[str, int, str]]:
    """The profile keys (file, line, name) of every numba kernel of the project: a
    profiler sees a dispatcher's call as a call of the function it compiled."""
    keys = set()
    for module, loaded in list(sys.modules.items()):
        if module.startswith(("planner", "fleet", "bridge")):
            for obj in list(vars(loaded).values()):
                if isinstance(obj, CPUDispatcher):
                    code = obj.py_func.__code__
                    keys.add((code.co_filename, code.co_firstlineno, code.co_name))
    return keys


def compiled_share(profile: cProfile.Profile) -> tuple[float, float]:
    """Seconds in compiled kernels and in everything else (own time) of a profile."""
    kernels = compiled_functions()
    compiled = other = 0.0
    for key, (_, _, own, _, _) in pstats.Stats(profile).stats.items():
        if key in kernels:
            compiled += own
        else:
            other += own
    return compiled, other


def run(scenario, evict: Evictor, ticks: int, profiles=None) -> StepTimes:
    """The steps' CPU times; with ``profiles`` ({"warm": Profile, "cold": Profile}) each
    step also runs under its tick's profiler (which slows the Python part)."""
    nodes = {a.name: AgvNode(scenario, a.name) for a in scenario.agvs}
    times = StepTimes()

    def collect(tick, world):
        measured = FIRST_TICK <= tick.tick < FIRST_TICK + ticks
        kind = "cold" if tick.tick % 2 else "warm"
        replies = {}
        for name in world.live_agvs():
            if measured and kind == "cold":
                evict()
            profile = profiles[kind] if measured and profiles else None
            started = time.thread_time()
            if profile:
                profile.enable()
            out = nodes[name].on_tick(tick)
            if profile:
                profile.disable()
            if measured:
                times.add(kind, time.thread_time() - started)
            replies[name] = out.command
        return replies

    run_lockstep(World(scenario), collect, lambda key, msg: None)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--agvs", type=int, default=50)
    parser.add_argument("--ticks", type=int, default=100, help="measured ticks (half cold)")
    llc = last_level_cache_bytes()
    default_mb = 2 * llc // 1024**2 if llc else 64
    parser.add_argument(
        "--evict-mb", type=int, default=default_mb, help="memory written before a cold step"
    )
    args = parser.parse_args()
    if args.agvs < 1 or args.ticks < 2 or args.evict_mb < 1:
        parser.error("--agvs and --evict-mb must be at least 1, --ticks at least 2")
    sim_time = (FIRST_TICK + args.ticks + 1) * 0.1
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "cold-step.toml"
        path.write_text(scenario_text(args.agvs, sim_time))
        scenario = load_scenario(path)
    llc_text = f"{llc / 1024**2:g} MiB" if llc else "unknown"
    print(
        f"cold_step: {args.agvs} AGVs in process, ticks {FIRST_TICK}-{FIRST_TICK + args.ticks}; "
        f"last-level cache {llc_text}, {args.evict_mb} MiB written before each cold step"
    )
    AgvNode(scenario, scenario.agvs[0].name).warm_up()
    times = run(scenario, Evictor(args.evict_mb), args.ticks)
    if not (times.steps["warm"] and times.steps["cold"]):
        sys.exit("cold_step: every AGV stopped before the measured ticks (fewer --ticks?)")
    warm, cold = times.ms_per_step("warm"), times.ms_per_step("cold")
    print(f"  warm step  {warm:.3f} ms per AGV ({times.steps['warm']} steps)")
    print(f"  cold step  {cold:.3f} ms per AGV ({times.steps['cold']} steps)")
    print(f"  cold/warm  {cold / warm:.2f}x")
    profiles = {kind: cProfile.Profile(time.thread_time) for kind in ("warm", "cold")}
    steps = run(scenario, Evictor(args.evict_mb), args.ticks, profiles).steps
    (k_warm, p_warm), (k_cold, p_cold) = (compiled_share(profiles[k]) for k in ("warm", "cold"))
    print("  profiled again (the profiler slows the Python part), own CPU time per AGV step:")
    parts = (("compiled kernels", k_warm, k_cold), ("Python around them", p_warm, p_cold))
    for what, w, c in parts:
        w_ms, c_ms = 1e3 * w / steps["warm"], 1e3 * c / steps["cold"]
        print(f"    {what:<18}  warm {w_ms:.3f} ms, cold {c_ms:.3f} ms: {c_ms / w_ms:.2f}x")


if __name__ == "__main__":
    main()
