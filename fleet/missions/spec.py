"""What a scenario says about the work of a shift (the ``[[stations]]`` and ``[tasks]``
tables, and ``tasks`` in ``[[agvs]]``): plain frozen data, read by ``fleet.missions.format``.
"""

from __future__ import annotations

from dataclasses import dataclass

from planner.maps.grid import Point

PARKING = "parking"
"""The group of parking stations: where ``agvs.count`` places a fleet (fleet.sweep.keys)."""


@dataclass(frozen=True)
class Station:
    name: str
    position: Point
    dwell: float = 0.0  # s spent there per visit
    group: str = ""


@dataclass(frozen=True)
class Generator:
    """Requests from a station of group ``source`` to one of group ``target`` at
    ``rate_per_hour`` on average (a Poisson process drawn from ``seed``)."""

    rate_per_hour: float
    source: str
    target: str
    seed: int = 0


@dataclass(frozen=True)
class TaskList:
    """An AGV's own work: stations taken in pairs (pick-up, drop-off), in order; from
    the first pair again after the last with ``repeat``."""

    stations: tuple[str, ...]
    repeat: bool = False

    def pairs(self) -> tuple[tuple[str, str], ...]:
        return tuple(zip(self.stations[0::2], self.stations[1::2], strict=True))


@dataclass(frozen=True)
class Missions:
    shift: float  # s: the run ends then (the scenario's time_limit still caps it)
    stations: tuple[Station, ...]
    generator: Generator | None = None
    lists: tuple[tuple[str, TaskList], ...] = ()  # (AGV name, its list), fleet order

    def group(self, group: str) -> tuple[Station, ...]:
        return tuple(s for s in self.stations if s.group == group)
