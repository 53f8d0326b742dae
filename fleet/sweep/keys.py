"""``--vary KEY=V1,V2,...``: a dotted key into a scenario file and the values it takes.

A key walks the scenario's TOML document: a table key by its name
(``planner.algorithm``, ``agv_defaults.max_speed``), a list entry by its ``name``
or its index (``obstacles.walker.start_at``, ``agvs.0.max_speed``,
``agvs.agv1.goal``). A table on the way that the file does not have yet is made
(``agv_defaults`` in a scenario without one). Whether the key means anything and the
value has the right type is left to the scenario's own checks: the edited document
is parsed again by ``fleet.scenario.parse_scenario``, so every scenario error applies.

One key is not a path: ``agvs.count`` (a positive integer N) makes the fleet N AGVs,
``agv1`` .. ``agvN``, each like the file's first ``[[agvs]]`` entry, started on the first N
stations of group ``parking`` in the file's order (fleet sizing: a shift's AGVs return
to their starts when idle).

Values are TOML values (``1.5``, ``true``, ``[19.5, 19.5]``, ``"fusion"``); a bare word
is a string (``fusion``). ``START:STOP:STEP`` is every number from START to STOP
inclusive in steps of STEP (``0:40:2`` is 21 values).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass

import tomlkit
from tomlkit.items import AoT, Array

from fleet.missions.spec import PARKING
from fleet.toml_schema import ScenarioError

AGV_COUNT = "agvs.count"
MAX_RANGE_VALUES = 10_000  # a typo such as 0:40:0.0001 is an error, not a sweep of 400k runs


class SweepKeyError(ScenarioError):
    """A ``--vary`` that cannot be applied: bad syntax, a key that leads nowhere."""


@dataclass(frozen=True)
class Varied:
    """One ``--vary``: a dotted key and the values it takes, in the order given."""

    key: str
    values: tuple

    @property
    def parts(self) -> tuple[str, ...]:
        return tuple(self.key.split("."))


def parse_vary(text: str, option: str = "--vary") -> Varied:
    """``KEY=V1,V2,...`` as a ``Varied``; a ``SweepKeyError`` names what is wrong."""
    key, sep, values = text.partition("=")
    key = key.strip()
    if not sep or not key or not values.strip():
        raise SweepKeyError(f"{option} {text!r}: expected KEY=V1,V2,...")
    if any(not part for part in key.split(".")):
        raise SweepKeyError(f"{option} {text!r}: {key!r} has an empty part")
    parsed: list = []
    for item in split_values(values):
        parsed.extend(_range(item) or [parse_value(item)])
    if len(parsed) != len({repr(v) for v in parsed}):
        raise SweepKeyError(f"{option} {key}: a value is given twice")
    return Varied(key, tuple(parsed))


def split_values(text: str) -> list[str]:
    """``text`` split at the commas outside brackets, braces and quotes."""
    items, depth, quote, start = [], 0, "", 0
    for i, c in enumerate(text):
        if quote:
            quote = "" if c == quote else quote
        elif c in "\"'":
            quote = c
        elif c in "[{":
            depth += 1
        elif c in "]}":
            depth -= 1
        elif c == "," and depth == 0:
            items.append(text[start:i])
            start = i + 1
    items.append(text[start:])
    return [item.strip() for item in items]


def parse_value(text: str):
    """A TOML value, or the text itself as a string when it is not one."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        if not text:
            raise SweepKeyError("an empty value") from None
        return text


def _range(text: str) -> list | None:
    """``START:STOP:STEP`` as its numbers (ints if all three are), else None."""
    bounds = text.split(":")
    if len(bounds) != 3:
        return None
    try:
        numbers = [parse_value(b) for b in bounds]
    except SweepKeyError:
        return None
    if not all(isinstance(n, int | float) and not isinstance(n, bool) for n in numbers):
        return None
    start, stop, step = numbers
    if not (math.isfinite(start) and math.isfinite(stop) and step > 0 and stop >= start):
        raise SweepKeyError(f"range {text!r}: needs START <= STOP and STEP > 0")
    count = math.floor((stop - start) / step + 1e-9) + 1
    if count > MAX_RANGE_VALUES:
        raise SweepKeyError(f"range {text!r} has {count} values (at most {MAX_RANGE_VALUES})")
    if all(isinstance(n, int) for n in numbers):
        return list(range(start, stop + 1, step))
    return [round(start + i * step, 9) for i in range(count)]


def apply(doc: tomlkit.TOMLDocument, key: str, value) -> None:
    """Set ``key`` (dotted) to ``value`` in the TOML document ``doc``, in place."""
    if key == AGV_COUNT:
        set_agv_count(doc, value)
        return
    parts = key.split(".")
    node = doc
    for depth, part in enumerate(parts[:-1]):
        where = ".".join(parts[: depth + 1])
        if isinstance(node, AoT | Array | list):
            node = _entry(node, part, where)
        elif isinstance(node, dict):
            if part not in node:  # a new table: inline below the top (TOML allows it there)
                node[part] = tomlkit.table() if node is doc else tomlkit.inline_table()
            node = node[part]
        else:
            raise SweepKeyError(f"{key}: {'.'.join(parts[:depth])} is a value, not a table")
        if not isinstance(node, dict | list):
            raise SweepKeyError(f"{key}: {where} is a value ({node!r}), not a table or list")
    last = parts[-1]
    if isinstance(node, AoT | Array | list):
        raise SweepKeyError(f"{key}: {'.'.join(parts[:-1])} is a list: name one of its entries")
    node[last] = value


def _entry(items, part: str, where: str):
    """The entry of a list named ``part`` (its ``name`` key), or at index ``part``."""
    named = [e for e in items if isinstance(e, dict) and e.get("name") == part]
    if named:
        return named[0]
    if part.isdigit() and int(part) < len(items):
        return items[int(part)]
    names = [str(e["name"]) for e in items if isinstance(e, dict) and "name" in e]
    known = f"names: {', '.join(names)}; " if names else ""
    raise SweepKeyError(
        f"{where}: no such entry ({known}indexes 0..{len(items) - 1})"
        if items
        else f"{where}: the list is empty"
    )


def set_agv_count(doc: tomlkit.TOMLDocument, count) -> None:
    """``agvs.count``: ``count`` AGVs like the first, on the first parking stations."""
    if isinstance(count, bool) or not isinstance(count, int) or count < 1:
        raise SweepKeyError(f"{AGV_COUNT} must be a positive integer, got {count!r}")
    stations = doc.get("stations", [])
    spots = [s["position"] for s in stations if isinstance(s, dict) and s.get("group") == PARKING]
    if len(spots) < count:
        raise SweepKeyError(
            f"{AGV_COUNT} = {count}: the scenario has {len(spots)} stations of group "
            f"{PARKING!r} to start AGVs on"
        )
    agvs = doc.get("agvs") or [{}]
    template = {k: v for k, v in agvs[0].items() if k not in ("name", "start", "goal")}
    fleet = tomlkit.aot()
    for i, spot in enumerate(spots[:count]):
        entry = tomlkit.table()
        entry["name"] = f"agv{i + 1}"
        entry["start"] = list(spot)
        for k, v in template.items():
            entry[k] = v
        fleet.append(entry)
    doc["agvs"] = fleet
