"""Every bus key in one place, relative to a run's prefix.

A run's keys all live under ``<prefix>/``; recordings use the same keys
without the prefix as MCAP topics. ``message_type(key)`` says which message
a key carries, so the recorder and the replay need no other table.
"""

from __future__ import annotations

from bridge.messages import (
    AgvCommand,
    AgvState,
    Event,
    MapMsg,
    PlanMsg,
    ResultMsg,
    Tick,
    TrajectoryMsg,
)

WORLD_TICK = "world/tick"
WORLD_MAP = "world/map"
WORLD_EVENT = "world/event"
WORLD_RESULT = "world/result"
ALIVE = "alive"


def agv_command(name: str) -> str:
    return f"agv/{name}/command"


def agv_state(name: str) -> str:
    """What AGVs answered before the world integrated commands (older recordings)."""
    return f"agv/{name}/state"


def agv_plan(name: str) -> str:
    return f"agv/{name}/plan"


def agv_trajectory(name: str) -> str:
    return f"agv/{name}/trajectory"


def alive_world() -> str:
    return f"{ALIVE}/world"


def alive_agv(name: str) -> str:
    return f"{ALIVE}/agv/{name}"


def alive_recorder() -> str:
    return f"{ALIVE}/recorder"


def message_type(key: str):
    """The message class a relative key carries, or None for keys that carry none."""
    if key == WORLD_TICK:
        return Tick
    if key == WORLD_MAP:
        return MapMsg
    if key == WORLD_EVENT:
        return Event
    if key == WORLD_RESULT:
        return ResultMsg
    parts = key.split("/")
    if len(parts) == 3 and parts[0] == "agv":
        kinds = {"command": AgvCommand, "state": AgvState, "plan": PlanMsg}
        return {**kinds, "trajectory": TrajectoryMsg}.get(parts[2])
    return None


def agv_name(key: str) -> str | None:
    """The AGV a relative ``agv/<name>/...`` key belongs to."""
    parts = key.split("/")
    return parts[1] if len(parts) == 3 and parts[0] == "agv" else None
