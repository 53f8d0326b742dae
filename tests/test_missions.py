"""Shifts of transport work (fleet.missions): the format, the seeded requests, the
assignment rule, a case computed by hand, and the task events through a real MCAP file."""

from __future__ import annotations

import itertools
import json
import re
import subprocess
import sys

import pytest

from bridge import keys
from fleet.missions.dispatch import Dispatcher
from fleet.missions.requests import generated_requests
from fleet.missions.spec import Generator, Missions, Station
from fleet.runtime.inprocess import run_in_process, run_recorded
from fleet.scenario import ScenarioError, load_scenario, parse_scenario
from planner.core.status import (
    ASSIGNED,
    AT_HOME,
    AT_PICK_UP,
    DELIVERED,
    LOADING,
    PARKED,
    PICKED_UP,
    REQUESTED,
    TASK_EVENTS,
    TO_PICK_UP,
)
from recordings.analysis import analyze
from recordings.reader import open_recording

CLI = [sys.executable, "-m", "fleet.cli"]

# one AGV between two stations 10 m apart on an open floor
DISTANCE, DWELL_A, DWELL_B = 10.0, 20.0, 10.0
V, ACCEL, OMEGA, ALPHA = 1.0, 0.5, 60.0, 120.0


def two_stations(shift: float = 1200.0, extra: str = "") -> str:
    return f"""
name = "two-stations"
[map]
resolution = 1.0
grid = \"\"\"
..............
..............
.............#
\"\"\"
[agv_defaults]
radius = 0.3
max_speed = {V}
max_accel = {ACCEL}
max_omega = {OMEGA}
max_alpha = {ALPHA}
[[stations]]
name = "a"
position = [1.5, 1.5]
dwell = {DWELL_A}
[[stations]]
name = "b"
position = [{1.5 + DISTANCE}, 1.5]
dwell = {DWELL_B}
group = "drop"
[tasks]
shift = {shift}
{extra}
[[agvs]]
name = "agv1"
start = [1.5, 1.5]
tasks = ["a", "b"]
repeat = true
"""


def _drive_time(distance: float, v: float, a: float) -> float:
    """Rest to rest over ``distance``: accelerate, cruise, brake (a trapezoid)."""
    return distance / v + v / a


def test_one_agv_two_stations_makes_the_tasks_an_hour_computed_by_hand():
    """A cycle: load at a (20 s), drive 10 m, unload at b (10 s), turn round and drive
    back; each leg starts with a half turn on the spot (after the first) within the
    omega and alpha limits. By hand: leg = 10/1 + 1/0.5 = 12 s, half turn = 180/60 +
    60/120 = 3.5 s, cycle = 20 + 10 + 2 (12 + 3.5) = 61 s: 59.0 tasks an hour. The
    controller's final approach and the goal tolerance make the real cycle a little
    longer: within 5 %."""
    cycle = DWELL_A + DWELL_B + 2 * (_drive_time(DISTANCE, V, ACCEL) + 180 / OMEGA + OMEGA / ALPHA)
    events = []

    def sink(key, msg):
        if key == keys.WORLD_EVENT and msg.kind == DELIVERED:
            events.append(msg.time)

    summary = run_in_process(parse_scenario(two_stations()), outbox=sink)
    assert summary.end_reason == "shift over" and summary.success
    gaps = [b - a for a, b in itertools.pairwise(events)]
    measured = sum(gaps) / len(gaps)  # the steady cycle, delivery to delivery
    assert measured == pytest.approx(cycle, rel=0.05)
    per_hour = 3600 / cycle
    first = DWELL_A + _drive_time(DISTANCE, V, ACCEL) + DWELL_B  # no turn before the first
    expected = 1 + (1200 - first) // cycle  # deliveries in the 1200 s shift
    assert abs(summary.tasks["delivered"] - expected) <= 1
    assert summary.tasks["throughput_per_hour"] == summary.tasks["delivered"] * 3.0
    assert 3600 / measured == pytest.approx(per_hour, rel=0.05)


