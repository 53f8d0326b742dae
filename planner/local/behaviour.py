"""The local planner's profiles: which critics score, which filters drop, what drives when
nothing is admissible, and what the controller around DWA does beyond the paper.

Each profile is written out once, below, one line per part on why it is on. The
``paper`` profile is Guo et al. 2023 as reproduced: Eq. (10)'s three critics, Eq. (7),
braking when nothing is admissible, free heading, an instant initial turn, arrival on
entering the tolerance. The ``default`` profile turns everything on; ``free_heading``
keeps the paper's free heading in it (no facing critic). The README lists what each part
buys, measured by ``benchmarks/nav_bench.py``; ``planner.local.critics`` describes the
critics.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace

from planner.core.profiles import PAPER, check_profile
from planner.local.critics.base import Critic
from planner.local.critics.clearance import Clearance
from planner.local.critics.facing import Facing
from planner.local.critics.heading import Heading
from planner.local.critics.route import OnRoute
from planner.local.critics.speed import Speed
from planner.local.fallback import Brake, Evade
from planner.local.filters import Admissible, ArrivalSpeed, Filter, NoRetreat, YieldEarly

STEADY_TOLERANCE = 0.2
"""The default's steady choice: keep the acceleration unless a sample scores this near the
best (a fraction of the scores' spread)."""


@dataclass(frozen=True)
class LocalBehaviour:
    """A profile: DWA's parts (``critics``, ``filters`` in order, ``fallback``, the steady
    choice's tolerance, 0 for the first best) and the switches of the controller around it
    (``planner.nav.fusion``), each False unless the profile turns it on."""

    critics: tuple[Critic, ...]
    filters: tuple[Filter, ...]
    fallback: Brake | Evade
    steady_tolerance: float = 0.0
    route_check: bool = False
    recover: bool = False
    smooth_arrival: bool = False
    recorded_turn: bool = False
    final_approach: bool = False
    turn_round: bool = False
    tight_turns: bool = False
    pass_beside: bool = False
    lane_speed: bool = False
    keep_right: bool = False

    @functools.cached_property  # asked every control cycle
    def wants_route_offsets(self) -> bool:
        """Whether a critic scores how far the samples stray from the route."""
        return any(critic.uses_route_offsets for critic in self.critics)


EQ_10 = (Heading(), Clearance(), Speed())  # the paper's score, weighed by the config's

PAPER_BEHAVIOUR = LocalBehaviour(
    critics=EQ_10,
    filters=(
        Admissible(),  # Eq. (7): only what can brake within its clearance
        ArrivalSpeed(),  # the goal: slow enough to stop there (else DWA circles it)
    ),
    fallback=Brake(),  # the paper: nothing admissible, brake
)

DEFAULT_BEHAVIOUR = LocalBehaviour(
    critics=(
        *EQ_10,
        Facing(weight=0.3),  # the body faces its travel: sensors and narrow side ahead
        OnRoute(weight=0.3),  # lined up with a narrow passage before it gets there
    ),
    filters=(
        Admissible(),  # Eq. (7), with the lane's braking room along the route
        NoRetreat(),  # another AGV in reach: brake or step aside, never drive off the target
        YieldEarly(),  # keep to trajectories that leave the AGV off the walkers' way
        ArrivalSpeed(),  # the goal: slow enough to stop there
    ),
    fallback=Evade(),  # nothing admissible: the command that delays contact longest
    steady_tolerance=STEADY_TOLERANCE,  # the chosen acceleration stops flipping every cycle
    route_check=True,  # every cycle: replan at once when sensed obstacles block the route
    recover=True,  # stalled: bounded recoveries (replan, wait, back off, rotate), then failed
    smooth_arrival=True,  # arrived = inside the tolerance and stopped, braking within limits
    recorded_turn=True,  # the initial heading turn is driven within omega/alpha limits
    final_approach=True,  # near the goal: score by the distance to it, not by clearance
    turn_round=True,  # a target behind an AGV that cannot reverse: turn on the spot first
    tight_turns=True,  # switch late, or stop and turn, where the route turns into a narrow stretch
    pass_beside=True,  # a key node gone past beside, the next in plain sight: switch on, not back
    lane_speed=True,  # on the route: speed bounded by the room to brake ahead, not beside
    keep_right=True,  # another AGV coming the other way: follow the route shifted right
)


def local_behaviour(profile: str, *, free_heading: bool = False) -> LocalBehaviour:
    """The parts of ``profile``; ``free_heading`` drops the facing critic."""
    if check_profile(profile) == PAPER:
        return PAPER_BEHAVIOUR
    if free_heading:
        critics = tuple(c for c in DEFAULT_BEHAVIOUR.critics if not isinstance(c, Facing))
        return replace(DEFAULT_BEHAVIOUR, critics=critics)
    return DEFAULT_BEHAVIOUR
