"""The reservation layer on small hand-made maps: the roadmap, one PIBT step, execution
by precedence, and the schedule driving discrete agents with random delays."""

from __future__ import annotations

import random

import numpy as np
import pytest

from planner.maps.clearance import Clearance
from planner.maps.costmap import Costmap
from planner.maps.text_maps import parse_text_grid
from planner.traffic import lacam, pibt
from planner.traffic.loops import LoopWatch
from planner.traffic.precedence import Precedence
from planner.traffic.roadmap import UNREACHABLE, Roadmap
from planner.traffic.schedule import Schedule, ScheduleError

# a corridor one cell wide with a side pocket: two agents swap ends through it
POCKET = """
#######
#.....#
###.###
#######
"""
# a ring round a block
RING = """
#####
#...#
#.#.#
#...#
#####
"""
# a T-junction of single-lane corridors between two open bays
TEE = """
###########
#...###...#
#.........#
#...#.#...#
#####.#####
#####.#####
###########
"""
# two rooms joined by a one-cell door
DOOR = """
#########
#...#...#
#.......#
#...#...#
#########
"""


def roadmap_of(text: str, radius: float = 0.3, resolution: float = 1.0) -> Roadmap:
    grid = parse_text_grid(text.strip("\n"), resolution, "test")
    return Roadmap.for_costmap(Costmap.for_grid(grid, Clearance(radius, 0.0)))


def at(cell) -> tuple[float, float]:
    return (cell[0] + 0.5, cell[1] + 0.5)


def test_roadmap_is_the_free_cells_four_connected():
    roadmap = roadmap_of(POCKET)
    assert len(roadmap) == 6 and roadmap.spacing == 1
    junction = roadmap.node_at(at((3, 2)))
    pocket = roadmap.node_at(at((3, 1)))
    assert sorted(v for v in roadmap.neighbours[junction] if v >= 0) == sorted(
        [roadmap.node_at(at((2, 2))), roadmap.node_at(at((4, 2))), pocket]
    )
    assert [v for v in roadmap.neighbours[pocket] if v >= 0] == [junction]
    assert roadmap.distances(pocket)[roadmap.node_at(at((1, 2)))] == 3
    left = roadmap.node_at(at((1, 2)))
    assert roadmap.distances(left, frozenset({junction}))[pocket] == UNREACHABLE


def test_fine_grid_lattice_keeps_bodies_apart():
    """At 0.1 m cells the lattice spacing holds two 0.3 m bodies and the gap."""
    text = "\n".join(["#" * 22] + ["#" + "." * 20 + "#"] * 20 + ["#" * 22])
    roadmap = roadmap_of(text, radius=0.3, resolution=0.1)
    assert roadmap.spacing * 0.1 >= 0.7 - 1e-9
    centres = roadmap.centres
    gaps = [np.linalg.norm(centres[a] - centres[b]) for a in range(len(roadmap))
            for b in roadmap.neighbours[a] if b >= 0]  # fmt: skip
    assert min(gaps) >= 0.7 - 1e-9


def test_pibt_step_has_no_collision_swap_or_rotation():
    roadmap = roadmap_of(RING)
    cells = [(1, 1), (2, 1), (3, 1), (3, 2), (3, 3), (2, 3), (1, 3)]  # 7 of the 8 ring cells
    current = [roadmap.node_at(at(c)) for c in cells]
    goals = current[1:] + current[:1]  # everyone one cell on: only one can go (the gap)
    tables = [roadmap.distances(g) for g in goals]
    nxt = pibt.step(roadmap.neighbours, current, tables, [float(i) for i in range(7)])
    assert len(set(nxt)) == 7
    for i, j in [(i, j) for i in range(7) for j in range(7) if i != j]:
        assert not (nxt[i] == current[j] and nxt[j] == current[i])  # no swap
    moved = [i for i in range(7) if nxt[i] != current[i]]
    assert moved  # someone moves into the gap, and on from there
    occupied = set(current)
    # every mover goes into the free cell or follows one that left: no closed rotation
    freed = set(current) - set(nxt)
    assert any(nxt[i] not in occupied for i in moved)
    assert freed


def test_full_ring_does_not_rotate():
    """Eight agents on a ring of eight: a rotation would deadlock execution by precedence,
    so nobody moves."""
    roadmap = roadmap_of(RING)
    ring = [(1, 1), (2, 1), (3, 1), (3, 2), (3, 3), (2, 3), (1, 3), (1, 2)]
    current = [roadmap.node_at(at(c)) for c in ring]
    goals = current[1:] + current[:1]
    tables = [roadmap.distances(g) for g in goals]
    assert pibt.step(roadmap.neighbours, current, tables, [1.0] * 8) == current


