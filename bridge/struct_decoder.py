"""A compiled fast path for decoding messages: msgspec Structs that mirror the message types.

Every AGV decodes every tick, and the world and the recorder decode every AGV's
command: with 50 AGVs, parsing a tick with orjson and checking it with
``messages.from_dict`` cost ~0.2 ms on an idle core and ~0.6 ms per AGV per tick
with 50 processes on 2 cores, which kept the lockstep's floor at 27 ticks/s.
msgspec parses and checks in C into Structs generated here from the dataclasses'
type hints, each check at least as strict as ``from_dict``'s: finite numbers
(within the ints ``from_dict`` converts), counts in [0, MAX_COUNT],
the choices of ``CHOICES``, lists of at most MAX_LIST_ITEMS, no unknown fields.
The Struct is then copied into the message dataclass by generated straight-line
code, so the rest of the project sees the same types as before.

``decode_valid`` returns None for anything msgspec refuses, and the caller falls
back to the reference decoder (``json`` and ``from_dict``): what msgspec is
stricter about (lone surrogates, a byte-order mark, numbers near the float range)
is then accepted or refused exactly as before, with the same reason.
"""

from __future__ import annotations

import dataclasses
import functools
import typing
from typing import Annotated, Literal

import msgspec

from bridge.messages import CHOICES, FLOAT_INT_LIMIT, MAX_COUNT, MAX_LIST_ITEMS, optional_inner

# strict bounds: from_dict refuses an int of magnitude FLOAT_INT_LIMIT
_FLOAT = Annotated[float, msgspec.Meta(gt=-float(FLOAT_INT_LIMIT), lt=float(FLOAT_INT_LIMIT))]
_COUNT = Annotated[int, msgspec.Meta(ge=0, le=MAX_COUNT)]


def decode_valid(cls, payload: bytes, binary: bool = False):
    """The ``cls`` message of a JSON (``binary``: MessagePack) ``payload`` if msgspec's
    checks pass, else None."""
    struct = decode_struct(cls, payload, binary)
    return None if struct is None else to_message(cls, struct)


def decode_struct(cls, payload: bytes, binary: bool = False):
    """The first half of ``decode_valid``: the payload parsed and checked into the Struct
    mirroring ``cls`` (every check done), not yet copied into the dataclass; None if
    msgspec refuses it. A reader that may drop the message after a look at a few fields
    (an AGV at a tick in which it stands held) saves the copy, half of the decoding."""
    decode, _ = _decoder(cls, binary)
    try:
        return decode(payload)
    except msgspec.MsgspecError:
        return None


def to_message(cls, struct):
    """The ``cls`` message of a Struct from ``decode_struct``."""
    return _copier(cls)(struct)


@functools.cache
def _decoder(cls, binary: bool):
    kind = msgspec.msgpack.Decoder if binary else msgspec.json.Decoder
    return kind(_struct(cls)).decode, _copier(cls)


def _type(hint, choices=None):
    """The msgspec type, with constraints, of a field hinted ``hint``."""
    inner, optional = optional_inner(hint)
    if optional:
        return _type(inner) | None
    if typing.get_origin(hint) is list:
        item = _type(typing.get_args(hint)[0])
        return Annotated[list[item], msgspec.Meta(max_length=MAX_LIST_ITEMS)]
    if dataclasses.is_dataclass(hint):
        return _struct(hint)
    if choices is not None:
        return Literal[tuple(choices)]
    return {float: _FLOAT, int: _COUNT, str: str, bool: bool}[hint]


@functools.cache
def _struct(cls):
    """The Struct mirroring dataclass ``cls``: the same fields, defaults and order."""
    hints = typing.get_type_hints(cls)
    fields = []
    for f in dataclasses.fields(cls):
        kind = _type(hints[f.name], CHOICES.get((cls, f.name)))
        if f.default is not dataclasses.MISSING:
            fields.append((f.name, kind, f.default))
        elif f.default_factory is not dataclasses.MISSING:
            fields.append((f.name, kind, msgspec.field(default_factory=f.default_factory)))
        else:
            fields.append((f.name, kind))
    return msgspec.defstruct(cls.__name__, fields, forbid_unknown_fields=True)


@functools.cache
def _copier(cls):
    """A function from a ``_struct(cls)`` value to the ``cls`` dataclass, generated as
    straight-line code (nested messages copied, every other value taken as it is)."""
    hints = typing.get_type_hints(cls)
    env = {"cls": cls}
    values = []
    for f in dataclasses.fields(cls):
        inner, optional = optional_inner(hints[f.name])
        value = f"s.{f.name}"
        if typing.get_origin(inner) is list and dataclasses.is_dataclass(typing.get_args(inner)[0]):
            env[f"copy_{f.name}"] = _copier(typing.get_args(inner)[0])
            value = f"[copy_{f.name}(x) for x in s.{f.name}]"
        elif dataclasses.is_dataclass(inner):
            env[f"copy_{f.name}"] = _copier(inner)
            value = f"copy_{f.name}(s.{f.name})"
        if optional and value != f"s.{f.name}":
            value = f"None if s.{f.name} is None else {value}"
        values.append(value)
    exec(f"def copy(s):\n    return cls({', '.join(values)})", env)
    return env["copy"]
