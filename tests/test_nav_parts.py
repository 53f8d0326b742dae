"""The controller's parts (``planner.nav``), each on its own job: the progress checker's
window, the goal checker's tolerance, the key-node target switching on a constructed
route, and the modes a short run goes through."""

from __future__ import annotations

import math

import pytest

from planner.core.motion import step_pose
from planner.core.profiles import PAPER
from planner.core.status import BACK_OFF, REPLAN, ROTATE, WAIT
from planner.local.behaviour import local_behaviour
from planner.maps.distance_field import DistanceField
from planner.maps.text_maps import parse_text_grid
from planner.nav.fusion import FusionConfig, FusionController
from planner.nav.goal_checker import GoalChecker
from planner.nav.key_node_targets import KeyNodeTargets
from planner.nav.mode import Mode
from planner.nav.old_ground import OldGround
from planner.nav.progress_checker import ProgressChecker
from planner.nav.recovery_sequence import JAM_RESTARTS, RecoverySequence

DT = 0.5  # s: exact in binary, so the window's end falls on a cycle


def _open_floor(cols: int = 40, rows: int = 20):
    return parse_text_grid("\n".join(["." * cols] * rows), resolution=0.25)


# --- the progress checker ---------------------------------------------------------------
def test_the_progress_checker_fires_after_its_window_without_progress_and_not_before():
    checker = ProgressChecker(window=5.0, distance=0.3)
    assert checker.check(10.0, 0.0)  # the first length is progress
    for k in range(1, 10):
        now = k * DT
        assert not checker.check(10.0 - 0.25, now)  # less than 0.3 m better: not progress
        assert not checker.stalled(now)
    assert checker.stalled(5.0)


def test_progress_restarts_the_window():
    checker = ProgressChecker(window=5.0, distance=0.3)
    checker.check(10.0, 0.0)
    assert checker.check(9.6, 4.5)  # 0.4 m shorter: progress, the window starts again
    assert not checker.stalled(9.0)
    assert checker.stalled(9.5)
    checker.excuse(12.0)  # turning on the spot, or waiting: not a stall
    assert not checker.stalled(16.5)


def test_a_standing_controller_starts_its_first_recovery_at_the_window_s_end():
    config = FusionConfig()
    controller = FusionController(_open_floor(), (8.5, 2.5), config)
    pose = (1.5, 2.5, 0.0)
    controller.start(pose)
    started = {}
    for k in range(20):
        out = controller.step(pose, (0.0, 0.0, 0.0), k * DT)
        if out.recovery:
            started[k * DT] = out.recovery
    # the first cycle ends the start's turn (a turn is progress), the second measures the
    # route; the window then runs from that second cycle
    first = min(started)
    assert first == DT + config.progress_window
    assert started[first] == REPLAN


# --- the goal checker -------------------------------------------------------------------
def test_the_goal_checker_s_tolerance_and_its_stop():
    goal = (5.0, 5.0)
    smooth = GoalChecker(tolerance=0.2, stop_required=True)
    assert smooth.within((5.19, 5.0), goal) and not smooth.within((5.21, 5.0), goal)
    assert smooth.is_goal_reached((5.1, 5.1), goal, (0.0, 0.0, 0.0))
    assert not smooth.is_goal_reached((5.1, 5.1), goal, (0.2, 0.0, 0.0))  # still moving
    assert not smooth.is_goal_reached((5.3, 5.0), goal, (0.0, 0.0, 0.0))
    paper = GoalChecker(tolerance=0.2, stop_required=False)
    assert paper.is_goal_reached((5.1, 5.1), goal, (0.5, 0.0, 0.0))  # on entering it


# --- the key-node targets ---------------------------------------------------------------
ROUTE = [(4.0, 2.0), (4.0, 4.0), (8.0, 4.0)]  # from (1, 2): east, north, east


