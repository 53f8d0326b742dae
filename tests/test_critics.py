"""DWA as parts: each critic's scores by hand, the choice, the filters, the profiles."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from planner.local.admissible import admissible_mask
from planner.local.behaviour import DEFAULT_BEHAVIOUR, PAPER_BEHAVIOUR, local_behaviour
from planner.local.candidates import Candidates
from planner.local.choice import pick, weighed
from planner.local.config import DwaConfig
from planner.local.critics.clearance import Clearance
from planner.local.critics.facing import Facing
from planner.local.critics.heading import Heading
from planner.local.critics.route import OnRoute
from planner.local.critics.speed import Speed
from planner.local.cycle import Cycle
from planner.local.dwa import DwaPlanner
from planner.local.fallback import Brake, Evade
from planner.local.filters import Admissible, ArrivalSpeed, NoRetreat, YieldEarly
from planner.local.samples import Samples
from planner.local.window import braking_command
from planner.local.yielding import contact_later
from planner.maps.distance_field import DistanceField
from planner.maps.grid import GridMap

CFG = DwaConfig()
FIELD = DistanceField.from_grid(GridMap(np.zeros((20, 30), dtype=bool)))
NO_DISCS = np.zeros((0, 5))


def cycle(**changes) -> Cycle:
    """A cycle at (10, 10) heading +x, at rest, towards (15, 10); ``changes`` by field."""
    fields = dict(
        config=CFG, field=FIELD, pose=(10.0, 10.0, 0.0), command=(0.0, 0.0, 0.0),
        target=(15.0, 10.0), discs=NO_DISCS, reach=0.0, stop=False, previous=(0.0, 0.0, 0.0),
        approach=False, segment=None, route=None, came_by=(), walkers=None, lane_room=None,
        distance=0.0,
    )  # fmt: skip
    fields.update(changes)
    return Cycle(**fields)


def samples(commands, ends, clearance=None, offsets=None, lowering=NO_DISCS) -> Samples:
    """Hand-made samples: ``commands`` (N, 3) whose two-step trajectories go from the
    cycle's pose half-way to ``ends`` (N, 3) and end there."""
    commands, ends = np.array(commands, float), np.array(ends, float)
    start = np.array([10.0, 10.0, 0.0])
    paths = np.stack([(start + ends) / 2, ends], axis=1)  # (N, 2, 3)
    clearance = np.full(len(commands), 1.0) if clearance is None else np.array(clearance, float)
    offsets = None if offsets is None else np.array(offsets, float)
    return Samples(
        commands, paths[:, :, 0].copy(), paths[:, :, 1].copy(), paths[:, :, 2].copy(),
        clearance, clearance, clearance, admissible_mask(CFG, commands, clearance), offsets,
        NO_DISCS, lowering, 1.0,
        float(clearance.max()),
    )  # fmt: skip


def candidates(s: Samples) -> Candidates:
    return Candidates.of(np.arange(len(s.commands)), s)


# the critics, each on samples whose scores are known by hand -----------------------------
def test_heading_scores_the_direction_of_travel_at_the_end_against_the_bearing_to_target():
    s = samples(
        [(0.5, 0.0, 0.0), (0.0, 0.5, 0.0), (0.5, 0.0, 0.0)],
        [(11.0, 10.0, 0.0), (11.0, 10.0, 0.0), (11.0, 10.0, math.pi / 2)],
    )
    # from (11, 10) the target (15, 10) bears 0: travelling +x scores pi; sideways (+y)
    # or with the body turned +y at the end, the travel is 90 degrees off
    got = Heading().score(candidates(s), cycle())
    np.testing.assert_allclose(got, [math.pi, math.pi / 2, math.pi / 2])


def test_heading_gives_full_score_to_a_trajectory_that_passes_within_reach():
    s = samples([(0.5, 0.0, 0.0), (0.5, 0.0, 0.0)], [(16.0, 10.0, 0.0), (16.0, 12.0, 0.0)])
    # the first ends past the target, heading away from it, but its mid point (13, 10)
    # is 2 m from it; the second's (13, 11) is 2.24 m away
    plain = Heading().score(candidates(s), cycle())
    passing = Heading().score(candidates(s), cycle(reach=2.1))
    assert plain[0] == pytest.approx(0.0)
    assert passing[0] == math.pi and passing[1] == plain[1]


