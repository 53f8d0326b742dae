"""One AGV as a state machine: a tick in, its state for the next tick out.

The node owns its fusion controller and integrates its own motion (Eq. 4):
it reads its pose from the tick (the world's copy of its last answer), senses
temporary obstacles within the sensing radius, sees every other AGV and
moving obstacle as a disc moving at its current world-frame velocity, and
answers with its pose and command for tick k+1. The in-process runner and the
AGV process over Zenoh both call ``on_tick``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bridge.messages import AgvState, PlanMsg, Tick, TrajectoryMsg
from fleet.scenario import Scenario
from planner.dwa import step_pose
from planner.fusion import FusionController
from planner.global_planner import PlanResult, warm_up


@dataclass
class NodeOutput:
    """What one AGV says after a tick: its next state, and a plan when it made one."""

    state: AgvState
    plan: PlanMsg | None = None
    trajectory: TrajectoryMsg | None = None


class AgvNode:
    def __init__(self, scenario: Scenario, name: str):
        self.scenario = scenario
        self.spec = scenario.agv(name)
        self.name = name
        self.controller = FusionController(scenario.grid, self.spec.goal, self.spec.config)
        self._started = False

    def warm_up(self) -> None:
        """Load (or compile) every numba kernel this node uses, before the run starts."""
        warm_up()
        self.controller.dwa.plan((*self.spec.start, 0.0), (0.0, 0.0, 0.0), self.spec.goal)
        walker = np.array([[*self.spec.start, 0.0, 0.0, 0.1]])  # the evasion kernel, too
        self.controller.dwa.threatened((*self.spec.start, 0.0), walker)

    def on_tick(self, tick: Tick) -> NodeOutput:
        me = next(s for s in tick.agvs if s.name == self.name)
        pose = (me.x, me.y, me.theta)
        plan_msg = None
        if me.status == "failed":  # the world gave up on this AGV: stand still
            return NodeOutput(self._state(tick.tick + 1, pose, (0.0, 0.0, 0.0), "failed", None))
        if not self._started:
            self._started = True
            pose, plan = self.controller.start(pose)
            plan_msg = self._plan_msg(tick, plan, "initial")
        self._sense(tick, pose)
        step = self.controller.step(pose, (me.vx, me.vy, me.omega), tick.time, self._discs(tick))
        if step.plan is not None:
            plan_msg = self._plan_msg(tick, step.plan, "replan")
        new_pose = step_pose(pose, step.command, self.scenario.dt)
        state = self._state(tick.tick + 1, new_pose, step.command, step.status, step.target)
        state.plan_time_ms = step.plan_time_s * 1e3
        state.failure = self.controller.failure if step.status == "failed" else ""
        trajectory = None
        if len(step.trajectory):
            trajectory = TrajectoryMsg(
                self.name, tick.tick, np.round(step.trajectory[:, :2], 4).tolist()
            )
        return NodeOutput(state, plan_msg, trajectory)

    def _state(self, k, pose, command, status, target) -> AgvState:
        return AgvState(
            name=self.name,
            tick=k,
            x=float(pose[0]),
            y=float(pose[1]),
            theta=float(math.remainder(pose[2], 2 * math.pi)),
            vx=float(command[0]),
            vy=float(command[1]),
            omega=float(command[2]),
            radius=self.spec.radius,
            status=status,
            target=list(target) if target is not None else None,
        )

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

    def _discs(self, tick: Tick) -> np.ndarray:
        rows = []
        for s in tick.agvs:
            if s.name == self.name:
                continue
            c, si = math.cos(s.theta), math.sin(s.theta)
            rows.append([s.x, s.y, s.vx * c - s.vy * si, s.vx * si + s.vy * c, s.radius])
        rows.extend([o.x, o.y, o.vx, o.vy, o.radius] for o in tick.moving)
        return np.array(rows, dtype=float).reshape(-1, 5)

    def _plan_msg(self, tick: Tick, plan: PlanResult | None, reason: str) -> PlanMsg | None:
        return None if plan is None else plan_message(self.name, tick, plan, reason)


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
