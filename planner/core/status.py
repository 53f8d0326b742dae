"""What an AGV reports each tick, and which of those statuses end its run."""

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