def test_clearance_is_capped_and_on_the_final_approach_is_nearness_to_the_target():
    s = samples([(0.1, 0.0, 0.0)] * 3, [(14.0, 10.0, 0.0), (15.0, 10.0, 0.0), (10.0, 10.0, 0.0)],
                clearance=[0.5, 3.0, 1.0])  # fmt: skip
    np.testing.assert_allclose(Clearance().score(candidates(s), cycle()), [0.5, 2.0, 1.0])
    near = Clearance().score(candidates(s), cycle(approach=True))
    np.testing.assert_allclose(near, [2.0 - 1.0, 2.0 - 0.0, 2.0 - 2.0])  # cap - min(d, cap)


def test_speed_scores_the_linear_speed_and_facing_the_angle_off_the_body_heading():
    s = samples([(0.3, 0.4, 0.0), (0.0, -0.2, 0.1), (0.0, 0.0, 0.3)], [(11.0, 10.0, 0.0)] * 3)
    c = candidates(s)
    np.testing.assert_allclose(Speed().score(c, cycle()), [0.5, 0.2, 0.0])
    facing = Facing(weight=0.3).score(c, cycle())
    np.testing.assert_allclose(facing, [math.pi - math.atan2(0.4, 0.3), math.pi / 2, math.pi])


def test_on_route_scores_the_cap_less_the_offset_and_needs_a_segment():
    s = samples([(0.1, 0.0, 0.0)] * 3, [(11.0, 10.0, 0.0)] * 3, offsets=[0.0, 0.5, 3.0])
    on_segment = cycle(segment=((10.0, 10.0), (15.0, 10.0)))
    np.testing.assert_allclose(OnRoute(0.3).score(candidates(s), on_segment), [2.0, 1.5, 0.0])
    assert OnRoute(0.3).applies(on_segment) and not OnRoute(0.3).applies(cycle())


def test_eq_10s_weights_are_the_vehicles_the_profiles_own_critics_carry_theirs():
    cfg = DwaConfig(alpha=0.4, beta=0.5, gamma=0.6)
    assert [c.weight_in(cfg) for c in PAPER_BEHAVIOUR.critics] == [0.4, 0.5, 0.6]
    own = {c.name: c.weight_in(cfg) for c in DEFAULT_BEHAVIOUR.critics[3:]}
    assert own == {"facing": 0.3, "on_route": 0.3}


# the choice ------------------------------------------------------------------------------
def test_the_choice_adds_each_term_divided_by_its_sum_times_its_weight():
    terms = np.array([[1.0, 3.0], [2.0, 2.0], [0.0, 0.0]])  # a zero row counts nothing
    np.testing.assert_allclose(weighed(terms, np.array([1.0, 2.0, 5.0])), [1.25, 1.75])
    commands, speeds = np.zeros((2, 3)), np.zeros(2)
    assert pick(terms, np.array([1.0, 0.0, 0.0]), 0.0, commands, speeds, (0, 0, 0), (0, 0, 0),
                0.0, 0.01) == 1  # fmt: skip
    assert pick(terms[::-1].copy(), np.array([0.0, 1.0, 0.0]), 0.0, commands, speeds,
                (0, 0, 0), (0, 0, 0), 0.0, 0.01) == 0  # ties: the first  # fmt: skip


def _sideways_target(behaviour) -> tuple[float, float, float]:
    """The command chosen by an AGV moving +x at 0.3 m/s whose target lies 45 degrees to
    its left."""
    planner = DwaPlanner(CFG, FIELD, behaviour)
    return planner.plan((10.0, 5.0, 0.0), (0.3, 0.0, 0.0), (16.0, 11.0)).command


