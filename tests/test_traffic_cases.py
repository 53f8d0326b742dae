"""The traffic suite's cases (benchmarks/traffic_cases.py) are what its table says they are:
deterministic, the counts and widths of their family, starts and goals clear of the walls
and of each other, every goal reachable by the body alone, mirror cases exact mirrors."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from benchmarks import traffic_cases as tc
from benchmarks.nav_episodes import body_path
from bridge.messages import AgvState, Tick
from fleet.scenario import parse_scenario
from planner.maps.costmap import point_clearance
from planner.route.global_planner import plan_global

SEEDS = range(5)
ALL = [tc.make_case(f, s) for f in tc.FAMILIES for s in SEEDS]


def _by_family(family):
    return [c for c in ALL if c.family == family]


def _lane_width(case, x: float) -> float:
    """Width (m) of the free run of cells crossing the column at ``x`` (metres)."""
    grid = case.scenario.grid
    column = ~grid.blocked[:, int(x / grid.resolution)]
    return float(column.sum()) * grid.resolution


def test_deterministic_per_seed_and_different_between_seeds():
    for family in tc.FAMILIES:
        first = tc.make_case.__wrapped__(family, 1)
        again = tc.make_case.__wrapped__(family, 1)
        assert first.toml == again.toml and first.scenario.agvs == again.scenario.agvs, family
        assert tc.make_case.__wrapped__(family, 2).toml != first.toml, family


def test_names_and_at_least_five_seeds_per_family():
    assert {c.family for c in ALL} == set(tc.FAMILIES)
    for case in ALL:
        assert case.name == f"{case.family}/n{case.agvs}/s{case.seed}"
        assert case.agvs == len(case.scenario.agvs)
        assert case.mirror == (case.family in tc.MIRROR_FAMILIES)
    for family in tc.FAMILIES:
        assert len({c.toml for c in _by_family(family)}) == len(SEEDS), family


def test_the_scenario_is_its_toml_and_uses_the_suite_vehicle_and_planner():
    for case in ALL:
        s = case.scenario
        again = parse_scenario(case.toml)
        assert again.agvs == s.agvs and (again.grid.blocked == s.grid.blocked).all()
        assert s.dt == 0.1 and s.grid.resolution == tc.RES
        assert 60 < s.time_limit < 1000
        for a in s.agvs:
            c = a.config
            assert (c.algorithm, c.profile, c.safety_distance) == ("fusion", "default", 0.5)
            assert c.dwa.radius == 0.3 and c.dwa.max_speed == 1.0 and c.dwa.max_accel == 0.5
            assert math.isclose(math.degrees(c.dwa.max_omega), 60)
            assert math.isclose(math.degrees(c.dwa.max_alpha), 120)


def test_agv_counts_per_family():
    for case in ALL:
        names = [a.name for a in case.scenario.agvs]
        left = sum(n.startswith("L") for n in names)
        if case.family.startswith("corridor"):
            assert 2 <= case.agvs <= 6 and left >= 1 and case.agvs - left >= 1, case.name
        elif case.family.startswith("door"):
            assert 6 <= case.agvs <= 12 and left == case.agvs // 2 and case.agvs % 2 == 0
        elif case.family == "crossing":
            assert 4 <= case.agvs <= 8
            assert {n[0] for n in names} == set("WESN"), case.name  # every arm
        else:
            assert case.agvs == int(case.family.split("-")[1])
    # seed-dependent counts: the range is used, not one number
    for family in ("corridor-2", "corridor-3", "corridor-4", "door", "door-2m", "crossing"):
        assert len({c.agvs for c in _by_family(family)}) >= 2, family


def test_passage_widths():
    for width in (2, 3, 4):
        for case in _by_family(f"corridor-{width}"):
            mid = case.scenario.grid.width * tc.RES / 2
            assert _lane_width(case, mid) == pytest.approx(width * 0.5), case.name
    for family, door in (("door", 1.0), ("door-2m", 2.0), ("door-mirror", 1.0)):
        for case in _by_family(family):
            assert _lane_width(case, 10.1) == pytest.approx(door), case.name  # the wall
    crossing = _by_family("crossing")[0]
    assert _lane_width(crossing, 8.0) == pytest.approx(1.5)  # a west arm, between rooms
    for case in _by_family("warehouse-20") + _by_family("warehouse-10"):
        row = case.scenario.grid.blocked[int(8.0 / tc.RES)]  # through the lower shelves
        runs = [len(list(g)) for free, g in itertools.groupby(~row) if free]
        assert runs[1:-1] and set(runs[1:-1]) == {int(2.0 / tc.RES)}, case.name  # 2 m aisles
    big = _by_family("warehouse-20")[0].scenario.grid
    assert (big.width * tc.RES, big.height * tc.RES) == (62, 32)


def test_starts_and_goals_clear_of_walls_and_of_each_other():
    for case in ALL:
        agvs = case.scenario.agvs
        sep = tc.WAREHOUSE_SEPARATION if case.family.startswith("warehouse") else 1.0
        for a in agvs:
            for p in (a.start, a.goal):
                room = point_clearance(case.scenario.grid, p, 1.0)
                assert room >= tc.RADIUS + 0.05 - 1e-9, (case.name, a.name, p)
        for a, b in itertools.combinations(agvs, 2):
            assert math.dist(a.start, b.start) >= sep - 1e-9, (case.name, a.name, b.name)
            assert math.dist(a.goal, b.goal) >= sep - 1e-9, (case.name, a.name, b.name)


def test_each_agv_goes_to_the_other_side():
    for case in ALL:
        width = case.scenario.grid.width * tc.RES
        for a in case.scenario.agvs:
            if case.family.startswith(("corridor", "door")):
                assert (a.start[0] < width / 2) != (a.goal[0] < width / 2), (case.name, a.name)
            elif case.family == "crossing":
                centre = width / 2
                sx, sy = a.start[0] - centre, a.start[1] - centre
                gx, gy = a.goal[0] - centre, a.goal[1] - centre
                assert sx * gx + sy * gy < -50, (case.name, a.name)  # opposite rooms
            else:
                assert math.dist(a.start, a.goal) >= width / 3 - 1e-9


def test_goals_reachable_for_the_body_alone():
    for case in ALL:
        grid = case.scenario.grid
        for a in case.scenario.agvs:
            plan = plan_global(grid, a.start, a.goal, "improved", clearance=a.config.clearance)
            assert plan.found, (case.name, a.name)
    # the body's own lattice (independent of the planner): seed 0 of each family, and in
    # the warehouses (slow on their big lattice) two AGVs of the smallest
    for case in ALL:
        agvs = case.scenario.agvs
        if case.seed or case.family in ("warehouse-20", "warehouse-40"):
            continue
        if case.family.startswith("warehouse"):
            agvs = agvs[:2]
        for a in agvs:
            assert body_path(case.scenario.grid, a.start, a.goal, tc.RADIUS), (case.name, a.name)


def test_mirror_cases_are_exact_mirrors():
    for case in ALL:
        if not case.mirror:
            continue
        s = case.scenario
        width = s.grid.width * tc.RES
        assert (s.grid.blocked == s.grid.blocked[:, ::-1]).all(), case.name
        left = [a for a in s.agvs if a.name.startswith("L")]
        right = {a.name: a for a in s.agvs if a.name.startswith("R")}
        assert len(left) == len(right) == case.agvs // 2
        for a in left:
            b = right["R" + a.name[1:]]
            assert b.start == pytest.approx((width - a.start[0], a.start[1]), abs=1e-9)
            assert b.goal == pytest.approx((width - a.goal[0], a.goal[1]), abs=1e-9)
            assert (a.heading_deg + b.heading_deg) % 360 == pytest.approx(180)
            assert math.dist(a.start, a.goal) == pytest.approx(math.dist(b.start, b.goal))
    assert sum(c.mirror for c in ALL) == 3 * len(SEEDS)


def test_fast_subset():
    subset = tc.fast_subset()
    assert [(c.family, c.agvs) for c in subset] == [
        ("corridor-2-mirror", 2), ("corridor-3", 2), ("corridor-4", 4), ("door", 6),
        ("crossing", 4), ("warehouse-10", 10),
    ]  # fmt: skip
    assert [c.toml for c in subset] == [c.toml for c in tc.fast_subset()]


def _tick(k, states, final=False):
    return Tick(k, k * 0.1, [AgvState(n, k, 0, 0, 0, vx, 0, 0, 0.3, st) for n, vx, st in states],
                final=final)  # fmt: skip


def test_no_case_repeats_a_start_grid_cell_of_another_agv():
    for case in ALL:
        cells = [case.scenario.grid.cell_of(a.start) for a in case.scenario.agvs]
        assert len(set(cells)) == len(cells), case.name
        assert np.isfinite(case.scenario.time_limit)


def test_starts_and_goals_keep_out_of_the_passages_mouths():
    # an AGV that arrived in a doorway would close it for good (see tc.MOUTH_CLEAR)
    for case in ALL:
        if case.family.startswith("warehouse"):
            continue
        grid = case.scenario.grid
        room = ~grid.blocked
        fine = tc.FINE
        passages = []
        if case.family == "crossing":
            rooms = tc._crossing_rooms().values()
        else:
            width = grid.blocked.shape[1] // fine
            rows = range(grid.blocked.shape[0] // fine)
            left = range(0, 12 if case.family.startswith("corridor") else 20)
            right = range(width - len(left), width)
            rooms = [(left, rows), (right, rows)]
        inside = np.zeros(room.shape, dtype=bool)
        for cols, rs in rooms:
            inside[rs.start * fine : rs.stop * fine, cols.start * fine : cols.stop * fine] = True
        rr, cc = np.nonzero(room & ~inside)
        passages = np.column_stack(((cc + 0.5) * grid.resolution, (rr + 0.5) * grid.resolution))
        assert len(passages), case.name
        for a in case.scenario.agvs:
            for p in (a.start, a.goal):
                gap = np.hypot(*(passages - p).T).min()
                assert gap >= tc.MOUTH_CLEAR - tc.CELL / 2 - 1e-9, (case.name, a.name, p)
