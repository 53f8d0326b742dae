"""Issue #39's jam: an AGV shut in a dead end (a dock) by one that waits at its mouth to
go in.

PIBT reaches every goal only on roadmaps where every edge lies on a cycle (Okumura et
al., AIJ 2022); a dock in a wall is a dead end, a node with one neighbour. PIBT may plan
an AGV into it to make room (agv2 into dock-2 in the 4-AGV shift of seed 1, which then
delivered 54 tasks an hour instead of about 150). When the AGV whose goal the dock is
arrives at the mouth with the higher priority, each step it tries the dock first: the
AGV inside can leave only onto the mouth, a swap, so it stays, and the one at the mouth
stays too. Priorities grow by one a step for both, so their order never changes.

The schedule's loop watch (``planner.traffic.loops``) sees them stand still, and LaCAM
plans the two a way out; with the rest of the fleet still moving (the whole
configuration never repeating) as well as alone.
"""

from __future__ import annotations

import pytest

from planner.maps.clearance import Clearance
from planner.maps.costmap import Costmap
from planner.maps.text_maps import parse_text_grid
from planner.traffic.roadmap import Roadmap
from planner.traffic.schedule import Schedule

# a corridor one cell wide with a dock below its middle, (3, 1): a dead end; and, apart
# from it, a long corridor for a third agent that keeps moving meanwhile
POCKET = """
#######
#.....#
###.###
#######
"""
LONG = "\n".join(["#" * 62, "#......#" + "#" * 54, "###.###" + "." * 54 + "#", "#" * 62])


def at(cell) -> tuple[float, float]:
    return (cell[0] + 0.5, cell[1] + 0.5)


def shut_in(text, goal_of_the_one_inside, others=()):
    """A0 in the pocket (3, 1) going elsewhere; A1 at its mouth (3, 2) going into it, first
    by priority (it has waited longer, as agv1 had); ``others``: more (start, goal)."""
    grid = parse_text_grid(text.strip("\n"), 1.0, "pocket")
    roadmap = Roadmap.for_costmap(Costmap.for_grid(grid, Clearance(0.3, 0.0)))
    agents = [("A0", at((3, 1)), at(goal_of_the_one_inside)), ("A1", at((3, 2)), at((3, 1)))]
    agents += [(f"B{i}", at(s), at(g)) for i, (s, g) in enumerate(others)]
    schedule = Schedule(roadmap, agents)
    schedule.priorities = [0.2, 7.4] + [0.1] * len(others)
    return schedule, {name: start for name, start, _ in agents}


def drive(schedule, where, steps):
    """Agents hop along their released nodes; the tick each one arrived."""
    arrived = {}
    for tick in range(steps):
        running = {n: p for n, p in where.items() if n not in arrived}
        for r in schedule.update(running):
            if len(r.path) > 1:
                where[r.name] = tuple(r.path[1])
            elif r.to_goal:
                arrived[r.name] = tick
                schedule.arrived(r.name)
        assert len(set(where.values())) == len(where)
        if len(arrived) == len(where):
            break
    return arrived


@pytest.mark.parametrize("goal", [(1, 2), (5, 2)])
def test_an_agent_shut_in_a_dead_end_comes_out(goal):
    schedule, where = shut_in(POCKET, goal)
    arrived = drive(schedule, where, 40)
    assert set(arrived) == {"A0", "A1"}, f"shut in: {where}"
    assert schedule.searches >= 1


def test_it_comes_out_while_the_rest_of_the_fleet_moves_on():
    """B0 has 53 cells to go meanwhile, so the configuration of the moving agents changes
    every plan step until it is planned onto its goal: the two are searched for when they
    have stood still for the loop watch's STALL steps, before that."""
    schedule, where = shut_in(LONG, (5, 2), [((7, 1), (60, 1))])
    schedule.update(where)
    for _ in range(20):
        if schedule.searches:
            break
        schedule.update(where)  # nobody drives: only the plan goes on
    assert schedule.searches == 1
    assert 2 not in schedule.frozen, "searched for only once B0 was planned onto its goal"
    arrived = drive(schedule, where, 200)
    assert set(arrived) == {"A0", "A1", "B0"}, f"shut in: {where}"