def test_taking_a_critic_out_of_the_profile_changes_the_choice():
    facing = dataclasses.replace(
        PAPER_BEHAVIOUR, critics=(*PAPER_BEHAVIOUR.critics, Facing(weight=0.3))
    )
    with_facing, without = _sideways_target(facing), _sideways_target(PAPER_BEHAVIOUR)
    # facing its travel, the body moves straight on (and turns); without, it also slides
    # sideways towards the target
    assert with_facing[1] == 0.0 and without[1] > 0.0
    assert with_facing[0] == without[0] and with_facing[2] == without[2]


# the filters -----------------------------------------------------------------------------
def test_admissible_drops_contact_and_what_cannot_brake_within_its_clearance():
    a, alpha = CFG.max_accel, CFG.max_alpha
    room = 0.5
    fast = math.sqrt(2 * a * room)  # the fastest that brakes within 0.5 m
    s = samples(
        [(fast, 0.0, 0.0), (fast + 0.01, 0.0, 0.0), (0.0, 0.0, math.sqrt(2 * alpha * room) + 0.01),
         (0.0, 0.0, 0.0)],
        [(11.0, 10.0, 0.0)] * 4, clearance=[room, room, room, 0.0],
    )  # fmt: skip
    mask = Admissible().narrow(np.ones(4, bool), s, cycle())
    assert mask.tolist() == [True, False, False, False]  # the last touches: clearance 0


def test_arrival_speed_drops_what_cannot_stop_at_the_target_but_keeps_the_slowest():
    s = samples([(0.1, 0.0, 0.0), (0.3, 0.0, 0.0), (0.5, 0.0, 0.0)], [(11.0, 10.0, 0.0)] * 3)
    at_rest = cycle(stop=True, distance=0.1)  # sqrt(2 0.2 0.1) = 0.2 m/s
    assert ArrivalSpeed().narrow(np.ones(3, bool), s, at_rest).tolist() == [True, False, False]
    touching = cycle(stop=True, distance=0.0)
    assert ArrivalSpeed().narrow(np.ones(3, bool), s, touching).tolist() == [True, False, False]
    assert ArrivalSpeed().narrow(np.ones(3, bool), s, cycle()).all()  # not stopping


def test_no_retreat_drops_driving_off_the_target_only_while_another_agv_is_in_reach():
    s = samples([(0.5, 0.0, 0.0), (-0.5, 0.0, 0.0)], [(11.0, 10.0, 0.0), (9.0, 10.0, 0.0)])
    assert NoRetreat().narrow(np.ones(2, bool), s, cycle()).all()  # no disc in reach
    agv = np.array([[12.0, 10.0, -0.5, 0.0, 0.3]])
    s.lowering = agv
    assert NoRetreat().narrow(np.ones(2, bool), s, cycle()).tolist() == [True, False]
    # a walker does not plan: from it the AGV may back off
    assert NoRetreat().narrow(np.ones(2, bool), s, cycle(walkers=agv)).all()


def test_yield_early_keeps_to_end_points_off_a_walkers_way():
    # a walker comes head-on along the route, which runs +x through the AGV
    route = [(10.0, 10.0), (25.0, 10.0)]
    walker = np.array([[16.0, 10.0, -1.0, 0.0, 0.3]])
    s = samples([(0.5, 0.0, 0.0), (0.0, 0.5, 0.0)], [(11.0, 10.0, 0.0), (10.0, 12.0, 0.0)])
    narrowed = YieldEarly().narrow(np.ones(2, bool), s, cycle(route=route, walkers=walker))
    assert narrowed.tolist() == [False, True]  # on the route it is met; 2 m aside it is not
    assert YieldEarly().narrow(np.ones(2, bool), s, cycle(route=route)).all()


def _aisle(bay: bool = False) -> DistanceField:
    """A 1 m aisle along y = 10 (0.5 m cells), with a 1 m bay on its north side at x = 11..12."""
    blocked = np.ones((40, 60), dtype=bool)
    blocked[19:21, :] = False
    if bay:
        blocked[21:23, 22:24] = False
    return DistanceField.from_grid(GridMap(blocked, 0.5))


