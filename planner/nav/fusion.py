"""The fusion controller of Guo et al. 2023 (section 4) and its two comparison variants.

One controller per AGV. It plans globally once, then every control cycle
runs DWA towards the current local target:

- ``fusion`` (the paper): improved A* key nodes are the successive local
  targets, and the initial heading is turned towards the first key node.
- ``astar-dwa`` (the paper's comparison hybrid, ref. [34]): traditional A*,
  its turning points as local targets, no initial-heading alignment.
- ``dwa``: DWA alone, aimed at the final goal; no global plan, no replans.

Target switching: the local target advances to the next key node as soon as
the AGV is within ``switch_distance`` of it (the final goal never switches;
the AGV has arrived within ``goal_tolerance`` of it).

Beyond the paper: progress is the remaining route length (to the current
target, then along the key nodes to the goal). When its best value has not
dropped by ``progress_distance`` for ``progress_window`` seconds, the
controller replans globally on the static map plus the temporary obstacles
seen so far. A replan that finds no path means the goal is unreachable on
what the AGV knows: status ``failed``. A cycle in which DWA has no admissible
trajectory (boxed in, braking) reports ``blocked``.

The default profile (``planner/local_behaviour.py``) adds: the initial turn
driven within the omega and alpha limits; every cycle in which new obstacles
were sensed, a check of the remaining route against them and an immediate
replan when they block it (and round a walker standing on the route
nearby); a final approach scored by nearness to the goal;
arrival only when stopped inside the tolerance; bounded recoveries
(``planner/recovery.py``), whose replans go round discs parked on the route,
and then ``failed`` with the reason; a turn on the spot towards a target
behind; a key node gone by beside it switched from when the next is in plain sight
(``planner/passed_node.py``); early yielding to walkers (``planner/yielding.py``, in DWA).
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field

import numpy as np

from planner.core.errors import MapError
from planner.core.motion import wrap_angle
from planner.core.path_metrics import distance_to_path
from planner.core.profiles import DEFAULT, check_profile
from planner.core.status import BACK_OFF, REPLAN, ROTATE, WAIT, WAITING
from planner.local.behaviour import local_behaviour
from planner.local.config import DwaConfig
from planner.local.dwa import DwaPlanner, braking_command
from planner.local.keep_right import agv_coming, right_offset, shifted_right
from planner.local.lane_speed import oncoming, route_room
from planner.local.turning import turn_command
from planner.local.yielding import agvs_of, walker_near, walkers_standing
from planner.maps.clearance import Clearance
from planner.maps.costmap import Costmap
from planner.maps.distance_field import DistanceField
from planner.maps.grid import Cell, GridMap, Point, cells_in_disc
from planner.nav.passed_node import in_plain_sight, passed_beside
from planner.nav.recovery import DURATION_S, RECOVERIES, Recovery, is_stopped, recovery_command
from planner.nav.tight_turns import Corner, approach_command, approach_path, corners, stopped_enough
from planner.nav.trail import Trail
from planner.route.global_planner import DEFAULT_SAFETY_DISTANCE, PlanResult, plan_global
from planner.route.parked_discs import blocking_cells
from planner.route.route_check import blocked_point

VARIANTS = ("fusion", "astar-dwa", "dwa")
_GLOBAL_ALGORITHM = {"fusion": "improved", "astar-dwa": "traditional"}
GLOBAL_ALGORITHM = _GLOBAL_ALGORITHM
"""The global A* variant each planner variant plans with (``dwa`` has none)."""


CALM_WINDOWS = 3
"""Progress windows without a stall after which the recoveries start again from the first."""

BEHIND = math.radians(120.0)
"""A target this far off the body's heading is behind it: turn round on the spot first ..."""
FACED = math.radians(30.0)
"""... and to a waiting place, until it is this near the heading. Handing over to DWA at
``BEHIND`` left it 120° off, and DWA's arc to it from there is a loop (door n10 s4: L5,
sent from one waiting place to another behind it, looped in the crowded room). Not for
route targets: a longer turn there set the progress checker's recoveries off at tight
corners (nav_bench seed 4 failed)."""

PARKED_ROUNDS = 3
"""How many times a recovery replan goes round the discs parked on the plan it drew."""

