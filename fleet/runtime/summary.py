"""The end-of-run summary: per AGV and for the run, as a table or as JSON."""

from __future__ import annotations

import math
from dataclasses import dataclass

from fleet.runtime.world import SHIFT_OVER, World
from planner.core.errors import MapError
from planner.core.path_metrics import self_crossings
from planner.core.status import ARRIVED, FAILED, FINISHED
from planner.nav.fusion import GLOBAL_ALGORITHM
from planner.route.global_planner import plan_global
from recordings.task_stats import shift_stats
from recordings.text_table import text_table


@dataclass(frozen=True)
class AgvSummary:
    name: str
    status: str
    arrival_time: float | None
    distance: float
    collisions: int
    min_clearance: float
    failure: str = ""
    route_length: float | None = None  # m, the AGV's first global route (None: no route)
    clipped: int = 0  # commands the world clipped to the AGV's limits
    refused: int = 0  # reports the world did not believe
    waiting_time: float = 0.0  # s waiting outside passages other AGVs had
    self_crossings: int = 0  # times its driven path crossed itself: its loops
    recoveries: int = 0  # recovery behaviours started after no progress


@dataclass(frozen=True)
class RunSummary:
    scenario: str
    sim_time: float
    wall_time: float
    ticks: int
    collisions: int
    end_reason: str
    agvs: tuple[AgvSummary, ...]
    traffic: str = ""  # the traffic mode the run used (zones or reservations)

    tasks: dict | None = None  # a shift's throughput (recordings.task_stats)

    @property
    def success(self) -> bool:
        """Every AGV arrived and nothing collided; for a shift: it ran to its end with
        no AGV failed and nothing collided."""
        if self.end_reason == SHIFT_OVER:
            return self.collisions == 0 and all(a.status != FAILED for a in self.agvs)
        return self.collisions == 0 and all(a.status == ARRIVED for a in self.agvs)

    def to_json(self) -> dict:
        return {
            "scenario": self.scenario,
            "sim_time": round(self.sim_time, 6),
            "wall_time": round(self.wall_time, 3),
            "ticks": self.ticks,
            "collisions": self.collisions,
            "end_reason": self.end_reason,
            "traffic": self.traffic,
            "agvs": [
                {
                    "name": a.name,
                    "status": a.status,
                    "arrival_time": a.arrival_time,
                    "distance": round(a.distance, 4),
                    "route_length": None if a.route_length is None else round(a.route_length, 4),
                    "collisions": a.collisions,
                    "min_clearance": round(a.min_clearance, 4)
                    if math.isfinite(a.min_clearance)
                    else None,
                    "waiting_time": round(a.waiting_time, 3),
                    "self_crossings": a.self_crossings,
                    "recoveries": a.recoveries,
                    **({"failure": a.failure} if a.failure else {}),
                    **({"clipped_commands": a.clipped} if a.clipped else {}),
                    **({"refused_reports": a.refused} if a.refused else {}),
                }
                for a in self.agvs
            ],
            **({"tasks": self.tasks} if self.tasks is not None else {}),
        }

    def table(self) -> str:
        """Per AGV, then the run in a line, then each AGV that failed with its reason."""
        header = [
            [
                "AGV",
                "status",
                "arrival",
                "distance",
                "route",
                "loops",
                "recoveries",
                "collisions",
                "min clearance",
            ],
            ["", "", "s", "m", "m", "", "", "", "m"],
        ]
        rows = [
            [
                a.name,
                a.status,
                "-" if a.arrival_time is None else f"{a.arrival_time:.1f}",
                f"{a.distance:.2f}",
                "-" if a.route_length is None else f"{a.route_length:.2f}",
                str(a.self_crossings),
                str(a.recoveries),
                str(a.collisions),
                f"{a.min_clearance:.2f}" if math.isfinite(a.min_clearance) else "-",
            ]
            for a in self.agvs
        ]
        arrived = sum(a.status == ARRIVED for a in self.agvs)
        done = f"{arrived}/{len(self.agvs)} arrived"
        if self.tasks is not None:
            t = self.tasks
            done = f"{t['delivered']}/{t['requested']} tasks delivered"
        lines = [
            text_table(header, rows, right_from=2),
            f"{self.scenario}: {done}, {self.collisions} collisions, "
            f"{self.sim_time:.1f} s simulated in {self.wall_time:.2f} s ({self.end_reason})",
        ]
        lines += [f"{a.name} failed: {a.failure}" for a in self.agvs if a.failure]
        return "\n".join(lines)


def summarize(world: World, wall_time: float) -> RunSummary:
    agvs = []
    for name, r in world.records.items():
        status = r.status
        if status not in FINISHED and world.missions is not None:
            status = world.states[name].status  # where the shift's end found it
        elif status not in FINISHED:
            status = "timeout" if world.end_reason == "time limit" else status
        agvs.append(
            AgvSummary(
                name,
                status,
                r.arrival_time,
                r.distance,
                r.collisions,
                r.min_clearance,
                r.failure,
                route_length(world.scenario, name),
                r.clipped,
                r.refused,
                r.waiting_time,
                self_crossings(r.track),
                r.recoveries,
            )
        )
    return RunSummary(
        scenario=world.scenario.name,
        sim_time=world.time,
        wall_time=wall_time,
        ticks=world.tick,
        collisions=world.collisions,
        end_reason=world.end_reason,
        agvs=tuple(agvs),
        traffic=world.scenario.traffic_mode,
        tasks=_tasks(world),
    )


def _tasks(world: World) -> dict | None:
    """A shift's ``tasks`` block, from its task events as ``analyze`` reads them."""
    if world.missions is None:
        return None
    events = [
        {"kind": e.kind, "time": e.time, "agvs": [e.agv], "detail": e.detail}
        for e in world.missions.log
    ]
    return shift_stats(events, world.time).to_json()


def route_length(scenario, name: str) -> float | None:
    """Length (m) of the route AGV ``name`` planned first: its key nodes from its start to
    its goal, planned again here exactly as the AGV plans it (same map, variant, profile
    and clearance), so both run modes state it without asking the AGVs. None for DWA
    alone (no global route), when no path exists, or in a shift."""
    spec = scenario.agv(name)
    algorithm = GLOBAL_ALGORITHM.get(spec.config.algorithm)
    if algorithm is None or scenario.missions is not None:  # a shift: a route per task
        return None
    try:
        plan = plan_global(
            scenario.grid,
            spec.start,
            spec.goal,
            algorithm,
            profile=spec.config.profile,
            clearance=spec.config.clearance,
        )
    except MapError:
        return None
    return plan.length if plan.found else None
