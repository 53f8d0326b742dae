"""The scenario keys of a shift (scenarios/README.md): ``[[stations]]``, ``[tasks]`` and
``tasks``/``repeat`` in ``[[agvs]]``, read into ``fleet.missions.spec.Missions``.

Every mistake is one ScenarioError naming the key: a station in a wall or without room
for the fleet's widest body, a duplicate name, an unknown station or group.
"""

from __future__ import annotations

from fleet.missions.spec import Generator, Missions, Station, TaskList
from fleet.placement import check_room
from fleet.toml_schema import (
    MAX_TIME_LIMIT,
    ScenarioError,
    as_point,
    check_keys,
    get_int,
    get_list,
    get_number,
    get_str,
    get_table,
)
from planner.maps.grid import GridMap

STATION_KEYS = ("name", "position", "dwell", "group")
TASKS_KEYS = ("shift", "generator")
GENERATOR_KEYS = ("rate_per_hour", "from", "to", "seed")
AGV_TASK_KEYS = ("tasks", "repeat")


def parse_missions(doc: dict, grid: GridMap, agvs) -> Missions | None:
    """The shift of a scenario document (None without a ``[tasks]`` table); ``agvs``
    are the parsed AGV specs, in the order of the document's ``[[agvs]]``."""
    raw_agvs = doc.get("agvs", [])
    has_lists = any(isinstance(a, dict) and "tasks" in a for a in raw_agvs)
    if "tasks" not in doc:
        if "stations" in doc or has_lists:
            raise ScenarioError("[[stations]] and per-AGV tasks need a [tasks] table (its shift)")
        return None
    table = get_table(doc, "tasks", "")
    check_keys(table, TASKS_KEYS, "tasks")
    shift = get_number(table, "shift", "tasks", positive=True, maximum=MAX_TIME_LIMIT)
    radius = max(a.radius for a in agvs)
    stations = _stations(get_list(doc, "stations", "", default=[]), grid, radius)
    groups = sorted({s.group for s in stations if s.group})
    generator = None
    if "generator" in table:
        generator = _generator(get_table(table, "generator", "tasks"), stations, groups)
    names = {s.name for s in stations}
    lists = []
    for i, (entry, spec) in enumerate(zip(raw_agvs, agvs, strict=True)):
        if "repeat" in entry and "tasks" not in entry:
            raise ScenarioError(f"agvs[{i}].repeat needs agvs[{i}].tasks")
        if "tasks" in entry:
            lists.append((spec.name, _task_list(entry, f"agvs[{i}]", names)))
    if generator is None and not lists:
        raise ScenarioError("[tasks] needs a generator or an AGV with its own tasks")
    return Missions(shift, stations, generator, tuple(lists))


def _stations(raw: list, grid: GridMap, radius: float) -> tuple[Station, ...]:
    out: list[Station] = []
    for i, entry in enumerate(raw):
        where = f"stations[{i}]"
        if not isinstance(entry, dict):
            raise ScenarioError(f"{where} must be a table")
        check_keys(entry, STATION_KEYS, where)
        name = get_str(entry, "name", where)
        if not name or any(s.name == name for s in out):
            raise ScenarioError(f"{where}.name {name!r} is empty or not unique")
        position = as_point(get_list(entry, "position", where), f"{where}.position")
        check_room(grid, position, radius, f"station {name!r}", "position")
        dwell = get_number(entry, "dwell", where, default=0.0, minimum=0.0, maximum=MAX_TIME_LIMIT)
        group = get_str(entry, "group", where, default="")
        out.append(Station(name, position, dwell, group))
    return tuple(out)


def _generator(table: dict, stations: tuple[Station, ...], groups: list[str]) -> Generator:
    where = "tasks.generator"
    check_keys(table, GENERATOR_KEYS, where)
    rate = get_number(table, "rate_per_hour", where, positive=True, maximum=1e6)
    source, target = (get_str(table, key, where) for key in ("from", "to"))
    for key, group in (("from", source), ("to", target)):
        if group not in groups:
            known = ", ".join(groups) or "none: give [[stations]] a group"
            raise ScenarioError(f"{where}.{key} = {group!r} names no station group ({known})")
    targets = [s.name for s in stations if s.group == target]
    if len(targets) == 1 and any(s.name == targets[0] for s in stations if s.group == source):
        raise ScenarioError(f"{where}: group {target!r} has no station but the pick-up's")
    return Generator(rate, source, target, get_int(table, "seed", where, default=0, minimum=0))


def _task_list(entry: dict, where: str, names: set[str]) -> TaskList:
    stations = get_list(entry, "tasks", where)
    if not stations or len(stations) % 2:
        raise ScenarioError(
            f"{where}.tasks must list stations in pairs (pick-up, drop-off), got {stations!r}"
        )
    for j, name in enumerate(stations):
        if not isinstance(name, str) or name not in names:
            raise ScenarioError(f"{where}.tasks[{j}] = {name!r} names no station")
    for j in range(0, len(stations), 2):
        if stations[j] == stations[j + 1]:
            raise ScenarioError(f"{where}.tasks[{j}:{j + 2}] picks up and drops off at one station")
    repeat = entry.get("repeat", False)
    if not isinstance(repeat, bool):
        raise ScenarioError(f"{where}.repeat must be true or false, got {repeat!r}")
    return TaskList(tuple(stations), repeat)
