"""The traffic rule over real Zenoh sessions and real AGV processes: the same decisions
as in process, and a dead AGV that holds a passage does not stop the others."""

from __future__ import annotations

import os
import signal

from bridge import keys
from fleet.runtime.inprocess import run_in_process
from fleet.scenario import load_scenario
from planner.traffic.zones import DECISIONS, GO
from tests.processes import agv_pid
from tests.test_fleet_zenoh import hosted_world, state_key


def _event_key(event):
    return (event.tick, event.kind, tuple(event.agvs), event.detail)


def test_traffic_decisions_are_the_same_over_zenoh_as_in_process():
    """Every tick's states and intents, and every event, to the last bit."""
    expected, expected_events = {}, []

    def sink(key, msg):
        if key == keys.WORLD_TICK:
            expected[msg.tick] = ([state_key(s) for s in msg.agvs], msg.intents)
        elif key == keys.WORLD_EVENT:
            expected_events.append(_event_key(msg))

    reference = run_in_process(load_scenario("single-lane"), outbox=sink)
    with hosted_world("single-lane") as (_, bus, server, _):
        ticks = bus.subscribe(keys.WORLD_TICK)
        events = bus.subscribe(keys.WORLD_EVENT)
        summary = server.run()
    seen = {}
    while not ticks.empty():
        msg = ticks.get().msg
        seen[msg.tick] = ([state_key(s) for s in msg.agvs], msg.intents)
    seen_events = []
    while not events.empty():
        seen_events.append(_event_key(events.get().msg))
    assert any(kind in DECISIONS for _, kind, _, _ in expected_events)
    assert seen == expected
    assert seen_events == expected_events
    assert summary.to_json()["agvs"] == reference.to_json()["agvs"]


def test_kill_9_of_the_agv_holding_the_corridor_the_others_route_round_and_arrive():
    """The first AGV seen inside the corridor (x 9..15 m) with its claim granted is
    killed by its process name; the others route round it and arrive."""
    killed = {}

    def progress(world):
        for name, state in world.states.items():
            intent = world.intents.get(name)
            inside = 9.0 < state.x < 15.0 and 4.0 < state.y < 5.6
            if not killed and intent is not None and intent.phase == GO and inside:
                os.kill(agv_pid(name), signal.SIGKILL)
                killed[name] = (state.x, state.y)

    with hosted_world("single-lane", realtime=8.0, grace=0.0, progress=progress) as (
        _, _, server, _,
    ):  # fmt: skip
        summary = server.run().to_json()
    assert killed, "no AGV ever held the corridor"
    (victim,) = killed
    by_name = {a["name"]: a for a in summary["agvs"]}
    assert by_name[victim]["status"] == "failed"
    for name in set(by_name) - {victim}:
        assert by_name[name]["status"] == "arrived", summary
    assert summary["collisions"] == 0
