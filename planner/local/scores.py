"""DWA's choice among the admissible samples, compiled: Eq. (10), the default profile's
terms and the steady choice (see ``planner.local.dwa``).

One control cycle scores a few hundred samples. As numpy expressions these were some
thirty small array operations, each paying Python's and numpy's call overhead; compiled
they are one call. Every operation is the one numpy did, in the same order, and sums
follow numpy's pairwise order (``pairwise_sum``), so the choice is the same bit for bit.
They are written as loops: numba compiled the array expressions (broadcasting, fancy
indexing) four times slower, and a fresh install compiles every kernel before its first
run.
"""

from __future__ import annotations

import numba
import numpy as np

from planner.core.motion import wrap_angle

_EPS = 1e-9
_PAIRWISE_BLOCK = 128  # numpy's PW_BLOCKSIZE


@numba.njit(cache=True)
def _block_sum(values, start, count):
    """numpy's sum of one block (at most 128 values): eight running sums, combined in
    pairs, then the rest one by one (below 8 values, one by one from 0)."""
    if count < 8:
        total = 0.0
        for i in range(count):
            total += values[start + i]
        return total
    r = values[start : start + 8].copy()  # eight running sums
    i = 8
    while i < count - count % 8:
        for j in range(8):
            r[j] += values[start + i + j]
        i += 8
    total = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    while i < count:
        total += values[start + i]
        i += 1
    return total


@numba.njit(cache=True)
def pairwise_sum(values):
    """The sum of a 1-D float array as ``ndarray.sum`` computes it, bit for bit: numpy's
    ``pairwise_sum`` halves a run (at a multiple of 8) until it is a block of at most 128
    values, and adds each half's sum. Its recursion is walked here with a stack (a
    recursive compiled function crashed when loaded from numba's cache)."""
    frames = 64  # halving: deep enough for any array
    start = np.empty(frames, dtype=np.int64)
    count = np.empty(frames, dtype=np.int64)
    phase = np.zeros(frames, dtype=np.int64)  # 0: left half next, 1: right next, 2: add
    left = np.empty(frames)
    top, start[0], count[0] = 0, 0, values.size
    done = 0.0  # the sum of the run last finished
    while True:
        s, c = start[top], count[top]
        half = c // 2 - (c // 2) % 8
        if c <= _PAIRWISE_BLOCK:
            done = _block_sum(values, s, c)
        elif phase[top] < 2:
            if phase[top] == 1:
                left[top] = done
            phase[top] += 1
            start[top + 1] = s if phase[top] == 1 else s + half
            count[top + 1] = half if phase[top] == 1 else c - half
            phase[top + 1] = 0
            top += 1
            continue
        else:
            done = left[top] + done
        top -= 1
        if top < 0:
            return 0.0 + done


@numba.njit(cache=True)
def normalised(term):
    """``term`` divided by its sum (all zeros when the sum is zero)."""
    total = pairwise_sum(term)
    out = np.zeros(term.size)
    if total > 0:
        for i in range(term.size):
            out[i] = term[i] / total
    return out


@numba.njit(cache=True)
def speeds_of(commands):
    """(N,) |(vx, vy)| of (N, 3) commands."""
    out = np.empty(len(commands))
    for i in range(len(commands)):
        out[i] = np.hypot(commands[i, 0], commands[i, 1])
    return out


@numba.njit(cache=True)
def travel_angles(commands, speeds):
    """(N,) each sample's direction of travel off the body heading, atan2(vy, vx) (0 when
    standing): an omnidirectional AGV need not face where it goes. ``speeds``:
    ``speeds_of(commands)``."""
    out = np.zeros(len(commands))
    for i in range(len(commands)):
        if speeds[i] > _EPS:
            out[i] = np.arctan2(commands[i, 1], commands[i, 0])
    return out


@numba.njit(cache=True)
def xhead(travel, end_x, end_y, end_theta, target_x, target_y):
    """Eq. (10)'s heading term: pi - |error| between the bearing from the trajectory's end
    to the target and the direction of travel (``travel_angles`` off the end heading):
    that direction, not the body heading, is what must point at the target."""
    out = np.empty(travel.size)
    for i in range(travel.size):
        bearing = np.arctan2(target_y - end_y[i], target_x - end_x[i])
        out[i] = np.pi - abs(wrap_angle(bearing - (end_theta[i] + travel[i])))
    return out


@numba.njit(cache=True)
def facing(travel):
    """pi - the angle between the body heading and the direction of travel (pi standing)."""
    out = np.empty(travel.size)
    for i in range(travel.size):
        out[i] = np.pi - abs(travel[i])
    return out


@numba.njit(cache=True)
def on_route(offsets, cap):
    """cap - each trajectory's ``route_offsets`` (capped at ``cap``): trajectories that stay
    on the global route score highest, so the AGV lines up with a narrow passage the route
    goes through before it gets there."""
    out = np.empty(offsets.size)
    for i in range(offsets.size):
        out[i] = cap - min(offsets[i], cap)
    return out


