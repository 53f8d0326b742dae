"""From the fleet's messages (dict form) to Rerun rows: one state machine for replay and live.

A row is (entity path, kind, sim time in s, payload); a static row has no kind and
no time and carries ready archetypes. The replay gathers the rows of a whole
recording into columns, the live view logs each row as it comes: both see the same
rows, so they show the same entities.

Entity paths (everything on the map under ``world``, in world coordinates):

    world                         Transform3D, static: shows y up (see ``world_rows``)
    world/map                     Boxes2D, static: blocked cells (merged) and the border
    world/temporary               Boxes2D: temporary obstacles shown so far
    world/moving                  Points2D discs with labels: moving obstacles
    world/agv/<name>/body         Points2D disc (radius = AGV radius), labelled
    world/agv/<name>/heading      Arrows2D: heading
    world/agv/<name>/trail        LineStrips2D: one segment per tick (the view shows all history)
    world/agv/<name>/plan         LineStrips2D: global path (a replan replaces it)
    world/agv/<name>/plan/key_nodes  Points2D: key nodes
    world/agv/<name>/dwa          LineStrips2D: DWA's chosen trajectory (cleared on arrival)
    events                        TextLog: collisions, arrivals, failures, the end
    velocity/<q>/<name>           Scalars, q in vx, vy, speed (|v|), omega
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable
from typing import Any, NamedTuple

import rerun as rr

from bridge import keys
from bridge.messages import MessageError
from planner.agv_status import FINISHED
from recordings import rerun_kinds as kinds

TIMELINE = "sim_time"
WORLD = "world"
MAP = "world/map"
TEMPORARY = "world/temporary"
MOVING = "world/moving"
EVENTS = "events"
VELOCITY = "velocity"
QUANTITIES = ("vx", "vy", "speed", "omega")

# tab10: distinct colours for up to ten AGVs, then they repeat
PALETTE = (
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
)
WHITE, GREY, ORANGE = (230, 230, 230), (160, 160, 160), (255, 160, 0)
LEVELS = {"collision": "WARN", "failed": "ERROR"}


class Row(NamedTuple):
    path: str
    kind: Callable[[list], Iterable[rr.ComponentColumn]] | None  # a rerun_kinds function
    time: float | None  # sim_time in s, None for static
    payload: Any  # what ``kind`` takes; for a static row, the archetypes


def agv_path(name: str, part: str) -> str:
    return f"{WORLD}/agv/{rr.escape_entity_path_part(name)}/{part}"


def velocity_path(quantity: str, name: str) -> str:
    return f"{VELOCITY}/{quantity}/{rr.escape_entity_path_part(name)}"


def world_rows() -> list[Row]:
    """The static rows every view starts with.

    Rerun's 2-D views draw y down and cannot be told otherwise (rerun#1387); mirroring
    ``world`` keeps every entity in world coordinates (x right, y up, metres) and shows
    them y up."""
    return [
        Row(WORLD, None, None, [rr.Transform3D(scale=[1.0, -1.0, 1.0])]),
        Row(MOVING, None, None, [rr.Points2D.from_fields(colors=GREY, draw_order=25.0)]),
        Row(
            TEMPORARY,
            None,
            None,
            [rr.Boxes2D.from_fields(colors=ORANGE, radii=rr.Radius.ui_points(1.5), draw_order=1.0)],
        ),
    ]


class RowMaker:
    """Turns messages, in recording order, into rows.

    ``dt`` is the control period: an AGV state carries its tick but no time, and it
    arrives before the tick it belongs to, so its time is ``tick * dt`` (the world's
    own formula).
    """

    def __init__(self, dt: float):
        self.dt = dt
        self.agv_names: list[str] = []
        self._resolution = 1.0
        self._last_xy: dict[str, tuple[float, float]] = {}
        self._dwa_shown: set[str] = set()
        self._moving_shown = False
        self._temporary: list[list[int]] = []
        self._pending = world_rows()

    def feed(self, topic: str, data: dict) -> list[Row]:
        """The rows of one message (MessageError if it lacks what its topic carries)."""
        rows, self._pending = self._pending, []
        try:
            self._dispatch(topic, data, rows)
        except (KeyError, TypeError, ValueError) as err:
            raise MessageError(f"a {topic} message does not fit its type ({err!r})") from None
        return rows

    def _dispatch(self, topic: str, data: dict, rows: list[Row]) -> None:
        if topic == keys.WORLD_TICK:
            self._tick(data, rows)
        elif topic == keys.WORLD_MAP:
            self._map(data, rows)
        elif topic == keys.WORLD_EVENT:
            self._event(data, rows)
        else:
            name = keys.agv_name(topic)
            handler = {
                "command": self._state,
                "state": self._state,  # recordings before the world integrated commands
                "plan": self._plan,
                "trajectory": self._trajectory,
            }.get(topic.rsplit("/", 1)[-1])
            if name is not None and handler is not None:
                self._meet(name, rows)
                handler(name, data, rows)

    def _time(self, tick: int) -> float:
        return round(tick * self.dt, 9)

    # --- static ------------------------------------------------------------------
    def _map(self, data: dict, rows: list[Row]) -> None:
        res = self._resolution = data["resolution"]
        rects = blocked_rectangles(data["rows"])
        centers = [[(c0 + c1) * res / 2, (r0 + r1) * res / 2] for c0, r0, c1, r1 in rects]
        half = [[(c1 - c0) * res / 2, (r1 - r0) * res / 2] for c0, r0, c1, r1 in rects]
        w, h = data["width"] * res, data["height"] * res
        colors = [(90, 90, 90)] * len(rects) + [(200, 200, 200)]
        boxes = rr.Boxes2D(
            centers=[*centers, [w / 2, h / 2]],
            half_sizes=[*half, [w / 2, h / 2]],
            colors=colors,
            radii=rr.Radius.ui_points(1.0),
            draw_order=0.0,
        )
        rows.append(Row(MAP, None, None, [boxes]))

    def _meet(self, name: str, rows: list[Row]) -> None:
        """The first message of an AGV: its colour, label and drawing order, once."""
        if name in self.agv_names:
            return
        color = PALETTE[len(self.agv_names) % len(PALETTE)]
        faded = (*color, 140)
        self.agv_names.append(name)
        thick, thin = rr.Radius.ui_points(2.0), rr.Radius.ui_points(1.0)
        styles = {
            "body": rr.Points2D.from_fields(
                colors=color, labels=name, show_labels=True, draw_order=30.0
            ),
            "heading": rr.Arrows2D.from_fields(colors=WHITE, radii=thin, draw_order=31.0),
            "trail": rr.LineStrips2D.from_fields(colors=faded, radii=thick, draw_order=15.0),
            "plan": rr.LineStrips2D.from_fields(colors=color, radii=thin, draw_order=20.0),
            "plan/key_nodes": rr.Points2D.from_fields(
                colors=color, radii=rr.Radius.ui_points(4.0), draw_order=21.0
            ),
            "dwa": rr.LineStrips2D.from_fields(colors=WHITE, radii=thin, draw_order=22.0),
        }
        for part, style in styles.items():
            rows.append(Row(agv_path(name, part), None, None, [style]))
        for q in QUANTITIES:
            series = rr.SeriesLines(names=name, colors=color)
            rows.append(Row(velocity_path(q, name), None, None, [series]))

    # --- temporal ----------------------------------------------------------------
    def _tick(self, data: dict, rows: list[Row]) -> None:
        t = data["time"]
        for s in data["agvs"]:
            name = s["name"]
            self._meet(name, rows)
            x, y, r = s["x"], s["y"], s["radius"]
            rows.append(Row(agv_path(name, "body"), kinds.points, t, ([[x, y]], [r], None)))
            arrow = [1.5 * r * math.cos(s["theta"]), 1.5 * r * math.sin(s["theta"])]
            rows.append(Row(agv_path(name, "heading"), kinds.arrow, t, ([x, y], arrow)))
            last = self._last_xy.get(name)
            if last is not None and last != (x, y):
                rows.append(Row(agv_path(name, "trail"), kinds.strips, t, [[list(last), [x, y]]]))
            self._last_xy[name] = (x, y)
        moving = data["moving"]
        if moving or self._moving_shown:
            payload = (
                [[o["x"], o["y"]] for o in moving],
                [o["radius"] for o in moving],
                [o["name"] for o in moving],
            )
            rows.append(Row(MOVING, kinds.points, t, payload))
            self._moving_shown = bool(moving)
        if data["temporary"] != self._temporary:
            self._temporary = data["temporary"]
            res = self._resolution
            centers = [[(c + 0.5) * res, (r + 0.5) * res] for c, r in self._temporary]
            half = [[res / 2, res / 2]] * len(centers)
            rows.append(Row(TEMPORARY, kinds.boxes, t, (centers, half)))

    def _state(self, name: str, data: dict, rows: list[Row]) -> None:
        t = self._time(data["tick"])
        vx, vy, omega = data["vx"], data["vy"], data["omega"]
        for q, v in zip(QUANTITIES, (vx, vy, math.hypot(vx, vy), omega)):
            rows.append(Row(velocity_path(q, name), kinds.scalar, t, v))
        if data["status"] in FINISHED and name in self._dwa_shown:
            self._dwa_shown.discard(name)
            rows.append(Row(agv_path(name, "dwa"), kinds.strips, t, []))

    def _plan(self, name: str, data: dict, rows: list[Row]) -> None:
        t = data["time"]
        path = data["path"] if data["found"] else []
        key_nodes = data["key_nodes"] if data["found"] else []
        rows.append(Row(agv_path(name, "plan"), kinds.strips, t, [path] if path else []))
        rows.append(Row(agv_path(name, "plan/key_nodes"), kinds.points, t, (key_nodes, None, None)))

    def _trajectory(self, name: str, data: dict, rows: list[Row]) -> None:
        self._dwa_shown.add(name)
        points = data["points"]
        rows.append(Row(agv_path(name, "dwa"), kinds.strips, self._time(data["tick"]), [points]))

    def _event(self, data: dict, rows: list[Row]) -> None:
        kind, detail = data["kind"], data["detail"]
        text = " ".join([kind, *data["agvs"]])  # "arrived agv1", "collision left right"
        if detail and detail != kind:
            text += f": {detail}"
        rows.append(Row(EVENTS, kinds.text, data["time"], (text, LEVELS.get(kind, "INFO"))))


def blocked_rectangles(rows_top_down: list[str]) -> list[tuple[int, int, int, int]]:
    """Blocked cells as few rectangles (col0, row0, col1, row1), half-open, row 0 at
    the bottom: runs of '#' in a row, merged with the same run in the rows above.
    A 1000x1000 map would otherwise be up to a million boxes."""
    done: list[tuple[int, int, int, int]] = []
    open_runs: dict[tuple[int, int], int] = {}  # (col0, col1) -> first row
    height = len(rows_top_down)
    for row in range(height + 1):
        runs = set(_runs(rows_top_down[height - 1 - row])) if row < height else set()
        for run in [r for r in open_runs if r not in runs]:
            done.append((run[0], open_runs.pop(run), run[1], row))
        for run in runs:
            open_runs.setdefault(run, row)
    return sorted(done)


def _runs(line: str):
    return ((m.start(), m.end()) for m in re.finditer("#+", line))
