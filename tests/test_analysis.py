"""Analysis of recordings: synthetic recordings with known answers, and a real run."""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np
import pytest

from bridge import keys
from bridge.messages import AgvState, Event, MapMsg, ObstacleState, PlanMsg, Tick
from fleet.runtime.inprocess import run_in_process
from fleet.scenario import load_scenario
from planner.core.motion import step_pose, world_velocity
from planner.core.path_metrics import crossing_points
from recordings.analysis import analyze
from recordings.compare import compare
from recordings.plots import map_figure, save_plots
from recordings.reader import open_recording
from recordings.report import comparison_table, run_table, to_csv, to_json
from recordings.series import extract
from recordings.writer import RecordingWriter, record_sink

DT = 0.1


def state(name, tick, x=1.0, y=1.0, theta=0.0, vx=0.0, vy=0.0, omega=0.0, **kw) -> AgvState:
    return AgvState(name, tick, x, y, theta, vx, vy, omega, kw.pop("radius", 0.3), **kw)


def tick(k, agvs, moving=(), temporary=()) -> Tick:
    return Tick(k, round(k * DT, 9), list(agvs), list(moving), [list(c) for c in temporary])


def plan(name, key_nodes, reason="initial", found=True) -> PlanMsg:
    return PlanMsg(name, 0, 0.0, "improved", reason, found, key_nodes, key_nodes, 0, 0, 0, 1.0)


def write(path, ticks, rows=None, plans=(), events=(), result=None):
    """A recording as the fleet would write it, from the given messages."""
    dt_ns = round(DT * 1e9)
    with RecordingWriter(path, scenario_name="synthetic", scenario_text="", run_facts={}) as w:
        if rows is not None:
            w.write(keys.WORLD_MAP, MapMsg("m", len(rows[0]), len(rows), 1.0, rows), 0)
        for t in ticks:
            w.write(keys.WORLD_TICK, t, t.tick * dt_ns)
            for s in t.agvs:
                w.write(keys.agv_state(s.name), s, t.tick * dt_ns)
        for p in plans:
            w.write(keys.agv_plan(p.name), p, 0)
        for e in events:
            w.write(keys.WORLD_EVENT, e, e.tick * dt_ns)
        if result is not None:
            w.finish(result)
    return open_recording(path)


def drive(commands, start=(1.0, 1.0, 0.3)):
    """States of one AGV from tick 0 (at rest) under body-frame commands, moved by Eq. 4."""
    pose, states = start, [state("a", 0, *start)]
    for k, command in enumerate(commands, start=1):
        pose = step_pose(pose, command, DT)
        states.append(state("a", k, *pose, *command))
    return states


def test_constant_world_velocity_has_no_acceleration_or_jerk(tmp_path):
    # heading 0.7 rad, no turning, the same body command at every tick (tick 0 too)
    v = (0.4, 0.1, 0.0)
    states = [state("a", 0, 1.0, 1.0, 0.7, *v), *drive([v] * 50, (1.0, 1.0, 0.7))[1:]]
    a = analyze(write(tmp_path / "r.mcap", [tick(s.tick, [s]) for s in states])).agvs[0]
    assert a.rms_accel == pytest.approx(0.0, abs=1e-12)
    assert a.rms_jerk == pytest.approx(0.0, abs=1e-12)
    assert a.rms_speed_accel == pytest.approx(0.0, abs=1e-12)
    assert a.distance == pytest.approx(math.hypot(0.4, 0.1) * 50 * DT)


def test_uniform_acceleration_gives_that_rms_and_no_jerk(tmp_path):
    accel = 0.2
    states = drive([(accel * k * DT, 0.0, 0.0) for k in range(1, 40)])
    a = analyze(write(tmp_path / "r.mcap", [tick(s.tick, [s]) for s in states])).agvs[0]
    assert a.rms_accel == pytest.approx(accel)
    assert a.rms_speed_accel == pytest.approx(accel)
    assert a.rms_jerk == pytest.approx(0.0, abs=1e-9)


