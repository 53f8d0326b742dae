"""The world: the lockstep clock, obstacles, collisions, arrivals and the run's end.

``World`` is a state machine with no transport: ``first_tick()`` gives tick 0
and ``advance(replies)`` takes every AGV's state for the next tick and gives
that tick (or None when the run is over). The in-process runner calls it
directly; the Zenoh world process feeds it what arrives on the bus. Both
therefore produce the same ticks for the same scenario.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bridge.messages import AgvState, Event, MapMsg, ObstacleState, Tick
from fleet.scenario import Scenario
from planner.distance_field import DistanceField
from planner.grid_map import GridMap

DONE_STATUSES = ("arrived", "failed")


@dataclass
class AgvRecord:
    """What the world keeps of one AGV for the summary."""

    name: str
    status: str = "driving"
    arrival_time: float | None = None
    distance: float = 0.0
    collisions: int = 0
    min_clearance: float = math.inf
    failure: str = ""


class World:
    def __init__(self, scenario: Scenario):
        self.scenario = scenario
        self.tick = 0
        self.time = 0.0
        self.records = {a.name: AgvRecord(a.name) for a in scenario.agvs}
        self.states = {
            a.name: AgvState(
                name=a.name,
                tick=0,
                x=a.start[0],
                y=a.start[1],
                theta=math.radians(a.heading_deg),
                vx=0.0,
                vy=0.0,
                omega=0.0,
                radius=a.radius,
            )
            for a in scenario.agvs
        }
        self.events: list[Event] = []
        self.collisions = 0
        self._contacts: set[frozenset[str]] = set()
        self._temporary_shown: list[list[int]] = []
        self._static = DistanceField.from_grid(scenario.grid)
        self._field = self._static
        self._refresh_temporary()
        self.ended = False
        self.end_reason = ""

    # --- the clock ----------------------------------------------------------------
    def first_tick(self) -> Tick:
        self._check_contacts()
        return self._make_tick()

    def live_agvs(self) -> list[str]:
        """AGVs whose answer the next tick waits for: all but the failed ones (an
        arrived AGV keeps answering, parked, so every tick has every AGV's state)."""
        return [n for n, r in self.records.items() if r.status != "failed"]

    def _running(self) -> list[str]:
        return [n for n, r in self.records.items() if r.status not in DONE_STATUSES]

    def advance(self, replies: dict[str, AgvState]) -> Tick | None:
        """Apply every live AGV's state for tick+1; return that tick, or None at the end."""
        self.tick += 1
        self.time = round(self.tick * self.scenario.dt, 9)
        for name in self.live_agvs():
            reply = replies.get(name)
            if reply is None:
                continue  # no answer in time: it stays where it was
            old = self.states[name]
            record = self.records[name]
            record.distance += math.hypot(reply.x - old.x, reply.y - old.y)
            reply.tick = self.tick
            self.states[name] = reply
            if reply.status in DONE_STATUSES and record.status not in DONE_STATUSES:
                self._finish(name, reply.status, reply.failure or reply.status)
        self._refresh_temporary()
        self._check_contacts()
        if not self._running():
            self._end("every AGV is done")
        elif self.time >= self.scenario.time_limit - 1e-9:
            self._end("time limit")
        return None if self.ended else self._make_tick()

    def mark_failed(self, name: str, why: str) -> None:
        """An AGV that died or hung: it stays as a stopped obstacle at its last pose."""
        if self.records[name].status in DONE_STATUSES:
            return
        state = self.states[name]
        state.vx = state.vy = state.omega = 0.0
        state.status = "failed"
        self._finish(name, "failed", why)

    def drain_events(self) -> list[Event]:
        """The events since the last call (arrivals, failures, collisions, the end)."""
        events, self.events = self.events, []
        return events

    def final_tick(self) -> Tick:
        """The end state of the run (after the last ``advance``)."""
        tick = self._make_tick()
        tick.final = True
        return tick

    # --- internals ----------------------------------------------------------------
    def _finish(self, name: str, status: str, why: str) -> None:
        record = self.records[name]
        record.status = status
        if status == "arrived":
            record.arrival_time = self.time
        else:
            record.failure = why
        self.events.append(Event(self.tick, self.time, status, [name], why))

    def _end(self, reason: str) -> None:
        self.ended = True
        self.end_reason = reason
        self.events.append(Event(self.tick, self.time, "end", [], reason))

    def _make_tick(self) -> Tick:
        return Tick(
            tick=self.tick,
            time=self.time,
            agvs=[AgvState(**vars(s)) for s in self.states.values()],
            moving=self.moving_obstacles(),
            temporary=[list(c) for c in self._temporary_shown],
        )

    def moving_obstacles(self) -> list[ObstacleState]:
        out = []
        for ob in self.scenario.moving:
            x, y, vx, vy = ob.state_at(self.time)
            out.append(ObstacleState(ob.name, x, y, vx, vy, ob.radius))
        return out

    def _refresh_temporary(self) -> None:
        shown = [
            list(c)
            for t in self.scenario.temporary
            if t.appear_at <= self.time + 1e-9
            for c in t.cells
        ]
        if shown != self._temporary_shown:
            self._temporary_shown = shown
            self._field = self._static.with_blocked([tuple(c) for c in shown])

    def _check_contacts(self) -> None:
        """Clearances and collisions (AGV–wall, AGV–obstacle, AGV–AGV) at this tick.

        A collision is the onset of a contact between two bodies: a pair that
        stays in contact over several ticks counts once.
        """
        names = list(self.states)
        xs = np.array([self.states[n].x for n in names])
        ys = np.array([self.states[n].y for n in names])
        radii = np.array([self.states[n].radius for n in names])
        clearance = self._field.distance_at(xs, ys) - radii
        contacts = {frozenset((n, "wall")) for n, c in zip(names, clearance, strict=True) if c <= 0}
        for ob in self.moving_obstacles():
            gaps = np.hypot(xs - ob.x, ys - ob.y) - radii - ob.radius
            clearance = np.minimum(clearance, gaps)
            contacts.update(frozenset((names[i], ob.name)) for i in np.flatnonzero(gaps <= 0))
        if len(names) > 1:
            gaps = np.hypot(xs[:, None] - xs, ys[:, None] - ys) - radii[:, None] - radii
            np.fill_diagonal(gaps, np.inf)
            clearance = np.minimum(clearance, gaps.min(axis=1))
            for i, j in zip(*np.nonzero(np.triu(gaps <= 0)), strict=True):
                contacts.add(frozenset((names[i], names[j])))
        for name, c in zip(names, clearance, strict=True):
            record = self.records[name]
            record.min_clearance = min(record.min_clearance, float(c))
        for pair in sorted(contacts - self._contacts, key=sorted):
            self.collisions += 1
            involved = sorted(n for n in pair if n in self.records)
            for n in involved:
                self.records[n].collisions += 1
            self.events.append(
                Event(self.tick, self.time, "collision", involved, " and ".join(sorted(pair)))
            )
        self._contacts = contacts


def map_message(grid: GridMap) -> MapMsg:
    """The static map as published on ``world/map`` and recorded."""
    return MapMsg(grid.name, grid.width, grid.height, grid.resolution, grid.to_text().split("\n"))
