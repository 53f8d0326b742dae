"""The run on Foxglove's own schemas, so that Foxglove's 3D panel draws a recording.

Beside the project's channels the recorder writes (JSON, with Foxglove's published
JSON Schemas from ``recordings/foxglove_schemas``):

    foxglove/map     foxglove.Grid            the map once, in frame ``map``; cell value
                                              100 blocked, 0 free (as a ROS occupancy grid)
    foxglove/tf      foxglove.FrameTransform  every tick, ``map`` -> <AGV name>: its pose
    foxglove/agvs    foxglove.SceneUpdate     once per AGV: its disc, heading and name,
                                              locked to its frame (so they move with it)
    foxglove/plans   foxglove.SceneUpdate     every global plan: path and key nodes
                                              (entity <name>/plan, a replan replaces it)

Timestamps in these messages are the log times (the run's wall-clock start plus sim
time), which is what Foxglove lines frames up by.
"""

from __future__ import annotations

import base64
import json
import math
from functools import cache
from pathlib import Path

from bridge import keys
from recordings.map_frame import map_origin
from recordings.palette import agv_color

SCHEMAS = Path(__file__).with_name("foxglove_schemas")
MAP_FRAME = "map"
MAP, TF, AGVS, PLANS = "foxglove/map", "foxglove/tf", "foxglove/agvs", "foxglove/plans"
SCHEMA_OF = {
    MAP: "foxglove.Grid",
    TF: "foxglove.FrameTransform",
    AGVS: "foxglove.SceneUpdate",
    PLANS: "foxglove.SceneUpdate",
}
OCCUPIED, FREE = 100, 0
UINT8 = 1  # foxglove.NumericType
LINE_STRIP = 0  # foxglove.LineType
DELETE_MATCHING_ID = 0  # foxglove.SceneEntityDeletionType
_IDENTITY = {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}
_NEVER_EXPIRES = {"sec": 0, "nsec": 0}


@cache
def schema(name: str) -> bytes:
    """The published JSON Schema of a ``foxglove.*`` type, as stored in a recording."""
    return (SCHEMAS / f"{name}.json").read_bytes()


