"""The assignment rule of a shift: which AGV serves which request, and every AGV's goal.

Pure and deterministic (no clock, no bus, no I/O): the world calls ``update`` once per
tick with the time, where the AGVs stand and which of them stand at their goal, and
reads each AGV's goal and phase from ``agvs``. Both run modes run it in the world, so
they make the same decisions.

The rule:

- First come, first served: waiting requests are taken in the order they were made
  (time, then number). Each in turn goes to the idle AGV nearest its pick-up station
  (straight-line distance from where the AGV stands; ties by the fleet's order). Idle:
  no task, parked at home or on its way there. A request no idle AGV is left for waits
  in the queue.
- One AGV at a station at a time: a station is held by the AGV on its way to it or
  standing at it. A request whose pick-up is held waits (later ones may go first); a
  loaded AGV whose drop-off is held waits at the pick-up, holding it, until it is free.
- At a station an AGV stays the station's dwell; the load is picked up at the end of
  the pick-up's dwell, the task delivered at the end of the drop-off's. Then the AGV is
  idle and heads home (its start), unless a request is waiting for it.
- An AGV with its own task list serves that list only, in order, each task requested
  and assigned as the one before is delivered (the first at the start), and again from
  the first with ``repeat``; the generator's requests go to the other AGVs.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence, Set
from dataclasses import dataclass

from fleet.missions.requests import Request
from fleet.missions.spec import Missions, TaskList
from planner.core.status import (
    ASSIGNED,
    AT_DROP_OFF,
    AT_HOME,
    AT_PICK_UP,
    DELIVERED,
    PICKED_UP,
    REQUESTED,
    TO_DROP_OFF,
    TO_HOME,
    TO_PICK_UP,
)
from planner.maps.grid import Point

EPS = 1e-9
IDLE = (TO_HOME, AT_HOME)
RETIRED = "retired"  # an AGV stopped for good: no more work (not in the ticks)
DWELLING = (AT_PICK_UP, AT_DROP_OFF)


@dataclass
class Task:
    request: Request
    agv: str = ""
    assigned: float | None = None  # s
    picked_up: float | None = None
    delivered: float | None = None


@dataclass(frozen=True)
class TaskEvent:
    time: float
    kind: str  # planner.core.status.TASK_EVENTS
    task: Task
    agv: str = ""  # the AGV serving the task then ('' for a request not yet taken)

    @property
    def detail(self) -> str:
        """'task 3: pick-1 -> drop-2' (``recordings.task_stats.task_number`` reads it)."""
        r = self.task.request
        return f"task {r.number}: {r.source} -> {r.target}"


@dataclass
class AgvWork:
    """One AGV's part of the shift."""

    name: str
    home: Point
    position: Point
    goal: Point
    phase: str = AT_HOME
    station: str = ""  # the station of ``goal`` ('' for home)
    task: Task | None = None
    dwell_until: float = 0.0
    own: TaskList | None = None
    next_own: int = 0  # index of its own list's next pair
    busy: float = 0.0  # s with a task, so far (utilisation)


