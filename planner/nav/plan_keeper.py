"""What the AGV knows of its map, and the global plans it draws on that.

The initial plan is drawn on the static map. What the AGV senses on the way (temporary
obstacles inside its sensing radius), the AGVs that stopped for good (arrived, failed) and
the walkers standing on its route are kept, and every replan is drawn round them: the
global costmap of Nav2, updated by its obstacle layer. The keeper also says when what was
seen calls for a replan at once: a sensed obstacle blocks the remaining route, a walker
stands on it near ahead, an AGV stopped for good on it.
"""

from __future__ import annotations

import numpy as np

from planner.core.errors import MapError
from planner.core.path_metrics import distance_to_path
from planner.core.profiles import DEFAULT
from planner.maps.costmap import Costmap
from planner.maps.distance_field import DistanceField
from planner.maps.grid import Cell, GridMap, Point, cells_in_disc
from planner.nav.config import GLOBAL_ALGORITHM, FusionConfig
from planner.route.global_planner import PlanResult, plan_global
from planner.route.parked_discs import blocking_cells, held_point
from planner.route.route_check import blocked_point

PARKED_ROUNDS = 3
"""How many times a recovery replan goes round the discs parked on the plan it drew: each
plan round them can run into others parked further on; a few rounds find the way out of a
cluster, more only cost searches."""

STANDING_RANGE = 4.0
"""m: a walker standing on the route nearer than this is gone round at once (route check):
nearer, a walker that starts walking towards the AGV leaves it no time to step aside."""


class PlanKeeper:
    """The static map plus what was seen, and the global planner run on them."""

    def __init__(self, grid: GridMap, goal: Point, config: FusionConfig):
        self.grid = grid
        self.goal = goal
        self.config = config
        self.algorithm = GLOBAL_ALGORITHM.get(config.algorithm, "")
        self.known_cells: set[Cell] = set()  # temporary obstacles sensed so far
        self.static_field = DistanceField.for_grid(grid)
        self.field = self.static_field  # the static map plus the sensed obstacles
        # default profile: the map's costmap for this AGV (shared through the map's cache),
        # plus the temporary obstacles seen so far
        self.costmap = None
        if config.profile == DEFAULT:
            self.costmap = Costmap.for_grid(grid, config.clearance)
        self.parked: set[Cell] = set()  # cells of AGVs parked for good (``park``)
        self.rounded: set[Cell] = set()  # cells of standing walkers a replan went round
        self.parked_in_way = False  # one of the parked AGVs is on the route: replan
        self.parked_by: list = []  # ((x, y), radius, who) of those AGVs, to name them
        self.route_stale = False  # new obstacles sensed since the route was last checked
        self.map_error = ""  # why the last search could not start (a MapError), if it could not

    # --- what was seen --------------------------------------------------------------
    def see(self, cells) -> bool:
        """Temporary obstacle cells inside the sensing radius; True when any is new."""
        new = {tuple(c) for c in cells} - self.known_cells
        if not new:
            return False
        self.known_cells |= new
        if self.costmap is not None:
            self.costmap = self.costmap.with_blocked(new)
        self.field = DistanceField.for_grid(self.grid.with_blocked(self.known_cells))
        self.route_stale = True
        return True

    def park(self, discs, route: list[Point] | None, labels=()) -> None:
        """AGVs that stopped for good (arrived, failed) at (x, y, radius): obstacles for
        every later global plan (DWA sees them as discs anyway); ``route``: the rest of the
        route (None: none), which one of them may block; ``labels`` name them in a failure
        they cause."""
        if self.costmap is None:
            return
        self.parked_by = [((x, y), r, label) for (x, y, r), label in zip(discs, labels)]
        cells = set()
        for x, y, radius in discs:
            cells |= cells_in_disc(self.grid, (x, y), radius)
        self.parked = cells - self.known_cells
        reach = self.config.clearance.radius
        self.parked_in_way = any(
            route and distance_to_path(route, (x, y)) < radius + reach for x, y, radius in discs
        )

    def route_blocked(self, route: list[Point]) -> bool:
        """Whether obstacles sensed since the last check block ``route`` (from the AGV's
        position along the targets ahead)."""
        if not self.route_stale:
            return False
        self.route_stale = False
        radius = self.config.dwa.radius
        return blocked_point(self.field, route, radius, self.static_field) is not None

    def standing_on(self, position: Point, route: list[Point], walkers) -> np.ndarray | None:
        """The walkers within ``STANDING_RANGE`` to go round at once (as Nav2's obstacle
        layer puts a standing person in the global costmap) when one of them stands on
        ``route`` at a place not gone round before; None otherwise."""
        if walkers is None or not len(walkers):
            return None
        near = walkers[np.hypot(walkers[:, 0] - position[0], walkers[:, 1] - position[1])
                       < STANDING_RANGE]  # fmt: skip
        cells = set(blocking_cells(self.grid, near, route, self.config.dwa.radius))
        if not cells - self.rounded:
            return None
        self.rounded |= cells
        return near

    def take_parked_in_way(self) -> bool:
        """Whether an AGV stopped for good on the route since this was last asked."""
        in_way, self.parked_in_way = self.parked_in_way, False
        return in_way

    # --- planning -------------------------------------------------------------------
    def plan(self, position: Point, moving: np.ndarray | None = None) -> PlanResult:
        """A global plan from ``position`` on what is known; with ``moving`` (default
        profile), round the discs parked on the route too where that leaves a way."""
        if self.costmap is not None:
            costmap = self.costmap.with_blocked(self.parked) if self.parked else self.costmap
            known = costmap.grid
        else:
            known = self.grid.with_blocked(self.known_cells) if self.known_cells else self.grid
            costmap = None
        plan = self._search(known, costmap, position)
        if plan.found and moving is not None and costmap is not None:
            plan = self._round_parked(plan, position, moving)
        return plan

    def take_map_error(self) -> str:
        """The MapError a search since this was last asked ran into ('' none)."""
        error, self.map_error = self.map_error, ""
        return error

    def _search(self, known: GridMap, costmap: Costmap | None, position: Point) -> PlanResult:
        try:
            return plan_global(
                known,
                position,
                self.goal,
                self.algorithm,
                profile=self.config.profile,
                clearance=self.config.clearance,
                costmap=costmap,
            )
        except MapError as err:  # e.g. standing in a cell now known to be blocked
            points = {"goal": self.goal, "start": position}
            self.map_error = held_point(self.grid, points, self.parked_by) or str(err)
            return PlanResult(self.algorithm, position, self.goal, False)

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