class FoxgloveChannels:
    """Feeds on the fleet's messages (dict form) and returns the Foxglove messages
    they make, as (topic, message) pairs; ``stamp_ns`` is the message's log time."""

    WANTED = frozenset({keys.WORLD_MAP, keys.WORLD_TICK})

    def __init__(self):
        self._agvs: list[str] = []

    def wants(self, key: str) -> bool:
        return key in self.WANTED or key.endswith("/plan")

    def feed(self, key: str, data: dict, stamp_ns: int) -> list[tuple[str, dict]]:
        stamp = _time(stamp_ns)
        if key == keys.WORLD_MAP:
            return [(MAP, _grid(data, stamp))]
        if key == keys.WORLD_TICK:
            return self._tick(data, stamp)
        name = keys.agv_name(key)
        if name is not None:
            return [(PLANS, self._plan(name, data, stamp))]
        return []

    def _tick(self, data: dict, stamp: dict) -> list[tuple[str, dict]]:
        out = []
        for s in data["agvs"]:
            if s["name"] not in self._agvs:
                self._agvs.append(s["name"])
                out.append((AGVS, self._body(s, stamp)))
            transform = {
                "timestamp": stamp,
                "parent_frame_id": MAP_FRAME,
                "child_frame_id": s["name"],
                "translation": {"x": s["x"], "y": s["y"], "z": 0.0},
                "rotation": _yaw(s["theta"]),
            }
            out.append((TF, transform))
        return out

    def _color(self, name: str, alpha: float = 1.0) -> dict:
        r, g, b = agv_color(self._agvs.index(name))
        return {"r": r / 255, "g": g / 255, "b": b / 255, "a": alpha}

    def _body(self, s: dict, stamp: dict) -> dict:
        """A disc, a heading arrow and the name, in the AGV's own frame."""
        name, r = s["name"], s["radius"]
        body = _entity(stamp, s["name"], f"{name}/body", frame_locked=True)
        body["cylinders"] = [
            {
                "pose": _pose(0.0, 0.0),
                "size": {"x": 2 * r, "y": 2 * r, "z": 0.2},
                "bottom_scale": 1.0,
                "top_scale": 1.0,
                "color": self._color(name),
            }
        ]
        body["arrows"] = [
            {
                "pose": _pose(0.0, 0.0, z=0.2),
                "shaft_length": 1.4 * r,
                "shaft_diameter": 0.2 * r,
                "head_length": 0.6 * r,
                "head_diameter": 0.5 * r,
                "color": {"r": 0.1, "g": 0.1, "b": 0.1, "a": 1.0},
            }
        ]
        body["texts"] = [
            {
                "pose": _pose(0.0, 0.0, z=0.5),
                "billboard": True,
                "font_size": 14.0,
                "scale_invariant": True,
                "color": self._color(name),
                "text": name,
            }
        ]
        return {"deletions": [], "entities": [body]}

    def _plan(self, name: str, data: dict, stamp: dict) -> dict:
        entity_id = f"{name}/plan"
        if not data["found"]:
            deletion = {"timestamp": stamp, "type": DELETE_MATCHING_ID, "id": entity_id}
            return {"deletions": [deletion], "entities": []}
        if name not in self._agvs:  # a plan before the first tick
            self._agvs.append(name)
        plan = _entity(stamp, MAP_FRAME, entity_id, frame_locked=False)
        plan["lines"] = [
            {
                "type": LINE_STRIP,
                "pose": _pose(0.0, 0.0),
                "thickness": 2.0,
                "scale_invariant": True,
                "points": [_point(p) for p in data["path"]],
                "color": self._color(name, 0.8),
                "colors": [],
                "indices": [],
            }
        ]
        plan["spheres"] = [
            {"pose": _pose(*p), "size": {"x": 0.3, "y": 0.3, "z": 0.3}, "color": self._color(name)}
            for p in data["key_nodes"]
        ]
        return {"deletions": [], "entities": [plan]}


def _grid(data: dict, stamp: dict) -> dict:
    """The map as a foxglove.Grid: rows from the bottom (the grid's origin corner) up."""
    width, res = data["width"], data["resolution"]
    cells = bytes(OCCUPIED if c == "#" else FREE for row in reversed(data["rows"]) for c in row)
    x0, y0 = map_origin(data)
    return {
        "timestamp": stamp,
        "frame_id": MAP_FRAME,
        "pose": _pose(x0, y0),
        "column_count": width,
        "cell_size": {"x": res, "y": res},
        "row_stride": width,
        "cell_stride": 1,
        "fields": [{"name": "occupancy", "offset": 0, "type": UINT8}],
        "data": base64.b64encode(cells).decode(),
    }


def _entity(stamp: dict, frame: str, entity_id: str, *, frame_locked: bool) -> dict:
    return {
        "timestamp": stamp,
        "frame_id": frame,
        "id": entity_id,
        "lifetime": _NEVER_EXPIRES,
        "frame_locked": frame_locked,
        "metadata": [],
        "arrows": [],
        "cubes": [],
        "spheres": [],
        "cylinders": [],
        "lines": [],
        "triangles": [],
        "texts": [],
        "models": [],
    }


def _time(ns: int) -> dict:
    return {"sec": ns // 1_000_000_000, "nsec": ns % 1_000_000_000}


def _yaw(theta: float) -> dict:
    return {"x": 0.0, "y": 0.0, "z": math.sin(theta / 2), "w": math.cos(theta / 2)}


def _point(p: list[float]) -> dict:
    return {"x": p[0], "y": p[1], "z": 0.0}


def _pose(x: float, y: float, z: float = 0.0) -> dict:
    return {"position": {"x": x, "y": y, "z": z}, "orientation": dict(_IDENTITY)}


def encode(message: dict) -> bytes:
    return json.dumps(message, separators=(",", ":")).encode()
