"""ROS conventions and the planner profile from the map file to the fleet: the yaml origin
(the ``map`` frame), map_server's reading of pixels, unknown cells, the scenario keys
``profile`` / ``margin`` / ``[map] unknown``, ``--profile``, the map message, and
``nav2-depot`` in both run modes."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from bridge.messages import MapMsg, from_dict, to_dict
from fleet.cli import main as cli_main
from fleet.runtime.inprocess import run_in_process
from fleet.runtime.world import map_message
from fleet.scenario import ScenarioError, load_scenario, parse_scenario, with_profile
from planner.core.errors import MapError
from planner.local.config import DwaConfig
from planner.local.dwa import DwaPlanner
from planner.maps.distance_field import DistanceField
from planner.maps.grid import GridMap
from planner.maps.loaders import load_map
from planner.maps.movingai import load_movingai
from planner.maps.ros_map import load_ros_map
from planner.maps.text_maps import parse_text_grid
from recordings.reader import open_recording
from recordings.series import extract, map_grid

CLI = [sys.executable, "-m", "fleet.cli"]
FREE, OCCUPIED, UNKNOWN = 254, 0, 205


def _ros_map(tmp_path, pixels, origin="[-10.0, -5.5, 0.0]", extra="", name="m"):
    pixels = np.asarray(pixels)
    h, w = pixels.shape
    (tmp_path / f"{name}.pgm").write_bytes(
        f"P5\n{w} {h}\n255\n".encode() + pixels.astype("u1").tobytes()
    )
    path = tmp_path / f"{name}.yaml"
    path.write_text(
        f"image: {name}.pgm\nresolution: 0.5\norigin: {origin}\noccupied_thresh: 0.65\n"
        f"free_thresh: 0.196\nnegate: 0\n{extra}"
    )
    return path


# --- the map frame -----------------------------------------------------------------------
def test_a_ros_map_is_in_its_map_frame(tmp_path):
    grid = load_ros_map(_ros_map(tmp_path, [[FREE, FREE, OCCUPIED], [FREE, FREE, FREE]]))
    assert grid.origin == (-10.0, -5.5)
    assert grid.extent == (-10.0, -8.5, -5.5, -4.5)
    assert grid.cell_of((-9.9, -5.4)) == (0, 0)  # the image's bottom-left pixel
    assert grid.centre_of((2, 1)) == (-8.75, -4.75)  # its top-right pixel, an obstacle
    assert grid.blocked[1, 2] and not grid.blocked[0, 2]
    with pytest.raises(
        MapError, match=r"outside the map \(x in \[-10, -8.5\), y in \[-5.5, -4.5\)"
    ):
        grid.free_cell_of((0.25, 0.25), "start")
    for text_map in (parse_text_grid("..\n.."), load_movingai_example(tmp_path)):
        assert text_map.origin == (0.0, 0.0)


def load_movingai_example(tmp_path):
    path = tmp_path / "x.map"
    path.write_text("type octile\nheight 1\nwidth 2\nmap\n.@\n")
    return load_movingai(path)


def test_a_rotated_map_is_a_clear_error(tmp_path):
    with pytest.raises(MapError, match=r"origin yaw 0.5 rad is not supported"):
        load_map(_ros_map(tmp_path, [[FREE]], origin="[0, 0, 0.5]"))


def test_unknown_cells_are_obstacles_unless_asked(tmp_path):
    path = _ros_map(tmp_path, [[FREE, UNKNOWN, OCCUPIED]])
    assert load_map(path).to_text() == ".##"
    assert load_map(path, unknown="free").to_text() == "..#"
    with pytest.raises(MapError, match="unknown cells must be one of obstacle, free"):
        load_map(path, unknown="maybe")


def test_raw_mode_reads_pixels_as_map_server_does(tmp_path):
    # raw: the value is round(shade * 255), negate not applied; above 100 it is unknown
    raw = _ros_map(tmp_path, [[0, 10, 30, 100, 101]], extra="mode: raw\n", name="raw")
    assert load_map(raw).to_text() == "..###"
    assert load_map(raw, unknown="free").to_text() == "..##."
    negated = _ros_map(tmp_path, [[0, 10, 30]], extra="mode: raw\nnegate: 1\n", name="neg")
    negated.write_text(negated.read_text().replace("negate: 0\n", ""))
    assert load_map(negated).to_text() == "..#"


def test_distances_and_dwa_work_in_the_map_frame():
    blocked = np.zeros((20, 20), dtype=bool)
    blocked[10, 14] = True
    here, there = GridMap(blocked, 0.5), GridMap(blocked, 0.5, origin=(-3.0, 7.0))
    near = DistanceField.from_grid(here), DistanceField.from_grid(there)
    assert near[1].distance_at(-3.0 + 6.5, 7.0 + 5.25) == pytest.approx(
        near[0].distance_at(6.5, 5.25)
    )
    moving = np.array([[4.0, 4.0, 0.1, 0.0, 0.3]])
    shifted = moving + np.array([-3.0, 7.0, 0.0, 0.0, 0.0])
    a = DwaPlanner(DwaConfig(), near[0]).plan((5.0, 5.0, 0.0), (1.0, 0.0, 0.0), (9.0, 5.0), moving)
    b = DwaPlanner(DwaConfig(), near[1]).plan(
        (2.0, 12.0, 0.0), (1.0, 0.0, 0.0), (6.0, 12.0), shifted
    )
    assert a.command == b.command


# --- the map message ---------------------------------------------------------------------
def test_the_map_message_carries_the_origin_and_turns_back_into_the_map(public_data):
    grid = load_map(public_data / "nav2" / "tb3_sandbox.yaml")
    data = to_dict(map_message(grid))
    assert data["origin"] == [-10.0, -10.0]
    back = map_grid(data)
    assert back.origin == grid.origin and np.array_equal(back.blocked, grid.blocked)
    old = {k: v for k, v in data.items() if k != "origin"}  # a recording made before
    assert from_dict(MapMsg, old).origin == [0.0, 0.0]
    assert map_grid(old).origin == (0.0, 0.0)


# --- scenario keys -----------------------------------------------------------------------
BASE = '[map]\ngrid = """\n..........\n..........\n..........\n"""\n'
AGV = '[[agvs]]\nname = "a"\nstart = [0.5, 1.5]\ngoal = [9.5, 1.5]\n'


def test_profile_is_a_top_level_and_a_per_agv_key():
    assert parse_scenario(BASE + AGV).agvs[0].config.profile == "default"
    paper = parse_scenario(
        'profile = "paper"\n' + BASE + AGV + AGV.replace('"a"', '"b"') + 'profile = "default"\n'
    )
    assert [a.config.profile for a in paper.agvs] == ["paper", "default"]
    assert {a.config.profile for a in with_profile(paper, "paper").agvs} == {"paper"}
    with pytest.raises(ScenarioError, match="profile = 'fast' is not one of: default, paper"):
        parse_scenario('profile = "fast"\n' + BASE + AGV)


def test_margin_key_and_safety_distance_come_from_one_place():
    sc = parse_scenario(BASE + "[planner]\nmargin = 0.1\n" + AGV + "radius = 0.4\n")
    assert sc.agvs[0].config.clearance.safety_distance == pytest.approx(0.5)
    wide = parse_scenario(BASE + AGV + "radius = 0.45\n")  # default margin on its radius
    assert wide.agvs[0].config.safety_distance == pytest.approx(0.65)
    with pytest.raises(ScenarioError, match=r"planner: safety distance 0.2 m is below"):
        parse_scenario(BASE + "[planner]\nsafety_distance = 0.2\n" + AGV)
    with pytest.raises(ScenarioError, match="give safety_distance or margin, not both"):
        parse_scenario(BASE + "[planner]\nsafety_distance = 0.5\nmargin = 0.2\n" + AGV)
    own = parse_scenario(
        BASE + "[planner]\nsafety_distance = 0.6\n" + AGV + "[agvs.planner]\nmargin = 0.05\n"
    )
    assert own.agvs[0].config.safety_distance == pytest.approx(0.35)


def test_a_start_where_the_body_does_not_fit_is_refused(tmp_path):
    path = _ros_map(tmp_path, np.full((10, 10), FREE), origin="[-2.0, -2.0, 0.0]")
    text = f'[map]\nfile = "{path}"\n[[agvs]]\nname = "a"\nstart = [-1.8, 0.0]\ngoal = [2.5, 2.5]\n'
    with pytest.raises(ScenarioError, match=r"start \(-1.8, 0\) is 0.2000 m from an obstacle"):
        parse_scenario(text)
    ok = parse_scenario(text.replace("-1.8, 0.0", "-1.0, 0.0"))
    assert ok.grid.origin == (-2.0, -2.0)
    with pytest.raises(ScenarioError, match=r"map\.unknown = 'maybe' is not one of"):
        parse_scenario(text.replace("[[agvs]]", 'unknown = "maybe"\n[[agvs]]'))


# --- the CLI -------------------------------------------------------------------------------
def test_cli_plan_in_the_ros_frame_with_either_profile(public_data, capsys):
    sandbox = str(public_data / "nav2" / "tb3_sandbox.yaml")
    args = ["plan", sandbox, "--start", "-1.6", "-0.6", "--goal", "1.6", "0.6", "--json"]
    plans = {}
    for profile in ("default", "paper"):
        assert cli_main([*args, "--profile", profile]) == 0
        out = json.loads(capsys.readouterr().out)
        assert out["profile"] == profile
        plans[profile] = {p["algorithm"]: p for p in out["plans"]}
    default, paper = plans["default"]["improved"], plans["paper"]["improved"]
    assert default["key_nodes"][0] == [-1.6, -0.6] and default["clearance"] >= 0.3
    assert paper["clearance"] < 0.3  # the paper's route brushes a pillar
    assert cli_main([*args, "--radius", "0"]) == 2  # bad input
    assert "radius must be > 0" in capsys.readouterr().err


# --- fleets in the map frame ----------------------------------------------------------------
def test_a_fleet_runs_and_records_in_the_map_frame(public_data, tmp_path, capsys):
    sandbox = public_data / "nav2" / "tb3_sandbox.yaml"
    text = (
        f'name = "sandbox"\ntime_limit = 120\n[map]\nfile = "{sandbox}"\n'
        '[[agvs]]\nname = "a"\nstart = [-2.0, -0.5]\ngoal = [2.0, 0.5]\n'
        '[[agvs]]\nname = "b"\nstart = [0.5, 1.8]\ngoal = [-0.5, -1.8]\n'
    )
    scenario_path = tmp_path / "sandbox.toml"
    scenario_path.write_text(text)
    out = tmp_path / "sandbox.mcap"
    code = cli_main(["run", str(scenario_path), "--in-process", "-q", "--json", "-o", str(out)])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0, summary
    for agv in summary["agvs"]:
        assert agv["status"] == "arrived" and agv["collisions"] == 0
        assert agv["route_length"] > 3.5 and agv["distance"] >= 0.9 * agv["route_length"]
    series = extract(open_recording(out))
    assert series.grid.origin == (-10.0, -10.0)
    assert series.agvs.columns["x"][0, 0] == pytest.approx(-2.0)


def test_nav2_depot_arrives_in_both_modes():
    scenario = load_scenario("nav2-depot")
    assert len(scenario.agvs) >= 6 and scenario.grid.resolution == 0.05
    assert {a.goal[0] < a.start[0] for a in scenario.agvs} == {True, False}  # both ways
    local = run_in_process(scenario)
    assert local.success, local.table()
    done = subprocess.run(
        [*CLI, "run", "nav2-depot", "-q", "--json", "--no-record"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    bus = json.loads(done.stdout)
    assert bus["agvs"] == local.to_json()["agvs"]
    for agv in bus["agvs"]:
        assert agv["route_length"] > 20 and agv["distance"] >= agv["route_length"] * 0.95
