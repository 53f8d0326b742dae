"""The one root of every error agv-fleet reports to a user.

Each package raises its own subclass (``MapError``, ``ScenarioError``,
``MessageError``, ``RecordingError``, ``BusError`` …), and each subclass says
which of two kinds it is, so the command line can turn any of them into one
line and one exit code without knowing them all. It lives in ``planner/``, the
bottom layer, because every other package may import from there.
"""

from __future__ import annotations


class AgvFleetError(Exception):
    """Something agv-fleet can explain in one line."""


class BadInputError(AgvFleetError):
    """The user's input cannot be used: a file, map, scenario, argument or message."""


class EnvironmentFailure(AgvFleetError):
    """The machine, the bus or another process failed; the input may be fine."""


class MapError(BadInputError, ValueError):
    """A map that cannot be read, or a point that does not fit the map."""