def test_world_velocity_is_the_position_change_per_tick():
    rng = np.random.default_rng(3)
    commands = np.column_stack(
        (rng.uniform(0, 1, 60), rng.uniform(-0.3, 0.3, 60), rng.uniform(-0.5, 0.5, 60))
    )
    states = drive([tuple(c) for c in commands])
    col = {f: np.array([getattr(s, f) for s in states]) for f in ("x", "y", "theta")}
    velocity = world_velocity(col["theta"][1:], *commands.T[:2], commands[:, 2], DT)
    moved = np.column_stack((np.diff(col["x"]), np.diff(col["y"]))) / DT
    np.testing.assert_allclose(velocity, moved, atol=1e-9)


def test_smoothness_is_measured_on_the_path_actually_driven(tmp_path):
    rng = np.random.default_rng(7)
    commands = [
        (rng.uniform(0, 1), rng.uniform(-0.2, 0.2), rng.uniform(-0.4, 0.4)) for _ in "x" * 80
    ]
    states = drive(commands)
    a = analyze(write(tmp_path / "r.mcap", [tick(s.tick, [s]) for s in states])).agvs[0]
    xy = np.array([(s.x, s.y) for s in states])
    velocity = np.vstack(([0.0, 0.0], np.diff(xy, axis=0) / DT))  # at rest at tick 0
    accel = np.diff(velocity, axis=0) / DT
    jerk = np.diff(accel, axis=0) / DT
    assert a.rms_accel == pytest.approx(np.sqrt((accel**2).sum(axis=1).mean()))
    assert a.rms_jerk == pytest.approx(np.sqrt((jerk**2).sum(axis=1).mean()))
    speed_accel = np.diff(np.hypot(*velocity.T)) / DT
    assert a.rms_speed_accel == pytest.approx(np.sqrt((speed_accel**2).mean()))


def test_omega_sign_changes_and_mean_change_over_the_drive_only(tmp_path):
    omegas = [0.0, 0.1, 0.2, 0.0, -0.1, -0.1, 0.0, 0.3, 0.3, 0.0, 0.3, -0.2]
    states = [state("a", k, omega=w) for k, w in enumerate(omegas)]
    states[-1].status = "arrived"
    # parked after arrival: turning back and forth that must not count
    states += [state("a", k, omega=(-1) ** k, status="arrived") for k in range(12, 20)]
    a = analyze(write(tmp_path / "r.mcap", [tick(s.tick, [s]) for s in states])).agvs[0]
    assert a.omega_sign_changes == 3  # + + | - - | + + + | -  (zeros skipped)
    assert a.mean_abs_domega == pytest.approx(np.abs(np.diff(omegas)).mean())
    angular_accel = np.diff(omegas) / DT  # the parked ticks after arrival left out
    assert a.rms_angular_accel == pytest.approx(np.sqrt((angular_accel**2).mean()))
    jerk = np.diff(angular_accel) / DT
    assert a.rms_angular_jerk == pytest.approx(np.sqrt((jerk**2).mean()))
    assert a.arrival_time == pytest.approx(11 * DT)
    assert a.status == "arrived"