def test_task_events_round_trip_through_mcap_and_analyze_reads_them(tmp_path):
    path = tmp_path / "two.mcap"
    sent = []

    def also(key, msg):
        if key == keys.WORLD_EVENT and msg.kind in TASK_EVENTS:
            sent.append({"tick": msg.tick, "time": msg.time, "kind": msg.kind,
                         "agvs": msg.agvs, "detail": msg.detail})  # fmt: skip

    scenario = parse_scenario(two_stations(shift=300.0))
    summary = run_recorded(scenario, path, {"mode": "in-process"}, also=also)
    rec = open_recording(path)  # the mcap library's reader
    read = [e for e in rec.data_of(keys.WORLD_EVENT) if e["kind"] in TASK_EVENTS]
    assert read == sent and len(read) >= 4 * 3
    assert [e["kind"] for e in read[:4]] == [REQUESTED, ASSIGNED, PICKED_UP, DELIVERED]
    ticks = list(rec.data_of(keys.WORLD_TICK))
    assert ticks[0]["assignments"][0]["station"] == "a"
    assert {s["status"] for t in ticks for s in t["agvs"]} >= {LOADING}
    run = analyze(rec)
    assert run.tasks == summary.tasks
    assert run.tasks["delivered"] == summary.tasks["delivered"] >= 3
    agv = run.agvs[0]
    assert agv.deliveries == run.tasks["delivered"]
    assert agv.utilisation == pytest.approx(1.0)  # its own list: always a task
    assert agv.distance_per_task == pytest.approx(agv.distance / agv.deliveries)


def test_a_generator_with_a_fixed_seed_makes_the_same_shift_every_time():
    stations = (Station("p1", (1, 1), 0, "pick"), Station("p2", (2, 1), 0, "pick"),
                Station("d1", (5, 5), 0, "drop"), Station("d2", (6, 5), 0, "drop"))  # fmt: skip
    sources, targets = stations[:2], stations[2:]
    one = generated_requests(Generator(120.0, "pick", "drop", 7), sources, targets, 3600.0)
    again = generated_requests(Generator(120.0, "pick", "drop", 7), sources, targets, 3600.0)
    other = generated_requests(Generator(120.0, "pick", "drop", 8), sources, targets, 3600.0)
    assert one == again and one != other
    assert 90 <= len(one) <= 150  # a Poisson process of 120 an hour
    assert {r.source for r in one} == {"p1", "p2"} and {r.target for r in one} == {"d1", "d2"}
    assert all(a.time < b.time for a, b in itertools.pairwise(one))


def _dispatcher(homes, requests):
    stations = (Station("p", (10.0, 0.0), 5.0, "pick"), Station("q", (0.0, 10.0), 5.0, "pick"),
                Station("d", (10.0, 10.0), 0.0, "drop"))  # fmt: skip
    missions = Missions(3600.0, stations, Generator(60.0, "pick", "drop"))
    return Dispatcher(missions, homes, requests)


def test_the_nearest_idle_agv_takes_the_oldest_request_and_ties_go_by_fleet_order():
    from fleet.missions.requests import Request

    homes = {"far": (0.0, 0.0), "near": (9.0, 0.0), "twin": (11.0, 0.0)}
    d = _dispatcher(homes, [Request(1, 0.0, "p", "d"), Request(2, 0.0, "p", "d")])
    events = d.update(0.0, homes, set())
    assert [(e.kind, e.agv) for e in events] == [
        (REQUESTED, ""), (REQUESTED, ""), (ASSIGNED, "near"),
    ]  # fmt: skip
    # near and twin are equally far from p: near comes first in the fleet
    assert d.agvs["near"].phase == TO_PICK_UP and d.agvs["near"].goal == (10.0, 0.0)
    # request 2 waits: its pick-up p is held by near
    assert [t.request.number for t in d.queue] == [2]
    d.update(3.0, {**homes, "near": (10.0, 0.0)}, {"near"})
    assert d.agvs["near"].phase == AT_PICK_UP
    events = d.update(8.0, {**homes, "near": (10.0, 0.0)}, {"near"})
    assert [e.kind for e in events] == [PICKED_UP, ASSIGNED]  # p is free again
    assert events[1].agv == "twin"  # 1 m from p, nearer than far


