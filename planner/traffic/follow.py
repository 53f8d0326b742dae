"""Where an AGV drives on the nodes the schedule reserved for it.

The AGV drives to the end of the first straight run of its reserved nodes and stops
there unless more nodes are released on the way: on a straight aisle it keeps its speed
while the nodes ahead are released faster than it brakes; at a corner it stops and
turns (a forward-heading AGV turns on the spot). It never aims past a node it does not
hold, so DWA's arcs stay on the reserved cells, and where it stops nobody else is
planned to be.
"""

from __future__ import annotations

import itertools
import math

from planner.maps.grid import Point


def follow_point(path: list[list[float]]) -> Point:
    """The point to drive to and stop at: the last node of the first straight run of
    ``path`` (the reserved nodes from the one reached; a lone node: stay on it)."""
    if len(path) < 2:
        return tuple(path[0]) if path else None
    x0, y0 = path[0]
    heading = math.atan2(path[1][1] - y0, path[1][0] - x0)
    end = path[1]
    for a, b in itertools.pairwise(path[1:]):
        if abs(math.remainder(math.atan2(b[1] - a[1], b[0] - a[0]) - heading, math.tau)) > 1e-6:
            break
        end = b
    return (end[0], end[1])
