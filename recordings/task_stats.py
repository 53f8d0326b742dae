"""The throughput of a shift from its task events (``requested``, ``assigned``,
``picked-up``, ``delivered``: ``fleet.missions``), for ``analyze`` and the run summary.

A task event's detail starts with the task's number, ``task 12: pick-1 -> drop-2``;
its AGVs name the AGV that serves it (none for a request nobody has taken yet).

- throughput_per_hour: tasks delivered per hour of the shift (the run's length);
- task time: from request to delivery, of the tasks delivered (what a customer waits);
- queue time: from request to assignment, of the tasks assigned;
- per AGV: deliveries; utilisation, the share of the shift it had a task (from its
  assignment to its delivery, or to the shift's end); distance per task, the distance
  it drove (returns home too) over its deliveries.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from planner.core.status import ASSIGNED, DELIVERED, REQUESTED, TASK_EVENTS

_NUMBER = re.compile(r"task (\d+):")


def task_number(detail: str) -> int | None:
    """The task number of a task event's detail, else None."""
    match = _NUMBER.match(detail)
    return int(match.group(1)) if match else None


@dataclass
class _Task:
    requested: float | None = None
    assigned: float | None = None
    delivered: float | None = None
    agv: str = ""


@dataclass(frozen=True)
class ShiftStats:
    requested: int
    assigned: int
    delivered: int
    throughput_per_hour: float | None
    task_time_mean: float | None  # s
    task_time_p95: float | None
    queue_time_mean: float | None
    deliveries: dict[str, int] = field(default_factory=dict)  # by AGV
    busy: dict[str, float] = field(default_factory=dict)  # s with a task, by AGV

    def to_json(self) -> dict:
        """The ``tasks`` block of ``analyze --json`` and of the run summary."""
        keys = ("requested", "assigned", "delivered", "throughput_per_hour")
        out = {k: getattr(self, k) for k in keys}
        for key in ("task_time_mean", "task_time_p95", "queue_time_mean"):
            out[key] = getattr(self, key)
        return {k: round(v, 3) if isinstance(v, float) else v for k, v in out.items()}


def is_task_event(event: dict) -> bool:
    return event.get("kind") in TASK_EVENTS


def shift_stats(events: Iterable[dict], duration: float) -> ShiftStats:
    """The stats of the task events (dicts of the recording's ``world/event``) of a shift
    that ran ``duration`` s."""
    tasks: dict[int, _Task] = {}
    for e in events:
        number = task_number(str(e.get("detail", "")))
        if number is None or e.get("kind") not in TASK_EVENTS:
            continue
        task = tasks.setdefault(number, _Task())
        time = float(e.get("time", 0.0))
        if e["kind"] == REQUESTED:
            task.requested = time
        elif e["kind"] == ASSIGNED:
            task.assigned, task.agv = time, (e.get("agvs") or [""])[0]
        elif e["kind"] == DELIVERED:
            task.delivered = time
    made = [t for t in tasks.values() if t.requested is not None]
    assigned = [t for t in made if t.assigned is not None]
    delivered = [t for t in assigned if t.delivered is not None]
    lead = np.array([t.delivered - t.requested for t in delivered])
    queue = np.array([t.assigned - t.requested for t in assigned])
    deliveries: dict[str, int] = {}
    busy: dict[str, float] = {}
    for t in assigned:
        end = t.delivered if t.delivered is not None else duration
        busy[t.agv] = busy.get(t.agv, 0.0) + max(0.0, end - t.assigned)
        deliveries[t.agv] = deliveries.get(t.agv, 0) + (t.delivered is not None)
    return ShiftStats(
        requested=len(made),
        assigned=len(assigned),
        delivered=len(delivered),
        throughput_per_hour=len(delivered) * 3600.0 / duration if duration > 0 else None,
        task_time_mean=float(lead.mean()) if len(lead) else None,
        task_time_p95=float(np.percentile(lead, 95)) if len(lead) else None,
        queue_time_mean=float(queue.mean()) if len(queue) else None,
        deliveries=deliveries,
        busy=busy,
    )
