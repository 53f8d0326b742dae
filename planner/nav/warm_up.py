"""The planner warms itself up: short real runs of one AGV's controller, on its own map and
route, load every compiled kernel (numba's on-disk cache, or a compile on first use) that
a run's control cycles use, before the run starts.

An AGV host warms one node, then forks its AGV processes: a kernel (or a signature of one)
the warm-up misses is loaded by every process on its first use, mid-run; with 50 AGVs on 2
cores that cost more than the kernels save. So the warm-up drives the controller through
the situations of a run rather than calling kernels from a list: each scene is a few
control cycles from the AGV's start towards its first key node, the discs built and the
pose stepped as a run does (``moving_discs``, ``step_pose``). A kernel added on one of these
paths is loaded with nothing to edit; one that only a new kind of situation reaches needs
that situation as a scene here (``tests/test_warm_up.py`` finds it missing).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planner.core.motion import moving_discs, step_pose
from planner.maps.grid import GridMap, Point
from planner.nav.fusion import FusionConfig, FusionController
from planner.route.global_planner import warm_up as warm_up_global_planner
from planner.traffic.guard import TrafficGuard

NO_DISCS = np.zeros((0, 5))
SCENE_CYCLES = 3
"""Control cycles per scene: the first ends the start's turn, the next ones plan."""
SCENE_SPEED = 0.5
"""Of the top speed, along the route: the scenes start driving, so the samples reach the
discs near (from rest they reach a few centimetres)."""
HEAD_ON_AT = 3.0
"""m ahead along the route: where the AGV coming head-on starts (inside keep-right's reach)."""
NEAR_AHEAD = 1.0
"""m: an AGV standing this far ahead and to the side is within reach of the AGV's samples."""
STALL_CYCLES = 60
"""1 s cycles standing still: enough for the whole recovery sequence to run out."""


@dataclass
class Scene:
    """A fresh controller at the AGV's start, facing along its route."""

    controller: FusionController
    pose: tuple[float, float, float]
    ahead: tuple[float, float]  # unit vector along the route's first segment
    length: float  # m, of that segment

    def point(self, distance: float, side: float = 0.0) -> Point:
        """The point ``distance`` along the first segment and ``side`` to its left."""
        (x, y, _), (ux, uy) = self.pose, self.ahead
        return (x + distance * ux - side * uy, y + distance * uy + side * ux)

    def discs(self, others: list[tuple[float, ...]], walkers: np.ndarray) -> np.ndarray:
        """The discs the AGV avoids, built as a run builds them: its own state first, then
        ``others`` (rows [x, y, theta, vx, vy, omega]), then the walkers."""
        radius = self.controller.config.dwa.radius
        rows = [(*self.pose, 0.0, 0.0, 0.0), *others]
        states = np.array([(*row, radius) for row in rows], dtype=float)
        return moving_discs(states, 0, walkers, self.controller.config.dwa.dt)

    def drive(self, discs, walkers, cycles: int = SCENE_CYCLES, hold: Point | None = None):
        """``cycles`` control cycles from ``SCENE_SPEED``, the pose stepped by each command
        as the world does."""
        controller, dt = self.controller, self.controller.config.dwa.dt
        command = (SCENE_SPEED * controller.config.dwa.max_speed, 0.0, 0.0)
        for k in range(cycles):
            out = controller.step(self.pose, command, k * dt, discs, walkers, hold=hold)
            command = out.command
            self.pose = step_pose(self.pose, command, dt)


def _head_on(scene: Scene) -> None:
    """Another AGV comes head-on along the route and one stands just ahead beside it:
    DWA round discs, keeping right, lane speed shed for an oncoming disc, no retreat from
    an AGV in reach."""
    theta = scene.pose[2] + math.pi
    coming = (*scene.point(min(scene.length, HEAD_ON_AT)), theta, 0.5, 0.0, 0.0)
    standing = (*scene.point(NEAR_AHEAD, side=NEAR_AHEAD), theta, 0.0, 0.0, 0.0)
    scene.drive(scene.discs([coming, standing], NO_DISCS), NO_DISCS)


