"""One AGV as a state machine: a tick in, its command for the next period out.

The node owns its fusion controller. It reads its pose from the tick (the
world integrates every AGV's motion, Eq. 4), senses temporary obstacles within
the sensing radius, sees every other AGV and moving obstacle as a disc moving
at its current world-frame velocity, and answers with its command (vx, vy,
omega) for tick k+1. The in-process runner and the AGV process over Zenoh both
call ``on_tick``.
"""

from __future__ import annotations

import itertools
import operator
from dataclasses import dataclass

import numpy as np

from bridge import keys
from bridge.messages import AgvCommand, AgvState, PlanMsg, Tick, TrajectoryMsg
from fleet.runtime.world import HELD
from fleet.scenario import RESERVATIONS, Scenario
from planner.core.motion import moving_discs
from planner.core.status import (
    DRIVING,
    FAILED,
    FINISHED,
    INITIAL,
    REPLAN,
    TRAFFIC,
    WAITING,
)
from planner.maps.clearance import Clearance
from planner.maps.costmap import Costmap
from planner.nav.fusion import FusionController
from planner.nav.reserved_drive import drive_reserved
from planner.nav.warm_up import warm_up
from planner.route.global_planner import PlanResult
from planner.traffic.follow import follow_point
from planner.traffic.guard import TrafficGuard
from planner.traffic.schedule import Reservation


@dataclass
class NodeOutput:
    """What one AGV says after a tick: its command, and a plan when it made one."""

    command: AgvCommand
    plan: PlanMsg | None = None
    trajectory: TrajectoryMsg | None = None


def publish_output(outbox, out: NodeOutput) -> None:
    """Send what an AGV says after a tick on its own keys: the same in both run modes
    (``outbox`` is the bus's ``publish`` or an in-process sink)."""
    name = out.command.name
    outbox(keys.agv_command(name), out.command)
    if out.plan:
        outbox(keys.agv_plan(name), out.plan)
    if out.trajectory:
        outbox(keys.agv_trajectory(name), out.trajectory)


