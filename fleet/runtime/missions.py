"""The world's side of a shift: it runs the dispatcher (``fleet.missions.dispatch``) once
per tick and hands every AGV its goal with the tick.

The world decides, the AGVs drive: an AGV that reports ``arrived`` within its goal
tolerance of the goal it was given stands at that goal; the dispatcher then starts its
dwell, ends it, or gives it its next goal, which goes out with the next tick (an
``Assignment`` per AGV) and to the traffic schedule in mode "reservations". The task
events (``requested``, ``assigned``, ``picked-up``, ``delivered``) become world events,
recorded and read by ``analyze``. Both run modes run this same code in the world.
"""

from __future__ import annotations

from bridge.messages import Assignment, Event
from fleet.missions.dispatch import DWELLING, Dispatcher, TaskEvent
from fleet.missions.requests import generated_requests
from planner.core.status import ARRIVED, AT_HOME, DRIVING, LOADING, PARKED, TASK_PHASES
from planner.maps.grid import Point


class MissionControl:
    def __init__(self, scenario):
        missions = scenario.missions
        end = min(missions.shift, scenario.time_limit)
        generator = missions.generator
        requests = []
        if generator is not None:
            sources, targets = missions.group(generator.source), missions.group(generator.target)
            requests = generated_requests(generator, sources, targets, end)
        homes = {a.name: a.start for a in scenario.agvs}
        self.dispatcher = Dispatcher(missions, homes, requests)
        self.at_goal: set[str] = set()  # AGVs standing at their goal since the last update
        self.log: list[TaskEvent] = []  # every task event of the run, for the summary

    def goal(self, name: str) -> Point:
        return self.dispatcher.agvs[name].goal

    def update(self, positions: dict[str, Point], tick: int, now: float) -> tuple[list, dict]:
        """The shift at ``now``: its events, and the AGVs whose goal changed (name -> goal)."""
        before = {n: a.goal for n, a in self.dispatcher.agvs.items()}
        events = self.dispatcher.update(now, positions, self.at_goal)
        self.at_goal = set()
        self.log.extend(events)
        changed = {n: a.goal for n, a in self.dispatcher.agvs.items() if a.goal != before[n]}
        out = [Event(tick, now, e.kind, [e.agv] * bool(e.agv), e.detail) for e in events]
        return out, changed

    def status(self, name: str, reported: str) -> str:
        """The status of an AGV of the shift in the ticks: ``loading`` at a station for
        its dwell, ``parked`` idle at home, else what it reported (``driving`` for an
        arrival the dispatcher has just answered with a new goal: the shift never ends
        an AGV's run, and others must not take it for one parked for good)."""
        phase = self.dispatcher.agvs[name].phase
        if phase in DWELLING:
            return LOADING
        if phase == AT_HOME:
            return PARKED
        return DRIVING if reported == ARRIVED else reported

    def assignments(self) -> list[Assignment]:
        return [
            Assignment(
                a.name,
                list(a.goal),
                a.task.request.number if a.task else 0,
                a.phase,
                a.station,
            )
            for a in self.dispatcher.agvs.values()
            if a.phase in TASK_PHASES
        ]

    def retire(self, name: str) -> None:
        self.dispatcher.retire(name)
