"""What the local planner does beyond the paper: one set of switches, built from the profile.

The ``paper`` profile turns everything off (Guo et al. 2023 as reproduced:
free heading, brake when nothing is admissible, an instant initial turn,
arrival on entering the tolerance). The ``default`` profile turns everything
on; ``free_heading`` keeps the paper's free heading in it. The README lists
what each switch buys, measured by ``benchmarks/nav_bench.py``.
"""

from __future__ import annotations

from dataclasses import dataclass

from planner.core.profiles import PAPER, check_profile


@dataclass(frozen=True)
class LocalBehaviour:
    evade: bool  # nothing admissible: the command that delays contact longest, not braking
    route_check: bool  # every cycle: replan at once when the sensed obstacles block the route
    recover: bool  # stalled: bounded recoveries (replan, wait, back off, rotate), then failed
    smooth_arrival: bool  # arrived = inside the tolerance and stopped, braking within limits
    recorded_turn: bool  # the initial heading turn is driven within omega/alpha limits
    final_approach: bool  # near the goal: score by the distance to it, not by clearance
    yield_early: bool  # keep to trajectories that leave the AGV off the walkers' way
    turn_round: bool  # a target behind an AGV that cannot reverse: turn on the spot first
    tight_turns: bool  # switch late, or stop and turn, where the route turns into a narrow stretch
    pass_beside: bool  # a key node gone past beside, the next in plain sight: switch on, not back
    lane_speed: bool  # on the route: speed bounded by the room to brake ahead, not beside
    keep_right: bool  # another AGV coming the other way: follow the route shifted right
    no_retreat: bool  # another AGV in reach: brake or step aside, never drive off the target
    route_weight: float  # weight of the term keeping trajectories on the global route
    face_travel_weight: float  # weight of the term facing the body along its travel
    steady_tolerance: float  # keep the acceleration unless this near the best (score spread)


STEADY_TOLERANCE = 0.2


def local_behaviour(profile: str, *, free_heading: bool = False) -> LocalBehaviour:
    """The switches of ``profile``; ``free_heading`` drops the facing term."""
    on = check_profile(profile) != PAPER
    return LocalBehaviour(
        evade=on,
        route_check=on,
        recover=on,
        smooth_arrival=on,
        recorded_turn=on,
        final_approach=on,
        yield_early=on,
        turn_round=on,
        tight_turns=on,
        pass_beside=on,
        lane_speed=on,
        keep_right=on,
        no_retreat=on,
        route_weight=0.3 if on else 0.0,
        face_travel_weight=0.3 if on and not free_heading else 0.0,
        steady_tolerance=STEADY_TOLERANCE if on else 0.0,
    )


PAPER_BEHAVIOUR = local_behaviour(PAPER)
