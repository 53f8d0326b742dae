"""One AGV's side of the traffic rule: claim the next passage, wait outside it, or go.

Each tick the guard looks along the AGV's route for the first passage within its
*request distance* (braking distance at full speed plus a waiting place and a safety
distance: far enough to stop outside), claims it with the mouth it will leave by,
and applies ``planner.traffic.zones.may_enter`` to the fleet's intents of the last tick.
Not allowed: the AGV holds at a *waiting place* ``WAIT_BACK`` safety distances
before the passage along its route, moved off the route to its right where the
costmap has room, so that AGVs coming out of the passage pass it; each AGV queued
before it on its side puts it ``QUEUE_GAP`` further back, and it moves up as they go
in. No place lies within a safety distance of another AGV's waiting place (the intents
carry them; of two sent to one place, the one that asked later chooses again), and of
the places with room, one the AGV drives to straight past no waiting AGV comes first.
While it waits and a holder of the passage reports no progress (a body in its way),
an AGV in that holder's way moves one queue place back, off that holder's way: it
yields. Once it waits or is let in, its claim reaches twice the request distance, so
that neither a place far down the queue nor the route planned from there drops it.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

from planner.core.path_metrics import distance_to_path
from planner.core.physics import braking_distance
from planner.local.config import DwaConfig
from planner.maps.costmap import Costmap
from planner.maps.grid import Point
from planner.traffic.passages import Crossing, Passages, RouteCells
from planner.traffic.zones import (  # fmt: skip
    BACK,
    CLEAR,
    GO,
    HELD,
    REQUEST,
    WAIT,
    YIELD,
    Intent,
    first_rival,
    holders,
    may_enter,
    queue,
    stuck_holders,
)

WAIT_BACK = (3.0, 4.0, 6.0)
"""The waiting place is this many safety distances before the passage along the route
(the first with room) ..."""
ASIDE = (2.0, 1.5, 1.0, 0.0)
"""... and this many safety distances to the right of the route (the first with room):
AGVs leaving the passage along the route pass it."""
QUEUE_GAP = 2.0
"""Safety distances between the waiting places of AGVs queued on the same side."""
IN_WAY = 2.0
"""Safety distances: a place this near a holder's way ahead is in it (two bodies with
their margins)."""
ROUTE_POINTS = 5
"""Route points ahead shared in an intent (the AGV's position, then key nodes)."""


@dataclass(frozen=True)
class TrafficDecision:
    """The guard's answer for one tick: the intent to share, and where to wait (None:
    drive on)."""

    intent: Intent
    hold: Point | None
    rejoin: bool = False  # it waited off its route and may go now: plan from where it is


class TrafficGuard:
    def __init__(self, costmap: Costmap, dwa: DwaConfig):
        self.costmap = costmap
        self.passages = Passages.for_costmap(costmap)
        safety = costmap.clearance.safety_distance
        braking = braking_distance(dwa.max_speed, dwa.max_accel)
        self.request_distance = braking + (max(WAIT_BACK) + 2) * safety
        self.stop_distance = braking + WAIT_BACK[0] * safety  # closer: stop before asking
        self.release_distance = WAIT_BACK[0] * safety
        self._claim: tuple[int, int | None] | None = None
        self._entry: int | None = None
        self._moved = False  # the waiting place was moved off a holder's way (once a claim)
        self._since = 0
        self._phase = CLEAR
        self._hold: Point | None = None
        self._ahead = 0  # AGVs queued before it on its side when its waiting place was chosen
        self._parked: list[tuple[float, float, float]] = []
        self._waiting: list[tuple[float, float, float]] = []  # other AGVs held, last tick
        # the route of the last tick, sampled, and the part of it an intent shares
        self._route: list[Point] = []
        self._route_cells: RouteCells | None = None
        self._shared_ahead: list[list[float]] = []

    def park(self, discs) -> None:
        """AGVs stopped for good (arrived, failed) at (x, y, radius): no waiting place within
        a safety distance of them (the rule sent an AGV to wait where another stood at its
        goal beside a door, and it circled the parked body for 10 s)."""
        self._parked = [tuple(d) for d in discs]
        if self._hold is not None and not self._room_at(self._hold):
            self._hold = None

    def decide(
        self,
        name: str,
        tick: int,
        position: Point,
        route: list[Point],
        intents: list[Intent],
        stalled: bool,
    ) -> TrafficDecision:
        """This tick's claim and waiting place. ``route`` is the rest of the AGV's route
        from the start of its current segment (the AGV is somewhere along, or beside,
        that segment); ``intents`` are the fleet's of the last tick (the world's tick
        carries them)."""
        if route != self._route:  # a new segment or a replan: sampled once, not per tick
            self._route, self._route_cells = route, self.passages.route_cells(route)
            self._shared_ahead = [[round(x, 2), round(y, 2)] for x, y in route[1:ROUTE_POINTS]]
        position_shared = [round(position[0], 2), round(position[1], 2)]
        shared = [position_shared, *(list(p) for p in self._shared_ahead)]
        along = _projection(route, position)
        crossing = self.passages.first_crossing(self._route_cells, self._reach(), along)
        beyond = crossing is not None and crossing.enter_at > self.request_distance
        if beyond and (self._claim is None or crossing.passage != self._claim[0]):
            crossing = None  # only a held claim reaches beyond the request distance
        if self._leaving(position, crossing):
            crossing = Crossing(self._claim[0], 0.0, 0.0, self._claim[1])
        if crossing is None:
            self._claim, self._phase = None, CLEAR
            return self._decision(Intent(name, tick, CLEAR, stalled=stalled, route=shared))
        # only a claim chooses places: not when clear
        self._waiting = self._discs(
            i for i in intents if i.name != name and i.phase in HELD and i.route
        )
        claim = (crossing.passage, crossing.exit)
        if claim != self._claim:
            self._claim, self._since, self._phase, self._hold = claim, tick, REQUEST, None
            self._entry, self._moved = crossing.entry, False
        intent = Intent(
            name, tick, self._phase, crossing.passage, crossing.exit, self._since,
            round(crossing.enter_at, 2), stalled, shared, entry=self._entry,
        )  # fmt: skip
        if crossing.enter_at <= 0.0 or self._phase == GO:
            rival = first_rival(intent, intents)
            if rival is None:
                intent.phase = self._phase = GO  # inside, or allowed in: holds the passage
                return self._decision(intent)
            if self._phase != BACK or self._hold is None:  # nose to nose: the later backs out
                self._hold = self._outside(position, crossing)
            intent.phase = self._phase = BACK
            return self._decision(intent, self._hold, [rival])
        seen = next((i for i in intents if i.name == name), None)
        if seen is None or (seen.passage, seen.exit, seen.since) != (*claim, self._since):
            others = [i for i in intents if i.passage == crossing.passage and i.name != name]
            if crossing.enter_at > self.stop_distance or not others:
                return self._decision(intent)  # the fleet has not seen this claim yet
            # asked this close while others claim it (after a replan, or from the start):
            # stop outside first
            self._hold = self._hold or self._waiting_place(route, along + crossing.enter_at)
            return self._decision(intent, self._hold)
        allowed, blockers = may_enter(name, intents)
        if allowed:
            waited = self._phase in HELD
            intent.phase = self._phase = GO
            return self._decision(intent, rejoin=waited)
        keep_off = [h.route for h in holders(crossing.passage, intents) if h.name != name]
        safety = self.costmap.clearance.safety_distance
        if (
            self._hold is not None
            and not self._moved
            and any(distance_to_path(r, self._hold) < IN_WAY * safety for r in keep_off)
        ):
            self._hold, self._moved = None, True  # a holder's way goes through it: once
        ahead = _ahead_on_my_side(intent, intents)
        if self._hold is not None and self._phase == WAIT and ahead < self._ahead:
            self._hold = None  # the queue moved up: so does its waiting place (it stayed
            # behind, and the next AGV to queue was sent to where it stood)
        if self._hold is not None and self._taken(intent, intents):
            self._hold = None
        if self._hold is None:
            self._ahead = ahead
            self._hold = self._waiting_place(
                route, along + crossing.enter_at, ahead, keep_off, position
            )
        stuck = stuck_holders(crossing.passage, intents)
        if self._phase not in (YIELD, BACK) and self._in_way_of(stuck, position):
            self._hold = self._waiting_place(
                route,
                along + crossing.enter_at,
                self._ahead + 1,
                [h.route for h in stuck],
                position,
            )  # one place further back in the queue, off the stuck holder's way
            intent.phase = self._phase = YIELD
        elif self._phase not in (YIELD, BACK):
            intent.phase = self._phase = WAIT
        return self._decision(intent, self._hold, blockers)

    def _reach(self) -> float:
        """How far ahead the claim is looked for: the request distance, and twice that once
        the AGV waits or is let in. A waiting place down a queue or after a yield can lie
        beyond the request distance, and so can the passage on the route planned from it
        when the AGV is let in; dropping the claim there sent the AGV on towards the
        passage unclaimed, to ask again last (in a crowd at a one-AGV door, an AGV drove
        2.6 times its route, looping through the room it waited in)."""
        return self.request_distance * (2.0 if self._phase in (WAIT, YIELD, GO) else 1.0)

    def _taken(self, me: Intent, intents: list[Intent]) -> bool:
        """Whether an AGV held before this one (``since``, then name) waits at a place within
        a safety distance of this one's. Two AGVs that ask in the same tick choose their
        places without seeing each other's; the later one chooses again, the earlier one
        keeps its place (two AGVs that asked together at a door chose one place, and the
        later one circled the other standing on it for 10 s)."""
        before = self._discs(
            i for i in intents
            if i.phase in HELD and i.hold and (i.since, i.name) < (me.since, me.name)
        )  # fmt: skip
        return self._crowded(self._hold, before)

    def _discs(self, held) -> list[tuple[float, float, float]]:
        """(x, y, radius) of each held AGV's waiting place (``_held_at``)."""
        radius = self.costmap.clearance.radius
        return [(*_held_at(i), radius) for i in held]

    def _clear_way(self, position: Point, place: Point) -> bool:
        """Whether the straight way from ``position`` to ``place`` passes no waiting AGV
        by less than both radii and half a safety distance (an AGV moving up a queue
        drove round one waiting between it and its new place: a loop)."""
        margin = self.costmap.clearance.radius + self.costmap.clearance.safety_distance / 2
        return all(
            distance_to_path([position, place], (x, y)) >= r + margin for x, y, r in self._waiting
        )

    def _in_way_of(self, stuck: list[Intent], position: Point) -> bool:
        """Whether this AGV, or its waiting place, is ``IN_WAY`` of the way ahead of a stuck
        holder: only then does it yield further back. Every waiting AGV
        yielding for any stuck holder churned the crowd at a 1.0 m door (the waiting
        AGVs looped through the rooms, up to 3.7 times their routes)."""
        reach = IN_WAY * self.costmap.clearance.safety_distance
        places = [position] if self._hold is None else [position, self._hold]
        return any(
            len(h.route) > 1 and any(distance_to_path(h.route, p) < reach for p in places)
            for h in stuck
        )

    def _leaving(self, position: Point, crossing: Crossing | None) -> bool:
        """Just out of the passage it held: it keeps it until its body is clear of the
        mouth (``WAIT_BACK[0]`` safety distances), where the waiting AGVs are not, unless
        another passage starts before that."""
        if self._phase != GO or self._claim is None:
            return False
        if crossing is not None and (
            crossing.passage == self._claim[0] or crossing.enter_at <= self.release_distance
        ):
            return False
        return self.passages.distance_to(position, self._claim[0]) < self.release_distance

    def replanned(self) -> None:
        """A new route: the waiting place is chosen again on it."""
        self._hold = None

    def _decision(self, intent: Intent, hold=None, blockers=(), rejoin=False) -> TrafficDecision:
        if intent.phase not in HELD:
            self._hold = None
        intent.waits_for = sorted(blockers)
        intent.hold = [] if hold is None else [round(hold[0], 2), round(hold[1], 2)]
        return TrafficDecision(intent, hold, rejoin)

    def _waiting_place(
        self, route: list[Point], enter_at: float, ahead: int = 0, keep_off=(), start=None
    ) -> Point:
        """``WAIT_BACK`` before the passage (``enter_at`` m along the route), and
        ``QUEUE_GAP`` further for each of the ``ahead`` AGVs queued before it on its side
        (a crowd at the mouth blocks the AGVs coming out), moved to the right of the
        route where free, and off the routes ``keep_off`` (the holders' routes ahead); where
        no place with room is clear of them, the one furthest off them (falling back to the
        route itself put an AGV waiting in a 1.5 m corridor's mouth on the holder's way).
        Places the AGV drives to from ``start`` past no waiting AGV come first."""
        safety = self.costmap.clearance.safety_distance
        furthest, best = -math.inf, None  # the place with room furthest off the holders' way
        clear = []  # the places with room off the holders' way
        for back in WAIT_BACK:
            back += ahead * QUEUE_GAP
            point, heading = _point_along(route, max(0.0, enter_at - back * safety))
            right = (math.sin(heading), -math.cos(heading))
            for aside in ASIDE:
                place = (point[0] + right[0] * aside * safety, point[1] + right[1] * aside * safety)
                if not (self._room_at(place) and self._room_at(_midpoint(point, place))):
                    continue
                off = min((distance_to_path(r, place) for r in keep_off), default=math.inf)
                if off >= IN_WAY * safety:
                    if start is None or self._clear_way(start, place):
                        return place
                    clear.append(place)
                if off > furthest:
                    furthest, best = off, place
        if clear:
            return clear[0]
        if best is not None:  # none clear of the holders' way: the least in it, not the route
            return best
        return _point_along(route, max(0.0, enter_at - WAIT_BACK[0] * safety))[0]

    def _outside(self, position: Point, crossing: Crossing) -> Point:
        """A waiting place beyond the passage's nearest mouth that is not the exit: where
        an AGV inside backs out to."""
        mouths = {m: c for m, c in self.passages.mouths(crossing.passage).items()}
        mouths.pop(crossing.exit, None)
        if not mouths:
            return position  # a dead end behind: the rule makes the other one back out
        mouth = min(mouths.values(), key=lambda c: math.dist(c, position))
        inner = self.passages.nearest_cell_centre(mouth, crossing.passage)
        away = (mouth[0] - inner[0], mouth[1] - inner[1])
        norm = math.hypot(*away) or 1.0
        safety = self.costmap.clearance.safety_distance
        for back in WAIT_BACK:
            place = (
                mouth[0] + away[0] / norm * back * safety,
                mouth[1] + away[1] / norm * back * safety,
            )
            if self._room_at(place):
                return place
        return mouth

    def _room_at(self, point: Point) -> bool:
        """Outside every passage, a safety distance from walls, parked AGVs and AGVs held
        at waiting places (each chose its place along its own route, and at a crowded
        1.0 m door one was sent where another already stood, and circled it)."""
        grid = self.costmap.grid
        cell = grid.cell_of(point)
        if not grid.contains_cell(cell) or self.passages.label[cell[1], cell[0]] >= 0:
            return False
        if self._crowded(point, [*self._parked, *self._waiting]):
            return False
        return self.costmap.distance[cell[1], cell[0]] >= self.costmap.clearance.safety_distance

    def _crowded(self, point: Point, discs) -> bool:
        """Whether a place lies within a safety distance of any of the (x, y, radius)
        ``discs`` (AGVs parked, or held at their waiting places)."""
        safety = self.costmap.clearance.safety_distance
        return any(math.dist(point, (x, y)) - r < safety for x, y, r in discs)


def _point_along(route: list[Point], at: float) -> tuple[Point, float]:
    """The point ``at`` m along a polyline and the polyline's heading there."""
    travelled = 0.0
    for a, b in itertools.pairwise(route):
        length = math.dist(a, b)
        if length > 0 and travelled + length >= at:
            t = (at - travelled) / length
            heading = math.atan2(b[1] - a[1], b[0] - a[0])
            return (a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t), heading
        travelled += length
    a, b = route[-2] if len(route) > 1 else route[0], route[-1]
    return tuple(b), math.atan2(b[1] - a[1], b[0] - a[0])


def _held_at(intent: Intent) -> Point:
    """Where a held AGV waits: its waiting place, or where it is when it shares none."""
    return tuple(intent.hold) if intent.hold else tuple(intent.route[0])


def _ahead_on_my_side(me: Intent, intents: list[Intent]) -> int:
    """How many AGVs wait for my passage before me and come from my side (my entry)."""
    return sum(
        1 for i in queue(me.passage, intents)
        if i.name != me.name and i.entry == me.entry and (i.since, i.name) < (me.since, me.name)
        and i.phase in HELD
    )  # fmt: skip


def _projection(route: list[Point], position: Point) -> float:
    """How far along the route's first segment the position lies (clamped to it)."""
    if len(route) < 2:
        return 0.0
    (ax, ay), (bx, by) = route[0], route[1]
    length2 = (bx - ax) ** 2 + (by - ay) ** 2
    if length2 == 0.0:
        return 0.0
    t = ((position[0] - ax) * (bx - ax) + (position[1] - ay) * (by - ay)) / length2
    return min(max(t, 0.0), 1.0) * math.sqrt(length2)


def _midpoint(a: Point, b: Point) -> Point:
    return ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
