"""The in-process simulation on the built-in scenarios: the paper's claims and the fleet."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

from fleet.builtin import builtin_scenarios
from fleet.runtime.inprocess import run_in_process
from fleet.scenario import load_scenario, with_algorithm
from planner.local.config import DwaConfig
from planner.maps.text_maps import parse_text_grid
from planner.nav.fusion import FusionConfig, FusionController

FLEET = (
    "warehouse", "crossing", "corridor", "nav2-depot", "aws-small-warehouse", "turtlebot3-world"
)  # fmt: skip
PAPER_FUSION = (*(f"paper-temporary-{n}" for n in range(4)), "paper-dynamic")


@pytest.fixture(scope="module")
def results():
    """Every built-in scenario, run once in process with its own planner."""
    return {name: run_in_process(load_scenario(name)) for name in builtin_scenarios()}


def test_every_builtin_scenario_ends_within_its_time_limit(results):
    assert set(results) >= {*FLEET, *PAPER_FUSION, "paper-concave"}
    for name, summary in results.items():
        limit = load_scenario(name).time_limit
        assert summary.sim_time <= limit + 1e-9, name
        assert summary.end_reason.startswith("every AGV") or summary.end_reason in (
            "time limit",
            "shift over",  # warehouse-shift: its one-hour shift
        )


def test_the_builtin_shift_runs_its_hour_without_collision_and_delivers(results):
    summary = results["warehouse-shift"]
    assert summary.success and summary.end_reason == "shift over", summary.table()
    assert all(a.min_clearance > 0 for a in summary.agvs)
    # 180 requests an hour: 8 AGVs keep up, within the last tasks still on their way
    assert summary.tasks["delivered"] >= 0.9 * summary.tasks["requested"]


@pytest.mark.parametrize("name", FLEET)
def test_fleet_scenarios_arrive_without_collision(results, name):
    summary = results[name]
    assert summary.success, summary.table()
    assert all(a.min_clearance > 0 for a in summary.agvs)


@pytest.mark.parametrize("name", (*PAPER_FUSION, "paper-concave"))
def test_fusion_arrives_without_collision(results, name):
    summary = results[name]
    assert summary.success, summary.table()


def test_dwa_alone_is_trapped_by_the_concave_obstacle():
    summary = run_in_process(with_algorithm(load_scenario("paper-concave"), "dwa"))
    (agv,) = summary.agvs
    assert agv.status != "arrived"
    assert summary.end_reason == "time limit"


def test_the_same_scenario_gives_the_same_run():
    scenario = load_scenario("crossing")
    first, second = run_in_process(scenario), run_in_process(scenario)
    assert first.to_json()["agvs"] == second.to_json()["agvs"]


def test_paper_fusion_turns_the_start_heading_to_the_first_key_node():
    grid = parse_text_grid("\n".join(["." * 10] * 10))
    for algorithm, expected in (("fusion", math.atan2(8.0, 3.0)), ("astar-dwa", 0.0)):
        config = FusionConfig(algorithm=algorithm, profile="paper")
        ctl = FusionController(grid, (3.5, 8.5), config)
        pose, plan = ctl.start((0.5, 0.5, 0.0))
        assert pose[2] == pytest.approx(expected), algorithm
        assert plan.found


def test_unreachable_goal_fails_instead_of_driving():
    grid = parse_text_grid("..#..\n..#..\n..#..")
    ctl = FusionController(grid, (4.5, 1.5), FusionConfig(dwa=DwaConfig()))
    _, plan = ctl.start((0.5, 1.5, 0.0))
    assert not plan.found
    assert ctl.step((0.5, 1.5, 0.0), (0.0, 0.0, 0.0), 0.0).status == "failed"


def test_cli_run_json_contract():
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "fleet.cli",
            "run",
            "corridor",
            "--in-process",
            "--json",
            "-q",
            "--no-record",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["scenario"] == "corridor" and out["collisions"] == 0
    assert out["sim_time"] > 0 and out["wall_time"] > 0
    assert {a["name"] for a in out["agvs"]} == {"left", "right"}
    for agv in out["agvs"]:
        assert agv["status"] == "arrived" and agv["collisions"] == 0
        assert agv["arrival_time"] > 0 and agv["distance"] > 20 and agv["min_clearance"] > 0


def test_cli_run_exit_status_is_1_when_an_agv_does_not_arrive():
    proc = subprocess.run(
        [sys.executable, "-m", "fleet.cli", "run", "paper-concave", "--in-process",
         "--algorithm", "dwa", "-q", "--no-record"],
        capture_output=True,
        text=True,
        timeout=300,
    )  # fmt: skip
    assert proc.returncode == 1
    assert "timeout" in proc.stdout
