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
from fleet.scenario import Scenario
from planner.core.motion import moving_discs, step_pose, wrap_angle
from planner.core.status import FAILED, FINISHED
from planner.local.keep_right import agv_coming
from planner.local.lane_speed import oncoming
from planner.local.no_retreat import retreating
from planner.maps.clearance import Clearance
from planner.maps.costmap import Costmap
from planner.nav.fusion import FusionController
from planner.nav.recovery import towards
from planner.nav.tight_turns import approach_command, approach_path
from planner.route.global_planner import PlanResult, warm_up
from planner.traffic.guard import TrafficGuard


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
        self.controller = FusionController(scenario.grid, self.spec.goal, self.spec.config)
        self.guard = traffic_guard(scenario, self.controller)
        self._parked: frozenset[str] = frozenset()
        self._started = False
        self._index = 0  # where this AGV's state was in the last tick's list

    def warm_up(self) -> None:
        """Load (or compile) every numba kernel this node uses, before the run starts.

        It plans this AGV's route once, on the run's map: the costmap's centring and
        clearance kernels are loaded only by a real route, and an AGV host that forks
        its AGV processes after this spares each of them loading them again (with 50
        AGVs on 2 cores, 0.8 s of the start-up). The node is spent: a throwaway."""
        warm_up()
        start, goal, dwa = self.spec.start, self.spec.goal, self.controller.dwa
        pose, rest, cfg = (*start, 0.0), (0.0, 0.0, 0.0), dwa.config
        self.controller.start(pose)
        # reach and stop: the heading critic's pass test and the arrival speed's bound
        dwa.plan(pose, rest, goal, segment=(start, goal), lane_room=1.0, reach=0.5, stop=True)
        walker = np.array([[*start, 0.0, 0.0, 0.1]])  # the disc and evasion kernels, too
        moving_discs(np.array([[*start, 0.0, 0.0, 0.0, 0.0, cfg.radius]] * 2), 0, walker, cfg.dt)
        dwa.plan(pose, rest, goal, walker)
        dwa.threatened(pose, walker)
        dwa.clearance_along(np.array([pose]), walker)  # its map and disc kernels, from Python
        # what a control cycle calls from Python beyond DWA (each signature is loaded
        # once per process: in each of 50 forked AGV processes it cost the first ticks)
        coming = np.array([[*goal, -0.5, 0.0, cfg.radius]])  # an AGV head-on
        agv_coming(start, (start, goal), cfg.radius, coming)
        oncoming(pose, (0.5, 0.0, 0.0), coming, cfg.max_accel, cfg.horizon_s)
        retreating(pose, np.zeros(2), np.zeros(2), goal)
        approach_path(cfg, pose, rest, goal, cfg.max_speed)
        approach_command(cfg, pose, rest, goal, cfg.max_speed)
        step_pose(pose, rest, cfg.dt)
        towards(cfg, rest, rest)  # the recoveries' commands
        wrap_angle(0.0)
        dwa.distance_field.distance_at(*start)
        dwa.distance_field.distance_at_point(*start)
        if self.guard is not None:
            self.guard.passages.first_crossing([start, goal], 1.0)

    def on_tick(self, tick: Tick) -> NodeOutput | None:
        """This AGV's answer to ``tick``; None for a tick that does not list it."""
        me = self._own_state(tick)
        if me is None:
            return None
        pose = (me.x, me.y, me.theta)
        plan_msg = None
        start_heading = None
        if me.status == FAILED:  # the world gave up on this AGV: stand still
            return NodeOutput(self._command(tick, (0.0, 0.0, 0.0), FAILED))
        if not self._started:
            self._started = True
            pose, plan = self.controller.start(pose)
            plan_msg = self._plan_msg(tick, plan, "initial")
            if pose[2] != me.theta:
                start_heading = float(pose[2])
        self._sense(tick, pose)
        self._park(tick)
        decision = None
        if self.guard is not None and self.controller.targets:
            route = self.controller.route_ahead()
            stalled = self.controller.stalled(tick.time)
            decision = self.guard.decide(
                self.name, tick.tick, (me.x, me.y), route, tick.intents, stalled
            )
            if decision.rejoin:  # it waited off its route: plan the way in from here
                plan_msg = self._plan_msg(tick, self.controller.replan((me.x, me.y)), "traffic")
                self.guard.replanned()
        walkers = _walkers(tick)
        step = self.controller.step(
            pose, (me.vx, me.vy, me.omega), tick.time, self._discs(tick, walkers), walkers,
            hold=decision.hold if decision else None,
        )  # fmt: skip
        if step.plan is not None:
            plan_msg = self._plan_msg(tick, step.plan, "replan")
            if self.guard is not None:
                self.guard.replanned()
        command = self._command(tick, step.command, step.status, step.target)
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
            self.controller.park(discs)
            if self.guard is not None:
                self.guard.park(discs)

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
    if controller.costmap is None or controller.config.algorithm == "dwa":
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
