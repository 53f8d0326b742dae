"""Each fact of a run defined once: the copies that must agree do, or are refused."""

from __future__ import annotations

from dataclasses import replace

import pytest

from fleet.runtime.world import World
from fleet.scenario import ScenarioError, load_scenario, parse_scenario
from planner.core.motion import CONTROL_PERIOD
from planner.local.config import DwaConfig
from planner.maps.clearance import CLEARANCE_CAP, Clearance
from planner.maps.text_maps import parse_text_grid
from planner.route.global_planner import plan_global
from recordings.rerun_log import recording_dt

TWO_AGVS = """
{dt}
[map]
grid = \"\"\"
........
........
\"\"\"
[[agvs]]
name = "a"
start = [0.5, 0.5]
goal = [7.5, 0.5]
[[agvs]]
name = "b"
start = [0.5, 1.5]
goal = [7.5, 1.5]
max_speed = 1.0
"""


def test_a_scenario_file_gives_every_agv_and_the_world_its_one_control_period():
    sc = parse_scenario(TWO_AGVS.format(dt="dt = 0.25"))
    assert sc.dt == 0.25
    assert [a.config.dwa.dt for a in sc.agvs] == [0.25, 0.25]
    assert World(sc).dt == 0.25


def test_without_dt_every_copy_is_the_papers_control_period():
    sc = parse_scenario(TWO_AGVS.format(dt=""))
    assert CONTROL_PERIOD == 0.1
    assert sc.dt == DwaConfig().dt == CONTROL_PERIOD
    assert [a.config.dwa.dt for a in sc.agvs] == [CONTROL_PERIOD] * 2
    assert recording_dt([]) == CONTROL_PERIOD  # a recording cut before its second tick


def test_a_scenario_whose_agv_plans_with_another_period_is_refused_in_one_line():
    sc = load_scenario("warehouse")
    with pytest.raises(ScenarioError) as err:
        replace(sc, dt=0.2)  # the world would step by 0.2 s, every AGV plan 0.1 s periods
    message = str(err.value)
    assert "\n" not in message
    assert f"AGV {sc.agvs[0].name!r}" in message and "0.1 s" in message and "0.2 s" in message
    other = replace(sc.agvs[-1], config=replace(sc.agvs[-1].config, dwa=DwaConfig(dt=0.05)))
    with pytest.raises(ScenarioError, match=f"AGV {other.name!r} plans with .* 0.05 s"):
        replace(sc, agvs=(*sc.agvs[:-1], other))


def test_the_default_radius_and_clearance_cap_are_one_number_each():
    assert DwaConfig().radius == Clearance().radius
    assert DwaConfig().clearance_cap == CLEARANCE_CAP
    # a route through open space reports its clearance up to the same cap DWA credits
    wide = parse_text_grid("\n".join(["." * 30] * 11), 1.0)
    plan = plan_global(wide, (4.5, 5.5), (25.5, 5.5), "improved", profile="default")
    assert plan.found and plan.clearance == CLEARANCE_CAP
