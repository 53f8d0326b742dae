"""MAPF benchmark with vehicle dynamics: MovingAI maps and .scen files, first N agents.

``python benchmarks/mapf_bench.py [--data DIR] [--suite warehouse|room|random|all] [--agents 10,25]
[--scens 6,7] [--traffic reservations] [--zenoh K] [--time-limit S] [--json]``
(from the repository root) runs, in process, each instance: the map at 1 m cells, AGVs of
radius 0.3 m at 1 m/s, 0.5 m/s², 60 °/s, starts and goals the first N rows of the
``.scen`` file, in the chosen traffic mode; and each AGV alone on the same map (its solo
run, in the same traffic mode by default, ``--solo zones`` its own route and DWA; cached in
``runs/mapf_solo.json``). Per instance:
arrivals, collisions, whether the run reached its time limit, the flowtime ratio
(Σ arrival times ÷ Σ solo arrival times; an AGV that did not arrive counts the time
limit), the makespan ratio (last arrival ÷ longest solo run), and the traffic layer's
CPU per AGV per tick (the world's schedule, mode "reservations"). ``--zenoh K`` also
runs the first K instances over Zenoh and says whether every AGV's status and arrival
time equal the in-process run's. ``--kill-9 N`` runs only the first warehouse instance
with N agents over Zenoh and kills (-9, by PID) the first AGV seen driving in a
single-lane aisle: the others must arrive, or fail naming it.

The data (``/work/shared/data/mapf`` by default, the MovingAI MAPF benchmark: see its
README) is read from ``--data``; a missing file is one line of error and exit status 2.
Targets (printed as PASS/MISS; a MISS never changes the exit status): 100 % arrival,
0 collisions, no run at its limit, flowtime ratio ≤ 1.3 at N = 50 and ≤ 1.6 at N = 100,
the layer ≤ 1 ms per AGV per tick at N = 100.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import sys
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from fleet.runtime.inprocess import run_in_process  # noqa: E402
from fleet.scenario import ZONES, Scenario, parse_scenario, with_traffic  # noqa: E402
from planner.core.errors import AgvFleetError  # noqa: E402
from planner.maps.movingai import load_movingai_scenarios  # noqa: E402

DATA = Path("/work/shared/data/mapf")
SUITES = {
    "warehouse": ("warehouse-10-20-10-2-1", [f"random-{i}" for i in (6, 7, 8, 9, 10)]),
    "room": ("room-32-32-4", [f"random-{i}" for i in (6, 7, 8, 9, 10)]),
    # open floor with 10 % random obstacles: the LaCAM README's worked example
    "random": ("random-32-32-10", ["random-1"]),
}
DEFAULT_AGENTS = {"warehouse": (10, 25, 50, 100), "room": (10, 25), "random": (10, 25, 50, 100)}
SOLO_CACHE = ROOT / "runs" / "mapf_solo.json"
FLOWTIME_TARGET = {50: 1.3, 100: 1.6}
CPU_TARGET_MS = 1.0


def scenario_for(map_path: Path, scen_path: Path, n: int, time_limit: float) -> Scenario:
    """The first ``n`` agents of a .scen file as a scenario (the public TOML format)."""
    rows = load_movingai_scenarios(scen_path)
    if len(rows) < n:
        raise AgvFleetError(f"{scen_path} has {len(rows)} agents, fewer than {n}")
    lines = [
        f'name = "{scen_path.stem}-n{n}"',
        f"time_limit = {time_limit}",
        "[map]",
        f'file = "{map_path.resolve()}"',
        "resolution = 1.0",
        "[agv_defaults]",
        "radius = 0.3\nmax_speed = 1.0\nmax_accel = 0.5\nmax_omega = 60.0",
    ]
    for i, row in enumerate(rows[:n]):
        (sc, sr), (gc, gr) = row.start, row.goal
        lines += [
            "[[agvs]]",
            f'name = "R{i}"',
            f"start = [{sc + 0.5}, {sr + 0.5}]",
            f"goal = [{gc + 0.5}, {gr + 0.5}]",
        ]
    return parse_scenario("\n".join(lines) + "\n", scen_path)


def solo_times(scenario: Scenario, key: str, cache: dict, mode: str) -> list[float]:
    """Each AGV alone on the map in traffic mode ``mode`` (zones alone: no rule, its route
    and DWA; reservations alone: straight from node to node): arrival times."""
    out = []
    for spec in scenario.agvs:
        k = f"{key}/{spec.start}/{spec.goal}" + ("" if mode == ZONES else f"/{mode}")
        if k not in cache:
            alone = replace(with_traffic(scenario, mode), agvs=(spec,), name=f"{key}-solo")
            agv = run_in_process(alone).agvs[0]
            cache[k] = agv.arrival_time if agv.status == "arrived" else None
        out.append(cache[k])
    return out


def run_instance(scenario: Scenario, traffic: str) -> dict:
    worlds = []
    t0 = time.perf_counter()
    summary = run_in_process(with_traffic(scenario, traffic), progress=worlds.append)
    wall = time.perf_counter() - t0
    world = worlds[-1] if worlds else None
    cpu = None
    if world is not None and world.reservations is not None and world.reservations.updates:
        layer = world.reservations
        cpu = layer.cpu_s / layer.updates / len(scenario.agvs) * 1e3
    agvs = summary.agvs
    return {
        "arrived": sum(a.status == "arrived" for a in agvs),
        "collisions": summary.collisions,
        "at_limit": summary.end_reason == "time limit",
        "times": [a.arrival_time for a in agvs],
        "statuses": [a.status for a in agvs],
        "failures": [a.failure for a in agvs if a.failure],
        "cpu_ms_per_agv_tick": cpu,
        "wall_s": wall,
    }


def ratios(result: dict, solo: list[float | None], limit: float) -> tuple[float, float]:
    times = [t if t is not None else limit for t in result["times"]]
    solo = [s if s is not None else limit for s in solo]
    return sum(times) / sum(solo), max(times) / max(solo)


def run_zenoh(scenario: Scenario, traffic: str) -> list:
    from fleet.runtime.launcher import FleetOptions, run_fleet

    with_mode = with_traffic(scenario, traffic)
    path = ROOT / "runs" / f"{scenario.name}-zenoh.toml"
    path.parent.mkdir(exist_ok=True)
    path.write_text(with_mode.source.replace("[map]", f'[traffic]\nmode = "{traffic}"\n[map]', 1))
    summary = run_fleet(parse_scenario(path.read_text(), path), FleetOptions(str(path)))
    return [(a.status, a.arrival_time) for a in summary.agvs]


def in_aisle(scenario: Scenario, point) -> bool:
    """Whether a point lies in a single-lane aisle: its cell is free with blocked cells
    left and right, or above and below."""
    grid = scenario.grid
    col, row = grid.cell_of(point)

    def blocked(c, r):
        return not grid.contains_cell((c, r)) or bool(grid.blocked[r, c])

    return (blocked(col - 1, row) and blocked(col + 1, row)) or (
        blocked(col, row - 1) and blocked(col, row + 1)
    )


def kill_9(scenario: Scenario, traffic: str) -> int:
    """Over Zenoh: kill -9 (by its PID) the first AGV seen driving inside a single-lane
    aisle; the others must arrive, or fail naming it."""
    from fleet.runtime.launcher import FleetOptions, run_fleet
    from tests.processes import agv_pid

    path = ROOT / "runs" / f"{scenario.name}-kill.toml"
    path.parent.mkdir(exist_ok=True)
    path.write_text(scenario.source.replace("[map]", f'[traffic]\nmode = "{traffic}"\n[map]', 1))
    killed = {}

    def progress(world):
        for name, state in world.states.items():
            point = (state.x, state.y)
            driving = world.tick > 20 and world.records[name].status == "driving"
            moving = math.hypot(state.vx, state.vy) > 0.2
            if not killed and driving and moving and in_aisle(scenario, point):
                os.kill(agv_pid(name), signal.SIGKILL)
                killed[name] = (round(state.x, 2), round(state.y, 2), world.time)

    options = FleetOptions(str(path), tick_timeout=10.0)  # a busy machine is not a death
    summary = run_fleet(parse_scenario(path.read_text(), path), options, progress).to_json()
    (victim,) = killed or {"-": None}
    agvs = summary["agvs"]
    ok = [a for a in agvs if a["name"] != victim]
    arrived = sum(a["status"] == "arrived" for a in ok)
    named = [a for a in ok if a["status"] != "arrived" and victim in a["failure"]]
    neither = len(ok) - arrived - len(named)
    print(f"kill -9 of {victim} at {killed.get(victim)} (x, y, t): of the {len(ok)} others "
          f"{arrived} arrived, {len(named)} failed naming it, {neither} neither; "
          f"collisions {summary['collisions']}")  # fmt: skip
    print(f"end: {summary['end_reason']}")
    for a in agvs:
        if a["status"] != "arrived":
            print(f"  {a['name']}: {a['status']} {a['failure']}")
    good = killed and arrived + len(named) == len(ok) and not summary["collisions"]
    print(f"kill -9 target: {'PASS' if good else 'MISS'}")
    return 0


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--data", type=Path, default=DATA, help=f"MovingAI files (default {DATA})")
    p.add_argument("--suite", choices=(*SUITES, "all"), default="all")
    p.add_argument("--agents", help="comma-separated N (default: 10,25,50,100 / room 10,25)")
    p.add_argument(
        "--scens",
        help="which .scen files: K for random-K, or a full suffix such as even-7 (default: "
        "random-6..10 of warehouse and room, random-1 of random)",
    )  # fmt: skip
    p.add_argument("--traffic", default="reservations", choices=("reservations", "zones"))
    p.add_argument("--time-limit", type=float, default=900.0)
    p.add_argument(
        "--solo", choices=("same", "zones"), default="same",
        help="the solo runs in the same traffic mode (default: the ratios measure what the "
        "others cost) or in zones (each AGV's own route and DWA)",
    )  # fmt: skip
    p.add_argument("--zenoh", type=int, default=0, metavar="K")
    p.add_argument("--json", action="store_true")
    p.add_argument(
        "--kill-9", type=int, metavar="N", help="only: N agents of the first warehouse .scen "
        "over Zenoh, kill -9 of the first AGV driving in an aisle",
    )  # fmt: skip
    args = p.parse_args(argv)
    try:
        return _bench(args)
    except AgvFleetError as err:
        print(f"mapf_bench: {err}", file=sys.stderr)
        return 2


def _bench(args) -> int:
    if args.kill_9:
        map_name = SUITES["warehouse"][0]
        scen = _scen_path(args.data, map_name, (args.scens or "6").split(",")[0])
        if not scen.is_file():
            raise AgvFleetError(f"no {scen}: give the MovingAI MAPF files with --data DIR")
        scenario = scenario_for(args.data / f"{map_name}.map", scen, args.kill_9, args.time_limit)
        return kill_9(scenario, args.traffic)
    suites = list(SUITES) if args.suite == "all" else [args.suite]
    cache = json.loads(SOLO_CACHE.read_text()) if SOLO_CACHE.exists() else {}
    rows, zenoh_left = [], args.zenoh
    for suite in suites:
        map_name, _ = SUITES[suite]
        map_path = args.data / f"{map_name}.map"
        if not map_path.is_file():
            raise AgvFleetError(f"no {map_path}: give the MovingAI MAPF files with --data DIR")
        agents = [int(n) for n in args.agents.split(",")] if args.agents else DEFAULT_AGENTS[suite]
        for k in args.scens.split(",") if args.scens else SUITES[suite][1]:
            scen = _scen_path(args.data, map_name, k)
            if not scen.is_file():
                raise AgvFleetError(f"no {scen}: give the MovingAI MAPF files with --data DIR")
            for n in agents:
                scenario = scenario_for(map_path, scen, n, args.time_limit)
                solo_mode = args.traffic if args.solo == "same" else ZONES
                solo = solo_times(scenario, scen.stem, cache, solo_mode)
                SOLO_CACHE.parent.mkdir(exist_ok=True)
                SOLO_CACHE.write_text(json.dumps(cache))
                result = run_instance(scenario, args.traffic)
                flow, make = ratios(result, solo, args.time_limit)
                row = {"instance": f"{scen.stem} n={n}", "n": n, **result}
                row.update(flowtime_ratio=round(flow, 3), makespan_ratio=round(make, 3))
                if zenoh_left > 0:
                    zenoh_left -= 1
                    mine = list(zip(result["statuses"], result["times"], strict=True))
                    row["zenoh_same"] = run_zenoh(scenario, args.traffic) == mine
                rows.append(row)
                print(_line(row), file=sys.stderr, flush=True)
    if args.json:
        print(json.dumps(rows))
    else:
        _table(rows)
    return 0


def _scen_path(data: Path, map_name: str, k: str) -> Path:
    """``7`` names ``random-7``; ``even-7`` names itself."""
    return data / f"{map_name}-{'random-' + k if k.isdigit() else k}.scen"


def _line(r: dict) -> str:
    cpu = "-" if r["cpu_ms_per_agv_tick"] is None else f"{r['cpu_ms_per_agv_tick']:.3f}"
    zenoh = "" if "zenoh_same" not in r else f"  zenoh same: {r['zenoh_same']}"
    fail = f"  first failure: {r['failures'][0]}" if r["failures"] else ""
    return (
        f"{r['instance']:<44} arrived {r['arrived']:>3}/{r['n']:<3} collisions "
        f"{r['collisions']:>2} limit {'yes' if r['at_limit'] else 'no ':<3} flowtime "
        f"{r['flowtime_ratio']:.2f} makespan {r['makespan_ratio']:.2f} layer {cpu} ms/AGV/tick "
        f"({r['wall_s']:.0f} s){zenoh}{fail}"
    )


def _table(rows: list[dict]) -> None:
    for r in rows:
        print(_line(r))
    ok = all(r["arrived"] == r["n"] and not r["collisions"] and not r["at_limit"] for r in rows)
    print(f"targets: 100 % arrival, 0 collisions, no run at its limit: {'PASS' if ok else 'MISS'}")
    for n, target in FLOWTIME_TARGET.items():
        at = [r["flowtime_ratio"] for r in rows if r["n"] == n]
        if at:
            worst = max(at)
            print(f"flowtime ratio at N = {n}: worst {worst:.2f} (≤ {target}): "
                  f"{'PASS' if worst <= target else 'MISS'}")  # fmt: skip
    cpus = [r["cpu_ms_per_agv_tick"] for r in rows if r["n"] == 100 and r["cpu_ms_per_agv_tick"]]
    if cpus:
        print(f"layer CPU at N = 100: worst {max(cpus):.3f} ms/AGV/tick (≤ {CPU_TARGET_MS}): "
              f"{'PASS' if max(cpus) <= CPU_TARGET_MS else 'MISS'}")  # fmt: skip


if __name__ == "__main__":
    sys.exit(main())