@numba.njit(cache=True)
def jerk(commands, command, previous, speed):
    """(N,) how much each sample changes the last cycle's acceleration, in m/s per period.

    Linear axes: |(sample - command) - (command - previous)|; omega adds the same change
    times the current ``speed`` (|(vx, vy)| of ``command``), since a turn rate change of
    dw changes the world-frame velocity by speed x dw.
    """
    keep_x = 2.0 * command[0] - previous[0]
    keep_y = 2.0 * command[1] - previous[1]
    keep_w = 2.0 * command[2] - previous[2]
    out = np.empty(len(commands))
    for i in range(len(commands)):
        linear = np.hypot(commands[i, 0] - keep_x, commands[i, 1] - keep_y)
        out[i] = linear + speed * abs(commands[i, 2] - keep_w)
    return out


@numba.njit(cache=True)
def _first_best(score):
    """The index of the highest score, the first of equals (``np.argmax``)."""
    best = 0
    for i in range(1, score.size):
        if score[i] > score[best]:
            best = i
    return best


@numba.njit(cache=True)
def steady_choice(score, change, tolerance, speeds, speed, step):
    """The sample of least ``change`` among those scoring within ``tolerance`` of the best
    (ties: the higher score, then the first).

    ``tolerance`` is a fraction of the scores' spread. The normalised scores
    of neighbouring samples differ by little, so the plain argmax hops
    between them every cycle and the acceleration flips; preferring the
    steadiest near-best sample keeps the acceleration unless a clearly
    better command exists. But when the best sample is faster than the
    current ``speed``, only near-best samples at least ``step`` faster count:
    the speed term, divided by its sum over thousands of samples, differs by
    less than the tolerance between neighbouring speeds, so without this the
    choice kept a crawl (0.14 m/s for 90 s in a 1.0 m corridor whose Eq. 7
    limit is 0.45 m/s).
    """
    top, low = score[0], score[0]
    for value in score:
        top, low = max(top, value), min(low, value)
    floor = top - tolerance * (top - low)
    faster_only = False
    if speeds[_first_best(score)] > speed + step:
        for i in range(score.size):
            if score[i] >= floor and speeds[i] >= speed + step:
                faster_only = True
                break
    best = -1
    for i in range(score.size):
        near = score[i] >= floor and (not faster_only or speeds[i] >= speed + step)
        if near and (
            best < 0
            or change[i] < change[best]
            or (change[i] == change[best] and score[i] > score[best])
        ):
            best = i
    return best


@numba.njit(cache=True)
def choose(
    ok, commands, xs, ys, thetas, clearance, offsets, target_x, target_y, reach, approach,
    weights, cap, steady, command, previous, speed, step,
):  # fmt: skip
    """The index (into ``commands``) of the admissible sample DWA drives: the best of
    Eq. (10) plus the default profile's terms, or the steadiest near-best.

    ``ok``: the admissible samples' indices; ``xs``, ``ys``, ``thetas`` (N, K) their
    rollouts, ``clearance`` (N,) their least clearance; ``offsets`` (N,) how far each
    strays from the route (used when the route weight is > 0). A trajectory within
    ``reach`` (> 0) of the target scores full xhead; with ``approach`` nearness of the
    end to the target replaces the clearance. ``weights``: alpha, beta, gamma of Eq. (10),
    then the facing and route weights; ``cap``: the largest clearance (and nearness)
    credited. ``steady`` > 0: the steady choice's tolerance, for a ``command`` (moving at
    ``speed``) after ``previous``, ``step`` the least speed-up that counts as faster.
    """
    alpha, beta, gamma, face_weight, route_weight = weights
    n, last = ok.size, xs.shape[1] - 1
    sampled = np.empty((n, 3))
    end_x, end_y, end_theta, room = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    for i in range(n):
        k = ok[i]
        sampled[i, 0], sampled[i, 1], sampled[i, 2] = commands[k, 0], commands[k, 1], commands[k, 2]
        end_x[i], end_y[i], end_theta[i] = xs[k, last], ys[k, last], thetas[k, last]
    speeds = speeds_of(sampled)
    travel = travel_angles(sampled, speeds)
    head = xhead(travel, end_x, end_y, end_theta, target_x, target_y)
    for i in range(n):
        if reach > 0:  # a trajectory that passes the target: full xhead
            k, near = ok[i], np.inf
            for step_k in range(last + 1):
                gap_x, gap_y = xs[k, step_k] - target_x, ys[k, step_k] - target_y
                near = min(near, gap_x * gap_x + gap_y * gap_y)
            if near <= reach * reach:
                head[i] = np.pi
        if approach:  # nearness to the target in place of clearance
            room[i] = cap - min(np.hypot(end_x[i] - target_x, end_y[i] - target_y), cap)
        else:
            room[i] = clearance[ok[i]]
        room[i] = min(room[i], cap)
    by_head, by_room, by_speed = normalised(head), normalised(room), normalised(speeds)
    score = np.empty(n)
    for i in range(n):
        score[i] = alpha * by_head[i] + beta * by_room[i] + gamma * by_speed[i]
    if face_weight > 0:
        by_facing = normalised(facing(travel))
        for i in range(n):
            score[i] = score[i] + face_weight * by_facing[i]
    if route_weight > 0:
        strays = np.empty(n)
        for i in range(n):
            strays[i] = offsets[ok[i]]
        by_route = normalised(on_route(strays, cap))
        for i in range(n):
            score[i] = score[i] + route_weight * by_route[i]
    if steady > 0 and speed >= _EPS:  # at rest: nothing to keep
        change = jerk(sampled, command, previous, speed)
        return ok[steady_choice(score, change, steady, speeds, speed, step)]
    return ok[_first_best(score)]