def _targets(profile: str = PAPER) -> tuple[KeyNodeTargets, DistanceField]:
    field = DistanceField.from_grid(_open_floor(40, 40))  # 10 m square: no tight corner
    config = FusionConfig(profile=profile)
    targets = KeyNodeTargets(config, local_behaviour(profile), ROUTE[-1])
    targets.follow(list(ROUTE), (1.0, 2.0), field)
    return targets, field


def _advance(targets, field, position, heading=0.0):
    return targets.advance((*position, heading), (0.5, 0.0, 0.0), field, lambda node: None)


def test_the_target_switches_within_the_switch_distance_and_never_from_the_goal():
    targets, field = _targets()
    assert targets.segment_start() == (1.0, 2.0)
    _advance(targets, field, (2.9, 2.0))  # 1.1 m short: still the first node
    assert targets.current == ROUTE[0]
    assert targets.remaining((2.9, 2.0)) == pytest.approx(1.1 + 2.0 + 4.0)
    _advance(targets, field, (3.1, 2.0))  # 0.9 m: the next
    assert targets.current == ROUTE[1] and targets.segment_start() == ROUTE[0]
    assert targets.route_ahead() == ROUTE
    _advance(targets, field, (4.0, 3.5))
    assert targets.current == ROUTE[2] and targets.final
    _advance(targets, field, ROUTE[2])  # the goal is never switched from
    assert targets.final and targets.current == ROUTE[2]


def test_nodes_within_reach_at_once_are_all_passed():
    targets, field = _targets()
    targets.follow([(4.0, 2.0), (4.2, 2.4), (8.0, 4.0)], (1.0, 2.0), field)
    _advance(targets, field, (3.8, 2.2))
    assert targets.index == 2


def test_a_node_gone_by_beside_is_passed_when_the_next_is_in_plain_sight():
    beside = (5.0, 2.7)  # 1.2 m off the first node, gone past it beside; 1.3 m short of the next
    paper, field = _targets(PAPER)
    _advance(paper, field, beside)
    assert paper.current == ROUTE[0]  # the paper only switches within reach: back to it
    default, field = _targets("default")
    _advance(default, field, beside)
    assert default.current == ROUTE[1]


# --- the modes of a short run -------------------------------------------------------------
def _run(controller, pose, cycles, hold_from=None, hold_until=None, hold=None):
    """Drive ``controller`` with the pose stepped by its commands (as the world does); the
    modes in the order they came."""
    modes, command, dt = [controller.mode], (0.0, 0.0, 0.0), controller.config.dwa.dt
    for k in range(cycles):
        held = hold if hold_from is not None and hold_from <= k < hold_until else None
        out = controller.step(pose, command, k * dt, hold=held)
        command = out.command
        pose = step_pose(pose, command, dt)
        if controller.mode is not modes[-1]:
            modes.append(controller.mode)
        if controller.mode.finished:
            break
    return modes


def test_a_short_run_turns_in_place_drives_waits_drives_and_arrives():
    controller = FusionController(_open_floor(), (8.5, 2.5), FusionConfig())
    pose = (1.5, 2.5, math.pi)  # facing away from the goal
    controller.start(pose)
    # the turn takes some 10 s at the default turn rate; a hold during it would wait for it
    modes = _run(controller, pose, 600, hold_from=110, hold_until=150, hold=(5.5, 2.5))
    assert modes == [
        Mode.TURNING_IN_PLACE, Mode.DRIVING, Mode.WAITING, Mode.DRIVING, Mode.ARRIVED
    ]  # fmt: skip


def test_no_route_fails_at_once_with_the_reason():
    # a pocket walled off from the goal
    rows = ["#" * 20, "#...#" + "." * 15, "#" * 20]
    controller = FusionController(parse_text_grid("\n".join(rows)), (18.5, 1.5), FusionConfig())
    pose = (2.5, 1.5, 0.0)
    controller.start(pose)
    assert not controller.targets and controller.mode is Mode.FAILED  # no route at all
    assert "no path to the goal" in controller.failure
    assert controller.step(pose, (0.0, 0.0, 0.0), 0.0).status == "failed"