def test_a_request_waits_in_the_queue_while_no_agv_is_idle():
    from fleet.missions.requests import Request

    homes = {"only": (0.0, 0.0)}
    d = _dispatcher(homes, [Request(1, 0.0, "p", "d"), Request(2, 1.0, "q", "d")])
    d.update(0.0, homes, set())
    d.update(1.0, homes, set())
    assert [t.request.number for t in d.queue] == [2]
    d.update(2.0, {"only": (10.0, 0.0)}, {"only"})
    d.update(7.0, {"only": (10.0, 0.0)}, {"only"})  # picked up, on to d
    d.update(9.0, {"only": (10.0, 10.0)}, {"only"})  # delivered (no dwell): takes q's
    assert d.tasks[0].delivered == 9.0 and d.tasks[1].assigned == 9.0
    assert d.queue == [] and d.agvs["only"].goal == (0.0, 10.0)
    assert d.tasks[1].assigned - d.tasks[1].request.time == 8.0  # its queue time


def test_idle_agvs_go_home_and_stand_there_parked():
    scenario = parse_scenario(two_stations(shift=60.0).replace("repeat = true", "repeat = false"))
    statuses = []

    def sink(key, msg):
        if key == keys.WORLD_TICK:
            statuses.append((msg.agvs[0].status, msg.assignments[0].phase))

    run_in_process(scenario, outbox=sink)
    assert statuses[-1] == (PARKED, AT_HOME)  # back at a after its one task
    assert (LOADING, AT_PICK_UP) in statuses


def test_the_builtin_warehouse_shift_is_a_one_hour_shift_with_node_reservations():
    scenario = load_scenario("warehouse-shift")
    assert scenario.time_limit == scenario.missions.shift == 3600.0
    assert scenario.traffic == "reservations"
    groups = {s.group for s in scenario.missions.stations}
    assert groups == {"pick", "drop", "parking"}
    assert scenario.missions.generator.source == "pick"


BAD = {
    "a station outside the map": (
        'name = "a"\nposition = [1.5, 1.5]', 'name = "a"\nposition = [20.5, 1.5]',
        "station 'a': position (20.5, 1.5) is outside the map",
    ),
    "a station in a wall": (
        'name = "b"\nposition = [11.5, 1.5]', 'name = "b"\nposition = [13.5, 0.5]',
        "station 'b': position (13.5, 0.5) is inside an obstacle",
    ),
    "a station without room for the body": (
        'name = "b"\nposition = [11.5, 1.5]', 'name = "b"\nposition = [12.9, 0.5]',
        "station 'b': position (12.9, 0.5) is 0.1000 m from an obstacle",
    ),
    "an unknown group": ("", 'generator = { rate_per_hour = 60, from = "pik", to = "drop" }',
                         "names no station group"),
    "an unknown station": ('tasks = ["a", "b"]', 'tasks = ["a", "c"]', "names no station"),
    "an unknown key": ("dwell = 10.0", "dwel = 10.0", "unknown key stations[1].dwel"),
    "an odd task list": ('tasks = ["a", "b"]', 'tasks = ["a", "b", "a"]', "in pairs"),
}  # fmt: skip


@pytest.mark.parametrize("what", BAD)
def test_bad_shift_input_is_one_line_and_exit_2(tmp_path, what):
    old, new, message = BAD[what]
    text = two_stations(extra=new if not old else "")
    if old:
        assert old in text
        text = text.replace(old, new, 1)
    with pytest.raises(ScenarioError, match=re.escape(message)):
        parse_scenario(text)
    path = tmp_path / "bad.toml"
    path.write_text(text)
    out = subprocess.run([*CLI, "run", str(path), "--in-process", "--no-record"],
                         capture_output=True, text=True, timeout=60)  # fmt: skip
    assert out.returncode == 2
    assert len(out.stderr.strip().splitlines()) == 1 and message in out.stderr
    assert "Traceback" not in out.stderr


