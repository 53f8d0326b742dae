"""DWA for an omnidirectional AGV: motion model, window, clearance, scoring, braking."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from planner.core.motion import step_pose
from planner.local.admissible import admissible_mask
from planner.local.choice import steady_choice
from planner.local.clearance import lower_by_discs, static_clearance
from planner.local.config import DwaConfig
from planner.local.critics.route import on_route
from planner.local.dwa import DwaPlanner
from planner.local.normalise import pairwise_sum
from planner.local.rollout import rollout, rollout_turns, route_offsets, sample_reach
from planner.local.window import braking_command, dynamic_window, window, window_axis
from planner.maps.distance_field import DistanceField
from planner.maps.grid import GridMap

CFG = DwaConfig()
DEG = math.pi / 180


def open_field(width: int = 30, height: int = 20) -> DistanceField:
    return DistanceField.from_grid(GridMap(np.zeros((height, width), dtype=bool)))


def disc_clearance(trajectory: np.ndarray, discs: np.ndarray, dt: float, radius: float):
    """Smallest gap between the AGV on ``trajectory`` (K x 3, steps 1..K) and moving discs."""
    t = dt * np.arange(1, len(trajectory) + 1)[:, None]
    cx, cy = discs[:, 0] + discs[:, 2] * t, discs[:, 1] + discs[:, 3] * t
    gaps = np.hypot(trajectory[:, :1] - cx, trajectory[:, 1:2] - cy) - discs[:, 4] - radius
    return gaps.min()


# --- motion model ---------------------------------------------------------------------------
def test_pure_sideways_motion_at_ninety_degrees_moves_along_minus_x():
    x, y, theta = step_pose((1.0, 2.0, math.pi / 2), (0.0, 1.0, 0.0), 0.5)
    assert (x, y, theta) == pytest.approx((0.5, 2.0, math.pi / 2))


def test_displacement_uses_the_heading_at_the_start_of_the_period():
    theta = math.pi / 6
    x, y, new_theta = step_pose((0.0, 0.0, theta), (2.0, 1.0, 0.5), 0.1)
    assert x == pytest.approx((2.0 * math.cos(theta) - 1.0 * math.sin(theta)) * 0.1)
    assert y == pytest.approx((2.0 * math.sin(theta) + 1.0 * math.cos(theta)) * 0.1)
    assert new_theta == pytest.approx(theta + 0.05)


def test_heading_is_wrapped():
    assert step_pose((0.0, 0.0, 3.1), (0.0, 0.0, 1.0), 0.1)[2] == pytest.approx(3.2 - 2 * math.pi)


def test_rollout_repeats_the_motion_model():
    pose = (3.0, 4.0, 0.7)
    commands = np.array([[1.0, 0.3, 0.2], [0.5, -0.4, -0.35], [0.0, 0.0, 0.1]])
    xs, ys, thetas = rollout(pose, commands, 0.1, 30)
    for n, command in enumerate(commands):
        p = pose
        for k in range(30):
            p = step_pose(p, tuple(command), 0.1)
            assert (xs[n, k], ys[n, k]) == pytest.approx(p[:2], abs=1e-9)
            assert math.remainder(thetas[n, k] - p[2], math.tau) == pytest.approx(0, abs=1e-9)


# --- configuration --------------------------------------------------------------------------
def test_defaults_are_the_papers():
    assert (CFG.max_speed, CFG.max_accel, CFG.v_resolution, CFG.dt) == (2.0, 0.2, 0.01, 0.1)
    assert CFG.max_omega == pytest.approx(20 * DEG)
    assert CFG.max_alpha == pytest.approx(50 * DEG)
    assert CFG.omega_resolution == pytest.approx(1 * DEG)
    assert (CFG.alpha, CFG.beta, CFG.gamma) == (0.1, 0.2, 0.2)


@pytest.mark.parametrize(
    "bad",
    [{"max_speed": 0}, {"dt": -0.1}, {"alpha": -1}, {"min_vx": 0.5}, {"predict_time": 0.05},
     {"radius": math.nan}],
)  # fmt: skip
def test_bad_configurations_are_rejected(bad):
    name = next(iter(bad))
    with pytest.raises(ValueError, match=name):
        DwaConfig(**bad)


# --- the dynamic window ---------------------------------------------------------------------
@pytest.mark.parametrize(
    "command",
    [(0.5, 0.1, 5 * DEG), (0.0, 0.0, 0.0), (1.95, 0.3, -19 * DEG), (1.5, 1.3, 20 * DEG),
     (0.01, -1.99, 0.0)],
)  # fmt: skip
def test_every_sample_respects_the_speed_and_acceleration_limits(command):
    samples = dynamic_window(CFG, command)
    dv, dw = CFG.max_accel * CFG.dt, CFG.max_alpha * CFG.dt
    eps = 1e-9
    assert len(samples) > 0
    assert np.all(np.abs(samples[:, 0] - command[0]) <= dv + eps)
    assert np.all(np.abs(samples[:, 1] - command[1]) <= dv + eps)
    assert np.all(np.abs(samples[:, 2] - command[2]) <= dw + eps)
    assert np.all(samples[:, 0] >= CFG.min_vx - eps)
    assert np.all(np.abs(samples[:, :2]) <= CFG.max_speed + eps)
    assert np.all(np.hypot(samples[:, 0], samples[:, 1]) <= CFG.max_speed + eps)
    assert np.all(np.abs(samples[:, 2]) <= CFG.max_omega + eps)
    assert np.any(np.all(np.isclose(samples, command, rtol=0, atol=1e-9), axis=1))


def test_window_size_at_the_papers_resolution():
    assert len(dynamic_window(CFG, (0.5, 0.1, 5 * DEG))) == 5 * 5 * 11
    at_rest = dynamic_window(CFG, (0.0, 0.0, 0.0))
    assert len(at_rest) == 3 * 5 * 11  # no reversing: vx in {0, 0.01, 0.02}
    assert np.any(np.all(at_rest == 0.0, axis=1))  # standing still is exactly a sample


def test_a_command_beyond_the_limits_is_brought_back_at_full_deceleration():
    dv = CFG.max_accel * CFG.dt
    axis = window_axis(2.5, CFG.min_vx, CFG.max_speed, dv, CFG.v_resolution)
    assert axis.tolist() == pytest.approx([2.5 - dv])


@pytest.mark.parametrize(
    "command",
    [(0.5, 0.1, 5 * DEG), (0.0, 0.0, 0.0), (1.95, 0.3, -19 * DEG), (0.3, 0.0, 80 * DEG),
     (1.99, 0.2, 0.0)],
)  # fmt: skip
def test_the_windows_turn_rates_roll_out_as_a_search_for_them_would(command):
    samples = window(CFG, command)
    omegas, which = np.unique(samples.commands[:, 2], return_inverse=True)
    np.testing.assert_array_equal(samples.omegas[samples.which], samples.commands[:, 2])
    np.testing.assert_array_equal(samples.omegas, omegas)
    np.testing.assert_array_equal(samples.which, which)
    pose = (3.0, 4.0, 0.7)
    x, y, theta = pose
    np.testing.assert_array_equal(  # how a control cycle rolls them out (``Samples.of``)
        rollout_turns(
            x, y, theta, samples.commands, samples.omegas, samples.which, CFG.dt, CFG.steps
        ),
        rollout(pose, samples.commands, CFG.dt, CFG.steps),
    )


def test_sample_reach_is_the_farthest_trajectory_point_as_numpy_computes_it():
    rng = np.random.default_rng(3)
    for _ in range(200):
        xs = rng.normal(size=(int(rng.integers(1, 400)), 30)) * rng.choice([0.1, 3.0, 50.0])
        ys = rng.normal(size=xs.shape)
        pose = (float(rng.normal()), float(rng.normal()), 0.0)
        expected = math.sqrt(float(((xs - pose[0]) ** 2 + (ys - pose[1]) ** 2).max()))
        assert sample_reach(pose, xs, ys) == expected


# --- clearance and admissibility ------------------------------------------------------------
def test_moving_discs_are_predicted_at_the_time_of_each_step():
    field = open_field(10, 10)
    cfg = DwaConfig(predict_time=1.0)
    xs, ys, _ = rollout((5.0, 5.0, 0.0), np.zeros((1, 3)), cfg.dt, cfg.steps)  # standing still
    disc = np.array([[3.0, 6.0, 1.0, 0.0, 0.2]])  # at (4, 6) after the horizon's last step (1 s)
    static = static_clearance(xs, ys, field.samples, 1 / field.spacing, cfg.radius)
    clearance = lower_by_discs(xs, ys, static, disc, cfg.dt, cfg.radius)
    assert clearance[0] == pytest.approx(math.sqrt(2) - 0.2 - cfg.radius, abs=1e-9)


def test_discs_lower_the_clearance_exactly_as_the_minimum_over_steps_and_discs():
    # the kernel skips the square root of pairs too far to matter: the result must still be
    # the exact minimum wherever it is positive (and not positive where that is not)
    field = open_field(10, 10)
    rng = np.random.default_rng(3)
    commands = np.column_stack((rng.uniform(0, 1, 200), rng.uniform(-1, 1, 200), np.zeros(200)))
    xs, ys, _ = rollout((5.0, 5.0, 0.0), commands, CFG.dt, CFG.steps)
    discs = np.column_stack(
        (rng.uniform(1, 9, (8, 2)), rng.uniform(-0.5, 0.5, (8, 2)), rng.uniform(0.1, 0.3, 8))
    )
    static = static_clearance(xs, ys, field.samples, 1 / field.spacing, CFG.radius)
    got = lower_by_discs(xs, ys, static, discs, CFG.dt, CFG.radius)
    t = (np.arange(CFG.steps) + 1) * CFG.dt
    dx = xs[:, :, None] - (discs[:, 0] + discs[:, 2] * t[:, None])
    dy = ys[:, :, None] - (discs[:, 1] + discs[:, 3] * t[:, None])
    gaps = np.sqrt(dx * dx + dy * dy) - discs[:, 4] - CFG.radius
    want = np.minimum(static, gaps.min(axis=(1, 2)))
    assert (want > 0).any() and (want <= 0).any()
    assert np.array_equal(got[want > 0], want[want > 0])
    assert (got[want <= 0] <= 0).all()


def test_on_route_scores_the_largest_distance_from_the_route_segment():
    # two trajectories along y = 1 and y = 0.5 beside the segment (0, 0)-(4, 0), the first
    # running past its end to (6, 1): its largest distance is to the end point, sqrt(5)
    xs = np.array([np.linspace(0.5, 6.0, 12), np.linspace(0.5, 3.0, 12)])
    ys = np.array([np.full(12, 1.0), np.full(12, 0.5)])
    offsets = route_offsets(xs, ys, ((0.0, 0.0), (4.0, 0.0)))
    got = on_route(offsets, 3.0)
    assert got == pytest.approx([3.0 - math.sqrt(5.0), 2.5], abs=1e-12)
    assert on_route(offsets, 1.0) == pytest.approx([0.0, 0.5])
    # a segment of no length: the distance to its point
    assert on_route(route_offsets(xs[1:, :1], ys[1:, :1], ((0.5, 0.0), (0.5, 0.0))), 3.0)[0] == 2.5


def test_static_clearance_subtracts_the_radius():
    field = open_field(10, 10)
    xs, ys, _ = rollout((1.5, 5.0, 0.0), np.array([[0.0, 0.0, 0.0]]), 0.1, 5)
    clearance = static_clearance(xs, ys, field.samples, 1 / field.spacing, 0.3)
    assert clearance[0] == pytest.approx(1.2, abs=0.05)


def test_admissible_means_able_to_brake_within_the_clearance():
    commands = np.array(
        [[0.6, 0.0, 0.0], [0.5, 0.4, 0.0], [0.0, 0.0, 1.3], [0.0, 0.0, 1.4], [0.0, 0.0, 0.0]]
    )
    clearance = np.array([1.0, 1.0, 1.0, 1.0, 0.0])
    # speed <= sqrt(2 * 1.0 * 0.2) = 0.632; |omega| <= sqrt(2 * 1.0 * 0.873) = 1.32
    assert admissible_mask(CFG, commands, clearance).tolist() == [True, False, True, False, False]


# --- choices ---------------------------------------------------------------------------------
@pytest.mark.parametrize("side", [1, -1])
def test_xhead_turns_towards_the_local_target(side):
    planner = DwaPlanner(CFG, open_field())
    result = planner.plan((10.0, 10.0, 0.0), (0.5, 0.0, 0.0), (10.0, 10.0 + side * 5.0))
    assert result.admissible
    assert math.copysign(1, result.command[2]) == side and result.command[2] != 0


def test_xhead_aims_at_the_local_target_not_straight_ahead():
    planner = DwaPlanner(CFG, open_field())
    ahead = planner.plan((10.0, 10.0, 0.0), (0.5, 0.0, 0.0), (20.0, 10.0))
    assert ahead.command[2] == 0.0


def test_chosen_trajectory_starts_with_the_motion_model():
    planner = DwaPlanner(CFG, open_field())
    pose, command = (10.0, 10.0, 0.3), (0.5, 0.1, 2 * DEG)
    result = planner.plan(pose, command, (20.0, 15.0))
    assert result.trajectory.shape == (CFG.steps, 3)
    assert result.trajectory[0] == pytest.approx(step_pose(pose, result.command, CFG.dt))


def test_driving_at_a_wall_stops_before_it():
    blocked = np.zeros((10, 30), dtype=bool)
    blocked[:, 20] = True  # a wall across the whole map: no way round
    field = DistanceField.from_grid(GridMap(blocked))
    planner = DwaPlanner(CFG, field)
    pose, command = (12.0, 5.0, 0.0), (1.0, 0.0, 0.0)
    for _ in range(600):
        command = planner.plan(pose, command, (25.0, 5.0)).command
        pose = step_pose(pose, command, CFG.dt)
        assert field.distance_at(pose[0], pose[1]) - CFG.radius > 0, pose
    assert pose[0] < 20.0 - CFG.radius
    assert step_pose(pose, command, 1.0)[0] - pose[0] == pytest.approx(0, abs=0.05)


def test_a_disc_coming_head_on_is_avoided():
    planner = DwaPlanner(CFG, open_field())
    pose, command = (5.0, 10.0, 0.0), (0.8, 0.0, 0.0)
    disc = np.array([[14.0, 10.0, -0.8, 0.0, 0.3]])
    for _ in range(250):
        command = planner.plan(pose, command, (25.0, 10.0), disc).command
        pose = step_pose(pose, command, CFG.dt)
        disc[0, :2] += disc[0, 2:4] * CFG.dt
        gap = math.hypot(pose[0] - disc[0, 0], pose[1] - disc[0, 1]) - 0.3 - CFG.radius
        assert gap > 0, (pose, disc)
    assert pose[0] > 14.0  # and it got past


def test_chosen_trajectories_never_touch_obstacles_in_clutter():
    rng = np.random.default_rng(3)
    grid = GridMap(rng.random((30, 30)) < 0.15)
    field = DistanceField.from_grid(grid)
    planner = DwaPlanner(CFG, field)
    chosen = 0
    for _ in range(300):
        x, y = rng.random(2) * 30
        if field.distance_at(x, y) < CFG.radius + 0.1:
            continue
        discs = np.column_stack(
            (rng.uniform(x - 5, x + 5, (6, 2)), rng.uniform(-1, 1, (6, 2)), np.full(6, 0.3))
        )
        command = (rng.uniform(0, 0.3), rng.uniform(-0.1, 0.1), rng.uniform(-0.2, 0.2))
        result = planner.plan((x, y, rng.uniform(-3, 3)), command, tuple(rng.random(2) * 30), discs)
        if not result.admissible:
            continue
        chosen += 1
        path = result.trajectory
        assert field.distance_at(path[:, 0], path[:, 1]).min() - CFG.radius > 0
        assert disc_clearance(path, discs, CFG.dt, CFG.radius) > 0
    assert chosen > 50


def test_boxed_in_it_brakes_as_hard_as_allowed():
    blocked = np.ones((3, 3), dtype=bool)
    blocked[1, 1] = False  # one free cell, the AGV in it moving at 0.5 m/s
    planner = DwaPlanner(CFG, DistanceField.from_grid(GridMap(blocked)))
    command = (0.5, -0.1, 10 * DEG)
    result = planner.plan((1.5, 1.5, 0.0), command, (5.0, 5.0))
    assert not result.admissible and result.admissible_samples == 0 and result.samples == 275
    assert result.command == pytest.approx((0.48, -0.08, 5 * DEG))
    assert result.command == pytest.approx(braking_command(CFG, command))
    assert result.trajectory.shape == (CFG.steps, 3)


def test_braking_stops_at_zero():
    assert braking_command(CFG, (0.01, -0.015, 2 * DEG)) == (0.0, -0.0, 0.0)


def test_a_new_distance_field_makes_temporary_obstacles_known():
    field = open_field()
    planner = DwaPlanner(CFG, field)
    pose, command = (10.0, 10.5, 0.0), (0.5, 0.0, 0.0)
    assert planner.plan(pose, command, (20.0, 10.5)).admissible
    planner.distance_field = field.with_blocked([(11, 10)])  # 0.5 m ahead: too close to stop
    after = planner.plan(pose, command, (20.0, 10.5))
    assert not after.admissible and after.command == braking_command(CFG, command)


# --- arriving (beyond the paper) --------------------------------------------------------
def test_stop_brakes_to_rest_at_the_target():
    planner = DwaPlanner(CFG, open_field(40, 20))
    pose, command, goal = (2.0, 10.0, 0.0), (0.0, 0.0, 0.0), (30.0, 10.0)
    dv = CFG.max_accel * CFG.dt
    for _ in range(1200):
        previous = command
        command = planner.plan(pose, command, goal, reach=0.2, stop=True).command
        speed = math.hypot(command[0], command[1])
        room = math.dist(pose[:2], goal)
        hardest = math.hypot(max(abs(previous[0]) - dv, 0), max(abs(previous[1]) - dv, 0))
        # never faster than it can brake within the distance left, unless braking hard
        assert speed <= max(math.sqrt(2 * CFG.max_accel * room), hardest) + 1e-9
        pose = step_pose(pose, command, CFG.dt)
        if math.dist(pose[:2], goal) <= 0.2:
            break
    assert math.dist(pose[:2], goal) <= 0.2
    assert math.hypot(command[0], command[1]) < 0.35  # arriving slowly, not racing through


def test_without_reach_plain_dwa_overshoots_a_close_target():
    planner = DwaPlanner(CFG, open_field(40, 20))
    pose, command, goal = (2.0, 10.0, 0.0), (0.0, 0.0, 0.0), (12.0, 10.0)
    for _ in range(600):
        command = planner.plan(pose, command, goal).command
        pose = step_pose(pose, command, CFG.dt)
    assert math.dist(pose[:2], goal) > 0.2  # it does not stay at the target


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
def test_compiled_sums_equal_numpys_bit_for_bit(scale):
    """The compiled scores divide by sums; a sum in another order (a plain loop) differs
    in the last bits and can flip a choice between near-equal samples."""
    rng = np.random.default_rng(7)
    for n in [*range(0, 300), 1000, 4099]:
        values = rng.random(n) * scale * rng.choice([1e-6, 1.0, 1e6], n)
        assert pairwise_sum(values) == values.sum(), n
    plain = rng.random(1000)
    assert sum(plain.tolist()) != plain.sum()  # the order matters for these values


def test_the_steady_choice_breaks_ties_by_score_then_first():
    score = np.array([1.0, 0.99, 0.995, 0.995, 0.2])
    change = np.array([0.5, 0.1, 0.1, 0.1, 0.0])
    # within 10 % of the spread of the best: 0..3; least change: 1, 2, 3; best score: 2, 3
    assert steady_choice(score, change, 0.1, np.zeros(5), 0.0, 0.01) == 2


def test_config_numbers_are_floats_whatever_the_file_wrote():
    """A scenario file may write ``max_accel = 1``: the kernels still see one type (a new
    type would compile them again mid-run, after the warm-up)."""
    config = DwaConfig(max_accel=1, max_speed=2, dt=0.1)
    assert all(type(getattr(config, f.name)) is float for f in dataclasses.fields(config))
    assert config.max_accel == 1.0
