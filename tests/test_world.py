"""The world state machine: lockstep ticks, the physics of commands, contacts, arrivals,
failures, the end."""

from __future__ import annotations

import math

import pytest

from bridge.messages import AgvCommand
from fleet.runtime.world import World
from fleet.scenario import parse_scenario

# a vehicle that can go anywhere on this small map in one tick, so that tests place AGVs
# with commands; the limits themselves are tested with the paper's vehicle below
SCENARIO = '''
dt = 0.5
time_limit = 5
[agv_defaults]
max_speed = 100
max_accel = 1000
[map]
grid = """
..........
..........
..........
"""
[[agvs]]
name = "a"
start = [1.5, 1.5]
goal = [8.5, 1.5]
[[agvs]]
name = "b"
start = [4.5, 1.5]
goal = [8.5, 2.5]
[[obstacles]]
type = "temporary"
cells = [[7, 0]]
appear_at = 1.0
'''


def moved(world: World, name: str, x: float, y: float, status: str = "driving"):
    """The command that takes AGV ``name`` to (x, y) in one tick, reporting ``status``."""
    s = world.states[name]
    dx, dy = (x - s.x) / world.dt, (y - s.y) / world.dt
    c, si = math.cos(s.theta), math.sin(s.theta)
    vx, vy = dx * c + dy * si, -dx * si + dy * c
    return AgvCommand(name, world.tick + 1, vx, vy, 0.0, status)


def still(world: World, name: str) -> AgvCommand:
    return moved(world, name, world.states[name].x, world.states[name].y)


def test_ticks_carry_every_agv_and_advance_time():
    world = World(parse_scenario(SCENARIO))
    tick = world.first_tick()
    assert (tick.tick, tick.time) == (0, 0.0)
    assert [s.name for s in tick.agvs] == ["a", "b"]
    tick = world.advance({"a": moved(world, "a", 2.0, 1.5), "b": moved(world, "b", 4.5, 1.5)})
    assert (tick.tick, tick.time) == (1, 0.5)
    assert tick.agvs[0].x == pytest.approx(2.0) and tick.agvs[0].tick == 1
    assert world.records["a"].distance == pytest.approx(0.5)


def test_arrivals_and_failures_end_the_run():
    world = World(parse_scenario(SCENARIO))
    world.first_tick()
    world.advance({"a": moved(world, "a", 8.5, 1.5), "b": still(world, "b")})
    # an arrival is claimed at the pose the AGV was given: at its goal, stopped there
    stop_here = AgvCommand("a", world.tick + 1, 0.0, 0.0, 0.0, "arrived")
    tick = world.advance({"a": stop_here, "b": still(world, "b")})
    assert world.records["a"].arrival_time == 1.0
    assert world.live_agvs() == ["a", "b"]  # an arrived AGV keeps answering, parked
    assert tick is not None
    world.mark_failed("b", "lost liveliness")
    assert world.advance({}) is None
    assert world.end_reason == "every AGV is done: 1 arrived, 1 failed"
    assert world.records["b"].status == "failed" and world.states["b"].vx == 0.0


def test_the_time_limit_ends_the_run():
    world = World(parse_scenario(SCENARIO))
    tick = world.first_tick()
    ticks = 0
    while tick is not None:
        tick = world.advance({n: still(world, n) for n in world.live_agvs()})
        ticks += 1
    assert ticks == 10 and world.time == 5.0 and world.end_reason == "time limit"


# --- the world is the physics ---------------------------------------------------------------
PAPER_VEHICLE = SCENARIO.replace("max_speed = 100\nmax_accel = 1000\n", "")


def test_a_command_beyond_the_vehicle_limits_is_clipped_and_counted():
    world = World(parse_scenario(PAPER_VEHICLE))  # Table 1: 0.2 m/s², 20 °/s, 50 °/s²
    world.first_tick()
    teleport = moved(world, "a", 8.5, 1.5, "driving")  # 14 m/s from standing
    world.advance({"a": teleport, "b": still(world, "b")})
    state = world.states["a"]
    assert state.vx == pytest.approx(0.2 * 0.5)  # one period of the acceleration limit
    assert state.x == pytest.approx(1.5 + 0.1 * 0.5)
    assert world.records["a"].clipped == 1
    spin = AgvCommand("a", world.tick + 1, 0.1, 0.0, math.radians(90))
    world.advance({"a": spin, "b": still(world, "b")})
    assert world.states["a"].omega == pytest.approx(math.radians(20))  # the ω limit
    assert world.records["a"].clipped == 2
    events = [e for e in world.drain_events() if e.kind == "clipped"]
    assert [e.agvs for e in events] == [["a"]]  # an event the first time, then counted


def test_an_arrival_claimed_away_from_the_goal_is_refused():
    world = World(parse_scenario(SCENARIO))
    world.first_tick()
    world.advance({"a": moved(world, "a", 3.0, 1.5, "arrived"), "b": still(world, "b")})
    assert world.records["a"].status == "driving" and world.records["a"].arrival_time is None
    assert world.states["a"].status == "driving" and world.records["a"].refused == 1
    refused = [e for e in world.drain_events() if e.kind == "refused"]
    assert refused and "from the goal" in refused[0].detail


def test_the_paper_turn_at_the_start_is_accepted_only_at_tick_0_and_in_that_profile():
    paper = World(parse_scenario(SCENARIO.replace("dt = 0.5", 'dt = 0.5\nprofile = "paper"')))
    paper.first_tick()
    turn = still(paper, "a")
    turn.start_heading = 1.0
    paper.advance({"a": turn, "b": still(paper, "b")})
    assert paper.states["a"].theta == pytest.approx(1.0)
    late = still(paper, "a")
    late.start_heading = 2.0
    paper.advance({"a": late, "b": still(paper, "b")})
    assert paper.states["a"].theta == pytest.approx(1.0) and paper.records["a"].refused == 1
    default = World(parse_scenario(SCENARIO))
    default.first_tick()
    turn = still(default, "a")
    turn.start_heading = 1.0
    default.advance({"a": turn, "b": still(default, "b")})
    assert default.states["a"].theta == 0.0 and default.records["a"].refused == 1


def test_the_end_reason_says_who_arrived():
    world = World(parse_scenario(SCENARIO))
    world.first_tick()
    world.advance({"a": moved(world, "a", 8.5, 1.5), "b": moved(world, "b", 8.5, 2.5)})
    assert world.advance({n: moved(world, n, *world.scenario.agv(n).goal, "arrived")
                          for n in ("a", "b")}) is None  # fmt: skip
    assert world.end_reason == "every AGV arrived"
