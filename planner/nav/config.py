"""What one AGV's controller is configured with: the planner variant, the profile, DWA's
parameters and the controller's own distances and times (defaults are the paper's)."""

from __future__ import annotations

from dataclasses import dataclass, field

from planner.core.profiles import DEFAULT, check_profile
from planner.local.config import DwaConfig
from planner.maps.clearance import Clearance
from planner.route.global_planner import DEFAULT_SAFETY_DISTANCE

VARIANTS = ("fusion", "astar-dwa", "dwa")
GLOBAL_ALGORITHM = {"fusion": "improved", "astar-dwa": "traditional"}
"""The global A* variant each planner variant plans with (``dwa`` has none)."""


@dataclass(frozen=True)
class FusionConfig:
    """Everything one AGV's planner needs; defaults are the paper's. Each is a scenario key
    (``scenarios/README.md``)."""

    algorithm: str = "fusion"
    profile: str = DEFAULT
    dwa: DwaConfig = field(default_factory=DwaConfig)
    safety_distance: float = DEFAULT_SAFETY_DISTANCE
    # m: the next key node becomes the local target within this of the current one: early
    # enough that DWA rounds the corner instead of stopping on it
    switch_distance: float = 1.0
    goal_tolerance: float = 0.2  # m: arrived within it
    progress_window: float = 5.0  # s: no progress for this long is a stall (replan, recover)
    # m: the remaining route must shrink by this much to count as progress: more than an
    # AGV dithering on the spot gains
    progress_distance: float = 0.3
    approach_distance: float = 3.0  # m: the final approach starts this close to the goal
    free_heading: bool = False  # default profile: keep the paper's free heading

    def __post_init__(self) -> None:
        check_profile(self.profile)
        if self.algorithm not in VARIANTS:
            raise ValueError(
                f"unknown planner algorithm {self.algorithm!r}: choose one of {', '.join(VARIANTS)}"
            )
        positive = (
            "safety_distance", "switch_distance", "goal_tolerance", "progress_window",
            "approach_distance",
        )  # fmt: skip
        for name in positive:
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be > 0, got {getattr(self, name)}")
        self.clearance  # noqa: B018 - a safety distance below the radius is an error

    @property
    def clearance(self) -> Clearance:
        """The AGV's radius (``dwa.radius``) and margin (safety_distance - radius)."""
        return Clearance.from_safety_distance(self.dwa.radius, self.safety_distance)
