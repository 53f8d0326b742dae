"""What the controller is doing: one mode at a time, instead of a flag per mode."""

from __future__ import annotations

import enum

from planner.core import status


class Mode(enum.Enum):
    """The controller's state between control cycles.

    TURNING_IN_PLACE -> DRIVING: the turn towards the first key node at the start, or
    towards the next stretch once stopped at a tight corner, has ended (or a walker is
    coming: evading beats finishing the turn). DRIVING -> RECOVERING: the progress checker
    found no progress and the recovery sequence started a timed recovery; back to DRIVING
    when its time is up. DRIVING <-> WAITING: the traffic rule holds the AGV at a waiting
    place, for as long as it holds it. ARRIVED and FAILED end the run; their values are
    the statuses an AGV reports in them (``planner.core.status``).
    """

    TURNING_IN_PLACE = "turning in place"
    DRIVING = status.DRIVING
    RECOVERING = "recovering"
    WAITING = status.WAITING
    ARRIVED = status.ARRIVED
    FAILED = status.FAILED

    @property
    def finished(self) -> bool:
        """Whether the run has ended in this mode."""
        return self in (Mode.ARRIVED, Mode.FAILED)