class Dispatcher:
    def __init__(
        self, missions: Missions, homes: Mapping[str, Point], requests: Sequence[Request] = ()
    ):
        """``homes``: every AGV's start, in the fleet's order; ``requests``: the
        generator's, in time order."""
        own = dict(missions.lists)
        self.agvs = {
            n: AgvWork(n, tuple(h), tuple(h), tuple(h), own=own.get(n)) for n, h in homes.items()
        }
        self.pending = list(requests)  # not yet made
        self.queue: list[Task] = []  # made, waiting for an AGV
        self.tasks: list[Task] = []  # every task made so far
        self.holder: dict[str, str] = {}  # station -> the AGV holding it
        self.now = 0.0
        self._numbers = len(self.pending)  # own-list tasks are numbered after these
        self._dwell = {s.name: s.dwell for s in missions.stations}
        self._position = {s.name: s.position for s in missions.stations}

    def update(self, now: float, positions: Mapping[str, Point], at_goal: Set[str]):
        """Advance the shift to ``now``: its task events, in the order they happened."""
        events: list[TaskEvent] = []
        for agv in self.agvs.values():
            if agv.task is not None:
                agv.busy += now - self.now
            agv.position = tuple(positions.get(agv.name, agv.position))
        self.now = now
        while self.pending and self.pending[0].time <= now + EPS:
            task = Task(self.pending.pop(0))
            self.tasks.append(task)
            self.queue.append(task)
            events.append(TaskEvent(now, REQUESTED, task, task.agv))
        for agv in self.agvs.values():
            arrived = agv.name in at_goal
            while self._advance(agv, arrived, events):
                arrived = False  # a new goal: not there yet
        self._assign(events)
        return events

    # --- one AGV ----------------------------------------------------------------------
    def _advance(self, agv: AgvWork, arrived: bool, events: list[TaskEvent]) -> bool:
        """One step of ``agv``'s work, if it can make one now; True when it set a new goal."""
        now = self.now
        if agv.phase in IDLE and agv.task is not None:  # its own next task waits for
            if agv.task.request.source in self.holder:  # its pick-up station to be free
                return False
            self._go(agv, TO_PICK_UP, agv.task.request.source)
            return True
        if agv.phase == TO_HOME and arrived:
            agv.phase = AT_HOME
        elif agv.phase in (TO_PICK_UP, TO_DROP_OFF) and arrived:
            agv.phase = AT_PICK_UP if agv.phase == TO_PICK_UP else AT_DROP_OFF
            agv.dwell_until = now + self._dwell[agv.station]
            return self._advance(agv, False, events)  # a dwell of 0 ends at once
        elif agv.phase == AT_PICK_UP and now >= agv.dwell_until - EPS:
            task = agv.task
            if task.picked_up is None:
                task.picked_up = now
                events.append(TaskEvent(now, PICKED_UP, task, task.agv))
            if self.holder.get(task.request.target, agv.name) != agv.name:
                return False  # the drop-off is held: wait here, holding the pick-up
            del self.holder[agv.station]
            self._go(agv, TO_DROP_OFF, task.request.target)
            return True
        elif agv.phase == AT_DROP_OFF and now >= agv.dwell_until - EPS:
            task = agv.task
            task.delivered = now
            events.append(TaskEvent(now, DELIVERED, task, task.agv))
            del self.holder[agv.station]
            agv.task = None
            if agv.own is not None:
                return self._own_next(agv, events)
            self._go_home(agv)
            return True
        elif agv.phase == AT_HOME and agv.own is not None and agv.next_own == 0:
            return self._own_next(agv, events)  # the start of the shift
        return False

    def _own_next(self, agv: AgvWork, events: list[TaskEvent]) -> bool:
        """The next task of ``agv``'s own list, requested and assigned now; else home."""
        pairs = agv.own.pairs()
        if agv.next_own >= len(pairs) and agv.own.repeat:
            agv.next_own = 0
        if agv.next_own >= len(pairs) or not pairs:
            agv.next_own = len(pairs) + 1  # done: it does not start over at home
            self._go_home(agv)
            return agv.goal != agv.position
        source, target = pairs[agv.next_own]
        agv.next_own += 1
        self._numbers += 1
        task = Task(Request(self._numbers, self.now, source, target))
        self.tasks.append(task)
        events.append(TaskEvent(self.now, REQUESTED, task, task.agv))
        self._give(agv, task, events)
        return True

    def _assign(self, events: list[TaskEvent]) -> None:
        """First come, first served, each waiting request to the nearest idle AGV."""
        for task in list(self.queue):
            if task.request.source in self.holder:
                continue
            idle = [
                a for a in self.agvs.values() if a.phase in IDLE and a.own is None and not a.task
            ]
            if not idle:
                return
            pick_up = self._position[task.request.source]
            agv = min(idle, key=lambda a: math.dist(a.position, pick_up))  # first of ties
            self.queue.remove(task)
            self._give(agv, task, events)

    def _give(self, agv: AgvWork, task: Task, events: list[TaskEvent]) -> None:
        task.agv, task.assigned = agv.name, self.now
        agv.task = task
        events.append(TaskEvent(self.now, ASSIGNED, task, task.agv))
        if task.request.source in self.holder:  # only for its own list: home till free
            self._go_home(agv)
        else:
            self._go(agv, TO_PICK_UP, task.request.source)

    def _go(self, agv: AgvWork, phase: str, station: str) -> None:
        self.holder[station] = agv.name
        agv.phase, agv.station, agv.goal = phase, station, self._position[station]

    def _go_home(self, agv: AgvWork) -> None:
        agv.phase, agv.station, agv.goal = TO_HOME, "", agv.home
        if agv.position == agv.home:
            agv.phase = AT_HOME

    # --- an AGV lost --------------------------------------------------------------------
    def retire(self, name: str) -> None:
        """``name`` stopped for good (failed, died): it takes no more work, its stations
        are free again, and a task it had not picked up yet waits for another AGV."""
        agv = self.agvs[name]
        for station in [s for s, holder in self.holder.items() if holder == name]:
            del self.holder[station]
        task, agv.task = agv.task, None
        own, agv.phase, agv.own = agv.own, RETIRED, None
        if task is not None and task.picked_up is None and own is None:
            task.agv, task.assigned = "", None
            self.queue.append(task)
            self.queue.sort(key=lambda t: (t.request.time, t.request.number))
