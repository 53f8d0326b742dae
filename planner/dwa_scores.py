"""DWA's choice among the admissible samples, compiled: Eq. (10), the default profile's
terms and the steady choice (see ``planner.dwa``).

One control cycle scores a few hundred samples. As numpy expressions these were some
thirty small array operations, each paying Python's and numpy's call overhead; compiled
they are one call. Every operation is the one numpy did, in the same order, and sums
follow numpy's pairwise order (``pairwise_sum``), so the choice is the same bit for bit.
"""

from __future__ import annotations

import numba
import numpy as np

from planner.motion import wrap_angle

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
    r0, r1, r2, r3 = values[start], values[start + 1], values[start + 2], values[start + 3]
    r4, r5, r6, r7 = values[start + 4], values[start + 5], values[start + 6], values[start + 7]
    i = 8
    while i < count - count % 8:
        j = start + i
        r0, r1, r2, r3 = r0 + values[j], r1 + values[j + 1], r2 + values[j + 2], r3 + values[j + 3]
        r4, r5, r6, r7 = (
            r4 + values[j + 4],
            r5 + values[j + 5],
            r6 + values[j + 6],
            r7 + values[j + 7],
        )
        i += 8
    total = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
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
    return term / total if total > 0 else np.zeros_like(term)


@numba.njit(cache=True)
def speeds_of(commands):
    """(N,) |(vx, vy)| of (N, 3) commands."""
    return np.hypot(commands[:, 0], commands[:, 1])


@numba.njit(cache=True)
def travel_angles(commands, speeds):
    """(N,) each sample's direction of travel off the body heading, atan2(vy, vx) (0 when
    standing): an omnidirectional AGV need not face where it goes. ``speeds``:
    ``speeds_of(commands)``."""
    return np.where(speeds > _EPS, np.arctan2(commands[:, 1], commands[:, 0]), 0.0)


@numba.njit(cache=True)
def xhead(travel, end_x, end_y, end_theta, target_x, target_y):
    """Eq. (10)'s heading term: pi - |error| between the bearing from the trajectory's end
    to the target and the direction of travel (``travel_angles`` off the end heading):
    that direction, not the body heading, is what must point at the target."""
    bearing = np.arctan2(target_y - end_y, target_x - end_x)
    return np.pi - np.abs(wrap_angle(bearing - (end_theta + travel)))


@numba.njit(cache=True)
def facing(travel):
    """pi - the angle between the body heading and the direction of travel (pi standing)."""
    return np.pi - np.abs(travel)


@numba.njit(cache=True)
def on_route(offsets, cap):
    """cap - each trajectory's ``route_offsets`` (capped at ``cap``): trajectories that stay
    on the global route score highest, so the AGV lines up with a narrow passage the route
    goes through before it gets there."""
    return cap - np.minimum(offsets, cap)


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
    return np.hypot(commands[:, 0] - keep_x, commands[:, 1] - keep_y) + speed * np.abs(
        commands[:, 2] - keep_w
    )


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
    top, low = score.max(), score.min()
    near = score >= top - tolerance * (top - low)
    if speeds[np.argmax(score)] > speed + step:
        faster = near & (speeds >= speed + step)
        if faster.any():
            near = faster
    best = -1
    for i in range(score.size):
        if near[i] and (
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
    sampled = commands[ok]
    end_x, end_y, end_theta = xs[ok, -1], ys[ok, -1], thetas[ok, -1]
    speeds = speeds_of(sampled)
    travel = travel_angles(sampled, speeds)
    head = xhead(travel, end_x, end_y, end_theta, target_x, target_y)
    if reach > 0:
        gap_x, gap_y = xs[ok] - target_x, ys[ok] - target_y
        reached = np.empty(ok.size, dtype=np.bool_)
        for i in range(ok.size):
            reached[i] = (gap_x[i] * gap_x[i] + gap_y[i] * gap_y[i]).min() <= reach * reach
        head = np.where(reached, np.pi, head)
    if approach:  # nearness to the target in place of clearance
        room = cap - np.minimum(np.hypot(end_x - target_x, end_y - target_y), cap)
    else:
        room = clearance[ok]
    score = (
        alpha * normalised(head)
        + beta * normalised(np.minimum(room, cap))
        + gamma * normalised(speeds)
    )
    if face_weight > 0:
        score = score + face_weight * normalised(facing(travel))
    if route_weight > 0:
        score = score + route_weight * normalised(on_route(offsets[ok], cap))
    if steady > 0 and speed >= _EPS:  # at rest: nothing to keep
        change = jerk(sampled, command, previous, speed)
        return ok[steady_choice(score, change, steady, speeds, speed, step)]
    return ok[np.argmax(score)]
