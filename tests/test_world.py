"""The world state machine: lockstep ticks, contacts, arrivals, failures, the end."""

from __future__ import annotations

from dataclasses import replace

import pytest

from fleet.runtime.world import World
from fleet.scenario import parse_scenario

SCENARIO = '''
dt = 0.5
time_limit = 5
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
    return replace(world.states[name], x=x, y=y, status=status)


def test_ticks_carry_every_agv_and_advance_time():
    world = World(parse_scenario(SCENARIO))
    tick = world.first_tick()
    assert (tick.tick, tick.time) == (0, 0.0)
    assert [s.name for s in tick.agvs] == ["a", "b"]
    tick = world.advance({"a": moved(world, "a", 2.0, 1.5), "b": moved(world, "b", 4.5, 1.5)})
    assert (tick.tick, tick.time) == (1, 0.5)
    assert tick.agvs[0].x == 2.0 and tick.agvs[0].tick == 1
    assert world.records["a"].distance == pytest.approx(0.5)


def test_temporary_obstacles_appear_on_time():
    world = World(parse_scenario(SCENARIO))
    assert world.first_tick().temporary == []
    stay = {n: world.states[n] for n in ("a", "b")}
    world.advance(stay)
    assert world.advance(stay).temporary == [[7, 0]]  # t = 1.0


def test_a_contact_counts_once_per_onset():
    world = World(parse_scenario(SCENARIO))
    world.first_tick()
    world.advance({"a": moved(world, "a", 4.0, 1.5), "b": world.states["b"]})  # 0.5 apart: touching
    assert world.collisions == 1
    assert world.records["a"].collisions == world.records["b"].collisions == 1
    assert world.records["a"].min_clearance == pytest.approx(0.5 - 0.6)
    world.advance({"a": moved(world, "a", 4.1, 1.5), "b": world.states["b"]})  # still touching
    assert world.collisions == 1
    world.advance({"a": moved(world, "a", 2.0, 1.5), "b": world.states["b"]})  # apart
    world.advance({"a": moved(world, "a", 4.0, 1.5), "b": world.states["b"]})  # again
    assert world.collisions == 2


def test_walls_and_the_map_border_collide():
    world = World(parse_scenario(SCENARIO))
    world.first_tick()
    world.advance({"a": moved(world, "a", 1.5, 0.2), "b": world.states["b"]})
    assert world.records["a"].collisions == 1
    assert world.events[-1].kind == "collision" and "wall" in world.events[-1].detail


def test_arrivals_and_failures_end_the_run():
    world = World(parse_scenario(SCENARIO))
    world.first_tick()
    tick = world.advance({"a": moved(world, "a", 8.5, 1.5, "arrived"), "b": world.states["b"]})
    assert world.records["a"].arrival_time == 0.5
    assert world.live_agvs() == ["a", "b"]  # an arrived AGV keeps answering, parked
    assert tick is not None
    world.mark_failed("b", "lost liveliness")
    assert world.advance({}) is None
    assert world.end_reason == "every AGV is done"
    assert world.records["b"].status == "failed" and world.states["b"].vx == 0.0


def test_the_time_limit_ends_the_run():
    world = World(parse_scenario(SCENARIO))
    tick = world.first_tick()
    ticks = 0
    while tick is not None:
        tick = world.advance({n: world.states[n] for n in world.live_agvs()})
        ticks += 1
    assert ticks == 10 and world.time == 5.0 and world.end_reason == "time limit"