class AgvNode:
    def __init__(self, scenario: Scenario, name: str):
        self.scenario = scenario
        self.spec = scenario.agv(name)
        self.name = name
        self._stopped_at: dict[str, float] = {}  # sim time each other AGV stopped for good
        self._index = 0  # where this AGV's state was in the last tick's list
        self._drive_to(self.spec.goal)

    def _drive_to(self, goal) -> None:
        """A controller for ``goal``: at the start, and in a shift for each new goal the
        world gives (it plans from where the AGV stands at the next tick)."""
        self.goal = tuple(goal)
        self.controller = FusionController(self.scenario.grid, self.goal, self.spec.config)
        self.guard = traffic_guard(self.scenario, self.controller)
        self._parked: frozenset[str] = frozenset()  # told again to the new controller
        self._started = False

    def warm_up(self) -> None:
        """Load (or compile) every numba kernel this node uses, before the run starts
        (``planner.nav.warm_up``). The node is spent: a throwaway."""
        spec = self.spec
        warm_up(self.scenario.grid, spec.start, spec.goal, spec.config, self.guard)

    def on_tick(self, tick: Tick) -> NodeOutput | None:
        """This AGV's answer to ``tick``; None for a tick that does not list it, or one in
        which a shift holds it at its goal (``HELD``)."""
        me = self._own_state(tick)
        if me is None:
            return None
        pose = (me.x, me.y, me.theta)
        plan_msg = None
        start_heading = None
        if me.status == FAILED:  # the world gave up on this AGV: stand still
            return NodeOutput(self._command(tick, (0.0, 0.0, 0.0), FAILED))
        if me.status in HELD:  # held at its goal by a shift (a dwell, or idle at home):
            return None  # it stands there, and the world does not wait for its answer
        if tick.assignments:
            goal = self._assigned_goal(tick)
            if goal != self.goal:
                self._drive_to(goal)
        if not self._started:
            self._started = True
            pose, plan = self.controller.start(pose)
            plan_msg = self._plan_msg(tick, plan, INITIAL)
            if pose[2] != me.theta and tick.tick == 0:
                start_heading = float(pose[2])
        self._sense(tick, pose)
        self._park(tick)
        decision = None
        reserved = self._reservation(tick)
        hold = None if reserved is None else self._follow(reserved)
        if self.guard is not None and self.controller.targets:
            route = self.controller.route_ahead()
            stalled = self.controller.stalled(tick.time)
            decision = self.guard.decide(
                self.name, tick.tick, (me.x, me.y), route, tick.intents, stalled
            )
            if decision.rejoin:  # it waited off its route: plan the way in from here
                plan_msg = self._plan_msg(tick, self.controller.replan((me.x, me.y)), TRAFFIC)
                self.guard.replanned()
        walkers = _walkers(tick)
        discs = self._discs(tick, walkers)
        velocity = (me.vx, me.vy, me.omega)
        if reserved is not None:
            final = self.controller.may_arrive
            step = drive_reserved(
                self.controller, pose, velocity, tick.time, hold, final, discs, walkers
            )
        else:
            step = self.controller.step(
                pose, velocity, tick.time, discs, walkers, hold=decision.hold if decision else None
            )
        if step.plan is not None:
            plan_msg = self._plan_msg(tick, step.plan, REPLAN)
            if self.guard is not None:
                self.guard.replanned()
        status = step.status
        if reserved is not None and status == WAITING and len(reserved.path) > 1:
            status = DRIVING  # on its way along reserved nodes: driving, not waiting
        command = self._command(tick, step.command, status, step.target)
        command.plan_time_ms = step.plan_time_s * 1e3
        command.start_heading = start_heading
        command.failure = self.controller.failure if step.status == FAILED else ""
        command.intent = decision.intent if decision else None
        command.recovery = step.recovery
        trajectory = None
        if len(step.trajectory):
            trajectory = TrajectoryMsg(
                self.name, tick.tick, step.trajectory[:, :2].round(4).tolist()
            )
        return NodeOutput(command, plan_msg, trajectory)

    def _assigned_goal(self, tick: Tick) -> tuple[float, float]:
        """This AGV's goal in a shift's ``tick`` (its own goal if the tick has none)."""
        mine = next((a for a in tick.assignments if a.name == self.name), None)
        return self.goal if mine is None else tuple(mine.goal)

    def _reservation(self, tick: Tick) -> Reservation | None:
        """This AGV's reservation in ``tick`` (traffic mode "reservations"), else None."""
        if self.scenario.traffic_mode != RESERVATIONS:
            return None
        return next((r for r in tick.reservations if r.name == self.name), None)

    def _follow(self, reserved: Reservation):
        """Where to drive on the reserved nodes (``planner.traffic.follow``); it may arrive
        only on the schedule's last node, its goal. Cut off from its goal by AGVs stopped
        for good, it fails naming them."""
        if reserved.blocked_by and not self.controller.mode.finished:
            who = ", ".join(reserved.blocked_by)
            self.controller.fail(f"cut off from its goal by {who} (stopped for good)")
        hold = follow_point(reserved.path)
        self.controller.may_arrive = reserved.to_goal and list(hold) == reserved.path[-1]
        return hold

    def _own_state(self, tick: Tick) -> AgvState | None:
        """This AGV's state in ``tick``: at its place in the last tick, else searched."""
        agvs = tick.agvs
        if self._index < len(agvs) and agvs[self._index].name == self.name:
            return agvs[self._index]
        for index, state in enumerate(agvs):
            if state.name == self.name:
                self._index = index
                return state
        return None

    def _command(self, tick: Tick, command, status: str, target=None) -> AgvCommand:
        return AgvCommand(
            name=self.name,
            tick=tick.tick + 1,
            vx=float(command[0]),
            vy=float(command[1]),
            omega=float(command[2]),
            status=status,
            target=list(target) if target is not None else None,
        )

    def _park(self, tick: Tick) -> None:
        """Tell the planner of AGVs that stopped for good (arrived or failed)."""
        parked = [s for s in tick.agvs if s.status in FINISHED and s.name != self.name]
        names = frozenset(s.name for s in parked)
        if names != self._parked:
            self._parked = names
            discs = [(s.x, s.y, s.radius) for s in parked]
            self.controller.park(discs, [self._stopped_label(s, tick.time) for s in parked])
            if self.guard is not None:
                self.guard.park(discs)

    def _stopped_label(self, state, now: float) -> str:
        """'AGV 'b', failed at t = 0.1 s (killed by signal 9)': who stands where, since when."""
        since = self._stopped_at.setdefault(state.name, now)
        why = f" ({state.failure})" if state.failure else ""
        return f"AGV '{state.name}', {state.status} at t = {since:.1f} s{why}"

    def _sense(self, tick: Tick, pose) -> None:
        if not tick.temporary:
            return
        grid = self.scenario.grid
        r2 = self.scenario.sensing_radius**2
        seen = []
        for col, row in tick.temporary:
            cx, cy = grid.centre_of((col, row))
            if (cx - pose[0]) ** 2 + (cy - pose[1]) ** 2 <= r2:
                seen.append((col, row))
        if seen:
            self.controller.see(seen)

    def _discs(self, tick: Tick, walkers: np.ndarray) -> np.ndarray:
        """Every other AGV and moving obstacle as (x, y, vx, vy, radius), world frame; one
        compiled call for all AGVs (with 100 AGVs, a call per AGV took most of a tick)."""
        agvs = tick.agvs
        values = itertools.chain.from_iterable(map(_STATE_FIELDS, agvs))  # np.array of
        # the rows took half as long again: it inspects each row's shape
        states = np.fromiter(values, dtype=float, count=7 * len(agvs)).reshape(len(agvs), 7)
        # on_tick found this AGV's row at self._index
        return moving_discs(states, self._index, walkers, self.scenario.dt)

    def _plan_msg(self, tick: Tick, plan: PlanResult | None, reason: str) -> PlanMsg | None:
        return None if plan is None else plan_message(self.name, tick, plan, reason)


