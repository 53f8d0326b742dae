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

import msgspec

from planner.core.errors import BadInputError
from planner.core.status import DRIVING, RECOVERY_KINDS, STATUSES, TASK_PHASES
from planner.traffic.schedule import Reservation
from planner.traffic.zones import PHASES, Intent

# No list in a message is longer (a tick's AGVs, a plan's path on the largest map):
# a decoded message is bounded however it was made.
MAX_LIST_ITEMS = 1_000_000
# No count in a message is larger (a run has at most a few million ticks, a map a few
# million cells); a tick times the longest dt in nanoseconds still fits an MCAP log time.
MAX_COUNT = 2**31 - 1


@dataclass
class MapMsg:
    """The static map of a run: rows top to bottom as printed, '.' free, '#' blocked.

    ``origin`` [x, y] is the world position of the map's bottom-left corner (the ROS
    ``map`` frame of a map_server map; [0, 0] for other maps and in recordings made
    before it existed): cell (col, row), row 0 at the bottom, covers
    [x + col*resolution, x + (col+1)*resolution) x [y + row*resolution, ...).
    """

    name: str
    width: int
    height: int
    resolution: float
    rows: list[str]
    origin: list[float] = field(default_factory=lambda: [0.0, 0.0])


@dataclass
class AgvState:
    """Pose (world frame) and body-frame command of one AGV at a tick, as the world
    integrated it (in ``Tick.agvs``)."""

    name: str
    tick: int
    x: float
    y: float
    theta: float
    vx: float
    vy: float
    omega: float
    radius: float
    status: str = DRIVING
    target: list[float] | None = None
    plan_time_ms: float = 0.0
    failure: str = ""  # why, when status is "failed"


@dataclass
class AgvCommand:
    """One AGV's answer to tick k: its body-frame command for the period up to ``tick``
    (k + 1), and what it reports. The world checks the command against the AGV's limits
    and integrates it; an AGV never states its own pose.

    ``start_heading`` is the paper's initial turn towards the first key node (the paper
    profile turns the AGV in place before it starts): the world accepts it in the answer
    to tick 0 only, and only for an AGV of the paper profile.
    """

    name: str
    tick: int
    vx: float
    vy: float
    omega: float
    status: str = DRIVING
    target: list[float] | None = None
    plan_time_ms: float = 0.0
    start_heading: float | None = None
    failure: str = ""  # why, when status is "failed"
    intent: Intent | None = None  # its traffic claim and route ahead (planner/traffic.py)
    recovery: str = ""  # the recovery it started this period (planner/recovery.py), '' none


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
class Assignment:
    """What an AGV of a shift does (``fleet.missions``): its current goal [x, y], the
    task it serves (0: none) and its phase; the AGV plans anew when its goal changes."""

    name: str
    goal: list[float]
    task: int = 0
    phase: str = TASK_PHASES[-1]
    station: str = ""  # the station of ``goal`` ('' for home)


@dataclass
class Tick:
    """The world's clock: tick k at time t with every AGV and obstacle.

    ``final`` marks the last tick of a run: the end state, which nobody answers.
    ``intents`` are the traffic intents that claim a passage, as the AGVs sent them with
    their commands for this tick: every AGV decides on the same ones
    (``planner.traffic.zones``).
    """

    tick: int
    time: float
    agvs: list[AgvState]
    moving: list[ObstacleState] = field(default_factory=list)
    temporary: list[list[int]] = field(default_factory=list)
    final: bool = False
    intents: list[Intent] = field(default_factory=list)  # passage claims, of tick k-1
    # traffic mode "reservations": the nodes each running AGV may enter, and whom it waits for
    reservations: list[Reservation] = field(default_factory=list)
    # a shift (fleet.missions): every AGV's goal and task; empty without one (and in
    # recordings made before it). Not in repr: the behaviour fingerprint hashes reprs
    assignments: list[Assignment] = field(default_factory=list, repr=False)


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


# string fields that take one of a few values
CHOICES = {
    (AgvState, "status"): STATUSES,
    (AgvCommand, "status"): STATUSES,
    (AgvCommand, "recovery"): ("", *RECOVERY_KINDS),
    (Intent, "phase"): PHASES,
    (Assignment, "phase"): TASK_PHASES,
}

