"""The fleet as a whole over time: how many AGVs drive, wait and stand, and how many
have arrived so far (``fleet/agvs/<state>`` and ``fleet/arrived`` in Rerun).

Twenty speed curves in one plot tell nothing; these four lines tell how a long run
went at a glance, whatever the fleet's size. At each tick every AGV is in exactly one
of: arrived; waiting (held by the traffic rule, or reporting ``waiting``); driving
(moving faster than ``AT_REST``, or turning, or at rest for less than ``STANDING_S``);
stopped (anything else: blocked, failed, at a station, or standing).
"""

from __future__ import annotations

import math

import rerun as rr

from planner.core.status import ARRIVED, DRIVING, WAITING
from planner.route.parked_discs import AT_REST
from planner.traffic.zones import HELD
from recordings import rerun_kinds as kinds
from recordings.rerun_rows import Row

FLEET = "fleet"
STATE_PLOT = f"{FLEET}/agvs"
ARRIVED_PLOT = f"{FLEET}/arrived"
TURNING = 0.05  # rad/s: an AGV turning on the spot faster than this drives
STANDING_S = 1.0
"""s: a driving AGV at rest for less than this still drives. Braking to a tight corner's
node, it is below ``AT_REST`` for a tick or two before its turn on the spot; counted as
stopped, the fleet's line dipped for 0.2 s 16 times in a nav2-depot run."""
STATES = (("driving", (60, 170, 75)), ("waiting", (255, 160, 0)), ("stopped", (220, 60, 50)))
ARRIVED_COLOR = (70, 110, 230)


def fleet_style_rows() -> list[Row]:
    """Names and colours of the four lines, static."""
    rows = [
        Row(f"{STATE_PLOT}/{state}", None, None, [rr.SeriesLines(names=state, colors=color)])
        for state, color in STATES
    ]
    style = rr.SeriesLines(names="arrived so far", colors=ARRIVED_COLOR)
    rows.append(Row(ARRIVED_PLOT, None, None, [style]))
    return rows


class FleetCounts:
    """The four counts, tick after tick (``rows``): remembers since when each driving AGV
    has been at rest."""

    def __init__(self) -> None:
        self._rest_since: dict[str, float] = {}

    def rows(self, tick: dict) -> list[Row]:
        """The four counts at one tick (a ``world/tick`` message, dict form)."""
        t = tick["time"]
        held = {i["name"] for i in tick.get("intents", []) if i["phase"] in HELD}
        counts = dict.fromkeys(("driving", "waiting", "stopped"), 0)
        arrived = 0
        for s in tick["agvs"]:
            if s["status"] == ARRIVED:
                arrived += 1
            elif s["status"] == WAITING or s["name"] in held:
                counts["waiting"] += 1
            elif self._driving(s, t):
                counts["driving"] += 1
            else:
                counts["stopped"] += 1
        rows = [Row(f"{STATE_PLOT}/{state}", kinds.scalar, t, n) for state, n in counts.items()]
        rows.append(Row(ARRIVED_PLOT, kinds.scalar, t, arrived))
        return rows

    def _driving(self, state: dict, t: float) -> bool:
        name = state["name"]
        if math.hypot(state["vx"], state["vy"]) > AT_REST or abs(state["omega"]) > TURNING:
            self._rest_since.pop(name, None)
            return True
        if state["status"] != DRIVING:
            return False
        since = self._rest_since.setdefault(name, t)
        return round(t - since, 9) < STANDING_S  # tick times are sums of floats