AISLE_ROUTE, AISLE_CAME_BY = [(10.0, 10.0), (25.0, 10.0)], [(10.0, 10.0), (0.0, 10.0)]
AISLE_ENDS = [(11.0, 10.0, 0.0), (10.0, 10.0, 0.0), (9.5, 10.0, 0.0), (10.0, 10.3, 0.0)]
AISLE_COMMANDS = [(0.2, 0.0, 0.0), (0.0, 0.0, 0.0), (-0.1, 0.0, 0.0), (0.0, 0.1, 0.0)]


def _yield_in_aisle(walker, bay: bool) -> list[bool]:
    s = samples(AISLE_COMMANDS, AISLE_ENDS)
    at = cycle(field=_aisle(bay), route=AISLE_ROUTE, came_by=AISLE_CAME_BY, walkers=walker)
    return YieldEarly().narrow(np.ones(4, bool), s, at).tolist()


def test_with_no_end_point_off_a_walkers_way_and_no_refuge_yield_early_backs_off():
    # the walker comes head-on at 1 m/s and walks on down the aisle the AGV came by, so
    # every end point is on its way; at 3 s it is at x = 13
    walker = np.array([[16.0, 10.0, -1.0, 0.0, 0.3]])
    s = samples(AISLE_COMMANDS, AISLE_ENDS)
    contact = contact_later(CFG, s.xs[:, -1], s.ys[:, -1], walker, 0.0, AISLE_ROUTE, AISLE_CAME_BY)
    # touching at 0.6 m: driving on is met at 4.4 s, standing at 5.4 s, backing off at 5.9 s,
    # 0.3 m aside (0.52 m along) at 5.48 s
    assert contact == pytest.approx([4.4, 5.4, 5.9, 5.48], abs=0.1)
    # the most clearance from its way (the measure before) kept only the step aside, which
    # the walker reaches as soon as standing: in the aisle the AGV drove on into it
    assert _yield_in_aisle(walker, bay=False) == [False, False, True, False]


def test_with_no_end_point_off_a_walkers_way_yield_early_heads_for_a_refuge_it_reaches_first():
    # the bay 1.5 m ahead: the AGV gets in (1.6 m from rest: 5.7 s) before a walker at
    # 1.5 m/s from x = 21 reaches its mouth (6 s): drive on, towards it
    walker = np.array([[21.0, 10.0, -1.5, 0.0, 0.3]])
    assert _yield_in_aisle(walker, bay=True) == [True, False, False, False]
    # a walker at 1 m/s from x = 16 is there first (4.4 s): back off, as with no bay
    walker = np.array([[16.0, 10.0, -1.0, 0.0, 0.3]])
    assert _yield_in_aisle(walker, bay=True) == [False, False, True, False]


# the profiles and fallbacks --------------------------------------------------------------
def test_each_profile_names_its_parts_once():
    for profile in (PAPER_BEHAVIOUR, DEFAULT_BEHAVIOUR):
        names = [part.name for part in (*profile.critics, *profile.filters)]
        assert len(names) == len(set(names))
    assert [c.name for c in PAPER_BEHAVIOUR.critics] == ["heading", "clearance", "speed"]
    assert [f.name for f in PAPER_BEHAVIOUR.filters] == ["admissible", "arrival_speed"]
    assert isinstance(PAPER_BEHAVIOUR.fallback, Brake)
    assert isinstance(DEFAULT_BEHAVIOUR.fallback, Evade)
    free = local_behaviour("default", free_heading=True)
    assert "facing" not in [c.name for c in free.critics]
    assert local_behaviour("paper", free_heading=True) == PAPER_BEHAVIOUR
    assert not any(
        getattr(PAPER_BEHAVIOUR, f.name)
        for f in dataclasses.fields(PAPER_BEHAVIOUR)
        if f.type == "bool"
    )


def test_with_nothing_admissible_the_paper_brakes_and_evade_brakes_for_agvs_only():
    command = (0.5, 0.1, 0.2)
    s = samples([(0.5, 0.0, 0.0)], [(11.0, 10.0, 0.0)])
    brake, path = Brake().command(s, cycle(command=command))
    assert brake == braking_command(CFG, command) and path.shape == (3, CFG.steps)
    s.in_reach = np.array([[11.0, 10.0, -0.5, 0.0, 0.3]])  # another AGV: brake
    assert Evade().command(s, cycle(command=command))[0] == brake
