"""From the fleet's messages (dict form) to Rerun rows: one state machine for replay and live.

A row is (entity path, kind, sim time in s, payload); a static row has no kind and
no time and carries ready archetypes. The replay gathers the rows of a whole
recording into columns, the live view logs each row as it comes: both see the same
rows, so they show the same entities.

Entity paths (everything on the map under ``world``, in world coordinates):

    world                         Transform3D, static: shows y up (see ``world_rows``)
    world/map                     Image + Transform3D, static: the grid, one pixel a cell
    world/passages                Image, static: the passages one AGV wide (traffic rule), for
                                  the first AGV's radius and the default margin
    world/temporary               Boxes2D: temporary obstacles shown so far
    world/moving                  Points2D discs with labels: moving obstacles
    world/agv/<name>/body         Points2D disc (radius = AGV radius)
    world/agv/<name>/heading      Arrows2D: heading, centre to beyond the rim
    world/agv/<name>/label        Points2D: the name, beside the disc (not over it)
    world/agv/<name>/start        Boxes2D, static: where the AGV started
    world/agv/<name>/goal         LineStrips2D, static: a cross on its goal (end of its path)
    world/agv/<name>/pose         Transform3D: the AGV's position (a frame to follow it in)
    world/agv/<name>/pose/follow  Transform3D, static: y up again inside that frame
    world/agv/<name>/trail        LineStrips2D: one segment per tick (the view shows all history)
    world/agv/<name>/plan         LineStrips2D: global path (a replan replaces it)
    world/agv/<name>/plan/key_nodes  Points2D: key nodes
    world/agv/<name>/dwa          LineStrips2D: DWA's chosen trajectory (cleared on arrival)
    world/agv/<name>/waiting      Points2D: a ring round an AGV the traffic rule holds, labelled
                                  with whom it waits for (cleared when it goes)
    world/agv/<name>/waiting/place  LineStrips2D: from that AGV to the waiting place the rule
                                  sent it to (cleared when it goes)
    world/roadmap                 LineStrips2D, static: the roadmap's edges (traffic mode
                                  "reservations"), for the first AGV's radius
    world/agv/<name>/reserved     LineStrips2D: the nodes the schedule reserved for the AGV
    events/<kind>                 TextLog: one entity per kind of event (the world's events:
                                  arrived, failed, collision, end, wait, go, yield, ...; and
                                  from the plans: replan, no path)
    velocity/<q>/<name>           Scalars, q in vx, vy (body frame), speed (|v|), omega

Beside them ``recordings.rerun_fleet`` makes ``fleet/...``: the fleet's counts per tick,
and ``recordings.rerun_tasks`` a shift's stations and each AGV's current task.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from typing import Any, NamedTuple

import numpy as np
import rerun as rr

from bridge import keys
from bridge.messages import MessageError
from planner.core.status import COLLISION, FAILED, FINISHED, INITIAL, RECOVERY, REPLAN
from planner.maps.clearance import Clearance
from planner.maps.costmap import Costmap
from planner.traffic.passages import NONE, Passages
from planner.traffic.roadmap import Roadmap
from planner.traffic.zones import HELD
from recordings import rerun_kinds as kinds
from recordings.map_frame import map_origin, map_size
from recordings.palette import agv_color
from recordings.rerun_tasks import TaskRows, station_rows, task_styles
from recordings.series import map_grid

TIMELINE = "sim_time"
WORLD = "world"
MAP = "world/map"
TEMPORARY = "world/temporary"
MOVING = "world/moving"
PASSAGES = "world/passages"
ROADMAP = "world/roadmap"
PASSAGE_RGBA = (255, 160, 0, 90)  # translucent orange over the map
EVENTS = "events"
VELOCITY = "velocity"
QUANTITIES = ("vx", "vy", "speed", "omega")

WHITE, GREY, ORANGE, DARK = (230, 230, 230), (160, 160, 160), (255, 160, 0), (20, 20, 20)
FREE_SHADE, BLOCKED_SHADE = 225, 70  # grey levels of the map image
NO_PATH = "no path"  # the kind of event a plan that found no path shows as
LEVELS = {COLLISION: "WARN", FAILED: "ERROR", NO_PATH: "WARN", RECOVERY: "WARN"}
WAITING_RING = 1.6  # x radius: the ring shows round the body
HEADING_LENGTH = 2.0  # x radius: the heading line sticks out of the disc, visible when small
LABEL_GAP = 1.0  # m right of the disc's rim: the name (centred on its anchor) never covers it


_AGV_HANDLERS = {  # the end of an AGV's key -> the RowMaker method that makes its rows
    "/command": "_state",
    "/state": "_state",  # recordings before the world integrated commands
    "/plan": "_plan",
    "/trajectory": "_trajectory",
}
AGV_ROW_TOPICS = tuple(_AGV_HANDLERS)
"""The ends of the AGV keys that make rows."""


class Row(NamedTuple):
    path: str
    kind: Callable[[list], Iterable[rr.ComponentColumn]] | None  # a rerun_kinds function
    time: float | None  # sim_time in s, None for static
    payload: Any  # what ``kind`` takes; for a static row, the archetypes


def agv_path(name: str, part: str) -> str:
    return f"{WORLD}/agv/{rr.escape_entity_path_part(name)}/{part}"


def event_path(kind: str) -> str:
    return f"{EVENTS}/{rr.escape_entity_path_part(kind)}"


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

    def __init__(self, dt: float, stations=()):
        """``stations``: a shift's, as ``rerun_tasks.stations_of`` gives them."""
        self.dt = dt
        self.agv_names: list[str] = []
        self.map_bounds: tuple[float, float, float, float] | None = None  # x0, y0, x1, y1 (m)
        self.end_time = 0.0  # sim time of the last tick seen
        self._resolution = 1.0
        self._origin = (0.0, 0.0)
        self._goal_shown: set[str] = set()
        self._last_xy: dict[str, tuple[float, float]] = {}
        self._dwa_shown: set[str] = set()
        self._moving_shown = False
        self._temporary: list[list[int]] = []
        self._map_msg: dict | None = None
        self._waiting_shown: set[str] = set()
        self._roadmap_of: dict | None = None  # the map, until the roadmap is drawn
        self._reserved_shown: set[str] = set()
        self._pending = world_rows() + station_rows(list(stations), Row)
        self._tasks = TaskRows(agv_path, Row)

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
            method = _AGV_HANDLERS.get(topic[topic.rfind("/") :])
            if name is not None and method is not None:
                self._meet(name, rows)
                getattr(self, method)(name, data, rows)

    def _time(self, tick: int) -> float:
        return round(tick * self.dt, 9)

    # --- static ------------------------------------------------------------------
    def _map(self, data: dict, rows: list[Row]) -> None:
        """The grid as one image, a pixel per cell (filled obstacles, and one image
        whatever the map's size), placed on the world by its transform."""
        self._map_msg = self._roadmap_of = data
        res = self._resolution = data["resolution"]
        x0, y0 = self._origin = map_origin(data)
        h = map_size(data)[1]
        self.map_bounds = map_bounds(data)
        cells = np.frombuffer("".join(data["rows"]).encode(), dtype=np.uint8)
        blocked = cells.reshape(data["height"], data["width"]) == ord("#")
        shades = np.where(blocked, BLOCKED_SHADE, FREE_SHADE).astype(np.uint8)
        # image row 0 (the top row) at the map's top edge, rows going down
        place = rr.Transform3D(translation=[x0, y0 + h, 0.0], scale=[res, -res, 1.0])
        image = rr.Image(shades, color_model="L", draw_order=0.0)
        rows.append(Row(MAP, None, None, [place, image]))

    def _meet(self, name: str, rows: list[Row]) -> None:
        """The first message of an AGV: its colour, label and drawing order, once."""
        if name in self.agv_names:
            return
        color = agv_color(len(self.agv_names))
        faded = (*color, 140)
        self.agv_names.append(name)
        thick, thin = rr.Radius.ui_points(2.0), rr.Radius.ui_points(1.0)
        styles = {
            "body": rr.Points2D.from_fields(colors=color, draw_order=30.0),
            "heading": rr.Arrows2D.from_fields(
                colors=DARK, radii=rr.Radius.ui_points(1.5), draw_order=31.0
            ),
            "label": rr.Points2D.from_fields(
                colors=color,
                radii=rr.Radius.ui_points(0.5),
                labels=name,
                show_labels=True,
                draw_order=32.0,
            ),
            "start": rr.Boxes2D.from_fields(colors=color, radii=thick, draw_order=12.0),
            "goal": rr.LineStrips2D.from_fields(colors=color, radii=thick, draw_order=12.0),
            "pose/follow": rr.Transform3D(scale=[1.0, -1.0, 1.0]),
            "trail": rr.LineStrips2D.from_fields(colors=faded, radii=thick, draw_order=15.0),
            "plan": rr.LineStrips2D.from_fields(colors=color, radii=thin, draw_order=20.0),
            "plan/key_nodes": rr.Points2D.from_fields(
                colors=color, radii=rr.Radius.ui_points(4.0), draw_order=21.0
            ),
            "dwa": rr.LineStrips2D.from_fields(colors=WHITE, radii=thin, draw_order=22.0),
            "waiting": rr.Points2D.from_fields(colors=ORANGE, show_labels=True, draw_order=29.0),
            "reserved": rr.LineStrips2D.from_fields(
                colors=faded, radii=rr.Radius.ui_points(4.0), draw_order=14.0
            ),
            **task_styles(color),
        }
        for part, style in styles.items():
            rows.append(Row(agv_path(name, part), None, None, [style]))
        for q in QUANTITIES:
            series = rr.SeriesLines(names=name, colors=color)
            rows.append(Row(velocity_path(q, name), None, None, [series]))

    # --- temporal ----------------------------------------------------------------
    def _tick(self, data: dict, rows: list[Row]) -> None:
        t = self.end_time = data["time"]
        if self._map_msg is not None and data["agvs"]:
            rows.append(_passages(self._map_msg, data["agvs"][0]["radius"]))
            self._map_msg = None
        self._waiting(t, data, rows)
        self._reserved(t, data, rows)
        rows.extend(self._tasks.rows(t, data))
        for s in data["agvs"]:
            name = s["name"]
            self._meet(name, rows)
            x, y, r = s["x"], s["y"], s["radius"]
            last = self._last_xy.get(name)
            if last is None:
                rows.append(_start(name, x, y, r))
            rows.append(Row(agv_path(name, "body"), kinds.points, t, ([[x, y]], [r], None)))
            length = HEADING_LENGTH * r
            arrow = [length * math.cos(s["theta"]), length * math.sin(s["theta"])]
            rows.append(Row(agv_path(name, "heading"), kinds.arrow, t, ([x, y], arrow)))
            beside = [[x + r + LABEL_GAP, y]]
            rows.append(Row(agv_path(name, "label"), kinds.points, t, (beside, None, None)))
            rows.append(Row(agv_path(name, "pose"), kinds.translation, t, [x, y]))
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
            res, (x0, y0) = self._resolution, self._origin
            centers = [[x0 + (c + 0.5) * res, y0 + (r + 0.5) * res] for c, r in self._temporary]
            half = [[res / 2, res / 2]] * len(centers)
            rows.append(Row(TEMPORARY, kinds.boxes, t, (centers, half)))

    def _waiting(self, t: float, data: dict, rows: list[Row]) -> None:
        """A ring round each AGV the traffic rule holds, labelled with whom it waits for."""
        held = {
            i["name"]: i
            for i in data.get("intents", [])  # none in recordings before the traffic rule
            if i["phase"] in HELD
        }
        for s in data["agvs"]:
            name = s["name"]
            if name in held:
                label = "waits for " + (", ".join(held[name].get("waits_for", [])) or "its turn")
                ring = ([[s["x"], s["y"]]], [WAITING_RING * s["radius"]], [label])
                rows.append(Row(agv_path(name, "waiting"), kinds.points, t, ring))
                hold = held[name].get("hold", [])  # none in recordings before it was shared
                way = [[[s["x"], s["y"]], hold]] if hold else []
                rows.append(Row(agv_path(name, "waiting/place"), kinds.strips, t, way))
                self._waiting_shown.add(name)
            elif name in self._waiting_shown:
                self._waiting_shown.discard(name)
                rows.append(Row(agv_path(name, "waiting"), kinds.points, t, ([], [], [])))
                rows.append(Row(agv_path(name, "waiting/place"), kinds.strips, t, []))

    def _reserved(self, t: float, data: dict, rows: list[Row]) -> None:
        """Traffic mode "reservations": the roadmap once, and each AGV's reserved nodes."""
        reservations = data.get("reservations", [])  # none before the mode existed
        if reservations and self._roadmap_of is not None and data["agvs"]:
            rows.append(_roadmap(self._roadmap_of, data["agvs"][0]["radius"]))
            self._roadmap_of = None
        now = set()
        for r in reservations:
            now.add(r["name"])
            path = [r["path"]] if len(r["path"]) > 1 else []
            rows.append(Row(agv_path(r["name"], "reserved"), kinds.strips, t, path))
        for name in self._reserved_shown - now:
            rows.append(Row(agv_path(name, "reserved"), kinds.strips, t, []))
        self._reserved_shown = now

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
        if path and name not in self._goal_shown:
            self._goal_shown.add(name)
            rows.append(_goal(name, path[-1]))
        if not data["found"]:
            self._log_event(t, NO_PATH, [name], data["reason"], rows)
        elif data["reason"] != INITIAL:
            detail = f"new path {data['length']:.1f} m"
            if data["reason"] != REPLAN:
                detail = f"{data['reason']}, {detail}"
            self._log_event(t, REPLAN, [name], detail, rows)

    def _trajectory(self, name: str, data: dict, rows: list[Row]) -> None:
        self._dwa_shown.add(name)
        points = data["points"]
        rows.append(Row(agv_path(name, "dwa"), kinds.strips, self._time(data["tick"]), [points]))

    def _event(self, data: dict, rows: list[Row]) -> None:
        self._log_event(data["time"], data["kind"], data["agvs"], data["detail"], rows)

    def _log_event(self, t: float, kind: str, agvs: list[str], detail: str, rows: list[Row]):
        """Any kind of event, on an entity of its own: "replan agv7: stuck, ..."."""
        text = " ".join([kind, *agvs])  # "arrived agv1", "collision left right"
        if detail and detail != kind:
            text += f": {detail}"
        rows.append(Row(event_path(kind), kinds.text, t, (text, LEVELS.get(kind, "INFO"))))