MESSAGE_TYPES = (MapMsg, AgvState, ObstacleState, Tick, PlanMsg, TrajectoryMsg, Event, ResultMsg)


class MessageError(BadInputError, ValueError):
    """A payload that does not decode to the expected message type."""


def encode(msg) -> bytes:
    """The message as compact JSON: the bytes on the bus and in recordings, in both run
    modes. msgspec encodes the dataclasses in C: a 50-AGV tick in 0.1 ms, against 0.65 ms
    for ``json.dumps(to_dict(msg))``. msgspec writes a non-finite number as ``null``: a
    decoder then refuses a message with one in a required number, and reads one in an
    optional number (``start_heading``) as absent. The world and the planners send only
    finite numbers; the decoders' checks are what keeps a forged one out."""
    return _ENCODER.encode(msg)


def plain_number(value):
    """numpy's float64 (some planner values are) as the float it equals; msgspec calls
    this only for the types it does not know, and names one it cannot encode."""
    if isinstance(value, float):
        return float(value)
    raise NotImplementedError


_ENCODER = msgspec.json.Encoder(enc_hook=plain_number)


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


def optional_inner(hint):
    """``hint`` without its ``| None``, and whether it had one (a message field is a type
    or a type or None)."""
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        (inner,) = [a for a in typing.get_args(hint) if a is not type(None)]
        return inner, True
    return hint, False


def _field_encoder(hint):
    """None where the value is JSON-ready as it is, else a function that makes it so."""
    inner, optional = optional_inner(hint)
    if optional:
        return _field_encoder(inner)
    origin = typing.get_origin(hint)
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
    """A decoding function for one message class, generated once from its type hints as
    straight-line Python (as ``dataclasses`` generates ``__init__``): with a converter
    call per field, checking a 100-AGV tick cost more than parsing its JSON. A valid
    value passes an inline check; any other goes to ``_SLOW_CHECKS``, which converts it
    (an int for a float) or raises with the field's path."""
    hints = typing.get_type_hints(cls)
    fields = dataclasses.fields(cls)
    code = _Code({"cls": cls, "names": frozenset(f.name for f in fields)})
    body = [
        "def decode(data, where):",
        "    if not isinstance(data, dict):",
        "        raise MessageError(f'{where}: expected an object, got {type(data).__name__}')",
        "    present = 0",
    ]
    for i, f in enumerate(fields):
        where = f"where + {'.' + f.name!r}"
        value = code.check("v", hints[f.name], where, CHOICES.get((cls, f.name)))
        body += [f"    v = data.get({f.name!r}, MISSING)", "    if v is MISSING:"]
        if f.default is not dataclasses.MISSING:
            body.append(f"        a{i} = {code.name(f.default)}")
        elif f.default_factory is not dataclasses.MISSING:
            body.append(f"        a{i} = {code.name(f.default_factory)}()")
        else:
            body.append(
                f"        raise MessageError(where + {': missing field ' + repr(f.name)!r})"
            )
        body += ["    else:", "        present += 1", f"        a{i} = {value}"]
    body += [
        "    if len(data) > present:",
        "        extra = sorted(set(data) - names)",
        "        raise MessageError(f'{where}: unknown field {extra[0]!r}')",
        f"    return cls({', '.join(f'a{i}' for i in range(len(fields)))})",
    ]
    return code.run(body, "decode")