def test_precedence_releases_in_plan_order():
    plan = Precedence([0, 2])
    plan.append(0, 1)  # agent 0 enters node 1 at step 1
    plan.append(1, 1)  # agent 1 follows it onto node 1 at step 2
    plan.append(0, 3)
    assert plan.release(1, 4) == (0, 0)  # agent 1 waits for agent 0's visit of node 1
    assert plan.release(0, 4) == (2, None)
    plan.reach(0, 1)
    assert plan.release(1, 4) == (0, 0)  # agent 0 is on node 1 still
    plan.reach(0, 2)
    assert plan.release(1, 4) == (1, None)


def run_discrete(text, pairs, seed=0, delay=0.3, steps=400, fail=None):
    """Agents hop node to node along their released nodes, each hop skipped with
    probability ``delay``; every tick checks that no two agents hold one node."""
    roadmap = roadmap_of(text)
    agents = [(f"A{i}", at(s), at(g)) for i, (s, g) in enumerate(pairs)]
    schedule = Schedule(roadmap, agents)
    rng = random.Random(seed)
    where = {name: start for name, start, _ in agents}
    arrived: dict[str, int] = {}
    for tick in range(steps):
        running = {n: p for n, p in where.items() if n not in arrived and n != fail}
        reservations = schedule.update(running)
        for r in reservations:
            assert not r.blocked_by, r
            if len(r.path) > 1 and rng.random() > delay:
                where[r.name] = tuple(r.path[1])
            elif len(r.path) == 1 and r.to_goal:  # parked for good at its goal
                arrived[r.name] = tick
                schedule.arrived(r.name)
        positions = list(where.values())
        assert len(set(positions)) == len(positions), f"two agents on a node at tick {tick}"
        if len(arrived) == len(agents) - (fail is not None):
            return arrived, schedule
    raise AssertionError(f"not everybody arrived in {steps} steps: {sorted(arrived)}")


@pytest.mark.parametrize("seed", range(5))
def test_swap_through_a_corridor_with_a_side_pocket(seed):
    arrived, _ = run_discrete(POCKET, [((1, 2), (5, 2)), ((5, 2), (1, 2))], seed)
    assert len(arrived) == 2


@pytest.mark.parametrize("seed", range(5))
def test_t_junction_crossing_traffic(seed):
    pairs = [((1, 5), (9, 4)), ((9, 5), (5, 1)), ((5, 1), (1, 4)), ((5, 2), (2, 5)),
             ((3, 4), (8, 5))]  # fmt: skip
    arrived, _ = run_discrete(TEE, pairs, seed)
    assert len(arrived) == 5


@pytest.mark.parametrize("seed", range(5))
def test_one_cell_door_both_ways(seed):
    left = [(1, 1), (1, 2), (1, 3), (2, 2)]
    right = [(7, 1), (7, 2), (7, 3), (6, 2)]
    pairs = list(zip(left, right, strict=True)) + list(zip(right, left, strict=True))
    arrived, schedule = run_discrete(DOOR, pairs, seed)
    assert len(arrived) == 8
    events = schedule.drain_events()
    assert any(e.kind == "waits-for" for e in events)


def test_ring_with_delays(seed=3):
    pairs = [((1, 1), (3, 3)), ((3, 3), (1, 1)), ((1, 3), (3, 1)), ((3, 1), (1, 3))]
    arrived, _ = run_discrete(RING, pairs, seed, delay=0.5)
    assert len(arrived) == 4


def test_a_failed_agent_is_gone_round_or_named():
    """A0 dies in the corridor's middle: A1 going round the ring still arrives; in the
    dead-end corridor, A1 is told that A0 cuts it off."""
    roadmap = roadmap_of(RING)
    schedule = Schedule(roadmap, [("A0", at((2, 1)), at((3, 3))), ("A1", at((3, 1)), at((1, 1)))])
    schedule.fail("A0", at((2, 1)))
    for _ in range(10):
        (reservation,) = schedule.update({"A1": at((3, 1))})
    assert not reservation.blocked_by
    assert len(reservation.path) > 1 and reservation.path[1] == list(at((3, 2)))
    corridor = roadmap_of(POCKET)
    schedule = Schedule(corridor, [("A0", at((2, 2)), at((5, 2))), ("A1", at((5, 2)), at((1, 2)))])
    schedule.fail("A0", at((2, 2)))
    (reservation,) = schedule.update({"A1": at((5, 2))})
    assert reservation.blocked_by == ["A0"]


def test_two_agents_on_one_node_is_an_error():
    with pytest.raises(ScheduleError, match="same roadmap node"):
        Schedule(roadmap_of(RING), [("A", at((1, 1)), at((3, 3))), ("B", at((1, 1)), at((2, 1)))])


