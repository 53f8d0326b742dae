"""The traffic layer: passages found from the costmap, the first-come rule, and fleets
that take turns in passages one AGV wide (in process; over Zenoh in test_traffic_zenoh)."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from bridge import keys
from bridge.messages import AgvCommand
from fleet.runtime.agv_node import AgvNode
from fleet.runtime.inprocess import run_in_process, run_recorded
from fleet.runtime.world import World
from fleet.scenario import load_scenario, parse_scenario
from planner.core.path_metrics import distance_to_path
from planner.local.config import DwaConfig
from planner.maps.clearance import Clearance
from planner.maps.costmap import Costmap
from planner.maps.text_maps import parse_text_grid
from planner.traffic.guard import QUEUE_GAP, TrafficGuard
from planner.traffic.passages import NONE, Passages
from planner.traffic.zones import (  # fmt: skip
    BACK,
    CLEAR,
    GO,
    REQUEST,
    WAIT,
    YIELD,
    Intent,
    first_rival,
    may_enter,
    waiting_for,
)
from recordings.analysis import analyze
from recordings.reader import open_recording
from recordings.rerun_view import save_rrd
from tests.test_rerun import read_rrd

ROOM = "#" + "." * 12 + "#" * 14 + "." * 12 + "#"
CORRIDOR = "#" + "." * 38 + "#"


def two_rooms(corridor_cells: int) -> str:
    """Two 6 x 2.5 m rooms joined by a 7 m corridor ``corridor_cells`` half-metre cells
    wide, as text rows top to bottom."""
    rows = ["#" * 40, *[ROOM] * 5, *[CORRIDOR] * corridor_cells, *[ROOM] * 5, "#" * 40]
    return "\n".join(rows)


WIDE = Clearance(0.4)  # an AGV 0.8 m wide: two cannot pass in 1.5 m, they can in 2 m


def passages_of(text: str, resolution: float = 0.5, clearance: Clearance = WIDE) -> Passages:
    grid = parse_text_grid(text, resolution=resolution)
    return Passages.build(Costmap.build(grid, clearance))


# --- passages -------------------------------------------------------------------------
def test_a_corridor_one_agv_wide_is_one_passage_with_a_mouth_at_each_end():
    passages = passages_of(two_rooms(3))  # 1.5 m: two 0.8 m AGVs cannot pass
    assert passages.count == 1
    middle = 3.75  # y of the corridor's midline
    assert passages.at((10.0, middle)) == 0
    assert passages.at((3.0, middle)) == NONE and passages.at((17.0, middle)) == NONE
    mouths = set(passages.mouth[passages.mouth != NONE].tolist())
    assert len(mouths) == 2
    east = passages.first_crossing([(2.0, middle), (18.0, middle)], lookahead=30.0)
    west = passages.first_crossing([(18.0, middle), (2.0, middle)], lookahead=30.0)
    assert east.passage == west.passage == 0
    assert east.exit != west.exit and {east.exit, west.exit} == mouths
    assert 4.0 < east.enter_at < 6.0 and 10.0 < east.leave_at < 12.0  # inside 6.5..13.5 m
    assert passages.first_crossing([(2.0, middle), (18.0, middle)], lookahead=3.0) is None


def test_wide_corridors_and_open_maps_have_no_passages():
    assert passages_of(two_rooms(4)).count == 0  # 2 m: two AGVs pass
    assert passages_of(two_rooms(3), clearance=Clearance()).count == 0  # 1.5 m, 0.6 m AGVs
    room = ["#" * 18, *["#" + "." * 16 + "#"] * 16, "#" * 18]  # 4 x 4 m at 0.25 m
    assert passages_of("\n".join(room), resolution=0.25).count == 0  # corners are nooks
    for name in ("corridor", "crossing", "warehouse"):  # 2 and 3 m lanes at 1 m cells
        grid = load_scenario(name).grid
        assert Passages.build(Costmap.build(grid, Clearance())).count == 0, name


def test_a_dock_is_a_passage_with_one_mouth_and_a_route_ending_inside_has_no_exit():
    dock = "#" * 9 + "..." + "#" * 8  # 1.5 m wide, 3 m deep, below a 9 x 4 m room
    rows = ["#" * 20, *["#" + "." * 18 + "#"] * 8, *[dock] * 6, "#" * 20]
    passages = passages_of("\n".join(rows))
    assert passages.count == 1
    assert len(set(passages.mouth[passages.mouth != NONE].tolist())) == 1
    into = passages.first_crossing([(5.0, 6.0), (5.25, 3.5), (5.25, 0.8)], lookahead=30.0)
    assert into is not None and into.exit is None


# --- the rule -------------------------------------------------------------------------
def claim(name, phase, exit, since, passage=0):
    return Intent(name, 10, phase, passage, exit, since)


def test_first_come_first_served_and_ties_go_by_name():
    intents = [claim("b", WAIT, 1, 5), claim("a", WAIT, 2, 5), claim("c", WAIT, 1, 3)]
    assert may_enter("c", intents) == (True, [])  # asked first
    assert may_enter("a", intents) == (False, ["c"])  # the other way: waits for c
    assert may_enter("b", intents) == (False, ["a"])  # c's way, but a asked before it
    convoy = [claim("b", WAIT, 1, 5), claim("a", WAIT, 2, 6), claim("c", WAIT, 1, 3)]
    assert may_enter("b", convoy) == (True, [])  # right behind c, the same way
    tie = [claim("b", WAIT, 1, 5), claim("a", WAIT, 2, 5)]
    assert may_enter("a", tie) == (True, []) and may_enter("b", tie) == (False, ["a"])


def test_holders_let_in_only_their_own_direction_and_nobody_overtakes_a_waiting_agv():
    inside = claim("h", GO, 1, 0)
    assert may_enter("x", [inside, claim("x", WAIT, 2, 1)]) == (False, ["h"])
    assert may_enter("y", [inside, claim("y", WAIT, 1, 1)]) == (True, [])
    # an opposite AGV asked before y: y waits behind it even though it goes h's way
    queue = [inside, claim("x", WAIT, 2, 1), claim("y", REQUEST, 1, 2)]
    assert may_enter("y", queue) == (False, ["x"])
    assert waiting_for(queue) == {"x": ["h"]}


def test_an_agv_stopping_inside_goes_alone_and_yielding_agvs_still_queue():
    docked = claim("d", GO, None, 0)
    assert may_enter("x", [docked, claim("x", WAIT, None, 1)]) == (False, ["d"])
    backed_off = [claim("x", YIELD, 2, 1), claim("y", WAIT, 1, 2)]
    assert may_enter("x", backed_off) == (True, [])  # a yielding AGV is not a holder
    assert may_enter("y", backed_off) == (False, ["x"])


MID = 3.75  # y of the two rooms' corridor midline
EASTWARD = [(2.0, MID), (18.0, MID)]


def _waiting_east_of_a_holder(others=()):
    """A guard for AGV x at (4.5, MID) driving east through the corridor while h, going
    west, holds it: x asked, then waits (``others``: more intents of the fleet). Returns
    the guard, x's last decision and the holder's passage and exit."""
    costmap = Costmap.build(parse_text_grid(two_rooms(3), resolution=0.5), WIDE)
    guard = TrafficGuard(costmap, DwaConfig(max_speed=1.0, max_accel=0.5))
    west = guard.passages.first_crossing([(18.0, MID), (2.0, MID)], lookahead=30.0)
    holder = Intent("h", 1, GO, west.passage, west.exit, 0, route=[[10.0, MID], [2.0, MID]])
    asked = guard.decide("x", 1, (4.5, MID), EASTWARD, [holder, *others], stalled=False)
    fleet = [holder, asked.intent, *others]
    waits = guard.decide("x", 2, (4.5, MID), EASTWARD, fleet, stalled=False)
    assert waits.intent.phase == WAIT and waits.hold is not None
    return guard, waits, holder


def test_a_guard_that_keeps_its_route_samples_decides_as_a_fresh_guard_after_a_replan():
    """The guard samples its route once per route (``Passages.route_cells``): after the
    route changes, it must decide on the new route, not on the samples of the old."""
    costmap = Costmap.build(parse_text_grid(two_rooms(3), resolution=0.5), WIDE)
    config = DwaConfig(max_speed=1.0, max_accel=0.5)
    kept = TrafficGuard(costmap, config)
    east = kept.decide("x", 1, (4.5, MID), EASTWARD, [], stalled=False)
    assert east.intent.passage is not None
    westward = [(15.5, MID), (2.0, MID)]  # replanned: back west, from the other room
    after = kept.decide("x", 2, (15.5, MID), westward, [east.intent], stalled=False)
    fresh = TrafficGuard(costmap, config).decide(
        "x", 2, (15.5, MID), westward, [east.intent], stalled=False
    )
    assert after.intent.exit == fresh.intent.exit != east.intent.exit
    assert after.intent.route == fresh.intent.route == [[15.5, MID], [2.0, MID]]


def test_no_waiting_place_within_a_safety_distance_of_a_parked_agv():
    """An AGV that arrived at its goal beside a 1 m door stood where the rule then sent the
    next one to wait, and that one circled the parked body for 10 s (traffic_bench door
    n6 s0)."""
    guard, waits, holder = _waiting_east_of_a_holder()
    guard.park([(*waits.hold, WIDE.radius)])  # another AGV arrived right there
    moved = guard.decide("x", 3, (4.5, MID), EASTWARD, [holder, waits.intent], stalled=False)
    assert moved.intent.phase == WAIT and moved.hold is not None
    safety = guard.costmap.clearance.safety_distance
    assert math.dist(moved.hold, waits.hold) - WIDE.radius >= safety


def test_no_waiting_place_within_a_safety_distance_of_another_waiting_agv():
    """Waiting places were chosen along each AGV's own route, and at a crowded 1.0 m door
    one fell where another AGV already waited, and the newcomer circled it (door n12 s3:
    R5 for 10 s)."""
    _, alone, _ = _waiting_east_of_a_holder()
    standing = Intent("w", 1, WAIT, 7, 0, 0, route=[list(alone.hold)])  # waits for another
    _, waits, _ = _waiting_east_of_a_holder(others=[standing])
    safety = WIDE.safety_distance
    assert math.dist(waits.hold, alone.hold) - WIDE.radius >= safety


def test_of_two_agvs_sent_to_one_waiting_place_the_later_chooses_again():
    """Two AGVs that ask in the same tick choose their places without seeing each other's
    and can choose the same one (door n12 s3: R5 circled R4 standing on its place for
    10 s). The intents share the places; the AGV that asked later moves, the earlier
    one keeps its place."""
    kept = {}
    for other, since in (("w", 0), ("y", 1)):  # before x (since 0), after x (since 1, "y")
        guard, waits, holder = _waiting_east_of_a_holder()
        assert waits.intent.hold == [round(v, 2) for v in waits.hold]
        there = Intent(
            other, 2, WAIT, waits.intent.passage, waits.intent.exit, since,
            route=[[1.0, 1.0]], hold=list(waits.hold),  # still on its way there
        )  # fmt: skip
        fleet = [holder, waits.intent, there]
        kept[other] = guard.decide("x", 3, (4.5, MID), EASTWARD, fleet, stalled=False).hold
        assert kept[other] is not None
    safety = WIDE.safety_distance
    assert math.dist(kept["w"], waits.hold) - WIDE.radius >= safety
    assert kept["y"] == waits.hold


def test_a_waiting_place_is_one_the_agv_drives_to_past_no_waiting_agv():
    """Sent to a place across an AGV waiting between, an AGV drove round it, a loop in a
    crowded room (door n12 s3: R1 round R2). Of the places with room, one with a clear
    straight way comes first."""
    costmap = Costmap.build(parse_text_grid(two_rooms(3), resolution=0.5), WIDE)
    guard = TrafficGuard(costmap, DwaConfig(max_speed=1.0, max_accel=0.5))
    west = guard.passages.first_crossing([(18.0, MID), (2.0, MID)], lookahead=30.0)
    holder = Intent("h", 1, GO, west.passage, west.exit, 0, route=[[10.0, MID], [2.0, MID]])
    between = (4.25, MID)  # held for another passage, on x's route
    other = Intent("w", 1, WAIT, west.passage + 1, 0, 0, route=[list(between)], hold=[*between])
    asked = guard.decide("x", 1, (2.0, MID), EASTWARD, [holder, other], stalled=False)
    fleet = [holder, other, asked.intent]
    waits = guard.decide("x", 2, (2.0, MID), EASTWARD, fleet, stalled=False)
    assert waits.intent.phase == WAIT
    passing = distance_to_path([(2.0, MID), waits.hold], between)
    assert passing >= 2 * WIDE.radius + WIDE.safety_distance / 2


def test_only_an_agv_in_a_stuck_holders_way_yields_further_back():
    """Every waiting AGV yielding for any stuck holder churned the crowd at a 1.0 m door
    (traffic_bench door n12 s3: waiting AGVs looped through the rooms, up to 3.7 times
    their routes); only those within two safety distances of its way ahead yield."""
    phases = {}
    for label, holder_way in (
        ("away", [[7.0, MID], [3.0, 6.5]]),
        ("through", [[7.0, MID], [2.0, MID]]),
    ):
        guard, waits, holder = _waiting_east_of_a_holder()
        stuck = replace(holder, tick=2, stalled=True, route=holder_way)
        phases[label] = guard.decide("x", 3, (4.5, MID), EASTWARD, [stuck, waits.intent], False)
    assert phases["away"].intent.phase == WAIT  # its way leaves the corridor northwards
    assert phases["through"].intent.phase == YIELD
    assert math.dist(phases["through"].hold, (4.5, MID)) > 0.5  # moved further back


def test_a_waiting_agv_keeps_its_claim_beyond_the_request_distance():
    """A waiting place down a queue, or a replan from it, can put the passage beyond the
    request distance; dropping the claim there sent the AGV on towards the passage to ask
    again, last (traffic_bench door n12 s3: waiting AGVs looped through the rooms). A
    waiting AGV keeps its claim, with the tick it first asked, out to twice that distance;
    an AGV that has not asked does not claim so far ahead."""
    guard, waits, holder = _waiting_east_of_a_holder()
    detour = [(4.5, MID), (2.5, 1.5), (2.5, MID), (18.0, MID)]
    far = guard.passages.first_crossing(detour, lookahead=30.0).enter_at
    assert guard.request_distance < far < 2 * guard.request_distance
    guard.replanned()
    kept = guard.decide("x", 3, (4.5, MID), detour, [holder, waits.intent], stalled=False)
    assert kept.intent.phase == WAIT and kept.intent.since == waits.intent.since
    let_in = guard.decide("x", 4, (4.5, MID), detour, [kept.intent], stalled=False)
    assert let_in.intent.phase == GO and let_in.rejoin  # the holder left: x goes ...
    guard.replanned()
    going = guard.decide("x", 5, (4.5, MID), detour, [let_in.intent], stalled=False)
    assert going.intent.phase == GO  # ... and still holds after its replan from afar
    fresh = TrafficGuard(guard.costmap, DwaConfig(max_speed=1.0, max_accel=0.5))
    assert fresh.decide("z", 3, (4.5, MID), detour, [holder], stalled=False).intent.phase == CLEAR


def test_the_waiting_place_moves_up_as_the_queue_does():
    """A waiting place ``QUEUE_GAP`` further back for each AGV queued before it stayed
    there when those went in, and the next AGV to queue was sent to the same place."""
    room = "#" + "." * 24 + "#" * 10 + "." * 24 + "#"  # rooms 12 m wide, the corridor 5 m
    corridor = "#" + "." * 58 + "#"
    text = "\n".join(["#" * 60, *[room] * 5, *[corridor] * 3, *[room] * 5, "#" * 60])
    guard = TrafficGuard(
        Costmap.build(parse_text_grid(text, resolution=0.5), WIDE),
        DwaConfig(max_speed=1.0, max_accel=0.5),
    )
    east_route = [(1.0, MID), (29.0, MID)]
    west = guard.passages.first_crossing([(29.0, MID), (1.0, MID)], lookahead=40.0)
    east = guard.passages.first_crossing(east_route, lookahead=40.0)
    holder = Intent("h", 1, GO, west.passage, west.exit, 0, route=[[20, MID], [12, MID], [5, 6.5]])
    first = Intent(
        "a", 1, WAIT, east.passage, east.exit, 0, route=[[12, MID], [29, MID]], entry=east.entry
    )
    asked = guard.decide("x", 1, (8.0, MID), east_route, [holder, first], stalled=False)
    behind = guard.decide("x", 2, (8.0, MID), east_route, [holder, first, asked.intent], False)
    went_in = replace(first, tick=2, phase=GO)
    moved = guard.decide("x", 3, (8.0, MID), east_route, [holder, went_in, behind.intent], False)
    assert behind.intent.phase == moved.intent.phase == WAIT
    safety = guard.costmap.clearance.safety_distance
    assert moved.hold[0] - behind.hold[0] == pytest.approx(QUEUE_GAP * safety)  # moved up


# --- fleets ---------------------------------------------------------------------------
def corridor_swap(cells: int, agvs: list[tuple[str, tuple, tuple]]) -> str:
    rows = two_rooms(cells)
    text = [
        'name = "swap"', "dt = 0.1", "time_limit = 200", "[map]", "resolution = 0.5",
        f'grid = """\n{rows}\n"""', "[agv_defaults]", "radius = 0.4", "max_speed = 1.0",
        "max_accel = 0.5", "max_omega = 60", "max_alpha = 120",
    ]  # fmt: skip
    for name, start, goal in agvs:
        heading = 180 if goal[0] < start[0] else 0
        text += [
            "[[agvs]]", f'name = "{name}"', f"start = [{start[0]}, {start[1]}]",
            f"goal = [{goal[0]}, {goal[1]}]", f"heading = {heading}",
        ]  # fmt: skip
    return "\n".join(text)


def run_with_events(scenario):
    events = []

    def sink(key, msg):
        if key == keys.WORLD_EVENT:
            events.append(msg)

    return run_in_process(scenario, outbox=sink), events


def test_mirror_symmetric_agvs_take_turns_in_a_corridor_one_agv_wide():
    """The paper's method deadlocks here (both drive in and meet head-on); the rule lets
    the AGV first in the queue (by name, as both asked at once) through first."""
    mid = 3.75
    text = corridor_swap(3, [("a", (2.0, mid), (18.0, mid)), ("b", (18.0, mid), (2.0, mid))])
    summary, events = run_with_events(parse_scenario(text))
    assert summary.success, summary.table()
    assert summary.end_reason == "every AGV arrived"
    by_name = {a.name: a for a in summary.agvs}
    assert by_name["a"].arrival_time < by_name["b"].arrival_time
    assert by_name["a"].waiting_time == 0.0 and by_name["b"].waiting_time > 5.0
    waits = [e for e in events if e.kind == WAIT]
    goes = [e for e in events if e.kind == GO]
    assert [e.agvs for e in waits] == [["b", "a"]] and [e.agvs for e in goes] == [["b"]]
    assert summary.agvs[0].min_clearance > 0 and summary.agvs[1].min_clearance > 0


def test_the_paper_profile_has_no_traffic_rule():
    mid = 3.75
    text = corridor_swap(3, [("a", (2.0, mid), (18.0, mid)), ("b", (18.0, mid), (2.0, mid))])
    text = text.replace('name = "swap"', 'name = "swap"\nprofile = "paper"')
    summary, events = run_with_events(parse_scenario(text.replace("200", "60")))
    assert not [e for e in events if e.kind in (WAIT, GO)]
    assert summary.agvs[0].waiting_time == summary.agvs[1].waiting_time == 0.0


def test_single_lane_builtin_four_agvs_swap_rooms_without_contact():
    summary, events = run_with_events(load_scenario("single-lane"))
    assert summary.success, summary.table()
    assert any(e.kind == WAIT for e in events)
    assert sum(a.waiting_time for a in summary.agvs) > 0


def test_the_recording_and_rerun_show_who_waits_where_and_the_passages(tmp_path):
    mid = 3.75
    text = corridor_swap(3, [("a", (2.0, mid), (18.0, mid)), ("b", (18.0, mid), (2.0, mid))])
    scenario = parse_scenario(text)
    mcap, rrd = tmp_path / "swap.mcap", tmp_path / "swap.rrd"
    run_recorded(scenario, mcap, {})
    recording = open_recording(mcap)
    analysis = analyze(recording)
    by_name = {a.name: a for a in analysis.agvs}
    assert by_name["b"].waiting_time > 5.0 and by_name["b"].waits == 1
    assert by_name["a"].waiting_time == 0.0 and analysis.traffic_events == 2  # wait, go
    save_rrd(recording, rrd)
    shown = read_rrd(rrd)
    assert shown["/world/passages"].static >= 1
    ticks = [m.data for m in recording.of("world/tick")]
    held = [t for t in ticks if any(i["name"] == "b" and i["phase"] == WAIT for i in t["intents"])]
    rings = [r for r in shown["/world/agv/b/waiting"].rows if r[1]["Points2D:positions"]]
    assert len(rings) == len(held)
    assert all(r[1]["Points2D:labels"] == ["waits for a"] for r in rings)
    places = [r for r in shown["/world/agv/b/waiting/place"].rows if r[1]["LineStrips2D:strips"]]
    assert len(places) == len(held)  # a line from b to where it was sent, while it waits
    last_hold = next(i["hold"] for i in held[-1]["intents"] if i["name"] == "b")
    assert places[-1][1]["LineStrips2D:strips"][0][-1] == pytest.approx(last_hold)
    assert "/world/agv/a/waiting" not in shown or not any(
        r[1]["Points2D:positions"] for r in shown["/world/agv/a/waiting"].rows
    )
    assert len(shown["/events/wait"].rows) == 1 and len(shown["/events/go"].rows) == 1


def test_two_agvs_that_meet_inside_a_corridor_the_later_backs_out_and_both_arrive():
    """Both start inside, nose to nose: a deadlock the rule breaks at once (``back``)."""
    mid = 3.75
    text = corridor_swap(3, [("a", (8.5, mid), (18.0, mid)), ("b", (11.5, mid), (2.0, mid))])
    summary, events = run_with_events(parse_scenario(text))
    assert summary.success, summary.table()
    backs = [e for e in events if e.kind == BACK]
    assert [e.agvs for e in backs] == [["b", "a"]]  # same first ask: by name, b is later
    by_name = {a.name: a for a in summary.agvs}
    assert by_name["a"].arrival_time < by_name["b"].arrival_time


def test_first_rival_is_the_earlier_holder_going_the_other_way():
    me = claim("m", GO, 1, 4)
    assert first_rival(me, [me, claim("x", GO, 2, 3), claim("y", GO, 2, 2)]) == "y"
    assert first_rival(me, [me, claim("x", GO, 2, 5)]) is None  # I came first: x backs out
    assert first_rival(me, [me, claim("x", GO, 1, 1)]) is None  # same way: a convoy
    assert first_rival(me, [me, claim("x", WAIT, 2, 1)]) is None  # not inside


def test_a_convoy_comes_in_and_goes_out_by_the_same_mouths():
    inside = Intent("h", 10, GO, 0, exit=3, since=0, entry=1)
    merging = Intent("m", 10, WAIT, 0, exit=3, since=1, entry=2)  # from a side arm
    behind = Intent("b", 10, WAIT, 0, exit=3, since=1, entry=1)
    assert may_enter("m", [inside, merging]) == (False, ["h"])
    assert may_enter("b", [inside, behind]) == (True, [])


def test_every_agv_finds_the_same_passages_whatever_its_own_radius():
    mid = 3.75
    text = corridor_swap(3, [("a", (2.0, mid), (18.0, mid)), ("b", (18.0, mid), (2.0, mid))])
    text = text.replace('name = "b"', 'name = "b"\nradius = 0.3')
    scenario = parse_scenario(text)
    guards = [AgvNode(scenario, name).guard for name in ("a", "b")]
    assert guards[0].passages is guards[1].passages
    assert scenario.agv("a").radius != scenario.agv("b").radius


def test_the_world_refuses_an_intent_from_a_later_tick():
    mid = 3.75
    scenario = parse_scenario(corridor_swap(3, [("a", (2.0, mid), (18.0, mid))]))
    world = World(scenario)
    world.first_tick()
    forged = Intent("a", 0, GO, 0, exit=1, since=10**6)
    world.advance({"a": AgvCommand("a", 1, 0.0, 0.0, 0.0, intent=forged)})
    assert "a" not in world.intents and world.records["a"].refused == 1
    honest = Intent("a", 0, REQUEST, 0, exit=1, since=1)
    world.advance({"a": AgvCommand("a", 2, 0.0, 0.0, 0.0, intent=honest)})
    assert world.intents["a"].phase == REQUEST
    malformed = Intent("a", 0, WAIT, 0, exit=1, since=1, hold=[1.0, 2.0, 3.0])
    world.advance({"a": AgvCommand("a", 3, 0.0, 0.0, 0.0, intent=malformed)})
    assert "a" not in world.intents and world.records["a"].refused == 2