JAM_RANGE = 2.0
"""m: an AGV that had another AGV this near (centre to centre) at one of the stalls of its
recovery sequence is in a jam, not at a dead end: when the sequence runs out it starts
again (``JAM_RESTARTS`` times)."""

JAM_RESTARTS = 2

STANDING_RANGE = 4.0
"""m: a walker standing on the route nearer than this is gone round at once (route check):
nearer, a walker that starts walking towards the AGV leaves it no time to step aside."""


@dataclass(frozen=True)
class FusionConfig:
    """Everything one AGV's planner needs; defaults are the paper's."""

    algorithm: str = "fusion"
    profile: str = DEFAULT
    dwa: DwaConfig = field(default_factory=DwaConfig)
    safety_distance: float = DEFAULT_SAFETY_DISTANCE
    switch_distance: float = 1.0
    goal_tolerance: float = 0.2
    progress_window: float = 5.0
    progress_distance: float = 0.3
    approach_distance: float = 3.0  # m: the final approach starts this close to the goal
    free_heading: bool = False  # default profile: keep the paper's free heading

    def __post_init__(self) -> None:
        check_profile(self.profile)
        if self.algorithm not in VARIANTS:
            raise ValueError(
                f"unknown planner algorithm {self.algorithm!r}: choose one of {', '.join(VARIANTS)}"
            )
        positive = (
            "safety_distance", "switch_distance", "goal_tolerance", "progress_window",
            "approach_distance",
        )  # fmt: skip
        for name in positive:
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be > 0, got {getattr(self, name)}")
        self.clearance  # noqa: B018 - a safety distance below the radius is an error

    @property
    def clearance(self) -> Clearance:
        """The AGV's radius (``dwa.radius``) and margin (safety_distance - radius)."""
        return Clearance.from_safety_distance(self.dwa.radius, self.safety_distance)


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


