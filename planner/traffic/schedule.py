"""The fleet's traffic schedule: PIBT steps planned ahead on the roadmap, executed by
precedence. The ``reservations`` traffic mode (the zone rule is ``planner.traffic.zones``).

Where it runs, and why: the world keeps the schedule (as Open-RMF's traffic schedule
does), and every tick carries each AGV's reservation. PIBT is one joint step for all
agents: computed by every AGV from the intents on the bus it would cost N times the
CPU (at 100 AGVs, the whole step in every AGV every tick), and the world already sees
every state. The world is the same code in both run modes, so the reservations, and
the recordings, are the same in process and over Zenoh. The AGVs still drive
themselves (DWA): the schedule gives each one the nodes it may enter and whom it waits
for; nothing else.

Each update:
1. Progress: an AGV that has reached (``Roadmap.reach``) one of its released nodes has
   left the earlier ones (``planner.traffic.precedence``).
2. AGVs stopped for good leave the plan: one that arrived stays on its goal node (the
   plan froze it there when it planned it onto its goal); one that failed (or died)
   becomes a body on the nodes it covers, and every AGV's plan beyond its released
   nodes is planned again round it.
3. Planning ahead: while an AGV has fewer nodes planned beyond the one it reached than
   it may hold (step 4), one more PIBT step (``planner.traffic.pibt``) for all agents
   not yet at their goals. Nothing else bounds the plan: a window of 20 steps ahead of
   the AGV furthest behind stopped every AGV's plan whenever one vehicle lagged (turning
   on the spot, held up), on half the ticks of 50 AGVs on the MovingAI warehouse, and
   the even `.scen` files' flowtime ratios at N = 50 fell from 1.41–1.49 to 1.22–1.23
   without it. An agent planned onto its goal is frozen there: a fixed node for the
   others from then on (an AGV parks for good when it arrives).
4. Release: each AGV gets up to ``RELEASE`` nodes ahead of the one it reached whose
   earlier visits are done, or as many as it needs to stop in from its top speed if that
   is more (it drives on the braking curve to the last node it holds: with fewer, a fast
   AGV would brake towards each next node and saw-tooth at cruise); the first node it
   does not get names whom it waits for.

An AGV whose goal no way on the roadmap reaches any more (bodies stopped for good cut
it off) is told so, with the names of the bodies on its shortest way (``blocked_by``).
A goal can be given at any tick (``set_goal``): the next step plans towards it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from planner.core.errors import BadInputError
from planner.maps.grid import Point
from planner.traffic import lacam, pibt
from planner.traffic.loops import LoopWatch
from planner.traffic.precedence import Precedence
from planner.traffic.roadmap import GAP, UNREACHABLE, Roadmap

RELEASE = 4
"""Nodes an AGV may hold ahead of the one it has reached, at least (braking from 1 m/s
takes one node on a 1 m lattice at 0.5 m/s²); more for an AGV that needs them to stop."""
STEPS_PER_UPDATE = 4
"""PIBT steps planned at most per update (per tick)."""


class ScheduleError(BadInputError):
    """A fleet the schedule cannot take (two AGVs on one node, a start off the roadmap)."""


@dataclass
class Reservation:
    """What the schedule tells one AGV at a tick: ``path`` are the points of the nodes it
    holds, from the one it reached to the last released (the last is its goal point when
    ``to_goal``); ``waits_for`` the AGV whose planned visit of its next node comes first;
    ``blocked_by`` the bodies stopped for good that cut it off from its goal."""

    name: str
    path: list[list[float]] = field(default_factory=list)
    waits_for: list[str] = field(default_factory=list)
    to_goal: bool = False
    blocked_by: list[str] = field(default_factory=list)


@dataclass
class ScheduleEvent:
    kind: str  # "reserved", "waits-for" or "searched"
    agvs: list[str]
    detail: str


RESERVED, WAITS_FOR, SEARCHED = "reserved", "waits-for", "searched"
EVENT_KINDS = (RESERVED, WAITS_FOR, SEARCHED)


class Schedule:
    def __init__(
        self,
        roadmap: Roadmap,
        agents: list[tuple[str, Point, Point]],
        stopping: list[float] | None = None,
    ):
        """``agents``: (name, start, goal) of every AGV, in the fleet's order;
        ``stopping``: each one's braking distance from its top speed (m, default 0)."""
        self.roadmap = roadmap
        self.names = [a[0] for a in agents]
        step = roadmap.spacing * roadmap.costmap.grid.resolution
        self.holds = [
            max(RELEASE, 1 + math.ceil(d / step - 1e-9)) for d in stopping or [0.0] * len(agents)
        ]
        self.goal_points = [tuple(a[2]) for a in agents]
        starts = [self.node_of(f"AGV {name!r}", start, "start") for name, start, _ in agents]
        self.goals = [self.node_of(f"AGV {name!r}", goal, "goal") for name, _, goal in agents]
        for what, nodes in (("start", starts), ("goal", self.goals)):
            seen: dict[int, str] = {}
            for name, node in zip(self.names, nodes, strict=True):
                if node in seen:
                    raise ScheduleError(
                        f"AGVs {seen[node]!r} and {name!r} have their {what} on the same "
                        f"roadmap node {roadmap.centre(node)}: the reservations need one each"
                    )
                seen[node] = name
        self.plan = Precedence(starts)
        self.config = list(starts)  # every agent's node at the last plan step
        # PIBT's first priorities: the trip length as a fraction (longer trips first)
        trips = [int(roadmap.distances(g)[s]) for s, g in zip(starts, self.goals, strict=True)]
        self.priorities = [t / max(1, len(roadmap)) if t < UNREACHABLE else 0.0 for t in trips]
        self.directions = [-1] * len(agents)  # of each agent's last planned move
        self.frozen: set[int] = set()  # agents planned onto their goals: fixed from then on
        self.failed: dict[int, set[int]] = {}  # agents stopped for good off plan: their nodes
        self.done: set[int] = set()  # agents that arrived or failed
        self.waiting: dict[int, int | None] = {}  # whom each agent waited for, last update
        self.events: list[ScheduleEvent] = []
        self.loops = LoopWatch()
        self.searches = 0  # LaCAM searches made (PIBT pushing agents back and forth)
        self._freeze_at_goals()

    def node_of(self, who: str, point: Point, what: str) -> int:
        """The roadmap node of ``who``'s ``what`` (start, goal, a station's position) at
        ``point``; a ScheduleError when it is on none or too far off its node's centre."""
        node = self.roadmap.node_at(point)
        if node is None:
            raise ScheduleError(f"{who}: its {what} {tuple(point)} is on no roadmap node")
        off = math.dist(point, self.roadmap.centres[node])
        if off > self.roadmap.reach:
            # a body standing off its node reaches into the next one's room (single-lane,
            # 0.5 m cells: an AGV parked at its goal 0.56 m off its node was hit)
            x, y = self.roadmap.centre(node)
            raise ScheduleError(
                f"{who}: its {what} {tuple(point)} is {off:.2f} m from the nearest "
                f"roadmap node ({x:g}, {y:g}), more than {self.roadmap.reach:.2f} m: put it "
                "on a node (the lattice of cells the body fits, every "
                f"{self.roadmap.spacing} cells)"
            )
        return node

    # --- lifelong -----------------------------------------------------------------------
    def set_goal(self, name: str, goal: Point) -> None:
        """A new goal for a running AGV: the plan is made again from the nodes everybody
        holds, towards it."""
        agent = self.names.index(name)
        self.goals[agent] = self.node_of(f"AGV {name!r}", goal, "goal")
        self.goal_points[agent] = tuple(goal)
        self.frozen.discard(agent)
        self.loops.new_goal(agent)
        self._plan_again()

    def fail(self, name: str, position: Point) -> None:
        """An AGV stopped for good off its plan (failed, died, cut off): a body on the nodes
        it covers; the plan beyond everybody's released nodes is made again round it."""
        agent = self.names.index(name)
        if agent in self.failed:
            return
        self.done.add(agent)
        self.frozen.discard(agent)
        self.plan.remove(agent)
        reach = 2 * self.roadmap.costmap.clearance.radius + GAP
        held = {self.plan.nodes[a][self.plan.released[a]] for a in range(len(self.names))}
        covered = {
            n for n in range(len(self.roadmap))
            if math.dist(self.roadmap.centres[n], position) < reach
        } - (held - {self.plan.nodes[agent][-1]})  # fmt: skip
        self.failed[agent] = covered | {self.plan.nodes[agent][-1]}
        self._plan_again()

    def _plan_again(self) -> None:
        """Drop every plan beyond its released nodes: the next steps start from there
        (a step of PIBT needs every agent on a node of its own: the held ones are)."""
        for agent in range(len(self.names)):
            if agent not in self.failed:
                self.plan.truncate(agent)
                self.config[agent] = self.plan.nodes[agent][-1]
        self.frozen = {a for a in self.frozen if self.config[a] == self.goals[a]}

    def arrived(self, name: str) -> None:
        self.done.add(self.names.index(name))

    # --- one tick -----------------------------------------------------------------------
    def update(self, positions: dict[str, Point]) -> list[Reservation]:
        """Progress, planning ahead and releases for the AGVs at ``positions`` (the running
        ones); their reservations, in the fleet's order."""
        for agent, name in enumerate(self.names):
            if name in positions and agent not in self.done:
                self._progress(agent, positions[name])
        for _ in range(STEPS_PER_UPDATE):
            if not self._needs_step():
                break
            self._plan_step()
        return [
            self._reserve(agent)
            for agent, name in enumerate(self.names)
            if name in positions and agent not in self.done
        ]

    def drain_events(self) -> list[ScheduleEvent]:
        events, self.events = self.events, []
        return events

    def _progress(self, agent: int, position: Point) -> None:
        plan = self.plan
        for entry in range(plan.released[agent], plan.progress[agent], -1):
            centre = self.roadmap.centres[plan.nodes[agent][entry]]
            if math.dist(centre, position) <= self.roadmap.reach:
                plan.reach(agent, entry)
                return

    def _needs_step(self) -> bool:
        """Whether an AGV has fewer nodes planned beyond the one it reached than it may
        hold (and can still reach its goal)."""
        plan = self.plan
        return any(
            len(plan.nodes[a]) - 1 - plan.progress[a] < self.holds[a] and not self._cut_off(a)
            for a in range(len(self.names))
            if a not in self.done and a not in self.frozen
        )

    def _fixed(self) -> frozenset[int]:
        nodes = {self.config[a] for a in self.frozen}
        for covered in self.failed.values():
            nodes |= covered
        return frozenset(nodes)

    def _cut_off(self, agent: int) -> bool:
        table = self.roadmap.distances(self.goals[agent], self._fixed())
        return table[self.config[agent]] >= UNREACHABLE

    def _plan_step(self) -> None:
        """One PIBT step for the agents not frozen; or, when PIBT is going round a loop
        (``planner.traffic.loops``), LaCAM's way to their goals for the agents in it."""
        moving = [
            a for a in range(len(self.names)) if a not in self.frozen and a not in self.failed
        ]
        fixed = self._fixed()
        current = [self.config[a] for a in moving]
        goals = [self.goals[a] for a in moving]
        group = self.loops.suspects(moving, goals, fixed, current)
        if group is not None and self._search(moving, group, fixed):
            return
        tables = [self.roadmap.distances(g, fixed) for g in goals]
        directions = [self.directions[a] for a in moving]
        priorities = [self.priorities[a] for a in moving]
        nodes = pibt.step(self.roadmap.neighbours, current, tables, priorities, fixed, directions)
        self._advance(moving, nodes)
        self._freeze_at_goals()

    def _search(self, moving: list[int], group: list[int], fixed: frozenset[int]) -> bool:
        """Plan LaCAM's way to their goals for the agents at ``group`` (positions in
        ``moving``), the other moving agents standing still; whether it found one."""
        self.searches += 1
        agents = [moving[i] for i in group]
        others = {self.config[a] for a in moving} - {self.config[a] for a in agents}
        blocked = fixed | others
        start = [self.config[a] for a in agents]
        goals = [self.goals[a] for a in agents]
        tables = [self.roadmap.distances(g, blocked) for g in goals]
        budget = lacam.BUDGET if len(agents) == len(moving) else lacam.BUDGET // 10
        configs = lacam.solve(self.roadmap.neighbours, start, goals, tables, blocked, budget)
        names = [self.names[a] for a in agents]
        found = f"a way of {len(configs)} steps" if configs else "no way within its budget"
        note = f"PIBT went round a loop; LaCAM found {found} for {', '.join(names)}"
        self.events.append(ScheduleEvent(SEARCHED, names, note))
        if not configs:
            self.loops.failed(agents)
            return False
        for sub in configs:
            nodes = [self.config[a] for a in moving]
            for i, v in zip(group, sub, strict=True):
                nodes[i] = v
            self._advance(moving, nodes)
        self.loops.solved(agents)
        self._freeze_at_goals()
        return True

    def _advance(self, moving: list[int], nodes: list[int]) -> None:
        """The next plan step: the ``moving`` agents go to ``nodes``."""
        priorities = [self.priorities[a] for a in moving]
        goals = [self.goals[a] for a in moving]
        for a, node, p in zip(
            moving, nodes, pibt.next_priorities(priorities, nodes, goals, moving)
        ):
            self.loops.moved(a, self.config[a], node, self.goals[a])
            if node != self.config[a]:
                self.directions[a] = list(self.roadmap.neighbours[self.config[a]]).index(node)
            self.config[a], self.priorities[a] = node, p
            self.plan.append(a, node)

    def _freeze_at_goals(self) -> None:
        """Freeze the agents planned onto their goals, unless that cuts another agent off
        from its goal (a goal in a corridor another has to pass): such an agent stays in
        the plan (PIBT may push it off its goal) and is frozen once nobody needs its node."""
        for a in range(len(self.names)):
            if a in self.failed or a in self.frozen or self.config[a] != self.goals[a]:
                continue
            fixed = self._fixed()
            with_a = fixed | {self.config[a]}
            if not any(
                self.roadmap.distances(self.goals[b], with_a)[self.config[b]] >= UNREACHABLE
                and self.roadmap.distances(self.goals[b], fixed)[self.config[b]] < UNREACHABLE
                for b in range(len(self.names))
                if b != a and b not in self.frozen and b not in self.done
            ):
                self.frozen.add(a)

    def _reserve(self, agent: int) -> Reservation:
        plan, name = self.plan, self.names[agent]
        count, blocker = plan.release(agent, self.holds[agent])
        nodes = plan.nodes[agent][plan.progress[agent] : plan.released[agent] + 1]
        path = [[round(float(v), 3) for v in self.roadmap.centres[n]] for n in nodes]
        to_goal = agent in self.frozen and plan.released[agent] == len(plan.nodes[agent]) - 1
        if to_goal:
            path[-1] = [round(v, 3) for v in self.goal_points[agent]]
        if count:
            self.events.append(ScheduleEvent(RESERVED, [name], _nodes_note(path[-count:])))
        waits = [] if blocker is None else [self.names[blocker]]
        if blocker != self.waiting.get(agent) and blocker is not None and blocker != agent:
            where = path[-1]
            note = f"next node after ({where[0]:g}, {where[1]:g}): {waits[0]} goes first"
            self.events.append(ScheduleEvent(WAITS_FOR, [name, *waits], note))
        self.waiting[agent] = blocker
        blocked_by = self._blockers(agent) if self._cut_off(agent) else []
        return Reservation(name, path, waits, to_goal, blocked_by)

    def _blockers(self, agent: int) -> list[str]:
        """The bodies stopped for good on the agent's shortest way to its goal with no
        body counted (walked down the free roadmap's distances)."""
        table = self.roadmap.distances(self.goals[agent])
        owner = {n: a for a, nodes in self.failed.items() for n in nodes}
        owner.update({self.config[a]: a for a in self.frozen})
        node, found = self.config[agent], []
        while table[node] > 0 and table[node] < UNREACHABLE:
            node = min(
                (int(v) for v in self.roadmap.neighbours[node] if v >= 0), key=table.__getitem__
            )
            if node in owner and self.names[owner[node]] not in found:
                found.append(self.names[owner[node]])
        return found


def _nodes_note(points: list[list[float]]) -> str:
    return "nodes " + " ".join(f"({x:g}, {y:g})" for x, y in points)