def test_a_new_goal_joins_at_any_tick():
    """Lifelong: A0 is on its way to the ring's far corner when it is given another goal;
    the next planned steps go there, and A1 keeps out of its way."""
    roadmap = roadmap_of(RING)
    schedule = Schedule(roadmap, [("A0", at((1, 1)), at((3, 3))), ("A1", at((3, 1)), at((1, 3)))])
    where = {"A0": at((1, 1)), "A1": at((3, 1))}
    schedule.update(where)
    schedule.set_goal("A0", at((2, 1)))
    for _ in range(40):
        for r in schedule.update(where):
            if len(r.path) > 1:
                where[r.name] = tuple(r.path[1])
            assert len(set(where.values())) == 2
    assert where["A0"] == at((2, 1)) and where["A1"] == at((1, 3))


def test_a_start_off_its_node_is_an_error():
    """A body standing between nodes reaches into a neighbour's room: refused."""
    with pytest.raises(ScheduleError, match="from the nearest roadmap node"):
        Schedule(roadmap_of(RING), [("A", (1.9, 1.5), at((3, 3)))])


# a dead-end corridor off a junction with a pocket on either side of it
DEAD_END = """
#########
#######.#
#.......#
#######.#
#######.#
#########
"""


def test_lacam_reorders_two_agents_in_a_dead_end_where_pibt_loops():
    """A0 stands at the dead end and must stop short of it, A1 must get behind it: both
    have to leave the corridor and come back in the other order. PIBT pushes them back
    and forth for ever; LaCAM finds the way, every step a valid one."""
    roadmap = roadmap_of(DEAD_END)
    start = [roadmap.node_at(at((1, 3))), roadmap.node_at(at((4, 3)))]
    goals = [roadmap.node_at(at((3, 3))), roadmap.node_at(at((2, 3)))]
    tables = [roadmap.distances(g) for g in goals]
    config, priorities = list(start), [0.5, 0.25]
    for _ in range(200):
        config_next = pibt.step(roadmap.neighbours, config, tables, priorities)
        priorities = pibt.next_priorities(priorities, config_next, goals, [0, 1])
        config = config_next
        assert config != goals, "PIBT alone solved it: the case no longer shows its loop"
    configs = lacam.solve(roadmap.neighbours, start, goals, tables)
    assert configs is not None and configs[-1] == goals
    for before, after in zip([start, *configs], configs, strict=False):
        assert len(set(after)) == 2  # no two agents on a node
        assert not (after[0] == before[1] and after[1] == before[0])  # no swap
        for a in range(2):
            assert after[a] == before[a] or after[a] in roadmap.neighbours[before[a]]


def test_lacam_says_when_there_is_no_way():
    """Two agents swapping ends of a corridor with no room to pass: None, not a loop."""
    roadmap = roadmap_of("#####\n#...#\n#####")
    start = [roadmap.node_at(at((1, 1))), roadmap.node_at(at((3, 1)))]
    tables = [roadmap.distances(g) for g in start[::-1]]
    assert lacam.solve(roadmap.neighbours, start, start[::-1], tables) is None


@pytest.mark.parametrize("seed", range(5))
def test_schedule_gets_out_of_a_dead_end_loop_with_delays(seed):
    """The schedule sees the configuration come back, searches with LaCAM, and both
    agents arrive, whatever the delays."""
    pairs = [((1, 3), (3, 3)), ((4, 3), (2, 3))]
    arrived, schedule = run_discrete(DEAD_END, pairs, seed)
    assert len(arrived) == 2 and schedule.searches >= 1


def test_loop_watch_names_whom_to_search_for():
    """A configuration seen before in the same context: everybody; an agent pushed off its
    goal twice: the agents pushed off theirs; a group searched in vain: not again until
    the goals or the fixed bodies change."""
    watch = LoopWatch()
    moving, goals, fixed = [0, 1, 2], [5, 6, 7], frozenset({9})
    assert watch.suspects(moving, goals, fixed, [1, 2, 3]) is None
    assert watch.suspects(moving, goals, fixed, [1, 2, 4]) is None
    assert watch.suspects(moving, goals, fixed, [1, 2, 3]) == [0, 1, 2]
    watch.failed(moving)
    assert watch.suspects(moving, goals, fixed, [1, 2, 3]) is None
    assert watch.suspects(moving, goals, frozenset(), [1, 2, 3]) is None  # a new context
    watch.moved(1, 6, 8, 6)
    watch.moved(2, 7, 3, 7)
    assert watch.suspects(moving, goals, frozenset(), [1, 8, 3]) is None  # once each
    watch.moved(1, 6, 8, 6)
    assert watch.suspects(moving, goals, frozenset(), [1, 8, 4]) == [1, 2]
    watch.solved([1, 2])
    assert watch.suspects(moving, goals, frozenset(), [1, 8, 5]) is None
