"""The fleet's message types: plain dataclasses with a dict form for the wire.

Every message crosses the bus and goes into recordings as JSON; ``to_dict``
and ``from_dict`` are the only codec, and ``json_schema`` derives the JSON
Schema that the recorder stores with each channel. Nothing here imports zenoh,
so the in-process mode uses the same types.
"""

from __future__ import annotations

import dataclasses
import functools
import types
import typing
from dataclasses import dataclass, field

AGV_STATUSES = ("driving", "arrived", "blocked", "failed")


@dataclass
class MapMsg:
    """The static map of a run: rows top to bottom as printed, '.' free, '#' blocked."""

    name: str
    width: int
    height: int
    resolution: float
    rows: list[str]


@dataclass
class AgvState:
    """Pose (world frame) and body-frame command of one AGV at a tick."""

    name: str
    tick: int
    x: float
    y: float
    theta: float
    vx: float
    vy: float
    omega: float
    radius: float
    status: str = "driving"
    target: list[float] | None = None
    plan_time_ms: float = 0.0
    failure: str = ""  # why, when status is "failed"


@dataclass
class ObstacleState:
    """A moving obstacle at a tick: world-frame position and velocity."""

    name: str
    x: float
    y: float
    vx: float
    vy: float
    radius: float


@dataclass
class Tick:
    """The world's clock: tick k at time t with every AGV and obstacle.

    ``final`` marks the last tick of a run: the end state, which nobody answers.
    """

    tick: int
    time: float
    agvs: list[AgvState]
    moving: list[ObstacleState] = field(default_factory=list)
    temporary: list[list[int]] = field(default_factory=list)
    final: bool = False


@dataclass
class PlanMsg:
    """A global plan of one AGV: the first one or a replan."""

    name: str
    tick: int
    time: float
    algorithm: str
    reason: str
    found: bool
    path: list[list[float]]
    key_nodes: list[list[float]]
    length: float
    turns: int
    turning_angle_deg: float
    plan_time_ms: float


@dataclass
class TrajectoryMsg:
    """DWA's chosen predicted trajectory for one control cycle."""

    name: str
    tick: int
    points: list[list[float]]


@dataclass
class Event:
    """Something that happened in the world: collision, arrival, failure, run end."""

    tick: int
    time: float
    kind: str
    agvs: list[str] = field(default_factory=list)
    detail: str = ""


@dataclass
class ResultMsg:
    """How the run ended: the run summary as JSON text (its shape is the CLI's --json)."""

    summary: str


MESSAGE_TYPES = (MapMsg, AgvState, ObstacleState, Tick, PlanMsg, TrajectoryMsg, Event, ResultMsg)


class MessageError(ValueError):
    """A payload that does not decode to the expected message type."""


def to_dict(msg) -> dict:
    """The message as plain JSON-ready data (``dataclasses.asdict`` deep-copies
    every value and made encoding a 50-AGV tick cost 0.5 ms)."""
    return _encoder(type(msg))(msg)


@functools.cache
def _encoder(cls):
    hints = typing.get_type_hints(cls)
    plan = [(f.name, _field_encoder(hints[f.name])) for f in dataclasses.fields(cls)]
    return lambda msg: {
        name: value if encode is None or value is None else encode(value)
        for name, encode in plan
        for value in (getattr(msg, name),)
    }


def _field_encoder(hint):
    """None where the value is JSON-ready as it is, else a function that makes it so."""
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        (inner,) = [a for a in typing.get_args(hint) if a is not type(None)]
        return _field_encoder(inner)
    if origin is list:
        inner = _field_encoder(typing.get_args(hint)[0])
        return None if inner is None else (lambda items: [inner(x) for x in items])
    if dataclasses.is_dataclass(hint):
        return _encoder(hint)
    return None


def from_dict(cls, data):
    """Build ``cls`` from a decoded JSON object, checking every field's type."""
    return _decoder(cls)(data, cls.__name__)


@functools.cache
def _decoder(cls):
    """A decoding function for one message class, built once from its type hints
    (resolving hints per message would cost more than the JSON parse)."""
    hints = typing.get_type_hints(cls)
    specs = []
    for f in dataclasses.fields(cls):
        required = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        specs.append((f.name, required, _converter(hints[f.name])))
    names = {f.name for f in dataclasses.fields(cls)}

    def decode(data, where):
        if not isinstance(data, dict):
            raise MessageError(f"{where}: expected an object, got {type(data).__name__}")
        kwargs = {}
        for name, required, convert in specs:
            if name in data:
                kwargs[name] = convert(data[name], f"{where}.{name}")
            elif required:
                raise MessageError(f"{where}: missing field {name!r}")
        if len(data) > len(kwargs):
            extra = sorted(set(data) - names)
            if extra:
                raise MessageError(f"{where}: unknown field {extra[0]!r}")
        return cls(**kwargs)

    return decode


def _converter(hint):
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        (inner,) = [a for a in typing.get_args(hint) if a is not type(None)]
        convert_inner = _converter(inner)
        return lambda v, where: None if v is None else convert_inner(v, where)
    if origin is list:
        (inner,) = typing.get_args(hint)
        convert_item = _converter(inner)

        def convert_list(v, where):
            if not isinstance(v, list):
                raise MessageError(f"{where}: expected a list")
            return [convert_item(x, where) for x in v]

        return convert_list
    if dataclasses.is_dataclass(hint):
        return _decoder(hint)
    if hint is float:
        return _to_float
    if hint in (int, str, bool):
        return functools.partial(_exactly, hint)
    raise TypeError(f"unsupported field type {hint!r}")


def _to_float(v, where):
    if type(v) is float or (type(v) is int):
        return float(v)
    raise MessageError(f"{where}: expected a number, got {v!r}")


def _exactly(kind, v, where):
    if type(v) is not kind:
        raise MessageError(f"{where}: expected {kind.__name__}, got {v!r}")
    return v


def json_schema(cls) -> dict:
    """JSON Schema (draft 2020-12) of a message type."""
    schema = _schema_of(cls)
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = cls.__name__
    return schema


def _schema_of(hint) -> dict:
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        (inner,) = [a for a in typing.get_args(hint) if a is not type(None)]
        return {"anyOf": [_schema_of(inner), {"type": "null"}]}
    if origin is list:
        return {"type": "array", "items": _schema_of(typing.get_args(hint)[0])}
    if dataclasses.is_dataclass(hint):
        hints = typing.get_type_hints(hint)
        fields = dataclasses.fields(hint)
        return {
            "type": "object",
            "properties": {f.name: _schema_of(hints[f.name]) for f in fields},
            "required": [
                f.name
                for f in fields
                if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
            ],
            "additionalProperties": False,
        }
    return {"type": {float: "number", int: "integer", str: "string", bool: "boolean"}[hint]}