def test_a_loop_driven_is_counted_and_named_in_the_run_line(tmp_path):
    # agv a drives on while circling: one full curl (a prolate cycloid from t = pi to 3 pi)
    t = np.linspace(math.pi, 3 * math.pi, 120)
    curl = np.column_stack((2.0 + 0.3 * t - 0.8 * np.sin(t), 3.0 - 0.8 * np.cos(t)))
    ticks = [
        tick(k, [state("a", k, x, y), state("b", k, 1.0 + 0.05 * k, 6.0)])
        for k, (x, y) in enumerate(curl)
    ]
    run = analyze(write(tmp_path / "r.mcap", ticks))
    assert [a.self_crossings for a in run.agvs] == [1, 0]
    assert run.self_crossings == 1
    assert "loops: paths crossed themselves 1 time (a 1)" in run_table(run)
    assert "loops:" not in run_table(analyze(write(tmp_path / "s.mcap", ticks[:20])))
    # the map plot marks where: one x in a's colour at the crossing, none for b
    figure = map_figure(extract(open_recording(tmp_path / "r.mcap")), "looping")
    marks = [line for line in figure.axes[0].lines if line.get_marker() == "x"]
    assert len(marks) == 1 and marks[0].get_color() == "C0"
    assert np.column_stack(marks[0].get_data()) == pytest.approx(crossing_points(curl))


def test_path_metrics_come_from_the_first_plan_found(tmp_path):
    key_nodes = [[0.0, 0.0], [3.0, 0.0], [3.0, 4.0], [6.0, 8.0]]
    plans = [
        plan("a", [], found=False),
        plan("a", key_nodes),
        plan("a", [[0.0, 0.0], [9.0, 9.0]], reason="replan"),
        plan("a", [[0.0, 0.0], [1.0, 9.0]], reason="replan"),
    ]
    states = [state("a", k) for k in range(3)]
    rec = write(tmp_path / "r.mcap", [tick(s.tick, [s]) for s in states], plans=plans)
    a = analyze(rec).agvs[0]
    assert a.path_length == pytest.approx(3 + 4 + 5)
    assert a.turns == 2
    assert a.turning_angle_deg == pytest.approx(90 + math.degrees(math.atan2(3, 4)))
    assert a.replans == 2


def test_clearance_to_obstacles_and_to_agvs_separately(tmp_path):
    rows = ["." * 10 for _ in range(10)]
    rows[4] = "." * 7 + "#" + ".."  # cell (7, 5): x in [7, 8], y in [5, 6]
    ticks = []
    for k in range(6):
        agvs = [state("a", k, 5.0, 5.5), state("b", k, 2.0, 5.5)]
        # a moving obstacle listed only at ticks 3 and 4; far, then 1.1 m from AGV a
        moving = [ObstacleState("m", 5.0, 9.0 if k == 3 else 6.6, 0, 0, 0.5)] if k in (3, 4) else []
        temporary = [(6, 5)] if k >= 3 else []  # x in [6, 7]: 1 m from AGV a
        ticks.append(tick(k, agvs, moving, temporary))
    a, b = analyze(write(tmp_path / "r.mcap", ticks, rows=rows)).agvs
    assert a.min_clearance_obstacles == pytest.approx(1.1 - 0.3 - 0.5, abs=1e-5)
    assert b.min_clearance_obstacles == pytest.approx(2.0 - 0.3, abs=1e-5)  # the map's edge
    assert a.min_clearance_agvs == b.min_clearance_agvs == pytest.approx(3.0 - 0.6)

    # without the moving obstacle the temporary cell is the nearest, then the fixed one
    for t in ticks:
        t.moving = []
    a = analyze(write(tmp_path / "s.mcap", ticks, rows=rows)).agvs[0]
    assert a.min_clearance_obstacles == pytest.approx(1.0 - 0.3, abs=1e-5)
    for t in ticks:
        t.temporary = []
    a = analyze(write(tmp_path / "t.mcap", ticks, rows=rows)).agvs[0]
    assert a.min_clearance_obstacles == pytest.approx(2.0 - 0.3, abs=1e-5)


