"""``agv-fleet paper``: the paper's experiments (section 5), recorded, then reported.

Every experiment is first written to MCAP recordings under the runs folder; the
report is then built only from those recordings, read back:

- Every experiment runs the planner profile ``paper`` (the paper exactly: safety
  distance to obstacle-cell centres, no inflation).
- Tables 2 and 3: one plan recording per map (``world/map`` and a ``PlanMsg`` on
  ``agv/traditional/plan`` and ``agv/improved/plan``), measured by
  ``recordings.plan_metrics`` from the recorded key nodes. The same maps are also
  planned with the ``default`` profile (the costmap planner) into
  ``default-table2-*.mcap`` / ``default-table3-*.mcap``: ``PaperResults.grid20_default``
  and ``random50_default``, to show what a footprint-safe planner changes. The 20x20 maps are the
  five bundled literature maps (start = the free cell nearest the bottom-left
  corner, goal = nearest the top-right); the 50x50 maps are seeded random maps
  with 20-30 % obstacles from (0, 0) to (49, 49). Seeds without a traditional
  path are recorded too, then skipped and counted.
- Figs. 8-11, Table 4 and the velocity-smoothness comparison: the built-in paper
  scenarios run in process with one planner variant each, recorded, measured by
  ``recordings.analysis``; Table 4 and the smoothness comparison also over many walker
  timings (``fleet.paper.timing_sweep``, into ``sweep/``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bridge.keys import WORLD_MAP, agv_plan
from fleet.builtin import bundled_maps
from fleet.paper.timing_sweep import TimingSweep, record_timing_sweep
from fleet.runtime.agv_node import plan_message
from fleet.runtime.inprocess import run_recorded
from fleet.runtime.world import map_message
from fleet.scenario import Scenario, load_scenario, with_algorithm, with_profile
from planner.core.profiles import DEFAULT, PAPER
from planner.core.status import INITIAL
from planner.maps.grid import GridMap
from planner.maps.random_map import random_map
from planner.maps.text_maps import load_matrix_text
from planner.nav.fusion import FusionConfig
from planner.route.global_planner import DEFAULT_SAFETY_DISTANCE, plan_global, warm_up
from recordings.analysis import RunAnalysis, analyze
from recordings.plan_metrics import MapPlans, map_plans
from recordings.reader import open_recording
from recordings.series import RunSeries, extract
from recordings.writer import RecordingWriter

PLAN_ALGORITHMS = ("traditional", "improved")
RANDOM_SIZE = 50
RANDOM_START = (0.5, 0.5)
RANDOM_GOAL = (RANDOM_SIZE - 0.5, RANDOM_SIZE - 0.5)
DEFAULT_MAPS50 = 50
QUICK_MAPS50 = 5
# every (scenario, planner variant) run, in order
FLEET_RUNS = (
    ("paper-concave", "dwa"),
    ("paper-concave", "fusion"),
    ("paper-concave", "astar-dwa"),
    ("paper-temporary-0", "fusion"),
    ("paper-temporary-1", "fusion"),
    ("paper-temporary-2", "fusion"),
    ("paper-temporary-3", "fusion"),
    ("paper-temporary-3", "astar-dwa"),
    ("paper-temporary-3", "dwa"),
    ("paper-dynamic", "fusion"),
    ("paper-dynamic", "astar-dwa"),
    ("paper-dynamic", "dwa"),
)

Log = Callable[[str], None]


@dataclass
class FleetRun:
    scenario: str
    algorithm: str
    recording: Path
    analysis: RunAnalysis
    series: RunSeries
    spec: Scenario  # as run, with ``algorithm``: the configuration the report quotes


@dataclass
class PaperResults:
    """Everything the report needs, read back from the recordings."""

    runs_dir: Path
    grid20: list[MapPlans]
    random50: list[MapPlans]  # every seed tried, with or without a path
    maps50_wanted: int
    fleet: dict[tuple[str, str], FleetRun] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    # the same maps planned with the default profile (costmap, footprint-safe key nodes)
    grid20_default: list[MapPlans] = field(default_factory=list)
    random50_default: list[MapPlans] = field(default_factory=list)
    timing: TimingSweep | None = None  # paper-dynamic over many walker starts

    def run(self, scenario: str, algorithm: str) -> FleetRun:
        return self.fleet[(scenario, algorithm)]

    @property
    def config(self) -> FusionConfig:
        """The planner configuration of the first fleet run; every paper scenario has the
        same AGV and limits."""
        return self.run(*FLEET_RUNS[0]).spec.agvs[0].config


def random_ratio(seed: int) -> float:
    """Obstacle ratio of the seeded 50x50 map: 20 % to 30 % in 1 % steps, by seed."""
    return 0.20 + 0.10 * (seed % 11) / 10


def corner_free_cell(grid: GridMap, corner: str) -> tuple[int, int]:
    """The free cell nearest the bottom-left (or else the top-right) corner."""
    rows, cols = np.nonzero(~grid.blocked)
    if corner == "bottom-left":
        key = rows + cols
    else:
        key = (grid.height - 1 - rows) + (grid.width - 1 - cols)
    i = int(np.lexsort((cols, key))[0])
    return int(cols[i]), int(rows[i])


def grid20_maps() -> dict[str, Path]:
    """The bundled 20x20 literature maps, by name."""
    return {n: p for n, p in bundled_maps().items() if n.startswith("map20_")}


def _scenario_text(name: str, map_table: str, start, goal, profile: str = PAPER) -> str:
    """A scenario file with the map and one AGV per algorithm: the planning problem."""
    agvs = "".join(
        f'\n[[agvs]]\nname = "{a}"\nstart = [{start[0]}, {start[1]}]\ngoal = [{goal[0]}, '
        f"{goal[1]}]\n"
        f'planner = {{ algorithm = "{"fusion" if a == "improved" else "astar-dwa"}" }}\n'
        for a in PLAN_ALGORITHMS
    )
    description = "global plans, traditional vs improved A*"
    head = f'name = "{name}"\ndescription = "{description}"\nprofile = "{profile}"\n\n'
    return f"{head}{map_table}{agvs}"


def record_plans(
    path: Path,
    grid: GridMap,
    start,
    goal,
    name: str,
    facts: dict,
    map_table: str,
    profile: str = PAPER,
):
    """Plan with both A* variants and record the map and both plans into ``path``."""
    text = _scenario_text(name, map_table, start, goal, profile)
    run_facts = {
        "mode": "plan",
        "map": grid.name,
        "start": list(start),
        "goal": list(goal),
        "safety_distance": DEFAULT_SAFETY_DISTANCE,
        "profile": profile,
    }
    with RecordingWriter(
        path, scenario_name=name, scenario_text=text, run_facts={**run_facts, **facts}
    ) as writer:
        writer.write(WORLD_MAP, map_message(grid), 0)
        found = {}
        for algorithm in PLAN_ALGORITHMS:
            plan = plan_global(grid, start, goal, algorithm, profile=profile)
            writer.write(agv_plan(algorithm), plan_message(algorithm, None, plan, INITIAL), 0)
            found[algorithm] = plan.found
        writer.finish({"found": found})


def _file_prefix(profile: str) -> str:
    return "" if profile == PAPER else f"{profile}-"


def record_grid20(plan_dir: Path, log: Log, profile: str = PAPER) -> list[Path]:
    paths = []
    for name, file in grid20_maps().items():
        grid = load_matrix_text(file)
        start = grid.centre_of(corner_free_cell(grid, "bottom-left"))
        goal = grid.centre_of(corner_free_cell(grid, "top-right"))
        path = plan_dir / f"{_file_prefix(profile)}table2-{name}.mcap"
        table = f'[map]\nfile = "maps/{file.name}"\nresolution = 1.0\n'
        record_plans(path, grid, start, goal, f"table2-{name}", {"table": 2}, table, profile)
        paths.append(path)
    log(f"Table 2: planned and recorded {len(paths)} 20x20 maps (profile {profile})")
    return paths


def record_random50(plan_dir: Path, wanted: int, log: Log, seeds: int | None = None) -> list[Path]:
    """Seeded 50x50 maps until ``wanted`` of them have a path (at most 20x as many seeds),
    profile paper; with ``seeds``, exactly the first ``seeds`` seeds with the default
    profile (the maps of the paper's run, planned again)."""
    profile = PAPER if seeds is None else DEFAULT
    paths, made, seed = [], 0, 0
    while (made < wanted and seed < 20 * max(wanted, 1)) if seeds is None else seed < seeds:
        ratio = random_ratio(seed)
        corners = [(0, 0), (RANDOM_SIZE - 1, RANDOM_SIZE - 1)]
        grid = random_map(RANDOM_SIZE, RANDOM_SIZE, ratio, seed, keep_free=corners)
        path = plan_dir / f"{_file_prefix(profile)}table3-seed{seed:03d}.mcap"
        table = (
            f"[map]\nresolution = 1.0\nrandom = {{ width = {RANDOM_SIZE}, height = {RANDOM_SIZE}, "
            f"obstacle_ratio = {ratio:.2f}, seed = {seed} }}\n"
        )
        facts = {"table": 3, "seed": seed, "obstacle_ratio": ratio}
        record_plans(
            path, grid, RANDOM_START, RANDOM_GOAL, f"table3-seed{seed}", facts, table, profile
        )
        paths.append(path)
        made += open_recording(path).result["found"]["traditional"]
        seed += 1
        if seed % 10 == 0 and seeds is None:
            log(f"Table 3: {seed} seeds planned, {made}/{wanted} maps with a path")
    log(
        f"Table 3: planned and recorded {seed} seeded 50x50 maps, {made} with a path "
        f"(profile {profile})"
    )
    return paths


def record_fleet_run(fleet_dir: Path, scenario: Scenario) -> Path:
    config = scenario.agvs[0].config
    path = fleet_dir / f"{scenario.name}-{config.algorithm}.mcap"
    facts = {
        "mode": "in-process",
        "algorithm": config.algorithm,
        "profile": config.profile,
        "experiment": "agv-fleet paper",
    }
    run_recorded(scenario, path, facts)
    return path


def run_experiments(
    runs_dir: Path, maps50: int, log: Log, workers: int = 1, quick: bool = False
) -> PaperResults:
    """Record every experiment under ``runs_dir``, then read every recording back; the
    walker-timing sweep on ``workers`` processes (``quick``: a few timings)."""
    plan_dir, fleet_dir, sweep_dir = runs_dir / "plans", runs_dir / "fleet", runs_dir / "sweep"
    for folder in (plan_dir, fleet_dir, sweep_dir):
        folder.mkdir(parents=True, exist_ok=True)
        # a smaller --maps50 must not pick up old maps, nor the sweep runs of older code
        for old in folder.glob("*.mcap"):
            old.unlink()
    timings = {}
    t0 = time.perf_counter()
    warm_up()
    grid20_paths = record_grid20(plan_dir, log)
    random_paths = record_random50(plan_dir, maps50, log)
    grid20_default = record_grid20(plan_dir, log, DEFAULT)
    random_default = record_random50(plan_dir, maps50, log, seeds=len(random_paths))
    timings["plans"] = time.perf_counter() - t0

    t1 = time.perf_counter()
    fleet_paths, scenarios = {}, {}
    for i, (name, algorithm) in enumerate(FLEET_RUNS, 1):
        t = time.perf_counter()
        scenario = with_profile(with_algorithm(load_scenario(name), algorithm), PAPER)
        scenarios[(name, algorithm)] = scenario
        fleet_paths[(name, algorithm)] = record_fleet_run(fleet_dir, scenario)
        log(
            f"run {i}/{len(FLEET_RUNS)}: {name} with {algorithm} recorded "
            f"({time.perf_counter() - t:.1f} s)"
        )
    timings["fleet"] = time.perf_counter() - t1
    t = time.perf_counter()
    timing = record_timing_sweep(sweep_dir, workers, log, quick)
    timings["walker-timing sweep"] = time.perf_counter() - t

    t2 = time.perf_counter()
    results = PaperResults(
        runs_dir=runs_dir,
        grid20=[map_plans(open_recording(p)) for p in grid20_paths],
        random50=[map_plans(open_recording(p)) for p in random_paths],
        maps50_wanted=maps50,
        grid20_default=[map_plans(open_recording(p)) for p in grid20_default],
        random50_default=[map_plans(open_recording(p)) for p in random_default],
        timing=timing,
    )
    for key, path in fleet_paths.items():
        rec = open_recording(path)
        series = extract(rec)
        results.fleet[key] = FleetRun(*key, path, analyze(rec, series), series, scenarios[key])
    timings["analysis"] = time.perf_counter() - t2
    results.timings = timings
    log(
        f"read back and analysed {len(grid20_paths) + len(random_paths) + len(fleet_paths)} "
        "recordings"
    )
    return results
