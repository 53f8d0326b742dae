"""Which traffic mode suits a fleet, when its scenario leaves the choice to the planner.

Node reservations (``planner.traffic.schedule``) are for maps drawn one vehicle to a cell:
a MovingAI MAPF map, a warehouse of aisles one AGV wide. There the lattice the body fits
is the map's own cells (``Roadmap.spacing == 1``), the AGVs stand on cell centres, and
the zone rule cannot express "you take this aisle now, I take the next one" (it holds a
whole block of merged aisles for one direction). On a fine occupancy grid (a ROS map at
5 cm) the lattice is a coarse overlay: the AGVs would drive its staircase instead of
their own improved-A* routes, so the zone rule and DWA do better there. One AGV shares
space with nobody and drives its own route.

The rule, in order (the first that holds decides):
1. fewer than two AGVs: zones;
2. the lattice is coarser than the map's cells: zones;
3. a start or a goal is not on a node of its own (the schedule would refuse it): zones;
4. otherwise: reservations.
"""

from __future__ import annotations

from planner.maps.clearance import Clearance
from planner.maps.grid import GridMap, Point
from planner.traffic.roadmap import Roadmap
from planner.traffic.schedule import Schedule, ScheduleError


def suits_reservations(
    grid: GridMap, clearances: list[Clearance], agents: list[tuple[str, Point, Point]]
) -> bool:
    """The module's rule: True where node reservations suit the fleet ``agents`` (name,
    start, goal) with bodies ``clearances`` on ``grid``."""
    if len(agents) < 2:
        return False
    if Roadmap.spacing_for(grid, max(c.radius for c in clearances)) != 1:
        return False
    try:
        Schedule(Roadmap.for_fleet(grid, clearances), agents)
    except ScheduleError:
        return False
    return True