class _Code:
    """The source of one generated decoder: its helper functions and the values it uses."""

    def __init__(self, env: dict):
        self.env = {"MessageError": MessageError, "MISSING": dataclasses.MISSING, **env}
        self.env["MAX_LIST_ITEMS"] = MAX_LIST_ITEMS
        self.defs: list[str] = []

    def name(self, value) -> str:
        """A name under which the generated code sees ``value``."""
        name = f"_{len(self.env)}"
        self.env[name] = value
        return name

    def check(self, var: str, hint, where: str, choices=None) -> str:
        """An expression: ``var`` converted to ``hint``, else MessageError at path ``where``."""
        inner, optional = optional_inner(hint)
        if optional:
            return f"None if {var} is None else {self.check(var, inner, where)}"
        if typing.get_origin(hint) is list:
            (inner,) = typing.get_args(hint)
            item = self.check("x", inner, "where")
            items = f"items{len(self.defs)}"
            self.defs.append(
                f"def {items}(v, where):\n"
                "    if not isinstance(v, list):\n"
                "        raise MessageError(f'{where}: expected a list')\n"
                "    if len(v) > MAX_LIST_ITEMS:\n"
                "        raise MessageError(\n"
                "            f'{where}: {len(v)} items, more than {MAX_LIST_ITEMS}')\n"
                f"    return [{item} for x in v]"
            )
            return f"{items}({var}, {where})"
        if dataclasses.is_dataclass(hint):
            return f"{self.name(_decoder(hint))}({var}, {where})"
        slow = _SLOW_CHECKS[hint]
        if choices is not None:
            slow = functools.partial(_one_of, choices, slow)
            fast = f"type({var}) is str and {var} in {self.name(choices)}"
        else:
            fast = _FAST_CHECKS[hint].format(v=var)
        return f"{var} if {fast} else {self.name(slow)}({var}, {where})"

    def run(self, body: list[str], function: str):
        exec("\n".join([*self.defs, *body]), self.env)
        return self.env[function]


FLOAT_INT_LIMIT = 2**1023  # ints beyond any float's range do not convert


def _to_float(v, where):
    """A finite number: JSON from Python may carry NaN and Infinity, and one NaN pose
    would run through the planner and every later tick."""
    if type(v) is float:
        if v - v == 0.0:  # not for NaN or an infinity (a call to math.isfinite costs more)
            return v
    elif type(v) is int and -FLOAT_INT_LIMIT < v < FLOAT_INT_LIMIT:
        return float(v)
    raise MessageError(f"{where}: expected a finite number, got {v!r}"[:200])


def _natural(v, where):
    """Every integer of a message counts something (ticks, cells, turns)."""
    if type(v) is int and 0 <= v <= MAX_COUNT:
        return v
    raise MessageError(f"{where}: expected a count (0 to {MAX_COUNT}), got {v!r}"[:200])


def _one_of(choices, convert, v, where):
    v = convert(v, where)
    if v not in choices:
        raise MessageError(f"{where}: {v!r} is not one of {', '.join(choices)}"[:200])
    return v


def _exactly(kind, v, where):
    if type(v) is not kind:
        raise MessageError(f"{where}: expected {kind.__name__}, got {v!r}"[:200])
    return v


_SLOW_CHECKS = {
    float: _to_float,
    int: _natural,
    str: functools.partial(_exactly, str),
    bool: functools.partial(_exactly, bool),
}
# what passes without a call; "v - v == 0.0" is False for NaN and the infinities
_FAST_CHECKS = {
    float: "type({v}) is float and {v} - {v} == 0.0",
    int: f"type({{v}}) is int and 0 <= {{v}} <= {MAX_COUNT}",
    str: "type({v}) is str",
    bool: "type({v}) is bool",
}


def json_schema(cls) -> dict:
    """JSON Schema (draft 2020-12) of a message type."""
    schema = _schema_of(cls)
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = cls.__name__
    return schema


def _schema_of(hint) -> dict:
    inner, optional = optional_inner(hint)
    if optional:
        return {"anyOf": [_schema_of(inner), {"type": "null"}]}
    if typing.get_origin(hint) is list:
        return {"type": "array", "items": _schema_of(typing.get_args(hint)[0])}
    if dataclasses.is_dataclass(hint):
        hints = typing.get_type_hints(hint)
        fields = dataclasses.fields(hint)
        properties = {f.name: _schema_of(hints[f.name]) for f in fields}
        for (cls, name), choices in CHOICES.items():
            if cls is hint:
                properties[name] = {"type": "string", "enum": list(choices)}
        return {
            "type": "object",
            "properties": properties,
            "required": [
                f.name
                for f in fields
                if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
            ],
            "additionalProperties": False,
        }
    if hint is int:
        return {"type": "integer", "minimum": 0, "maximum": MAX_COUNT}
    return {"type": {float: "number", str: "string", bool: "boolean"}[hint]}