def _walker_crossing(scene: Scene) -> None:
    """A walker crosses just ahead, an AGV stands near: yielding early, evasion, the
    walkers' trail, no retreat from the AGV (a walker near keeps DWA driving where the
    straight approach to a tight corner would)."""
    x, y = scene.point(min(scene.length, 1.5), side=-1.0)
    radius = scene.controller.config.dwa.radius
    walkers = np.array([[x, y, -0.5 * scene.ahead[1], 0.5 * scene.ahead[0], radius]])
    standing = (*scene.point(NEAR_AHEAD, side=NEAR_AHEAD), 0.0, 0.0, 0.0, 0.0)
    scene.drive(scene.discs([standing], walkers), walkers)


def _waiting(scene: Scene) -> None:
    """The traffic rule holds the AGV at a place ahead, another AGV waiting beside: the
    straight approach to it, kept clear of discs."""
    hold = scene.point(min(scene.length, 1.0))
    beside = (*scene.point(0.0, side=2.0 * NEAR_AHEAD), 0.0, 0.0, 0.0, 0.0)
    scene.drive(scene.discs([beside], NO_DISCS), NO_DISCS, hold=hold)


def _blocker_sensed(scene: Scene) -> None:
    """A temporary obstacle sensed on the route ahead: the route check and its replan."""
    grid = scene.controller.grid
    cell = grid.cell_of(scene.point(min(scene.length, 1.0)))
    scene.controller.see([cell])
    scene.drive(scene.discs([], NO_DISCS), NO_DISCS)


def _facing_away(scene: Scene) -> None:
    """At rest facing away from the route: the initial turn on the spot (``turn_command``,
    braked on whole periods by ``stopping_rate``), as at a stop corner."""
    x, y, theta = scene.pose
    pose, discs = (x, y, theta + math.pi), scene.discs([], NO_DISCS)
    for k in range(SCENE_CYCLES):
        scene.controller.step(pose, (0.0, 0.0, 0.0), float(k), discs, NO_DISCS)


def _stalled_out(scene: Scene) -> None:
    """Standing still until the recovery sequence runs out: every recovery's commands."""
    controller, discs = scene.controller, scene.discs([], NO_DISCS)
    for k in range(STALL_CYCLES):
        controller.step(scene.pose, (0.0, 0.0, 0.0), float(k), discs, NO_DISCS)


DRIVES = (_head_on, _walker_crossing, _waiting, _blocker_sensed)
"""Scenes driven one after the other by one controller, each from the start."""


def _scene(grid: GridMap, start: Point, goal: Point, config: FusionConfig) -> Scene | None:
    """A fresh controller that planned the AGV's route, at the start facing along it; None
    when there is no route (a run of this AGV fails at once, too)."""
    controller = FusionController(grid, goal, config)
    controller.start((*start, 0.0))
    if not controller.targets or math.dist(start, controller.targets[0]) < 1e-9:
        return None
    target = controller.targets[0]
    length = math.dist(start, target)
    ahead = ((target[0] - start[0]) / length, (target[1] - start[1]) / length)
    return Scene(controller, (*start, math.atan2(ahead[1], ahead[0])), ahead, length)


def warm_up(
    grid: GridMap, start: Point, goal: Point, config: FusionConfig,
    guard: TrafficGuard | None = None,
) -> None:  # fmt: skip
    """Load every kernel the control cycles of an AGV from ``start`` to ``goal`` on ``grid``
    use (``guard``: its traffic guard's, too). It plans the AGV's real route: the
    costmap's centring and clearance kernels are loaded only by a real route."""
    warm_up_global_planner()
    scene = _scene(grid, start, goal, config)
    if scene is None:
        return
    if guard is not None:
        guard.decide("warm-up", 0, start, scene.controller.route_ahead(), [], False)
    at_start = scene.pose
    for drive in DRIVES:
        scene.pose = at_start
        drive(scene)
    _stalled_out(_scene(grid, start, goal, config))
    _facing_away(_scene(grid, start, goal, config))
