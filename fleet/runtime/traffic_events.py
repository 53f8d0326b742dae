"""Traffic decisions as world events: what the recording, ``analyze`` and Rerun show.

The world derives them from each AGV's intent (the AGVs decide, the world reports),
so both run modes record the same events. An event's kind is the phase the AGV
entered (``planner.traffic.zones.DECISIONS``): ``wait`` (held outside a passage another
AGV has; the event names whom it waits for), ``go`` (a waiting AGV may enter),
``yield`` (a holder is stuck: a waiting AGV moves further back to make room),
``back`` (two AGVs met inside a passage going opposite ways: the later one backs out;
a deadlock broken).
"""

from __future__ import annotations

from bridge.messages import Event
from planner.traffic.zones import BACK, GO, WAIT, YIELD, Intent


def traffic_events(before: Intent | None, now: Intent, tick: int, time: float) -> list[Event]:
    """The events of one AGV's intent changing from ``before`` to ``now``."""
    was = before.phase if before else None
    where = f"passage {now.passage}"
    if now.phase == WAIT and was != WAIT:
        who = ", ".join(now.waits_for) or "the AGVs ahead"
        detail = f"{where}: waits for {who}"
    elif now.phase == YIELD and was != YIELD:
        detail = f"{where}: a holder is stuck, moves further back"
    elif now.phase == BACK and was != BACK:
        detail = f"{where}: met {', '.join(now.waits_for)} inside, backs out (deadlock broken)"
    elif now.phase == GO and was in (WAIT, YIELD, BACK):
        detail = f"{where}: enters"
    else:
        return []
    return [Event(tick, time, now.phase, [now.name, *now.waits_for], detail)]
