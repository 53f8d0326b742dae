"""Issue #39's jam: an AGV shut in a dead end (a dock) by one that waits at its mouth to
go in. Both wait for ever.

PIBT reaches every goal only on roadmaps where every edge lies on a cycle (Okumura et
al., AIJ 2022); a dock in a wall is a dead end, a node with one neighbour. PIBT may plan
an AGV into it to make room (agv2 into dock-2 in the 4-AGV shift of seed 1, which then
delivered 54 tasks an hour instead of about 150). When the AGV whose goal the dock is
arrives at the mouth with the higher priority, each step it tries the dock first: the
AGV inside can leave only onto the mouth, a swap, so it stays, and the one at the mouth
stays too. Priorities grow by one a step for both, so their order never changes: no
step is ever planned again for either, and the AGVs behind them, or waiting for a
station one of them holds, wait for ever too.

The fix belongs in ``planner.traffic.pibt`` (being changed in parallel, so not made
here): an agent whose wanted node is held by one that cannot move because its only way
out is the wanter's own node steps aside, and the one shut in comes out behind it.
"""

from __future__ import annotations

import pytest

from planner.maps.clearance import Clearance
from planner.maps.costmap import Costmap
from planner.maps.text_maps import parse_text_grid
from planner.traffic.roadmap import Roadmap
from planner.traffic.schedule import Schedule

# a corridor one cell wide with a dock below its middle, (3, 1): a dead end
POCKET = """
#######
#.....#
###.###
#######
"""

DEAD_END = pytest.mark.xfail(
    strict=True,
    reason="PIBT shuts an agent in a dead end (issue #39): the fix is due in "
    "planner/traffic/pibt.py; drop this mark with it",
)


def at(cell) -> tuple[float, float]:
    return (cell[0] + 0.5, cell[1] + 0.5)


def shut_in(goal_of_the_one_inside):
    """A0 in the pocket (3, 1) going elsewhere; A1 at its mouth (3, 2) going into it, first
    by priority (it has waited longer, as agv1 had)."""
    grid = parse_text_grid(POCKET.strip("\n"), 1.0, "pocket")
    roadmap = Roadmap.for_costmap(Costmap.for_grid(grid, Clearance(0.3, 0.0)))
    agents = [("A0", at((3, 1)), at(goal_of_the_one_inside)), ("A1", at((3, 2)), at((3, 1)))]
    schedule = Schedule(roadmap, agents)
    schedule.priorities = [0.2, 7.4]
    return schedule, {name: start for name, start, _ in agents}


@DEAD_END
@pytest.mark.parametrize("goal", [(1, 2), (5, 2)])
def test_an_agent_shut_in_a_dead_end_comes_out(goal):
    schedule, where = shut_in(goal)
    arrived = set()
    for _ in range(40):
        running = {n: p for n, p in where.items() if n not in arrived}
        for r in schedule.update(running):
            if len(r.path) > 1:
                where[r.name] = tuple(r.path[1])
            elif r.to_goal:
                arrived.add(r.name)
                schedule.arrived(r.name)
        assert len(set(where.values())) == 2
        if len(arrived) == 2:
            return
    raise AssertionError(f"shut in: {where} (arrived: {sorted(arrived)})")