def map_bounds(map_data: dict) -> tuple[float, float, float, float]:
    """(x0, y0, x1, y1) in m of a ``world/map`` message (dict form)."""
    x0, y0 = map_origin(map_data)
    w, h = map_size(map_data)
    return (x0, y0, x0 + w, y0 + h)


def _passages(map_msg: dict, radius: float) -> Row:
    """The passages of the map (``planner.traffic.passages``) as a translucent image over it."""
    grid = map_grid(map_msg)
    passages = Passages.build(Costmap.build(grid, Clearance(radius)))
    inside = passages.label[::-1] != NONE  # image rows top down
    rgba = np.zeros((*inside.shape, 4), dtype=np.uint8)
    rgba[inside] = PASSAGE_RGBA
    x0, _, _, y1 = grid.extent
    res = grid.resolution
    place = rr.Transform3D(translation=[x0, y1, 0.0], scale=[res, -res, 1.0])
    return Row(PASSAGES, None, None, [place, rr.Image(rgba, color_model="RGBA", draw_order=0.5)])


def _roadmap(map_msg: dict, radius: float) -> Row:
    """The roadmap's edges (``planner.traffic.roadmap``), thin and grey under everything."""
    roadmap = Roadmap.build(Costmap.build(map_grid(map_msg), Clearance(radius)))
    edges = [
        [roadmap.centres[a].tolist(), roadmap.centres[b].tolist()]
        for a in range(len(roadmap))
        for b in roadmap.neighbours[a][:2]  # east and north: each edge once
        if b >= 0
    ]
    style = rr.LineStrips2D(
        np.asarray(edges, dtype=np.float32).reshape(-1, 2, 2),
        colors=GREY, radii=rr.Radius.ui_points(0.5), draw_order=1.0,
    )  # fmt: skip
    return Row(ROADMAP, None, None, [style])


def _start(name: str, x: float, y: float, r: float) -> Row:
    """A square around the AGV's first position."""
    square = rr.Boxes2D(centers=[[x, y]], half_sizes=[[r, r]])
    return Row(agv_path(name, "start"), None, None, [square])


def _goal(name: str, xy: list[float]) -> Row:
    """A cross in the AGV's colour on its goal (the end of its first path)."""
    x, y = xy
    d = 0.35
    cross = [[[x - d, y - d], [x + d, y + d]], [[x - d, y + d], [x + d, y - d]]]
    return Row(agv_path(name, "goal"), None, None, [rr.LineStrips2D(cross)])
