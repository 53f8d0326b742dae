"""Traffic mode "reservations" with the whole fleet: a block of single-lane aisles crossed
both ways, in process (recorded, analysed, drawn in Rerun), over real Zenoh sessions
and AGV processes (the same ticks), and with an AGV killed with -9 inside an aisle."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

from benchmarks.mapf_bench import scenario_for
from bridge import keys
from fleet.runtime.inprocess import run_in_process, run_recorded
from fleet.scenario import ScenarioError, parse_scenario, with_traffic
from recordings.analysis import analyze
from recordings.reader import open_recording
from recordings.rerun_view import save_rrd
from tests.processes import agv_pid
from tests.test_fleet_zenoh import hosted_world, state_key
from tests.test_rerun import read_rrd

# two shelf rows, aisles one cell (1 m) wide between open bays left and right
SHELVES = """
##################
#................#
#..#####.#####...#
#................#
#..#####.#####...#
#................#
##################
"""
LEFT = [(1.5, 1.5), (1.5, 3.5), (1.5, 5.5), (2.5, 2.5)]
RIGHT = [(16.5, 1.5), (16.5, 3.5), (16.5, 5.5), (14.5, 4.5)]
LEFT_GOALS = [(2.5, 1.5), (2.5, 3.5), (2.5, 5.5), (1.5, 4.5)]
RIGHT_GOALS = [(15.5, 5.5), (15.5, 3.5), (15.5, 1.5), (16.5, 2.5)]


def shelves_text(mode: str = "reservations") -> str:
    agvs = [(f"L{i}", s, g) for i, (s, g) in enumerate(zip(LEFT, RIGHT_GOALS, strict=True))]
    agvs += [(f"R{i}", s, g) for i, (s, g) in enumerate(zip(RIGHT, LEFT_GOALS, strict=True))]
    lines = [
        'name = "shelves"',
        "time_limit = 200.0",
        "[traffic]",
        f'mode = "{mode}"',
        "[map]",
        "resolution = 1.0",
        f'grid = """{SHELVES.strip()}"""',
        "[agv_defaults]",
        "radius = 0.3\nmax_speed = 1.0\nmax_accel = 0.5\nmax_omega = 60.0",
    ]
    for name, start, goal in agvs:
        lines += ["[[agvs]]", f'name = "{name}"', f"start = {list(start)}", f"goal = {list(goal)}"]
    return "\n".join(lines) + "\n"


def test_aisles_crossed_both_ways_all_arrive_recorded_and_drawn(tmp_path):
    scenario = parse_scenario(shelves_text())
    mcap, rrd = tmp_path / "shelves.mcap", tmp_path / "shelves.rrd"
    summary = run_recorded(scenario, mcap, {})
    assert summary.success, summary.table()
    recording = open_recording(mcap)
    analysis = analyze(recording)
    assert analysis.collisions == 0 and analysis.arrived == 8
    assert analysis.reservations > 8  # every AGV was released nodes, more than once
    events = [m.data for m in recording.of("world/event")]
    assert sum(e["kind"] == "reserved" for e in events) == analysis.reservations
    waits = [e for e in events if e["kind"] == "waits-for"]
    assert len(waits) == analysis.reservation_waits
    assert all(len(e["agvs"]) == 2 and e["agvs"][0] != e["agvs"][1] for e in waits)
    save_rrd(recording, rrd)
    shown = read_rrd(rrd)
    assert shown["/world/roadmap"].static >= 1
    reserved = [r for r in shown["/world/agv/L0/reserved"].rows if r[1]["LineStrips2D:strips"]]
    assert reserved  # the nodes L0 held, drawn while it drove


def test_reserved_nodes_never_overlap_and_bodies_keep_apart():
    """At every tick no node is reserved to two AGVs (the first node of each path is
    where it is, the rest what it may enter)."""
    overlaps = []

    def sink(key, msg):
        if key == keys.WORLD_TICK:
            held = [tuple(p) for r in msg.reservations for p in r.path]
            if len(held) != len(set(held)):
                overlaps.append(msg.tick)

    summary = run_in_process(parse_scenario(shelves_text()), sink)
    assert summary.success and not overlaps
    assert min(a.min_clearance for a in summary.agvs) > 0.0


DATA = Path(__file__).parent / "data" / "movingai"


def test_one_cell_doors_of_the_mapf_room_map_ten_agents_all_arrive():
    """room-32-32-4 (MovingAI MAPF benchmark), the first 10 agents of random-6."""
    scenario = scenario_for(
        DATA / "room-32-32-4.map", DATA / "room-32-32-4-random-6.scen", 10, 600.0
    )
    summary = run_in_process(with_traffic(scenario, "reservations"))
    assert summary.success, summary.table()


def test_auto_mode_is_the_default_and_bad_modes_are_refused():
    default = parse_scenario(shelves_text().replace('[traffic]\nmode = "reservations"\n', ""))
    assert default.traffic == "auto"
    with pytest.raises(ScenarioError, match="traffic"):
        parse_scenario(shelves_text("queues"))
    with pytest.raises(ScenarioError, match="unknown traffic mode"):
        with_traffic(parse_scenario(shelves_text()), "queues")


def test_two_agvs_starting_on_one_node_is_one_clear_error():
    text = shelves_text().replace("start = [2.5, 2.5]", "start = [1.6, 1.6]")
    with pytest.raises(ScenarioError, match="same roadmap node"):
        run_in_process(parse_scenario(text))


def test_the_same_ticks_over_zenoh_as_in_process(tmp_path):
    path = tmp_path / "shelves.toml"
    path.write_text(shelves_text())
    expected = {}

    def sink(key, msg):
        if key == keys.WORLD_TICK:
            expected[msg.tick] = ([state_key(s) for s in msg.agvs], msg.reservations)

    reference = run_in_process(parse_scenario(path.read_text(), path), outbox=sink)
    with hosted_world(str(path)) as (_, bus, server, _):
        ticks = bus.subscribe(keys.WORLD_TICK)
        summary = server.run()
    seen = {}
    while not ticks.empty():
        msg = ticks.get().msg
        seen[msg.tick] = ([state_key(s) for s in msg.agvs], msg.reservations)
    assert seen == expected
    assert summary.to_json()["agvs"] == reference.to_json()["agvs"]


def test_kill_9_inside_an_aisle_the_others_arrive_or_name_the_dead_agv(tmp_path):
    """The first AGV seen driving inside an aisle (x 4..13) is killed by its process id: the
    plan goes round it, and an AGV it cuts off fails naming it."""
    path = tmp_path / "shelves.toml"
    path.write_text(shelves_text())
    killed = {}

    def progress(world):
        for name, state in world.states.items():
            in_aisle = min(abs(state.y - y) for y in (1.5, 3.5, 5.5)) < 0.3
            inside = 4.0 < state.x < 13.0 and in_aisle
            if not killed and inside and world.records[name].status == "driving":
                os.kill(agv_pid(name), signal.SIGKILL)
                killed[name] = (state.x, state.y)

    with hosted_world(str(path), realtime=8.0, grace=0.0, progress=progress) as (
        _, _, server, _,
    ):  # fmt: skip
        summary = server.run().to_json()
    assert killed, "no AGV was ever inside an aisle"
    (victim,) = killed
    by_name = {a["name"]: a for a in summary["agvs"]}
    assert by_name[victim]["status"] == "failed"
    for name in set(by_name) - {victim}:
        agv = by_name[name]
        assert agv["status"] == "arrived" or victim in agv["failure"], agv
    assert summary["collisions"] == 0


def test_two_agvs_reorder_in_a_dead_end_recorded_with_the_search(tmp_path):
    """The dead end of tests/test_reservations.py driven by vehicles: PIBT alone pushes
    them back and forth for ever; the schedule's LaCAM search gets both in, and the
    recording has the ``searched`` event that ``analyze`` counts."""
    from tests.test_reservations import DEAD_END

    lines = [
        'name = "dead-end"',
        "time_limit = 300.0",
        '[traffic]\nmode = "reservations"',
        "[map]\nresolution = 1.0",
        f'grid = """{DEAD_END.strip()}"""',
        "[agv_defaults]",
        "radius = 0.3\nmax_speed = 1.0\nmax_accel = 0.5\nmax_omega = 60.0",
        '[[agvs]]\nname = "A0"\nstart = [1.5, 3.5]\ngoal = [3.5, 3.5]',
        '[[agvs]]\nname = "A1"\nstart = [4.5, 3.5]\ngoal = [2.5, 3.5]',
    ]
    mcap = tmp_path / "dead-end.mcap"
    summary = run_recorded(parse_scenario("\n".join(lines) + "\n"), mcap, {})
    assert summary.success, summary.table()
    recording = open_recording(mcap)
    analysis = analyze(recording)
    assert analysis.collisions == 0 and analysis.arrived == 2
    searched = [m.data for m in recording.of("world/event") if m.data["kind"] == "searched"]
    assert searched and analysis.reservation_searches == len(searched)
    assert "LaCAM found a way" in searched[0]["detail"]
