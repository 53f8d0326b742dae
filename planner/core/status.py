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
STATUSES = (DRIVING, BLOCKED, WAITING, ARRIVED, FAILED)
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
