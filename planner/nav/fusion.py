"""The fusion controller of Guo et al. 2023 (section 4) and its two comparison variants.

One controller per AGV. It plans globally once, then every control cycle
runs DWA towards the current local target:

- ``fusion`` (the paper): improved A* key nodes are the successive local
  targets, and the initial heading is turned towards the first key node.
- ``astar-dwa`` (the paper's comparison hybrid, ref. [34]): traditional A*,
  its turning points as local targets, no initial-heading alignment.
- ``dwa``: DWA alone, aimed at the final goal; no global plan, no replans.

The controller is put together from parts with Nav2's jobs (``planner.nav``'s docstring
lists them); a control cycle reads top-down in ``_step``: observe, check the goal, check
progress, pick the target, plan locally, command.

Beyond the paper: when the progress checker finds no progress, the controller replans
globally on the static map plus the temporary obstacles seen so far. A replan that finds
no path means the goal is unreachable on what the AGV knows: status ``failed``. A cycle in
which DWA has no admissible trajectory (boxed in, braking) reports ``blocked``.

The default profile (``planner.local.behaviour``) adds: the initial turn
driven within the omega and alpha limits; every cycle in which new obstacles
were sensed, a check of the remaining route against them and an immediate
replan when they block it (and round a walker standing on the route
nearby); a final approach scored by nearness to the goal;
arrival only when stopped inside the tolerance; bounded recoveries
(``planner.nav.recovery_sequence``), whose replans go round discs parked on the route,
and then ``failed`` with the reason; a turn on the spot towards a target
behind; a key node gone by beside it switched from when the next is in plain sight
(``planner.nav.passed_node``); early yielding to walkers (``planner.local.yielding``, in DWA).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from planner.core.motion import wrap_angle
from planner.core.status import BLOCKED, DRIVING, REPLAN, WAITING
from planner.local.behaviour import local_behaviour
from planner.local.dwa import DwaPlanner
from planner.local.turning import turn_command
from planner.local.window import braking_command
from planner.maps.grid import GridMap, Point
from planner.nav.config import GLOBAL_ALGORITHM, VARIANTS, FusionConfig
from planner.nav.dwa_inputs import lane_room, route_segment, straight_approach
from planner.nav.goal_checker import GoalChecker
from planner.nav.key_node_targets import KeyNodeTargets
from planner.nav.mode import Mode
from planner.nav.plan_keeper import PlanKeeper
from planner.nav.progress_checker import ProgressChecker
from planner.nav.recovery import DURATION_S, recovery_command
from planner.nav.recovery_sequence import RecoverySequence, agv_near
from planner.nav.tight_turns import Corner
from planner.nav.trail import Trail
from planner.nav.turn_round import FACED, TurnRound
from planner.route.global_planner import PlanResult

__all__ = ["GLOBAL_ALGORITHM", "VARIANTS", "ControlStep", "FusionConfig", "FusionController"]


@dataclass(frozen=True)
class ControlStep:
    """The outcome of one control cycle."""

    command: tuple[float, float, float]
    status: str
    target: Point | None
    trajectory: np.ndarray
    plan: PlanResult | None
    plan_time_s: float
    recovery: str = ""  # the recovery behaviour this cycle started ('' none)


def _step(command, status, target=None, trajectory=None, plan=None) -> ControlStep:
    empty = np.empty((0, 3))
    command = tuple(map(float, command))
    return ControlStep(
        command, status, target, empty if trajectory is None else trajectory, plan, 0.0
    )


STOP = (0.0, 0.0, 0.0)


class FusionController:
    """One AGV's planner: global plan + DWA, stepped once per control period."""

    def __init__(self, grid: GridMap, goal: Point, config: FusionConfig | None = None):
        self.config = config or FusionConfig()
        self.grid = grid
        self.goal = goal
        self.behaviour = local_behaviour(self.config.profile, free_heading=self.config.free_heading)
        self.plans = PlanKeeper(grid, goal, self.config)
        self.dwa = DwaPlanner(self.config.dwa, self.plans.field, self.behaviour)
        self.key_nodes = KeyNodeTargets(self.config, self.behaviour, goal)
        self.goal_checker = GoalChecker(self.config.goal_tolerance, self.behaviour.smooth_arrival)
        self.progress = ProgressChecker(self.config.progress_window, self.config.progress_distance)
        self.recoveries = RecoverySequence(
            self.config.progress_window, self.config.progress_distance
        )
        self.turn_round = TurnRound(self.config.dwa, self.behaviour.turn_round)
        self.trail = Trail()  # the way it came: where a head-on walker walks on
        self.mode = Mode.DRIVING
        self.failure = ""
        self.may_arrive = True  # False: at the goal, but the traffic schedule has it pass on
        self._previous = STOP  # the last cycle's command, for DWA's steadiness term
        self._recovery_started = ""  # in this cycle, for its ControlStep
        self._stalled_before: Point | None = None  # the target the AGV last stalled on

    @property
    def targets(self) -> list[Point]:
        """The key nodes of the route followed (the goal last); empty when there is none."""
        return self.key_nodes.nodes

    @property
    def corners(self) -> list[Corner]:
        return self.key_nodes.corners

    @property
    def costmap(self):
        """The costmap the global plans are drawn on (default profile), else None."""
        return self.plans.costmap

    # --- the global plan ------------------------------------------------------------
    def start(
        self, pose: tuple[float, float, float]
    ) -> tuple[tuple[float, float, float], PlanResult | None]:
        """Plan from the start pose; returns the (possibly turned) start pose and the plan."""
        plan = self._plan_from((pose[0], pose[1]))
        if self.config.algorithm == "fusion" and plan is not None and plan.found:
            if self.behaviour.recorded_turn:
                self.mode = Mode.TURNING_IN_PLACE  # driven by ``step`` within the limits
            else:
                first = self.targets[0]
                pose = (pose[0], pose[1], math.atan2(first[1] - pose[1], first[0] - pose[0]))
        return pose, plan

    def _plan_from(self, position: Point, moving: np.ndarray | None = None) -> PlanResult | None:
        """Plan from ``position`` on what is known (round the discs parked on the route
        too, with ``moving``) and follow the plan's key nodes; no plan: failed."""
        if self.config.algorithm == "dwa":
            self.key_nodes.aim_at(self.goal, position)
            return None
        plan = self.plans.plan(position, moving)
        self.failure = self.plans.take_map_error() or self.failure
        if not plan.found:
            who = "; ".join(label for _, _, label in self.plans.parked_by)
            parked = f" and the AGVs stopped for good ({who})" if self.plans.parked else ""
            self.failure = self.failure or f"no path to the goal on the known map{parked}"
            self.mode = Mode.FAILED
            self.key_nodes.drop()
            return plan
        # the start cell's centre is not a target: the AGV is already there; for
        # astar-dwa the key nodes are the traditional path's turning points
        nodes = list(plan.key_nodes[1:]) or [self.goal]
        nodes[-1] = self.goal
        self.key_nodes.follow(nodes, position, self.dwa.distance_field)
        return plan

    def replan(self, position: Point, moving: np.ndarray | None = None) -> PlanResult | None:
        """A new global route from ``position`` (the traffic rule moved the AGV off its
        route, or what it senses blocks it; with ``moving``, round the discs parked on
        it as ``_plan_from`` does); the progress measure restarts from it."""
        plan = self._plan_from(position, moving)
        self.progress.restart(self.key_nodes.remaining(position) if self.targets else math.inf)
        return plan

    def see(self, cells) -> bool:
        """Temporary obstacle cells inside the sensing radius; True when any is new."""
        new = self.plans.see(cells)
        if new:
            self.dwa.distance_field = self.plans.field
        return new

    def park(self, discs, labels=()) -> None:
        """AGVs that stopped for good (arrived, failed) at (x, y, radius): obstacles for
        every later global plan (DWA sees them as discs anyway); ``labels`` name them in a
        failure they cause."""
        self.plans.park(discs, self.key_nodes.route_ahead() if self.targets else None, labels)

    def fail(self, reason: str) -> None:
        """End the run as failed for ``reason`` (e.g. the traffic schedule found it cut off)."""
        self.mode = Mode.FAILED
        self.failure = reason

    def arrive(self) -> None:
        """End the run as arrived (a driver other than ``step`` brought it to the goal)."""
        self.mode = Mode.ARRIVED

    def stalled(self, now: float) -> bool:
        """No progress along the route for the progress window (waiting excluded)."""
        return self.progress.stalled(now)

    def route_ahead(self) -> list[Point]:
        """The rest of the route: from the start of the current segment, the targets
        still ahead."""
        return self.key_nodes.route_ahead()

    def remaining(self, position: Point) -> float:
        """Route length left: to the current target, then along the remaining targets."""
        return self.key_nodes.remaining(position)

    # --- the control cycle ------------------------------------------------------------
    def step(
        self,
        pose: tuple[float, float, float],
        command: tuple[float, float, float],
        now: float,
        moving: np.ndarray | None = None,
        walkers: np.ndarray | None = None,
        hold: Point | None = None,
    ) -> ControlStep:
        """One control cycle at time ``now``; ``moving`` rows are [x, y, vx, vy, radius]:
        every other AGV and moving obstacle; ``walkers`` those of them that do not avoid
        the AGV (the default profile gets out of their way early); ``hold``: wait there
        (the traffic rule keeps the AGV out of a passage)."""
        t0 = time.perf_counter()
        self._recovery_started = ""
        out = self._step(pose, command, now, moving, walkers, hold)
        self._previous = command
        return ControlStep(
            out.command, out.status, out.target, out.trajectory, out.plan,
            plan_time_s=time.perf_counter() - t0, recovery=self._recovery_started,
        )  # fmt: skip

    def _step(self, pose, command, now, moving, walkers, hold) -> ControlStep:
        if self.mode.finished:
            return _step(STOP, self.mode.value)
        # observe
        position = (pose[0], pose[1])
        self.trail.note(position)
        self.recoveries.ground.note(position)
        # check the goal
        if self.may_arrive and self.goal_checker.within(position, self.goal):
            if self.goal_checker.is_goal_reached(position, self.goal, command):
                self.mode = Mode.ARRIVED
                return _step(STOP, self.mode.value)
            return _step(braking_command(self.config.dwa, command), DRIVING, self.goal)
        # a turn on the spot or a recovery under way goes on
        if self.mode is Mode.TURNING_IN_PLACE and self.dwa.threatened(pose, moving):
            self.mode = Mode.DRIVING  # a walker is coming: evading beats finishing the turn
        if self.mode is Mode.TURNING_IN_PLACE:
            return self._turn(pose, command, now)
        if self.mode is Mode.RECOVERING:
            kind = self.recoveries.running(now)
            if kind is not None:
                return self._recover(kind, pose, command, moving)
            self.mode = Mode.DRIVING
        # what was seen may call for a new route at once
        plan = self._replan_for_what_was_seen(position, walkers)
        if self.mode is Mode.FAILED:
            return _step(STOP, self.mode.value, plan=plan)
        if hold is not None:
            return self._hold(pose, command, now, moving, walkers, hold, plan)
        self.mode = Mode.DRIVING
        # check progress
        if plan is None and self._no_progress(position, now) and self.config.algorithm != "dwa":
            plan = self._on_stall(position, now, moving, walkers)
            if self.mode is Mode.FAILED:
                return _step(STOP, self.mode.value, plan=plan)
            if self.mode is Mode.RECOVERING:
                return self._recover(self.recoveries.active.kind, pose, command, moving)
        # pick the target
        straight, stopped = self.key_nodes.advance(
            pose, command, self.dwa.distance_field,
            lambda node: self._straight_to(pose, command, node, moving, walkers),
        )  # fmt: skip
        if stopped:  # stopped at a tight corner: face the next stretch first
            self.mode = Mode.TURNING_IN_PLACE  # turn_command brakes omega, then turns
            return self._turn(pose, command, now)
        target, final = self.key_nodes.current, self.key_nodes.final
        if final and self.behaviour.tight_turns:  # the goal too: faced, then driven to straight
            straight = self._straight_to(pose, command, target, moving, walkers)
        # plan locally and command
        turn = None
        if not self._stopping_at(position, straight, final):
            turn = self.turn_round.command(self.dwa, pose, command, target, moving)
        if turn is not None:
            return _step(turn, DRIVING, target, plan=plan)
        if straight is not None:  # the last metres to a tight corner or the goal, straight
            return _step(straight[0], DRIVING, target, straight[1], plan)
        approach = (
            self.behaviour.final_approach
            and final
            and math.dist(position, target) <= self.config.approach_distance
        )
        reach = self.config.goal_tolerance if final else self.key_nodes.dwa_reach()
        result = self.dwa.plan(
            pose, command, target, moving, reach=reach, stop=final, previous=self._previous,
            approach=approach, segment=self._segment(pose, target, moving, walkers),
            route=[position, *self.key_nodes.ahead()],
            came_by=self.trail.back_from(position), walkers=walkers,
            lane_room=self._lane_room(pose, command, moving, walkers),
        )  # fmt: skip
        status = BLOCKED if not result.admissible else DRIVING
        return _step(result.command, status, target, result.trajectory, plan)

    # --- the parts of a cycle -----------------------------------------------------------
    def _replan_for_what_was_seen(self, position: Point, walkers) -> PlanResult | None:
        """Default profile: a replan at once when newly sensed obstacles block the remaining
        route, or round walkers standing on it near ahead; any profile: when an AGV stopped
        for good on it."""
        plan = None
        if self.behaviour.route_check and self.config.algorithm != "dwa":
            route = [position, *self.key_nodes.ahead()]
            if self.plans.route_blocked(route):  # the blocking cells are known: marked
                plan = self.replan(position)
            else:
                near = self.plans.standing_on(position, route, walkers)
                if near is not None:
                    plan = self.replan(position, near)
        if plan is None and self.plans.take_parked_in_way():
            plan = self.replan(position)
        return plan

    def _no_progress(self, position: Point, now: float) -> bool:
        """The progress checker's verdict, where the stalls have not been before; progress
        also tells the recovery sequence."""
        back = self.recoveries.ground.reached(position)
        if not back and self.progress.check(self.remaining(position), now):
            self.recoveries.progressed(now)
            return False
        return self.progress.stalled(now)

    def _on_stall(self, position: Point, now: float, moving, walkers) -> PlanResult | None:
        """No progress for ``progress_window``: replan (paper) or the next recovery of the
        sequence (default, whose replans go round the discs parked on the route where
        there is a way); failed when the sequence has run out."""
        if not self.behaviour.recover:
            plan = self._plan_from(position)
            self.progress.restart(math.inf, now)
            return plan
        kind = self.recoveries.next(now, position, agv_near(position, moving, walkers))
        if kind is None:
            self.mode = Mode.FAILED
            self.failure = (
                f"no progress after the recoveries {', '.join(self.recoveries.run)} "
                f"({self.remaining(position):.1f} m of route left)"
            )
            return None
        self._recovery_started = kind
        plan = self._plan_from(position, moving) if kind == REPLAN else None
        if self.targets:
            self.progress.restart(self.remaining(position))
            self._stalled_before = self.key_nodes.current
        self.progress.excuse(now + DURATION_S[kind])
        if self.recoveries.active is not None:
            self.mode = Mode.RECOVERING
        return plan

    def _recover(self, kind: str, pose, command, moving) -> ControlStep:
        """One period of the recovery ``kind`` under way."""
        field = self.dwa.distance_field
        cmd = recovery_command(kind, self.config.dwa, field, pose, command, moving)
        return _step(cmd, BLOCKED, self.key_nodes.current)

    def _hold(self, pose, command, now, moving, walkers, hold: Point, plan) -> ControlStep:
        """Drive to ``hold`` and wait there; waiting is not a stall (no recoveries). The last
        metres are driven straight where that is clear, as to a tight corner: DWA's arcs
        circled in front of the door while the waiting place moved."""
        self.progress.excuse(now, self.remaining(pose[:2]))
        self.mode = Mode.WAITING
        position = (pose[0], pose[1])
        if self.goal_checker.within(position, hold):  # there: stand
            return _step(braking_command(self.config.dwa, command), WAITING, hold, plan=plan)
        turn = self.turn_round.command(self.dwa, pose, command, hold, moving, FACED)
        if turn is not None:  # behind: turn, no circle
            return _step(turn, WAITING, hold, plan=plan)
        straight = self._straight_to(pose, command, hold, moving, walkers)
        if straight is not None:
            return _step(straight[0], WAITING, hold, straight[1], plan)
        result = self.dwa.plan(
            pose, command, hold, moving, reach=self.config.goal_tolerance, stop=True,
            previous=self._previous, approach=True, segment=(position, hold),
            lane_room=self._lane_room(pose, command, moving, walkers, [hold]),
        )  # fmt: skip
        return _step(result.command, WAITING, hold, result.trajectory, plan)

    def _turn(self, pose, command, now) -> ControlStep:
        """The turn on the spot towards the current target (the first key node at the start,
        the next stretch at a tight corner), as motion within the limits."""
        first = self.key_nodes.current
        bearing = math.atan2(first[1] - pose[1], first[0] - pose[0])
        error = float(wrap_angle(bearing - pose[2]))
        cmd = turn_command(self.config.dwa, error, command)
        if cmd is None:
            self.mode = Mode.DRIVING
            cmd = braking_command(self.config.dwa, command)
        self.progress.excuse(now)  # turning on the spot is progress for the progress checker
        return _step(cmd, DRIVING, first)

    def _stopping_at(self, position: Point, straight, final: bool) -> bool:
        """Whether the straight approach brakes within a tight corner's reach, to stop and
        turn to the next stretch there: a centimetre past the node, turning round to it
        first turned the body away from the next stretch (an omega sign change)."""
        if straight is None or final:
            return False
        reach = self.corners[self.key_nodes.index].reach
        return math.dist(position, self.key_nodes.current) <= reach

    def _segment(self, pose, target: Point, moving, walkers):
        segment = (self.key_nodes.segment_start(), target)
        return route_segment(self.behaviour, self.config, self.dwa, segment, pose, moving, walkers)

    def _straight_to(self, pose, command, node: Point, moving, walkers):
        position = (pose[0], pose[1])
        return straight_approach(
            self.config, self.dwa, pose, command, node, moving, walkers, self._stalled_before,
            [position, *self.key_nodes.ahead()], self.trail.back_from(position),
        )  # fmt: skip

    def _lane_room(self, pose, command, moving, walkers, nodes: list[Point] | None = None):
        corners = self.corners[self.key_nodes.index :]
        if nodes is None:
            nodes = self.key_nodes.ahead()
        return lane_room(
            self.behaviour, self.config, self.dwa, pose, command, moving, walkers, nodes, corners
        )
