"""Global plans read back from a recording and measured (the paper's Tables 2 and 3).

A plan recording (``agv-fleet paper`` writes one per map) holds the map on
``world/map`` and one ``PlanMsg`` per algorithm on ``agv/<algorithm>/plan``.
The metrics are recomputed here from the recorded key nodes with
``planner.core.path_metrics`` (length, turning times, total turning angle), not
taken from the numbers the planner put in the message.
"""

from __future__ import annotations

from dataclasses import dataclass

from bridge.keys import WORLD_MAP, agv_plan
from planner.core import path_metrics
from planner.maps.grid import GridMap
from recordings.reader import Recording
from recordings.series import map_grid


@dataclass(frozen=True)
class PlanMetrics:
    algorithm: str
    found: bool
    length: float | None  # m, through the key nodes
    turns: int | None
    turning_angle_deg: float | None
    key_nodes: tuple[tuple[float, float], ...]
    path: tuple[tuple[float, float], ...]


@dataclass(frozen=True)
class MapPlans:
    """The plans of one map, by algorithm (in the order asked for)."""

    path: str
    map_name: str
    grid: GridMap | None
    facts: dict
    plans: dict[str, PlanMetrics]

    @property
    def found(self) -> bool:
        return bool(self.plans) and all(p.found for p in self.plans.values())


def _points(raw) -> tuple[tuple[float, float], ...]:
    return tuple((float(p[0]), float(p[1])) for p in raw or ())


def measure_plan(data: dict, algorithm: str) -> PlanMetrics:
    """Metrics of one recorded plan (a decoded ``PlanMsg``)."""
    nodes = _points(data.get("key_nodes"))
    found = bool(data.get("found")) and len(nodes) > 0
    return PlanMetrics(
        algorithm=algorithm,
        found=found,
        length=path_metrics.path_length(nodes) if found else None,
        turns=path_metrics.turning_times(nodes) if found else None,
        turning_angle_deg=path_metrics.total_turning_angle_deg(nodes) if found else None,
        key_nodes=nodes,
        path=_points(data.get("path")),
    )


def map_plans(rec: Recording, algorithms=("traditional", "improved")) -> MapPlans:
    """The map and the first recorded plan of each algorithm, measured."""
    maps = list(rec.data_of(WORLD_MAP))
    grid = maps[0] if maps else {}
    plans = {}
    for algorithm in algorithms:
        recorded = list(rec.data_of(agv_plan(algorithm)))
        if recorded:
            plans[algorithm] = measure_plan(recorded[0], algorithm)
    return MapPlans(
        path=str(rec.path),
        map_name=str(grid.get("name", "")),
        grid=map_grid(grid) if grid else None,
        facts=rec.run,
        plans=plans,
    )
