"""The world: the lockstep clock, obstacles, collisions, arrivals and the run's end.

``World`` is a state machine with no transport: ``first_tick()`` gives tick 0
and ``advance(replies)`` takes every AGV's state for the next tick and gives
that tick (or None when the run is over). The in-process runner calls it
directly; the Zenoh world process feeds it what arrives on the bus. Both
therefore produce the same ticks for the same scenario.
"""

from __future__ import annotations

import math
from array import array
from dataclasses import dataclass, field

import numpy as np

from bridge.messages import AgvCommand, AgvState, Event, MapMsg, ObstacleState, Tick
from fleet.runtime.agv_gaps import agv_gaps
from fleet.runtime.missions import MissionControl
from fleet.runtime.reservations import Reservations
from fleet.runtime.traffic_events import traffic_events
from fleet.scenario import Scenario
from planner.core.motion import limit_command, step_pose
from planner.core.profiles import PAPER
from planner.core.status import (
    ARRIVED,
    CLIPPED,
    COLLISION,
    DRIVING,
    END,
    FAILED,
    FINISHED,
    LOADING,
    PARKED,
    RECOVERY,
    REFUSED,
    WAITING,
)
from planner.maps.distance_field import DistanceField
from planner.maps.grid import GridMap
from planner.traffic.guard import ROUTE_POINTS
from planner.traffic.zones import Intent

INTERRUPTED = "interrupted"  # the end reason of a run ended by Ctrl-C or SIGTERM
HELD = (LOADING, PARKED)  # statuses of an AGV a shift holds at its goal (fleet.missions)
SHIFT_OVER = "shift over"  # the end reason of a shift at its end (or its time limit)


@dataclass
class AgvRecord:
    """What the world keeps of one AGV for the summary."""

    name: str
    status: str = DRIVING
    arrival_time: float | None = None
    distance: float = 0.0
    collisions: int = 0
    min_clearance: float = math.inf
    failure: str = ""
    clipped: int = 0  # commands beyond the AGV's limits, clipped by the world
    refused: int = 0  # reports the world did not believe (an arrival away from the goal)
    waiting_time: float = 0.0  # s spent waiting outside a passage (planner/traffic.py)
    recoveries: int = 0  # recovery behaviours started after no progress (planner/recovery.py)
    track: array = field(default_factory=lambda: array("d"))  # x, y, x, y, ... tick by tick


