"""The words of a run's record: what an AGV reports each tick, which of those end its run,
why a plan was made, and the kinds of the world's events.

They are strings of the recording and of ``--json`` (a public contract): name them from
here, never spell them again.
"""

from __future__ import annotations

DRIVING = "driving"
BLOCKED = "blocked"  # no admissible command this cycle: braking
WAITING = "waiting"  # holding outside a passage another AGV has (planner/traffic.py)
ARRIVED = "arrived"
FAILED = "failed"
# an AGV of a shift (fleet.missions) the world holds at its goal: at a station for its
# dwell, or idle at home; the world writes them, an AGV reports ``arrived`` there
LOADING = "loading"
PARKED = "parked"
STATUSES = (DRIVING, BLOCKED, WAITING, ARRIVED, FAILED, LOADING, PARKED)
FINISHED = (ARRIVED, FAILED)  # an AGV in one of these has ended its run

# the recovery behaviours a stalled AGV runs (planner/recovery.py), reported as it starts
# one, and the kind of the world's event for that
REPLAN, WAIT, BACK_OFF, ROTATE = RECOVERY_KINDS = ("replan", "wait", "back off", "rotate")
RECOVERY = "recovery"

# why an AGV sent a plan (PlanMsg.reason): its first, a replan of its controller (REPLAN),
# or the way back onto its route after waiting off it for the traffic rule
INITIAL = "initial"
TRAFFIC = "traffic"

# the world's other events (an AGV's end is an event of its status, ARRIVED or FAILED)
CLIPPED = "clipped"  # a command beyond the AGV's limits, clipped
REFUSED = "refused"  # a report the world did not believe
COLLISION = "collision"
END = "end"

# the events of a transport task (fleet.missions): a request made, given to an AGV, its
# load picked up at the end of the pick-up's dwell, delivered at the end of the drop-off's
REQUESTED, ASSIGNED, PICKED_UP, DELIVERED = TASK_EVENTS = (
    "requested", "assigned", "picked-up", "delivered",
)  # fmt: skip
# what an AGV of a shift is doing (``Assignment.phase`` in the ticks)
TO_PICK_UP, AT_PICK_UP, TO_DROP_OFF, AT_DROP_OFF, TO_HOME, AT_HOME = TASK_PHASES = (
    "to pick-up", "at pick-up", "to drop-off", "at drop-off", "to home", "at home",
)  # fmt: skip
