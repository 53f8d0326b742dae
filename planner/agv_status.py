"""What an AGV reports each tick, and which of those statuses end its run."""

from __future__ import annotations

DRIVING = "driving"
BLOCKED = "blocked"  # no admissible command this cycle: braking
WAITING = "waiting"  # holding outside a passage another AGV has (planner/traffic.py)
ARRIVED = "arrived"
FAILED = "failed"
STATUSES = (DRIVING, BLOCKED, WAITING, ARRIVED, FAILED)
FINISHED = (ARRIVED, FAILED)  # an AGV in one of these has ended its run