class FusionController:
    """One AGV's planner: global plan + DWA, stepped once per control period."""

    def __init__(self, grid: GridMap, goal: Point, config: FusionConfig | None = None):
        self.config = config or FusionConfig()
        self.grid = grid
        self.goal = goal
        self.known_cells: set[Cell] = set()
        self.targets: list[Point] = []
        self.target_index = 0
        self.corners: list[Corner] = []  # how each target but the goal is passed
        self.status = "driving"
        self.failure = ""
        self.behaviour = local_behaviour(self.config.profile, free_heading=self.config.free_heading)
        self.static_field = DistanceField.from_grid(grid)
        self.dwa = DwaPlanner(self.config.dwa, self.static_field, self.behaviour)
        # default profile: the map's costmap for this AGV (shared through the map's cache),
        # plus the temporary obstacles seen so far
        self.costmap = None
        if self.config.profile == DEFAULT:
            self.costmap = Costmap.for_grid(grid, self.config.clearance)
        self._best_remaining = math.inf
        self._best_time = 0.0
        self._turning = False
        self._rounding = False  # turning round on the spot to a waiting place (``FACED``)
        self._previous = (0.0, 0.0, 0.0)
        self._recovery: Recovery | None = None
        self._recovery_started = ""  # in this cycle, for its ControlStep
        self._recoveries_run: list[str] = []  # the kinds this sequence has started
        self._jam_restarts = 0  # recovery sequences started again in a jam
        self._jammed = False  # another AGV was near at a stall of this sequence
        self._last_stall = -math.inf  # sim time of the last stall
        self._stalled_before: Point | None = None  # the target the AGV last stalled on
        self._planned_at = goal  # where the AGV was when it last planned
        self.trail = Trail()  # the way it came: where a head-on walker walks on
        self._route_stale = False  # new obstacles sensed since the route was last checked
        self.parked: set[Cell] = set()  # cells of AGVs parked for good (``park``)
        self._rounded: set[Cell] = set()  # cells of standing walkers a replan went round
        self._parked_in_way = False  # one of them is on the route: replan
        self.may_arrive = True  # False: at the goal, but the traffic schedule has it pass on

    # --- planning -----------------------------------------------------------------
    def start(
        self, pose: tuple[float, float, float]
    ) -> tuple[tuple[float, float, float], PlanResult | None]:
        """Plan from the start pose; returns the (possibly turned) start pose and the plan."""
        plan = self._plan_from((pose[0], pose[1]))
        if self.config.algorithm == "fusion" and plan is not None and plan.found:
            if self.behaviour.recorded_turn:
                self._turning = True  # driven by ``step`` within the limits
            else:
                first = self.targets[0]
                pose = (pose[0], pose[1], math.atan2(first[1] - pose[1], first[0] - pose[0]))
        return pose, plan

    def _plan_from(self, position: Point, moving: np.ndarray | None = None) -> PlanResult | None:
        """Plan from ``position`` on what is known; with ``moving`` (default profile), round
        the discs parked on the route too where that leaves a way."""
        if self.config.algorithm == "dwa":
            self.targets = [self.goal]
            self.target_index = 0
            self._planned_at = position
            return None
        if self.costmap is not None:
            costmap = self.costmap.with_blocked(self.parked) if self.parked else self.costmap
            known = costmap.grid
        else:
            known = self.grid.with_blocked(self.known_cells) if self.known_cells else self.grid
            costmap = None
        plan = self._search(known, costmap, position)
        if plan.found and moving is not None and costmap is not None:
            plan = self._round_parked(plan, position, moving)
        if not plan.found:
            parked = " and the AGVs stopped for good" if self.parked else ""
            self.failure = self.failure or f"no path to the goal on the known map{parked}"
            self.status = "failed"
            self.targets = []
            return plan
        # the start cell's centre is not a target: the AGV is already there; for
        # astar-dwa the key nodes are the traditional path's turning points
        self._planned_at = position
        self.targets = list(plan.key_nodes[1:]) or [self.goal]
        self.targets[-1] = self.goal
        self.target_index = 0
        self.corners = self._corners_of(position)
        return plan

    def _corners_of(self, position: Point) -> list[Corner]:
        """Each target's switch reach: the paper's ``switch_distance``, or (default profile)
        less where switching early would cut into a narrow stretch (``planner.nav.tight_turns``)."""
        reach = self.config.switch_distance
        if not self.behaviour.tight_turns:
            return [Corner(reach, False)] * (len(self.targets) - 1)
        radius = self.config.dwa.radius
        return corners(self.dwa.distance_field, radius, position, self.targets, reach)

    def _search(self, known: GridMap, costmap: Costmap | None, position: Point) -> PlanResult:
        try:
            return plan_global(
                known,
                position,
                self.goal,
                _GLOBAL_ALGORITHM[self.config.algorithm],
                profile=self.config.profile,
                clearance=self.config.clearance,
                costmap=costmap,
            )
        except MapError as err:  # e.g. standing in a cell now known to be blocked
            self.failure = str(err)
            return PlanResult(_GLOBAL_ALGORITHM[self.config.algorithm], position, self.goal, False)

    def see(self, cells) -> bool:
        """Temporary obstacle cells inside the sensing radius; True when any is new."""
        new = {tuple(c) for c in cells} - self.known_cells
        if not new:
            return False
        self.known_cells |= new
        if self.costmap is not None:
            self.costmap = self.costmap.with_blocked(new)
        self.dwa.distance_field = DistanceField.from_grid(self.grid.with_blocked(self.known_cells))
        self._route_stale = True
        return True

    # --- control ------------------------------------------------------------------
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

    def _step(self, pose, command, now, moving, walkers, hold=None) -> ControlStep:
        stop = (0.0, 0.0, 0.0)
        if self.status in ("arrived", "failed"):
            return _step(stop, self.status)
        position = (pose[0], pose[1])
        self.trail.note(position)
        if self.may_arrive and math.dist(position, self.goal) <= self.config.goal_tolerance:
            if not self.behaviour.smooth_arrival or is_stopped(command):
                self.status = "arrived"
                return _step(stop, self.status)
            return _step(braking_command(self.config.dwa, command), "driving", self.goal)
        if self._turning and self.dwa.threatened(pose, moving):
            self._turning = False  # a walker is coming: evading beats finishing the turn
        if self._turning:
            return self._turn(pose, command, now)
        if self._recovery is not None and now < self._recovery.until - 1e-9:
            kind = self._recovery.kind
            field = self.dwa.distance_field
            cmd = recovery_command(kind, self.config.dwa, field, pose, command, moving)
            return _step(cmd, "blocked", self.targets[self.target_index])
        self._recovery = None
        plan = None
        if self.behaviour.route_check:
            plan = self._check_route(position) or self._round_standing(position, walkers)
        if plan is None and self._parked_in_way:  # an AGV stopped for good on the route
            self._parked_in_way = False
            plan = self.replan(position)
        if self.status == "failed":
            return _step(stop, self.status, plan=plan)
        if hold is not None:
            return self._hold(pose, command, now, moving, walkers, hold, plan)
        if plan is None and self._stalled(position, now) and self.config.algorithm != "dwa":
            plan = self._on_stall(position, now, moving, walkers)
            if self.status == "failed":
                return _step(stop, self.status, plan=plan)
            if self._recovery is not None:
                return self._step(pose, command, now, moving, walkers)
        straight = self._advance_target(pose, command, moving, walkers)
        if self._turning:  # stopped at a tight corner: face the next stretch first
            return self._turn(pose, command, now)
        target = self.targets[self.target_index]
        final = self.target_index == len(self.targets) - 1
        if final and self.behaviour.tight_turns:  # the goal too: faced, then driven to straight
            straight = self._straight_to(pose, command, target, moving, walkers)
        approach = (
            self.behaviour.final_approach
            and final
            and math.dist(position, target) <= self.config.approach_distance
        )
        turn = self._turn_round(pose, command, target, moving)
        if turn is not None:
            return _step(turn, "driving", target, plan=plan)
        if straight is not None:  # the last metres to a tight corner or the goal, straight
            return _step(straight[0], "driving", target, straight[1], plan)
        reach = self.config.goal_tolerance if final else self._dwa_reach()
        result = self.dwa.plan(
            pose, command, target, moving, reach=reach, stop=final, previous=self._previous,
            approach=approach, segment=self._segment(pose, target, moving, walkers),
            route=[position, *self.targets[self.target_index :]],
            came_by=self.trail.back_from(position), walkers=walkers,
            lane_room=self._lane_room(pose, command, moving, walkers),
        )  # fmt: skip
        self.status = "blocked" if not result.admissible else "driving"
        return _step(result.command, self.status, target, result.trajectory, plan)

    def _hold(self, pose, command, now, moving, walkers, hold: Point, plan) -> ControlStep:
        """Drive to ``hold`` and wait there; waiting is not a stall (no recoveries). The last
        metres are driven straight where that is clear, as to a tight corner: DWA's arcs
        circled in front of the door while the waiting place moved."""
        self._best_time = now
        self._best_remaining = min(self._best_remaining, self.remaining(pose[:2]))
        self.status = WAITING
        position = (pose[0], pose[1])
        if math.dist(position, hold) <= self.config.goal_tolerance:  # there: stand
            return _step(braking_command(self.config.dwa, command), WAITING, hold, plan=plan)
        turn = self._turn_round(pose, command, hold, moving, FACED)  # behind: turn, no circle
        if turn is not None:
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

    def replan(self, position: Point, moving: np.ndarray | None = None) -> PlanResult | None:
        """A new global route from ``position`` (the traffic rule moved the AGV off its
        route, or what it senses blocks it; with ``moving``, round the discs parked on
        it as ``_plan_from`` does); the progress measure restarts from it."""
        plan = self._plan_from(position, moving)
        self._best_remaining = self.remaining(position) if self.targets else math.inf
        return plan

    def stalled(self, now: float) -> bool:
        """No progress along the route for the progress window (waiting excluded)."""
        return now - self._best_time >= self.config.progress_window

    def route_ahead(self) -> list[Point]:
        """The rest of the route: from the start of the current segment, the targets
        still ahead."""
        return [self._segment_start(), *self.targets[self.target_index :]]

    def park(self, discs) -> None:
        """AGVs that stopped for good (arrived, failed) at (x, y, radius): obstacles for
        every later global plan (DWA sees them as discs anyway)."""
        if self.costmap is None:
            return
        cells = set()
        for x, y, radius in discs:
            cells |= cells_in_disc(self.grid, (x, y), radius)
        self.parked = cells - self.known_cells
        reach = self.config.clearance.radius
        self._parked_in_way = any(
            self.targets and distance_to_path(self.route_ahead(), (x, y)) < radius + reach
            for x, y, radius in discs
        )

    def _segment(self, pose, target: Point, moving, walkers):
        """The route's current segment for DWA's on-route term, shifted to the right while
        another AGV comes the other way (``planner.local.keep_right``)."""
        segment = (self._segment_start(), target)
        if not self.behaviour.keep_right:
            return segment
        field, radius = self.dwa.distance_field, self.config.dwa.radius
        if not agv_coming(pose[:2], segment, radius, agvs_of(moving, walkers)):
            return segment
        return shifted_right(segment, right_offset(field, radius, segment))

    def _segment_start(self) -> Point:
        """Where the route's current segment starts: the previous key node, or where the
        AGV was when it planned."""
        return self.targets[self.target_index - 1] if self.target_index else self._planned_at

    def _turn(self, pose, command, now) -> ControlStep:
        """The turn on the spot towards the current target (the first key node at the start,
        the next stretch at a tight corner), as motion within the limits."""
        first = self.targets[self.target_index]
        bearing = math.atan2(first[1] - pose[1], first[0] - pose[0])
        error = float(wrap_angle(bearing - pose[2]))
        cmd = turn_command(self.config.dwa, error, command)
        if cmd is None:
            self._turning = False
            cmd = braking_command(self.config.dwa, command)
        self._best_time = now  # turning on the spot is progress for the progress checker
        return _step(cmd, "driving", first)

    def _turn_round(
        self, pose, command, target, moving, faced: float = BEHIND
    ) -> tuple[float, float, float] | None:
        """Default profile, an AGV that cannot reverse and a target behind it: the turn on
        the spot towards it (DWA's arcs only circle, turning the body while driving on),
        unless a walker is coming; None otherwise. An AGV too fast to stop within its
        clearance brakes straight first: turning while it braked from lane speed swept an
        arc into a wall (a replan at 1.2 m/s that sent the route back the way it came),
        while the way straight ahead is the old route's, clear at least to what made it
        replan. Once turning, it turns on until the target is ``faced`` off the heading."""
        if not self.behaviour.turn_round or self.config.dwa.min_vx < 0:
            return None
        bearing = math.atan2(target[1] - pose[1], target[0] - pose[0])
        error = float(wrap_angle(bearing - pose[2]))
        if abs(error) <= (faced if self._rounding else BEHIND) or self.dwa.threatened(pose, moving):
            self._rounding = False
            return None
        cfg = self.config.dwa
        stopping = math.hypot(command[0], command[1]) ** 2 / (2.0 * cfg.max_accel)
        if stopping > self.dwa.distance_field.distance_at_point(pose[0], pose[1]) - cfg.radius:
            return braking_command(cfg, command)
        turn = turn_command(cfg, error, command)
        self._rounding = turn is not None
        return turn

    def _straight_to(self, pose, command, node: Point, moving, walkers):
        """The command and predicted path of the straight approach to a tight corner, when
        within ``approach_distance``, no walker is near (``walker_near``; walkers standing
        still may be, once the AGV stalled before this corner) and, driven no faster than it
        can brake within its clearance (Eq. 7, as DWA's samples), it keeps clear of the map
        and the moving discs over the horizon; None: DWA drives (and avoids).

        A walker in range keeps the approach off because it stops and turns at the corner,
        slow to get out of a walker's way. But a walker that stopped where its walk ended
        may stand there for good, and a 1-cell gap that DWA's arcs cannot thread then
        failed the run (held-out nav_bench seeds 216, 276, 299)."""
        if math.dist(pose[:2], node) > self.config.approach_distance:
            return None
        if walker_near(pose, walkers) and not self._stuck_past_standing(node, pose, walkers):
            return None
        cfg = self.config.dwa
        room = self.dwa.clearance_along(
            approach_path(cfg, pose, command, node, cfg.max_speed), moving
        )
        if room <= 0.0:
            return None
        cap = math.sqrt(2.0 * room * cfg.max_accel)  # the approach keeps below Eq. (7)'s limit
        path = approach_path(cfg, pose, command, node, cap)
        if self.dwa.clearance_along(path, moving) <= 0.0:
            return None
        return approach_command(cfg, pose, command, node, cap), path

    def _stuck_past_standing(self, node: Point, pose, walkers) -> bool:
        """Whether the AGV stalled before on its way to ``node`` and every walker in range
        stands still."""
        before = self._stalled_before
        stuck = before is not None and math.dist(before, node) < self.config.goal_tolerance
        return stuck and walkers_standing(pose, walkers)

    def _lane_room(self, pose, command, moving, walkers, nodes: list[Point] | None = None):
        """The braking room the route ahead (or ``nodes``) grants DWA's samples that follow
        it (``planner.local.lane_speed``). With a walker near or a disc coming (``oncoming``),
        none: DWA still grants the hardest braking from the current speed, so the AGV slows
        to Eq. (7)'s speed, keeping the room to yield or pass, instead of finding nothing
        admissible at once."""
        if not self.behaviour.lane_speed:
            return None
        cfg = self.config
        if walker_near(pose, walkers) or oncoming(
            pose, command, moving, cfg.dwa.max_accel, cfg.dwa.horizon_s
        ):
            return 0.0
        if nodes is None:
            nodes = self.targets[self.target_index :]
        # a tight corner's bound applies from where its straight approach begins
        corners = self.corners[self.target_index :] if len(nodes) > 1 else []
        reaches = [cfg.approach_distance if c.stop else c.reach for c in corners]
        horizon = cfg.dwa.max_speed**2 / (2.0 * cfg.dwa.max_accel)
        return route_room(
            self.dwa.distance_field, cfg.dwa.radius, (pose[0], pose[1]), nodes, reaches, horizon
        )

    def _check_route(self, position: Point) -> PlanResult | None:
        """Replan at once when newly sensed obstacles block the remaining route."""
        if not self._route_stale or self.config.algorithm == "dwa":
            return None
        self._route_stale = False
        route = [position, *self.targets[self.target_index :]]
        blocker = blocked_point(
            self.dwa.distance_field, route, self.config.dwa.radius, self.static_field
        )
        if blocker is None:
            return None
        return self.replan(position)  # the blocking cells are in known_cells: marked

    def _round_standing(self, position: Point, walkers) -> PlanResult | None:
        """Replan at once round walkers standing on the route within ``STANDING_RANGE`` (as
        Nav2's obstacle layer puts a standing person in the global costmap), once per
        place they stand at; the route stays when there is no way round."""
        if walkers is None or not len(walkers) or self.config.algorithm == "dwa":
            return None
        near = walkers[np.hypot(walkers[:, 0] - position[0], walkers[:, 1] - position[1])
                       < STANDING_RANGE]  # fmt: skip
        route = [position, *self.targets[self.target_index :]]
        cells = set(blocking_cells(self.grid, near, route, self.config.dwa.radius))
        if not cells - self._rounded:
            return None
        self._rounded |= cells
        return self.replan(position, near)

    def _on_stall(self, position: Point, now: float, moving, walkers) -> PlanResult | None:
        """No progress for ``progress_window``: replan (paper) or the next recovery (default,
        whose replans go round the discs parked on the route where there is a way; with
        another AGV near, back off and rotate wait instead; in a jam of AGVs the sequence
        starts again, ``JAM_RESTARTS`` times, before it fails)."""
        if not self.behaviour.recover:
            plan = self._plan_from(position)
            self._best_remaining, self._best_time = math.inf, now
            return plan
        self._last_stall = now
        agv_near = _agv_near(position, moving, walkers)
        self._jammed = self._jammed or agv_near
        exhausted = len(self._recoveries_run) >= len(RECOVERIES)
        if exhausted and self._jammed and self._jam_restarts < JAM_RESTARTS:
            self._jam_restarts += 1
            self._recoveries_run, self._jammed = [], False
        elif exhausted:
            self.status = "failed"
            self.failure = (
                f"no progress after the recoveries {', '.join(self._recoveries_run)} "
                f"({self.remaining(position):.1f} m of route left)"
            )
            return None
        kind = RECOVERIES[len(self._recoveries_run)]
        if kind in (BACK_OFF, ROTATE) and agv_near:
            kind = WAIT  # the others plan too: moving into their room only pushes them
        self._recoveries_run.append(kind)
        self._recovery_started = kind
        plan = self._plan_from(position, moving) if kind == REPLAN else None
        if self.targets:
            self._best_remaining = self.remaining(position)
            self._stalled_before = self.targets[self.target_index]
        self._best_time = now + DURATION_S[kind]
        if DURATION_S[kind] > 0:
            self._recovery = Recovery(kind, now + DURATION_S[kind])
        return plan

    def _round_parked(self, plan: PlanResult, position: Point, moving) -> PlanResult:
        """``plan``, or a plan round the discs parked on it (and on each plan round them,
        up to ``PARKED_ROUNDS`` times) when there is one."""
        own = (self.grid.cell_of(position), self.grid.cell_of(self.goal))
        marked: set[Cell] = set()
        for _ in range(PARKED_ROUNDS):
            route = [position, *plan.key_nodes[1:]]
            cells = set(blocking_cells(self.grid, moving, route, self.config.dwa.radius))
            cells -= {*own, *marked}
            if not cells:
                break
            marked |= cells
            around = self.costmap.with_blocked(marked)
            rounded = self._search(around.grid, around, position)
            if not rounded.found:
                break
            plan = rounded
        return plan

    def _advance_target(self, pose, command, moving, walkers):
        """Switch to the next target within the current one's reach. A tight corner that
        the straight approach can drive to is switched from only once stopped there, and
        then turned on the spot towards the next; returns that approach's (command, path)
        for the current target, None when DWA drives (then a tight corner whose approach is
        not clear, e.g. with a walker near, is passed like any key node)."""
        last = len(self.targets) - 1
        while self.target_index < last:
            corner = self.corners[self.target_index]
            node = self.targets[self.target_index]
            distance = math.dist(pose[:2], node)
            straight = None
            if corner.stop:
                straight = self._straight_to(pose, command, node, moving, walkers)
            if straight is None:
                if distance > self._dwa_reach() and not self._passed_beside(pose, corner):
                    return None
            elif distance > corner.reach or not stopped_enough(self.config.dwa, command):
                return straight  # not there, or not stopped yet
            self.target_index += 1
            if straight is not None:
                self._turning = True  # turn_command brakes omega, then turns
                return None
        return None

    def _passed_beside(self, pose, corner: Corner) -> bool:
        """Default profile: the AGV went past the current key node beside it, beyond its
        reach, and sees the next one in plain sight (``planner.nav.passed_node``): it switches
        on instead of turning back to the node. Not at a stop corner (a narrow stretch
        follows: it is entered from the node)."""
        if not self.behaviour.pass_beside or corner.stop:
            return False
        position = (pose[0], pose[1])
        node, after = self.targets[self.target_index], self.targets[self.target_index + 1]
        if not passed_beside(position, self._segment_start(), node, after, corner.reach):
            return False
        field = self.dwa.distance_field
        return in_plain_sight(field, position, after, self.config.safety_distance)

    def _dwa_reach(self) -> float:
        """How near DWA must come to the current key node to switch to the next: the
        corner's reach, or the paper's ``switch_distance`` at a stop corner (DWA cannot
        stop on a point: near one its near-best samples spiral round it)."""
        corner = self.corners[self.target_index]
        return self.config.switch_distance if corner.stop else corner.reach

    def remaining(self, position: Point) -> float:
        """Route length left: to the current target, then along the remaining targets."""
        route = [position, *self.targets[self.target_index :]]
        return float(sum(math.dist(a, b) for a, b in itertools.pairwise(route)))

    def _stalled(self, position: Point, now: float) -> bool:
        remaining = self.remaining(position)
        if remaining < self._best_remaining - self.config.progress_distance:
            self._best_remaining, self._best_time = remaining, now
            if now - self._last_stall >= CALM_WINDOWS * self.config.progress_window:
                self._recoveries_run, self._jam_restarts = [], 0
                self._jammed = False
            return False
        return now - self._best_time >= self.config.progress_window


def _agv_near(position: Point, moving, walkers) -> bool:
    """Whether another AGV (a moving disc that is not a walker) is within ``JAM_RANGE``."""
    agvs = agvs_of(moving, walkers)
    return bool((np.hypot(agvs[:, 0] - position[0], agvs[:, 1] - position[1]) < JAM_RANGE).any())