def test_collisions_statuses_and_planning_time(tmp_path):
    ticks = [
        tick(k, [state("a", k, plan_time_ms=float(k)), state("b", k, 3.0, plan_time_ms=1.0)])
        for k in range(5)
    ]
    events = [
        Event(2, 0.2, "collision", ["a", "b"], "a and b"),
        Event(3, 0.3, "collision", ["a"], "a and wall"),
        Event(4, 0.4, "end", [], "time limit"),
    ]
    result = {"agvs": [{"name": "a", "status": "timeout"}, {"name": "b", "status": "failed"}]}
    run = analyze(write(tmp_path / "r.mcap", ticks, events=events, result=result))
    a, b = run.agvs
    assert (a.collisions, b.collisions, run.collisions) == (2, 1, 2)
    assert (a.status, b.status, a.arrival_time) == ("timeout", "failed", None)
    assert a.plan_time_mean_ms == pytest.approx(2.5)  # cycles 1..4: tick 0 is no cycle
    assert a.plan_time_p95_ms == pytest.approx(np.percentile([1, 2, 3, 4], 95))
    assert run.plan_time_mean_ms == pytest.approx((1 + 2 + 3 + 4 + 4 * 1.0) / 8)
    assert (run.finished, run.ticks, run.run_time, run.dt) == (True, 4, 0.4, pytest.approx(DT))


def test_compare_gives_the_percent_difference_to_the_first(tmp_path):
    runs = []
    for i, length in enumerate((12.0, 15.0)):
        states = [state("a", k) for k in range(3)]
        rec = write(
            tmp_path / f"{i}.mcap",
            [tick(s.tick, [s]) for s in states],
            plans=[plan("a", [[0.0, 0.0], [length, 0.0]])],
        )
        runs.append(analyze(rec))
    rows = {m.key: m for m in compare(runs)}
    assert rows["path_length"].values == (12.0, 15.0)
    assert rows["path_length"].change_pct == (0.0, pytest.approx(25.0))
    assert rows["collisions"].change_pct == (None, None)  # 0 in the first run
    table = comparison_table(runs)
    assert "+25.0 %" in table and "mean path length" in table
    assert json.loads(json.dumps(to_json(runs)))["comparison"][3]["metric"] == "path_length"


def test_a_real_run_agrees_with_the_worlds_summary(tmp_path):
    scenario = load_scenario("crossing")
    path = tmp_path / "crossing.mcap"
    with RecordingWriter(
        path, scenario_name=scenario.name, scenario_text=scenario.source, run_facts={}
    ) as writer:
        summary = run_in_process(scenario, outbox=record_sink(writer, scenario.dt))
        writer.finish(summary.to_json())
    rec = open_recording(path)
    run = analyze(rec)
    assert (run.ticks, run.run_time, run.collisions) == (
        summary.ticks,
        pytest.approx(summary.sim_time),
        summary.collisions,
    )
    for expected, got in zip(summary.agvs, run.agvs, strict=True):
        assert (got.name, got.status) == (expected.name, expected.status)
        assert got.arrival_time == pytest.approx(expected.arrival_time)
        assert got.distance == pytest.approx(expected.distance, abs=1e-9)
        assert got.self_crossings == expected.self_crossings
        least = min(got.min_clearance_obstacles, got.min_clearance_agvs)
        assert least == pytest.approx(expected.min_clearance, abs=1e-9)
        assert got.path_length is not None and got.rms_accel > 0

    table = run_table(run)
    assert all(a.name in table for a in scenario.agvs)
    rows = list(csv.DictReader(io.StringIO(to_csv([run]))))
    assert [r["row"] for r in rows] == ["run"] + ["agv"] * len(scenario.agvs)
    assert [r["name"] for r in rows[1:]] == [a.name for a in scenario.agvs]
    assert float(rows[1]["distance"]) == pytest.approx(summary.agvs[0].distance)
    assert float(rows[0]["distance"]) == pytest.approx(run.distance)  # the run's mean
    assert rows[0]["finished"] == "yes" and rows[0]["truncated"] == "no"
    assert not {"True", "False"} & {v for r in rows for v in r.values()}

    written = save_plots(extract(rec), tmp_path / "plots", "crossing", "crossing (fusion)")
    assert len(written) == 1 + len(scenario.agvs)
    for png in written:
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
