"""The requests of a shift from its generator: reproducible from the seed alone.

Arrivals are a Poisson process: the gaps between requests are exponential with mean
3600 / rate_per_hour s. Each request's pick-up is a station of the ``from`` group and
its drop-off one of the ``to`` group other than the pick-up, each drawn uniformly.
Everything is drawn from ``random.Random(seed).random()``, whose sequence Python keeps
the same across versions (its other methods' algorithms may change), so a seed means
the same shift everywhere.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass

from fleet.missions.spec import Generator, Station

MAX_REQUESTS = 100_000
"""Requests made at most in one shift (120 an hour for ten hours is 1200)."""


@dataclass(frozen=True)
class Request:
    number: int  # 1, 2, ...: the task's number in events and ticks
    time: float  # s
    source: str  # the pick-up station's name
    target: str  # the drop-off station's name


def generated_requests(
    generator: Generator, sources: tuple[Station, ...], targets: tuple[Station, ...], end: float
) -> list[Request]:
    """The requests made before ``end`` (s), in time order, numbered from 1."""
    draw = random.Random(generator.seed).random
    mean_gap = 3600.0 / generator.rate_per_hour
    out: list[Request] = []
    now = 0.0
    while len(out) < MAX_REQUESTS:
        now += -mean_gap * math.log(1.0 - draw())
        if now >= end:
            break
        source = sources[int(draw() * len(sources))]
        others = [s for s in targets if s.name != source.name]
        target = others[int(draw() * len(others))]
        out.append(Request(len(out) + 1, round(now, 6), source.name, target.name))
    return out
