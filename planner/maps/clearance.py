"""What an AGV needs around it: the one place that derives it from radius and margin.

An AGV is a disc of ``radius``; it must never come closer than that to an obstacle
(the body would touch it). ``margin`` is extra room the planner keeps where the space
allows. Their sum is the *safety distance* of the scenario files and the paper's key
nodes. Every consumer (the global planner's costmap and key nodes, DWA, the CLI, the
scenario files, analysis) gets these numbers from a :class:`Clearance`, so that no two
of them can disagree; a safety distance below the radius is an error, not a setting.

Distances are to obstacle *squares* (cell edges) and to the map's border, never to cell
centres, in the default profile; the ``paper`` profile measures the safety distance to
obstacle-cell centres, as the paper does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from planner.core.errors import BadInputError

DEFAULT_RADIUS = 0.3
"""m, the AGV of the paper's Table 1."""
DEFAULT_MARGIN = 0.2
"""m, kept beyond the radius where there is room (radius + margin = the paper's 0.5 m)."""
CLEARANCE_CAP = 2.0
"""m, the most clearance that counts: DWA's dist term credits no more (farther from every
obstacle is no safer), and a route's clearance is measured up to it."""

TOLERANCE = 1e-9
"""m: how far a distance may fall short of what an AGV needs and still meet it.

Distances are measured in cells and turned into metres, and radii turned into cells: each
conversion rounds (0.11 / 0.05 * 0.05 is 0.10999999999999999), so an exact comparison
refused a 0.11 m AGV exactly 0.11 m from a wall. A nanometre is far above that rounding
(~1e-16 of the value) and far below anything a map or a controller can tell apart."""


def keeps(distance, needed):
    """Whether ``distance`` is at least ``needed`` (m; numbers or numpy arrays), up to
    float rounding (:data:`TOLERANCE`): the one comparison of a clearance with a radius."""
    return distance >= needed - TOLERANCE


class ClearanceError(BadInputError, ValueError):
    """Radius, margin and safety distance that do not fit together."""


@dataclass(frozen=True)
class Clearance:
    """An AGV's radius and margin, metres."""

    radius: float = DEFAULT_RADIUS
    margin: float = DEFAULT_MARGIN

    def __post_init__(self) -> None:
        for name in ("radius", "margin"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ClearanceError(f"AGV {name} must be a number, got {value!r}")
            if not math.isfinite(value):
                raise ClearanceError(f"AGV {name} must be finite, got {value!r}")
        if not self.radius > 0:
            raise ClearanceError(f"AGV radius must be > 0, got {self.radius:g} m")
        if self.margin < 0:
            raise ClearanceError(f"AGV margin must be >= 0, got {self.margin:g} m")
        object.__setattr__(self, "radius", float(self.radius))
        object.__setattr__(self, "margin", float(self.margin))

    @property
    def safety_distance(self) -> float:
        """radius + margin: the distance kept from obstacles where there is room."""
        return self.radius + self.margin

    @classmethod
    def from_safety_distance(cls, radius: float, safety_distance: float) -> Clearance:
        """The clearance whose safety distance is ``safety_distance``; below the radius
        it is an error (the AGV's body would be allowed to touch obstacles)."""
        if not keeps(safety_distance, radius):
            raise ClearanceError(
                f"safety distance {safety_distance:g} m is below the AGV radius {radius:g} m: "
                "the AGV's body would touch obstacles (the safety distance is radius + margin; "
                "raise it or give a margin >= 0 instead)"
            )
        return cls(radius, max(0.0, safety_distance - radius))


def clearance_for(
    radius: float = DEFAULT_RADIUS,
    *,
    margin: float | None = None,
    safety_distance: float | None = None,
) -> Clearance:
    """The clearance of an AGV from its radius and either a margin or a safety distance
    (neither: the default margin). Both given must agree."""
    if (
        margin is not None
        and safety_distance is not None
        and not math.isclose(radius + margin, safety_distance, abs_tol=1e-9)
    ):
        raise ClearanceError(
            f"margin {margin:g} m and safety distance {safety_distance:g} m disagree for "
            f"radius {radius:g} m (safety distance = radius + margin): give one of them"
        )
    if safety_distance is not None and margin is None:
        return Clearance.from_safety_distance(radius, safety_distance)
    return Clearance(radius, DEFAULT_MARGIN if margin is None else margin)