def traffic_guard(scenario: Scenario, controller: FusionController) -> TrafficGuard | None:
    """The traffic guard of an AGV of the default profile that follows a global route
    (the paper profile treats other AGVs only as moving discs, as the paper does).

    Every guard of a run finds the passages for the same clearance, the largest of the
    fleet's, so that a passage id means the same passage to every AGV."""
    if (
        controller.costmap is None
        or controller.config.algorithm == "dwa"
        or scenario.traffic_mode == RESERVATIONS
    ):
        return None
    fleet = [a.config.clearance for a in scenario.agvs]
    widest = Clearance(max(c.radius for c in fleet), max(c.margin for c in fleet))
    return TrafficGuard(Costmap.for_grid(scenario.grid, widest), controller.config.dwa)


# shared by every tick without moving obstacles (writeable, though nothing writes it: for a
# read-only array numba would compile the kernels it is passed to again, mid-run)
_NO_WALKERS = np.zeros((0, 5))
_STATE_FIELDS = operator.attrgetter("x", "y", "theta", "vx", "vy", "omega", "radius")


def _walkers(tick: Tick) -> np.ndarray:
    """The moving obstacles as (x, y, vx, vy, radius) rows: discs that do not avoid an AGV."""
    if not tick.moving:
        return _NO_WALKERS
    moving = [(o.x, o.y, o.vx, o.vy, o.radius) for o in tick.moving]
    return np.array(moving, dtype=float).reshape(-1, 5)


def plan_message(name: str, tick: Tick | None, plan: PlanResult, reason: str) -> PlanMsg:
    """A global plan as published on ``agv/<name>/plan`` (tick None: before any tick)."""
    return PlanMsg(
        name=name,
        tick=tick.tick if tick else 0,
        time=tick.time if tick else 0.0,
        algorithm=plan.algorithm,
        reason=reason,
        found=plan.found,
        path=[list(p) for p in plan.path],
        key_nodes=[list(p) for p in plan.key_nodes],
        length=plan.length if plan.found else 0.0,
        turns=plan.turns if plan.found else 0,
        turning_angle_deg=plan.turning_angle_deg if plan.found else 0.0,
        plan_time_ms=plan.time_s * 1e3,
    )
