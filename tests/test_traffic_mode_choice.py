"""Which traffic mode a scenario gets when it leaves the choice to the planner
(``planner.traffic.mode_choice``), and how far ahead an AGV holds reserved nodes."""

from __future__ import annotations

import pytest

from fleet.scenario import load_scenario, parse_scenario
from planner.maps.clearance import Clearance
from planner.maps.costmap import Costmap
from planner.maps.text_maps import parse_text_grid
from planner.traffic.mode_choice import suits_reservations
from planner.traffic.roadmap import Roadmap
from planner.traffic.schedule import RELEASE, Schedule

AISLE = "#" * 22 + "\n#" + "." * 20 + "#\n#" + "." * 20 + "#\n" + "#" * 22
BODY = Clearance(0.3, 0.0)


def grid_of(resolution: float):
    return parse_text_grid(AISLE, resolution, "aisle")


def test_two_agvs_on_cell_centres_of_a_one_body_grid_get_reservations():
    agents = [("a", (1.5, 1.5), (19.5, 1.5)), ("b", (19.5, 2.5), (1.5, 2.5))]
    assert suits_reservations(grid_of(1.0), [BODY, BODY], agents)


@pytest.mark.parametrize(
    ("why", "resolution", "agents"),
    [
        ("one AGV shares space with nobody", 1.0, [("a", (1.5, 1.5), (19.5, 1.5))]),
        ("cells finer than a body", 0.25,
         [("a", (0.4, 0.4), (4.6, 0.4)), ("b", (4.6, 0.6), (0.4, 0.6))]),
        ("a start between cells", 1.0,
         [("a", (2.0, 1.5), (19.5, 1.5)), ("b", (19.5, 2.5), (1.5, 2.5))]),
    ],
)  # fmt: skip
def test_otherwise_zones(why, resolution, agents):
    assert not suits_reservations(grid_of(resolution), [BODY] * len(agents), agents), why


def test_the_built_ins_resolve_by_the_rule_and_an_explicit_mode_wins():
    modes = {name: load_scenario(name).traffic_mode for name in ("corridor", "warehouse")}
    assert modes == {"corridor": "reservations", "warehouse": "reservations"}
    # 0.05 m cells; 0.5 m cells for 0.8 m bodies; one AGV; starts on cell borders
    for name in ("nav2-depot", "single-lane", "paper-dynamic", "crossing"):
        assert load_scenario(name).traffic_mode == "zones", name
    text = load_scenario("corridor").source + '\n[traffic]\nmode = "zones"\n'
    assert parse_scenario(text).traffic_mode == "zones"


def released(stopping: float) -> int:
    """Nodes released ahead of the one reached, down a free aisle."""
    roadmap = Roadmap.for_costmap(Costmap.for_grid(grid_of(1.0), BODY))
    schedule = Schedule(roadmap, [("a", (1.5, 1.5), (20.5, 1.5))], [stopping])
    for _ in range(5):  # a few PIBT steps are planned per update
        (reservation,) = schedule.update({"a": (1.5, 1.5)})
    return len(reservation.path) - 1


def test_an_agv_holds_the_nodes_it_needs_to_stop_in():
    """On a 1 m lattice: at least RELEASE nodes; 10 m of braking (2 m/s at 0.2 m/s²) needs
    the 10 nodes to brake over and the one it stops on."""
    assert released(0.0) == RELEASE
    assert released(10.0) == 11
    assert released(4.5) == 6
