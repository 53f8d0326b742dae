"""Small typed accessors for TOML tables that name the offending key on error.

tomllib gives plain dicts; these helpers turn a wrong type, a missing key or
an unknown key into one ScenarioError whose message names the key's full path
(``agvs[2].start``), so a user can fix the file without reading a traceback.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from planner.core.errors import BadInputError

MAX_TIME_LIMIT = 36_000.0
"""s: the longest run a scenario may ask for (time_limit, a shift): at most 3.6 million
ticks."""


class ScenarioError(BadInputError, ValueError):
    """A scenario file that cannot be used; the message names the key or AGV."""


_MISSING = object()


def check_keys(table: dict, allowed: Iterable[str], where: str) -> None:
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        hint = ", ".join(sorted(allowed))
        raise ScenarioError(f"unknown key {_join(where, unknown[0])} (allowed here: {hint})")


def _join(where: str, key: str) -> str:
    return f"{where}.{key}" if where else key


def get_table(table: dict, key: str, where: str, required: bool = False) -> dict:
    value = table.get(key, _MISSING)
    if value is _MISSING:
        if required:
            raise ScenarioError(f"missing table [{_join(where, key)}]")
        return {}
    if not isinstance(value, dict):
        raise ScenarioError(f"{_join(where, key)} must be a table")
    return value


def get_str(table: dict, key: str, where: str, default=_MISSING, choices=None) -> str:
    value = table.get(key, default)
    if value is _MISSING:
        raise ScenarioError(f"missing key {_join(where, key)}")
    if not isinstance(value, str):
        raise ScenarioError(f"{_join(where, key)} must be a string, got {value!r}")
    if choices is not None and value not in choices:
        raise ScenarioError(f"{_join(where, key)} = {value!r} is not one of: {', '.join(choices)}")
    return value


def get_number(
    table: dict,
    key: str,
    where: str,
    default=_MISSING,
    minimum: float | None = None,
    positive: bool = False,
    maximum: float | None = None,
) -> float:
    value = table.get(key, default)
    if value is _MISSING:
        raise ScenarioError(f"missing key {_join(where, key)}")
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ScenarioError(f"{_join(where, key)} must be a number, got {value!r}")
    if positive and value <= 0:
        raise ScenarioError(f"{_join(where, key)} must be > 0, got {value!r}")
    if minimum is not None and value < minimum:
        raise ScenarioError(f"{_join(where, key)} must be >= {minimum:g}, got {value!r}")
    if maximum is not None and value > maximum:
        raise ScenarioError(f"{_join(where, key)} must be <= {maximum:g}, got {value!r}")
    return float(value)


def get_int(table: dict, key: str, where: str, default=_MISSING, minimum: int | None = None):
    value = table.get(key, default)
    if value is _MISSING:
        raise ScenarioError(f"missing key {_join(where, key)}")
    if isinstance(value, bool) or not isinstance(value, int):
        raise ScenarioError(f"{_join(where, key)} must be an integer, got {value!r}")
    if minimum is not None and value < minimum:
        raise ScenarioError(f"{_join(where, key)} must be >= {minimum}, got {value!r}")
    return value


def as_point(value, where: str) -> tuple[float, float]:
    """A [x, y] pair of numbers."""
    if (
        not isinstance(value, list)
        or len(value) != 2
        or any(isinstance(v, bool) or not isinstance(v, int | float) for v in value)
        or not all(math.isfinite(v) for v in value)
    ):
        raise ScenarioError(f"{where} must be a pair of numbers [x, y], got {value!r}")
    return float(value[0]), float(value[1])


def as_cell(value, where: str) -> tuple[int, int]:
    """A [col, row] pair of integers."""
    if (
        not isinstance(value, list)
        or len(value) != 2
        or any(isinstance(v, bool) or not isinstance(v, int) for v in value)
    ):
        raise ScenarioError(f"{where} must be a cell [col, row] of integers, got {value!r}")
    return int(value[0]), int(value[1])


def get_list(table: dict, key: str, where: str, default=_MISSING) -> list:
    value = table.get(key, default)
    if value is _MISSING:
        raise ScenarioError(f"missing key {_join(where, key)}")
    if not isinstance(value, list):
        raise ScenarioError(f"{_join(where, key)} must be a list")
    return value
