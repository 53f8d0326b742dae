"""The world's side of traffic mode "reservations": it keeps the fleet's schedule.

Why the world and not every AGV: see ``planner.traffic.schedule``. The world updates
the schedule once per tick from the states it integrated, hands every running AGV its
reservation with the tick, and records the schedule's decisions as events
(``reserved``: nodes released to an AGV; ``waits-for``: an AGV waits for another to
leave the node it needs next; ``searched``: LaCAM planned a way out of a loop of PIBT's).
Both run modes run this same code in the world.
"""

from __future__ import annotations

import time

from bridge.messages import Event
from fleet.scenario import RESERVATIONS
from fleet.toml_schema import ScenarioError
from planner.core.physics import braking_distance
from planner.core.status import ARRIVED
from planner.maps.grid import Point
from planner.traffic.roadmap import Roadmap
from planner.traffic.schedule import Reservation, Schedule, ScheduleError


class Reservations:
    def __init__(self, schedule: Schedule):
        self.schedule = schedule
        self.current: list[Reservation] = []
        self.cpu_s = 0.0  # CPU time spent in the schedule, for the benchmarks
        self.updates = 0

    @classmethod
    def of(cls, scenario) -> Reservations | None:
        """The schedule of a scenario in traffic mode "reservations" (None otherwise), on
        the roadmap of the fleet's widest clearance (one roadmap for every AGV)."""
        if scenario.traffic_mode != RESERVATIONS:
            return None
        roadmap = Roadmap.for_fleet(scenario.grid, [a.config.clearance for a in scenario.agvs])
        agents = [(a.name, a.start, a.goal) for a in scenario.agvs]
        stopping = [stopping_distance(a.config.dwa) for a in scenario.agvs]
        try:
            schedule = Schedule(roadmap, agents, stopping)
            for station in scenario.missions.stations if scenario.missions else ():
                schedule.node_of(f"station {station.name!r}", station.position, "position")
            return cls(schedule)
        except ScheduleError as err:
            raise ScenarioError(f"[traffic] mode = reservations: {err}") from None

    def update(self, running: dict[str, Point], tick: int, now: float) -> list[Event]:
        t0 = time.thread_time()  # CPU, not wall time: the machine may be busy
        self.current = self.schedule.update(running)
        self.cpu_s += time.thread_time() - t0
        self.updates += 1
        return [Event(tick, now, e.kind, e.agvs, e.detail) for e in self.schedule.drain_events()]

    def set_goal(self, name: str, goal: Point) -> None:
        """A new goal of an AGV of a shift (``fleet.missions``): planned towards from the
        next update."""
        self.schedule.set_goal(name, goal)

    def finish(self, name: str, status: str, position: Point) -> None:
        """An AGV stopped for good: parked at its goal, or a body the plan goes round."""
        if status == ARRIVED:
            self.schedule.arrived(name)
        else:
            self.schedule.fail(name, position)


def stopping_distance(dwa) -> float:
    """How far an AGV needs to stop from its top speed (m)."""
    return braking_distance(dwa.max_speed, dwa.max_accel)