def test_standing_still_runs_the_recovery_sequence_and_then_fails():
    controller = FusionController(_open_floor(), (8.5, 2.5), FusionConfig())
    pose = (1.5, 2.5, 0.0)
    controller.start(pose)
    modes, started = [controller.mode], []
    for k in range(200):
        out = controller.step(pose, (0.0, 0.0, 0.0), k * DT)
        started += [out.recovery] if out.recovery else []
        if controller.mode is not modes[-1]:
            modes.append(controller.mode)
        if controller.mode.finished:
            break
    assert started == [REPLAN, WAIT, BACK_OFF, REPLAN, ROTATE, REPLAN]
    timed = [Mode.RECOVERING, Mode.DRIVING]
    assert modes == [Mode.TURNING_IN_PLACE, Mode.DRIVING, *timed * 3, Mode.FAILED]
    assert controller.failure.startswith("no progress after the recoveries replan, wait")


def _stall_times(script, steps: int) -> dict[float, str]:
    """The recoveries a controller on the open floor (goal (8.5, 2.5)) starts, by time, with
    its position along y = 2.5 at each time given by ``script``."""
    controller = FusionController(_open_floor(), (8.5, 2.5), FusionConfig())
    controller.start((script(0.0), 2.5, 0.0))
    started = {}
    for k in range(steps):
        out = controller.step((script(k * DT), 2.5, 0.0), (0.0, 0.0, 0.0), k * DT)
        if out.recovery:
            started[k * DT] = out.recovery
    return started


def test_driving_back_to_where_the_agv_stalled_is_no_progress():
    # stalled at x = 4.5, then moved back to x = 2.5 and stalled there again; then driven
    # up to x = 4.5 once more. The route from x = 2.5 shrinks as it goes, but all of it is
    # where the sequence has been: the next recovery comes a window after the wait, as
    # if it stood; driven on beyond x = 4.5 it is progress again
    def back_and_forth(up_to: float):
        def x(now: float) -> float:
            if now < 6.0:
                return 4.5
            if now < 10.0:
                return 4.5 - 0.5 * (now - 6.0)
            return min(2.5 + max(0.0, now - 14.0), up_to)

        return x

    back = _stall_times(back_and_forth(4.5), 50)
    assert list(back.items()) == [(5.5, REPLAN), (10.5, WAIT), (18.5, BACK_OFF)]
    onwards = _stall_times(back_and_forth(8.0), 50)
    assert list(onwards.items()) == [(5.5, REPLAN), (10.5, WAIT), (24.5, BACK_OFF)]


def test_old_ground_is_where_a_sequence_was_up_to_its_last_stall():
    ground = OldGround(reach=0.3)
    ground.note((0.0, 0.0))  # no sequence yet: nothing kept
    ground.stall((1.0, 0.0))
    for x in (1.2, 1.4, 1.6, 1.8, 2.0):
        ground.note((x, 0.0))
    assert not ground.reached((0.0, 0.0)) and ground.reached((1.2, 0.1))
    assert not ground.reached((1.8, 0.0))  # reached since the last stall: not old yet
    ground.stall((2.0, 0.0))
    assert ground.reached((1.8, 0.0)) and not ground.reached((2.5, 0.0))
    ground.clear()
    assert not ground.reached((1.2, 0.0))


def test_a_jammed_sequence_starts_again_before_it_fails():
    sequence = RecoverySequence(progress_window=5.0, progress_distance=0.3)
    stalls = range(6 * (JAM_RESTARTS + 1) + 1)
    kinds = [sequence.next(10.0 * k, (0.0, 0.0), agv_near=True) for k in stalls]
    assert kinds[-1] is None and None not in kinds[:-1]
    assert kinds[:6] == [REPLAN, WAIT, WAIT, REPLAN, WAIT, REPLAN]  # no back-off into others