class World:
    def __init__(self, scenario: Scenario):
        self.scenario = scenario
        self.dt = scenario.dt
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
        self.intents: dict[str, Intent] = {}  # each running AGV's last traffic intent
        self.collisions = 0
        self._contacts: set[frozenset[str]] = set()
        self._temporary_shown: list[list[int]] = []
        self._static = DistanceField.for_grid(scenario.grid)
        self._field = self._static
        self._refresh_temporary()
        self.ended = False
        self.end_reason = ""
        self.reservations = Reservations.of(scenario)  # None: the zone rule
        self.missions = MissionControl(scenario) if scenario.missions else None

    # --- the clock ----------------------------------------------------------------
    def first_tick(self) -> Tick:
        self._check_contacts()
        self._dispatch()
        self._reserve()
        return self._make_tick()

    def live_agvs(self) -> list[str]:
        """AGVs whose answer the next tick waits for: all but the failed ones (an
        arrived AGV keeps answering, parked, so every tick has every AGV's state)."""
        return [n for n, r in self.records.items() if r.status != FAILED]

    def awaited(self) -> list[str]:
        """The live AGVs whose answer the next tick waits for: in a shift, not those it
        holds at their goal (``HELD``): the world knows their answer, standing still, and
        their nodes send none (idle AGVs cost no round trip on the bus)."""
        return [n for n in self.live_agvs() if self.states[n].status not in HELD]

    def _running(self) -> list[str]:
        return [n for n, r in self.records.items() if r.status not in FINISHED]

    def advance(self, commands: dict[str, AgvCommand]) -> Tick | None:
        """Integrate every live AGV's command for tick+1; return that tick, or None at the
        end. An AGV without a command (no answer in time) stays where it was."""
        self.tick += 1
        self.time = round(self.tick * self.scenario.dt, 9)
        for name in self.live_agvs():
            command = commands.get(name)
            if command is None and self.states[name].status in HELD:
                if self._stand_still(name):
                    continue
                command = AgvCommand(name, self.tick, 0.0, 0.0, 0.0, ARRIVED)  # stands still
            if command is not None:
                self._apply(name, command)
        self._refresh_temporary()
        self._check_contacts()
        self._dispatch()
        if not self._running():
            self._end(self._done_reason())
        elif self.time >= self.scenario.time_limit - 1e-9:
            self._end(SHIFT_OVER if self.missions else "time limit")
        if self.ended:
            return None
        self._reserve()
        return self._make_tick()

    def _dispatch(self) -> None:
        """A shift: the dispatcher's decisions for this tick, its new goals to the traffic
        schedule, and the status of every AGV it holds at a goal (``fleet.runtime.missions``)."""
        if self.missions is None:
            return
        live = self.live_agvs()
        positions = {n: (self.states[n].x, self.states[n].y) for n in live}
        events, goals = self.missions.update(positions, self.tick, self.time)
        self.events.extend(events)
        if self.reservations is not None:
            for name, goal in goals.items():
                self.reservations.set_goal(name, goal)
        for name in live:
            state = self.states[name]
            state.status = self.missions.status(name, state.status)

    def _goal(self, name: str):
        """Where AGV ``name`` is going: its goal, or in a shift its current task's."""
        return self.missions.goal(name) if self.missions else self.scenario.agv(name).goal

    def _reserve(self) -> None:
        """Traffic mode "reservations": the schedule's step for this tick (its events too)."""
        if self.reservations is not None:
            running = {
                n: (self.states[n].x, self.states[n].y)
                for n in self._running()
                if self.states[n].status not in HELD  # a shift holds it at its goal node:
            }  # frozen there in the plan, it needs no reservation (idle AGVs cost ~nothing)
            self.events.extend(self.reservations.update(running, self.tick, self.time))

    def _apply(self, name: str, command: AgvCommand) -> None:
        """The world as physics: the command within the AGV's limits, integrated (Eq. 4).

        An AGV may report ``failed`` (it gives up: stopped at once) or ``arrived`` (parked
        at once, if it is within its goal tolerance; a claim from anywhere else is refused
        and the AGV drives on). The paper profile's initial turn is accepted at tick 0.
        """
        old, record, spec = self.states[name], self.records[name], self.scenario.agv(name)
        pose = (old.x, old.y, old.theta)
        if command.start_heading is not None:
            if self.tick == 1 and spec.config.profile == PAPER:
                pose = (old.x, old.y, command.start_heading)
            else:
                self._refuse(name, "a start heading after tick 0 or outside the paper profile")
        status = command.status
        requested = (command.vx, command.vy, command.omega)
        goal = self._goal(name)
        if status == ARRIVED and math.dist(pose[:2], goal) > spec.config.goal_tolerance + 1e-9:
            far = math.dist(pose[:2], goal)
            self._refuse(name, f"arrival claimed {far:.2f} m from the goal")
            status = DRIVING
        if status in FINISHED:
            velocity = (0.0, 0.0, 0.0)  # parked, or stopped by the world
        else:
            previous = (old.vx, old.vy, old.omega)
            velocity, clipped = limit_command(previous, requested, spec.config.dwa, self.dt)
            if clipped:
                record.clipped += 1
                if record.clipped == 1:
                    self.events.append(
                        Event(self.tick, self.time, CLIPPED, [name], _limits_note(requested))
                    )
        x, y, theta = step_pose(pose, velocity, self.dt)
        record.distance += math.hypot(x - old.x, y - old.y)
        record.track.extend((x, y))
        if status == WAITING:
            record.waiting_time += self.dt
        self._take_intent(name, command.intent, status)
        if command.recovery and status not in FINISHED:
            record.recoveries += 1
            window = spec.config.progress_window
            why = f"no progress for {window:g} s: {command.recovery}"
            self.events.append(Event(self.tick, self.time, RECOVERY, [name], why))
        self.states[name] = AgvState(
            name, self.tick, x, y, theta, *velocity, old.radius, status,
            command.target, command.plan_time_ms, command.failure if status == FAILED else "",
        )  # fmt: skip
        if status == ARRIVED and self.missions:
            self.missions.at_goal.add(name)  # a shift goes on: the dispatcher answers
        elif status in FINISHED and record.status not in FINISHED:
            self._finish(name, status, command.failure or status)

    def _stand_still(self, name: str) -> bool:
        """``_apply`` of the answer the world knows for an AGV a shift holds at its goal
        (``HELD``: standing still, arrived), in a fraction of its time: most of a large
        fleet's AGVs are held at most ticks. The same state and records as ``_apply`` makes
        of that command, which passes every check and limit; False (``_apply`` decides) for
        an AGV away from its goal, whose claim ``_apply`` would refuse."""
        old, spec = self.states[name], self.scenario.agv(name)
        if math.dist((old.x, old.y), self._goal(name)) > spec.config.goal_tolerance + 1e-9:
            return False
        x, y, theta = step_pose((old.x, old.y, old.theta), (0.0, 0.0, 0.0), self.dt)
        record = self.records[name]
        record.distance += math.hypot(x - old.x, y - old.y)
        record.track.extend((x, y))
        self.intents.pop(name, None)
        self.states[name] = AgvState(
            name, self.tick, x, y, theta, 0.0, 0.0, 0.0, old.radius, ARRIVED
        )
        self.missions.at_goal.add(name)  # a shift goes on: the dispatcher answers
        return True

    def _take_intent(self, name: str, intent: Intent | None, status: str) -> None:
        """Keep a running AGV's intent for the next tick (its own name only) and make its
        traffic decisions events; a finished AGV's claim ends with it."""
        if status in FINISHED or intent is None or intent.name != name:
            self.intents.pop(name, None)
            return
        if (
            intent.since > self.tick
            or any(len(p) != 2 for p in intent.route)
            or len(intent.hold) not in (0, 2)
        ):
            self._refuse(name, "a traffic intent asked in a later tick or with malformed points")
            self.intents.pop(name, None)
            return
        intent.tick = self.tick
        intent.route = intent.route[:ROUTE_POINTS]  # the tick carries every AGV's: bounded
        intent.waits_for = [n for n in intent.waits_for[: len(self.records)] if n in self.records]
        self.events.extend(traffic_events(self.intents.get(name), intent, self.tick, self.time))
        self.intents[name] = intent

    def _refuse(self, name: str, what: str) -> None:
        """A report the world does not believe: counted, and an event the first time."""
        record = self.records[name]
        record.refused += 1
        if record.refused == 1:
            self.events.append(Event(self.tick, self.time, REFUSED, [name], what))

    def _done_reason(self) -> str:
        failed = sum(r.status == FAILED for r in self.records.values())
        if not failed:
            return "every AGV arrived"
        return f"every AGV is done: {len(self.records) - failed} arrived, {failed} failed"

    def mark_failed(self, name: str, why: str) -> None:
        """An AGV that died or hung: it stays as a stopped obstacle at its last pose."""
        if self.records[name].status in FINISHED:
            return
        state = self.states[name]
        state.vx = state.vy = state.omega = 0.0
        state.status = FAILED
        state.failure = why  # in the ticks too: an AGV it stops names it
        self.intents.pop(name, None)
        self._finish(name, FAILED, why)

    def drain_events(self) -> list[Event]:
        """The events since the last call (arrivals, failures, collisions, the end)."""
        events, self.events = self.events, []
        return events

    def interrupt(self) -> None:
        """End the run where it stands (Ctrl-C or SIGTERM), with the reason ``INTERRUPTED``."""
        self._end(INTERRUPTED)

    def final_tick(self) -> Tick:
        """The end state of the run (after the last ``advance``)."""
        tick = self._make_tick()
        tick.final = True
        return tick

    # --- internals ----------------------------------------------------------------
    def _finish(self, name: str, status: str, why: str) -> None:
        if self.missions is not None:
            self.missions.retire(name)  # only a failure ends an AGV's shift
        if self.reservations is not None:
            state = self.states[name]
            self.reservations.finish(name, status, (state.x, state.y))
        record = self.records[name]
        record.status = status
        if status == ARRIVED:
            record.arrival_time = self.time
        else:
            record.failure = why
        self.events.append(Event(self.tick, self.time, status, [name], why))

    def _end(self, reason: str) -> None:
        self.ended = True
        self.end_reason = reason
        self.events.append(Event(self.tick, self.time, END, [], reason))

    def _make_tick(self) -> Tick:
        return Tick(
            tick=self.tick,
            time=self.time,
            agvs=[AgvState(**vars(s)) for s in self.states.values()],
            moving=self.moving_obstacles(),
            temporary=[list(c) for c in self._temporary_shown],
            intents=self._claims(),
            reservations=self.reservations.current if self.reservations is not None else [],
            assignments=self.missions.assignments() if self.missions else [],
        )

    def _claims(self) -> list[Intent]:
        """The intents that claim a passage, in the fleet's order: all the traffic rule
        reads (the others stay in each AGV's command; every AGV decodes every tick, so a
        tick carries no more than the rule needs)."""
        return [
            self.intents[n]
            for n in self.states
            if n in self.intents and self.intents[n].passage is not None
        ]

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
            least, touching = agv_gaps(xs, ys, radii)
            clearance = np.minimum(clearance, least)
            for i, j in touching:
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
                Event(self.tick, self.time, COLLISION, involved, " and ".join(sorted(pair)))
            )
        self._contacts = contacts


def map_message(grid: GridMap) -> MapMsg:
    """The static map as published on ``world/map`` and recorded."""
    return MapMsg(
        grid.name,
        grid.width,
        grid.height,
        grid.resolution,
        grid.to_text().split("\n"),
        list(grid.origin),
    )


def _limits_note(requested) -> str:
    vx, vy, omega = requested
    return (
        f"command vx={vx:.3f} vy={vy:.3f} m/s omega={math.degrees(omega):.1f} deg/s "
        "is beyond the vehicle's limits: clipped (counted in the summary)"
    )
