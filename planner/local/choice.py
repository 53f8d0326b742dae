"""DWA's choice among the candidates: each critic's scores normalised, weighed and added up
(Eq. 10 and the profile's own terms), then the best, or the steadiest near-best.

The profile's ``steady_tolerance`` > 0 picks, among the candidates scoring near the best,
the one that changes the last cycle's acceleration least (``jerk``), so the chosen
acceleration stops flipping every cycle (``steady_choice``); 0 takes the first best.
Every operation is the one numpy did, in the same order, and sums follow numpy's
pairwise order (``planner.local.normalise``), so the choice is the same bit for bit; they
are loops, as numba compiled array expressions (broadcasting, fancy indexing) slower.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numba
import numpy as np

from planner.local.candidates import Candidates
from planner.local.critics.base import Critic
from planner.local.cycle import Cycle
from planner.local.normalise import normalised
from planner.local.yielding import walker_coming

_EPS = 1e-9


def choose(candidates: Candidates, critics: Sequence[Critic], cycle: Cycle, steady: float) -> int:
    """The index (into the cycle's samples) of the candidate DWA drives: the best by the
    ``critics`` that apply to ``cycle``, or with ``steady`` > 0 (the tolerance, a fraction
    of the scores' spread) the steadiest near-best."""
    cfg, command = cycle.config, cycle.command
    scoring = [c for c in critics if c.applies(cycle)]
    terms = np.empty((len(scoring), candidates.ok.size))
    for row, critic in enumerate(scoring):
        terms[row] = critic.score(candidates, cycle)
    weights = np.array([c.weight_in(cfg) for c in scoring])
    speed = math.hypot(command[0], command[1])
    # with a walker coming the AGV keeps the room to yield: no speeding up out of the
    # steady choice's tolerance
    step = cfg.v_resolution
    if steady > 0 and speed >= _EPS and walker_coming(cycle.pose, cycle.walkers):
        step = math.inf
    best = pick(
        terms, weights, steady, candidates.commands, candidates.speeds, command,
        cycle.previous, speed, step,
    )  # fmt: skip
    return int(candidates.ok[best])


@numba.njit(cache=True)
def weighed(terms, weights):
    """(n,) the sum over the rows of ``terms`` (one a critic) of each row divided by its sum
    (``normalised``) times its weight, the rows added in order."""
    score = np.zeros(terms.shape[1])
    for row in range(terms.shape[0]):
        by_term = normalised(terms[row])
        for i in range(score.size):
            score[i] = score[i] + weights[row] * by_term[i]
    return score


@numba.njit(cache=True)
def pick(terms, weights, steady, commands, speeds, command, previous, speed, step):
    """The index (into ``commands``, the candidates) of the best ``weighed`` score, or with
    ``steady`` > 0 for a ``command`` moving at ``speed`` after ``previous`` the
    ``steady_choice`` (``step``: the least speed-up that counts as faster)."""
    score = weighed(terms, weights)
    if steady > 0 and speed >= _EPS:  # at rest: nothing to keep
        change = jerk(commands, command, previous, speed)
        return steady_choice(score, change, steady, speeds, speed, step)
    return first_best(score)


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
def first_best(score):
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
    if speeds[first_best(score)] > speed + step:
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