def test_a_station_off_the_roadmap_in_reservations_mode_is_refused():
    text = two_stations().replace("position = [1.5, 1.5]", "position = [1.9, 1.5]", 1)
    text = text.replace("[tasks]", '[traffic]\nmode = "reservations"\n[tasks]')
    with pytest.raises(ScenarioError, match="station 'a'"):
        run_in_process(parse_scenario(text))


def test_the_summary_json_has_the_tasks_block():
    summary = run_in_process(parse_scenario(two_stations(shift=120.0)))
    block = json.loads(json.dumps(summary.to_json()))["tasks"]
    assert set(block) == {"requested", "assigned", "delivered", "throughput_per_hour",
                          "task_time_mean", "task_time_p95", "queue_time_mean"}  # fmt: skip


def test_rerun_draws_the_stations_and_each_agvs_current_task(tmp_path):
    from recordings.rerun_view import save_rrd
    from tests.test_rerun import read_rrd

    path, rrd = tmp_path / "two.mcap", tmp_path / "two.rrd"
    run_recorded(parse_scenario(two_stations(shift=120.0)), path, {"mode": "in-process"})
    save_rrd(open_recording(path), rrd)
    entities = read_rrd(rrd)  # the .rrd as Rerun's own reader reads it
    assert entities["/world/stations"].static >= 1
    labels = [
        label
        for _, row in entities["/world/agv/agv1/task"].rows
        for label in row.get("Points2D:labels") or []
    ]
    assert labels[:5] == ["task 1 to a", "task 1 at a", "task 1 to b", "task 1 at b", "task 2 to a"]
    assert len(entities["/world/agv/agv1/task/way"].rows) > 100  # drawn while it drives


def test_agvs_count_puts_the_fleet_on_the_parking_stations():
    import tomlkit

    from fleet.sweep.keys import SweepKeyError, apply

    doc = tomlkit.parse(load_scenario("warehouse-shift").source)
    apply(doc, "agvs.count", 32)
    scenario = parse_scenario(tomlkit.dumps(doc))
    parking = [s.position for s in scenario.missions.stations if s.group == "parking"]
    assert [a.start for a in scenario.agvs] == parking[:32]
    assert [a.name for a in scenario.agvs][-1] == "agv32"
    assert scenario.agvs[0].config == load_scenario("warehouse-shift").agvs[0].config
    with pytest.raises(SweepKeyError, match="stations of group 'parking'"):
        apply(doc, "agvs.count", 33)
    with pytest.raises(SweepKeyError, match="positive integer"):
        apply(doc, "agvs.count", 0)


def test_a_fleet_sizing_sweep_has_task_metrics_first_and_a_sizing_plot(tmp_path):
    from recordings.sweep_plots import SIZING_PLOT, save_box_plots
    from recordings.sweep_report import SweepEntry, stats_table, variant_stats

    def entry(count, seed, rate, time):
        tasks = {"requested": 100, "assigned": 100, "delivered": rate,
                 "throughput_per_hour": float(rate), "task_time_mean": time,
                 "task_time_p95": 2 * time, "queue_time_mean": 1.0}  # fmt: skip
        run = {"scenario": "warehouse-shift", "run_time": 3600.0, "tasks": tasks}
        return SweepEntry({"agvs.count": count}, {"tasks.generator.seed": seed}, "", False, run)

    entries = [entry(n, s, min(60 * n, 180) + s, 300 / n + 60) for n in (2, 4, 8) for s in (1, 2)]
    table = stats_table(variant_stats(entries), ["tasks.generator.seed"])
    assert table.splitlines()[2].startswith("tasks.throughput_per_hour (1/h)")
    assert "121.5 ±" in table  # 2 AGVs: 121 and 122 an hour
    paths = save_box_plots(entries, tmp_path, "warehouse-shift")
    sizing = tmp_path / SIZING_PLOT
    assert sizing in paths
    assert sizing.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and sizing.stat().st_size < 1_000_000
