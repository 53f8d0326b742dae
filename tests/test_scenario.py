"""Scenario files: the public format, and one clear error per mistake."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

from fleet.scenario import ScenarioError, load_scenario, parse_scenario

CONTRACT_EXAMPLE = '''
name = "paper-dynamic"
description = "..."
dt = 0.1
time_limit = 300
sensing_radius = 5.0

[map]
resolution = 1.0
grid = """
....#...
........
"""

[planner]
algorithm = "fusion"
alpha = 0.1
beta = 0.2
gamma = 0.2
safety_distance = 0.5

[agv_defaults]
radius = 0.3
max_speed = 2.0

[[agvs]]
name = "agv1"
start = [1.5, 1.5]
goal = [6.5, 0.5]
heading = 0.0

[[obstacles]]
type = "temporary"
cells = [[5, 1], [6, 1]]
appear_at = 0.0

[[obstacles]]
type = "moving"
radius = 0.4
waypoints = [[2.5, 0.5], [5.5, 0.5]]
speed = 0.5
mode = "bounce"
'''


def test_the_contract_example_parses():
    sc = parse_scenario(CONTRACT_EXAMPLE)
    assert sc.name == "paper-dynamic" and sc.dt == 0.1 and sc.time_limit == 300
    assert sc.grid.width == 8 and sc.grid.height == 2
    assert sc.grid.blocked[1, 4] and not sc.grid.blocked[0, 4]  # first text row is the top
    (agv,) = sc.agvs
    assert agv.start == (1.5, 1.5) and agv.goal == (6.5, 0.5)
    assert agv.config.algorithm == "fusion" and agv.config.safety_distance == 0.5
    assert agv.config.dwa.alpha == 0.1 and agv.radius == 0.3 and agv.config.dwa.max_speed == 2.0
    assert sc.temporary[0].cells == ((5, 1), (6, 1))
    assert sc.moving[0].radius == 0.4 and sc.moving[0].mode == "bounce"


def test_defaults_are_the_papers():
    sc = parse_scenario(
        '[map]\ngrid = """\n....\n"""\n[[agvs]]\nname = "a"\nstart = [0.5, 0.5]\ngoal = [3.5, 0.5]'
    )
    dwa = sc.agvs[0].config.dwa
    assert (dwa.max_speed, dwa.max_accel) == (2.0, 0.2)
    assert math.degrees(dwa.max_omega) == pytest.approx(20)
    assert math.degrees(dwa.max_alpha) == pytest.approx(50)
    assert (dwa.v_resolution, math.degrees(dwa.omega_resolution)) == (0.01, pytest.approx(1))
    assert (dwa.alpha, dwa.beta, dwa.gamma, dwa.dt) == (0.1, 0.2, 0.2, 0.1)


def test_per_agv_overrides():
    text = CONTRACT_EXAMPLE.replace(
        "heading = 0.0",
        'heading = 0.0\nradius = 0.25\nmax_omega = 30\n[agvs.planner]\nalgorithm = "dwa"',
    )
    agv = parse_scenario(text).agvs[0]
    assert agv.radius == 0.25 and agv.config.algorithm == "dwa"
    assert math.degrees(agv.config.dwa.max_omega) == pytest.approx(30)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("dt = 0.1", "dt = 0.1\ncolour = 3"), "unknown key colour"),
        (("alpha = 0.1", "alpha = 0.1\nalfa = 2"), "unknown key planner.alfa"),
        (("time_limit = 300", 'time_limit = "long"'), "time_limit must be a number"),
        (("start = [1.5, 1.5]", "start = [4.5, 1.5]"), "AGV 'agv1': start .* inside an obstacle"),
        (("goal = [6.5, 0.5]", "goal = [9.5, 0.5]"), "AGV 'agv1': goal .* outside the map"),
        (("start = [1.5, 1.5]", "start = [1.5]"), r"agvs\[0\].start must be a pair"),
        (('algorithm = "fusion"', 'algorithm = "rrt"'), "planner.algorithm = 'rrt' is not one of"),
        (('mode = "bounce"', 'mode = "zigzag"'), r"obstacles\[1\].mode"),
        (("cells = [[5, 1], [6, 1]]", "cells = [[5, 1], [16, 1]]"), "outside the map"),
        (("radius = 0.3", "radius = -0.3"), "agv_defaults.radius must be > 0"),
        (("resolution = 1.0", "resolution = 1.0\nfile = 'x.map'"), "exactly one of"),
        (("[map]", "[map"), "not valid TOML"),
    ],
)
def test_mistakes_name_the_key_or_agv(change, message):
    old, new = change
    assert old in CONTRACT_EXAMPLE
    with pytest.raises(ScenarioError, match=message):
        parse_scenario(CONTRACT_EXAMPLE.replace(old, new, 1))


def test_duplicate_agv_names_are_rejected():
    twice = CONTRACT_EXAMPLE.replace(
        "[[obstacles]]",
        '[[agvs]]\nname = "agv1"\nstart = [0.5, 0.5]\ngoal = [7.5, 1.5]\n\n[[obstacles]]',
        1,
    )
    with pytest.raises(ScenarioError, match="duplicate AGV name 'agv1'"):
        parse_scenario(twice)


def test_map_file_is_relative_to_the_scenario(tmp_path, public_data):
    maps = tmp_path / "maps"
    maps.mkdir()
    (maps / "arena.map").write_bytes((public_data / "movingai" / "arena.map").read_bytes())
    scen = tmp_path / "s.toml"
    scen.write_text(
        '[map]\nfile = "maps/arena.map"\n[[agvs]]\nname = "a"\nstart = [3.5, 3.5]\n'
        "goal = [4.5, 3.5]\n"
    )
    sc = load_scenario(scen)
    assert (sc.grid.width, sc.grid.height) == (49, 49) and sc.name == "s"


def test_random_map_keeps_starts_and_goals_free():
    text = (
        "[map]\nrandom = { width = 30, height = 20, obstacle_ratio = 0.45, seed = 3 }\n"
        '[[agvs]]\nname = "a"\nstart = [0.5, 0.5]\ngoal = [29.5, 19.5]\n'
    )
    sc = parse_scenario(text)
    assert sc.grid.obstacle_ratio == pytest.approx(0.45, abs=0.01)
    assert sc.grid.is_free((0, 0)) and sc.grid.is_free((29, 19))
    assert (parse_scenario(text).grid.blocked == sc.grid.blocked).all()  # seeded


def test_builtin_scenarios_load_by_name():
    assert load_scenario("warehouse").name == "warehouse"
    with pytest.raises(ScenarioError, match="neither a file nor a built-in scenario"):
        load_scenario("no-such-scenario")


def test_cli_reports_a_broken_scenario_in_one_line(tmp_path):
    broken = tmp_path / "broken.toml"
    broken.write_text(CONTRACT_EXAMPLE.replace("start = [1.5, 1.5]", "start = [4.5, 1.5]"))
    proc = subprocess.run(
        [sys.executable, "-m", "fleet.cli", "run", str(broken), "--in-process"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2
    assert proc.stderr.strip().count("\n") == 0, proc.stderr
    assert "inside an obstacle" in proc.stderr and "Traceback" not in proc.stderr


def test_an_agv_is_found_by_name_and_an_unknown_name_is_refused():
    scenario = load_scenario("warehouse")
    assert [scenario.agv(a.name) for a in scenario.agvs] == list(scenario.agvs)
    with pytest.raises(ScenarioError, match="no AGV named 'nobody'"):
        scenario.agv("nobody")
