"""A shift in Rerun (``fleet.missions``): the stations as markers, and each AGV's current
task as a labelled marker on its goal with a line from the AGV to it.

Entity paths (beside ``recordings.rerun_rows``'s):

    world/stations                Points2D, static: every station, labelled, coloured by
                                  group (pick, drop, parking, others)
    world/agv/<name>/task         Points2D: a ring on the AGV's goal labelled with its task
                                  ("task 12 to dock-2", "to home"), from the ticks' assignments
    world/agv/<name>/task/way     LineStrips2D: from the AGV to that goal (cleared at the goal)

The stations come from the scenario text the recording carries (``stations_of``); the
tasks from the ticks, so a live view and a replay draw the same.
"""

from __future__ import annotations

import tomllib

import rerun as rr

from planner.core.status import AT_DROP_OFF, AT_HOME, AT_PICK_UP, TO_HOME
from recordings import rerun_kinds as kinds

STATIONS = "world/stations"
GROUP_COLORS = {"pick": (70, 130, 230), "drop": (40, 170, 90), "parking": (150, 150, 150)}
OTHER_COLOR = (200, 120, 40)
STATION_RADIUS = 0.3  # m
Station = tuple[str, tuple[float, float], str]  # name, position, group


def stations_of(scenario_text: str | None) -> list[Station]:
    """The ``[[stations]]`` of a recording's scenario text (none if it has none or the text
    is not TOML: a recording is drawn whatever its scenario says)."""
    try:
        doc = tomllib.loads(scenario_text or "")
    except tomllib.TOMLDecodeError:
        return []
    out = []
    for s in doc.get("stations", []) if isinstance(doc.get("stations"), list) else []:
        position = s.get("position") if isinstance(s, dict) else None
        if isinstance(position, list) and len(position) == 2:
            out.append((str(s.get("name", "")), (float(position[0]), float(position[1])),
                        str(s.get("group", ""))))  # fmt: skip
    return out


def station_rows(stations: list[Station], row) -> list:
    """The static markers of ``stations`` (``row``: ``rerun_rows.Row``)."""
    if not stations:
        return []
    markers = rr.Points2D(
        [p for _, p, _ in stations],
        radii=STATION_RADIUS,
        colors=[GROUP_COLORS.get(g, OTHER_COLOR) for _, _, g in stations],
        labels=[n for n, _, _ in stations],
        show_labels=True,
        draw_order=11.0,
    )
    return [row(STATIONS, None, None, [markers])]


def task_styles(color) -> dict:
    """The static styles of an AGV's task entities, by part."""
    return {
        "task": rr.Points2D.from_fields(colors=color, show_labels=True, draw_order=13.0),
        "task/way": rr.LineStrips2D.from_fields(
            colors=(*color, 110), radii=rr.Radius.ui_points(1.0), draw_order=13.0
        ),
    }


def task_label(assignment: dict) -> str:
    phase, station = assignment["phase"], assignment.get("station", "")
    if phase in (TO_HOME, AT_HOME):
        return phase
    where = f"{'at' if phase in (AT_PICK_UP, AT_DROP_OFF) else 'to'} {station}"
    return f"task {assignment['task']} {where}"


class TaskRows:
    """The rows of the ticks' assignments: a label when it changes, the way every tick."""

    def __init__(self, path_of, row):
        self._path_of, self._row = path_of, row  # rerun_rows.agv_path, rerun_rows.Row
        self._shown: dict[str, tuple] = {}
        self._way: set[str] = set()

    def rows(self, t: float, data: dict) -> list:
        out = []
        assignments = data.get("assignments", [])  # none outside a shift
        if not assignments:
            return out
        where = {s["name"]: (s["x"], s["y"]) for s in data["agvs"]}
        for a in assignments:
            name, goal = a["name"], a["goal"]
            label = task_label(a)
            if self._shown.get(name) != (label, goal):
                self._shown[name] = (label, goal)
                payload = ([goal], [STATION_RADIUS * 1.6], [label])
                out.append(self._row(self._path_of(name, "task"), kinds.points, t, payload))
            going = a["phase"] not in (AT_HOME, AT_PICK_UP, AT_DROP_OFF) and name in where
            if going:
                way = [[list(where[name]), goal]]
                out.append(self._row(self._path_of(name, "task/way"), kinds.strips, t, way))
                self._way.add(name)
            elif name in self._way:
                self._way.discard(name)
                out.append(self._row(self._path_of(name, "task/way"), kinds.strips, t, []))
        return out
