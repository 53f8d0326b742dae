"""The compiled fast path decodes what the reference decoder accepts, to the same message,
and never accepts what the reference refuses."""

from __future__ import annotations

import dataclasses
import json

import pytest

from bridge.bus import _reference_decode, decode
from bridge.messages import (
    FLOAT_INT_LIMIT,
    MAX_COUNT,
    AgvCommand,
    MessageError,
    Tick,
    encode,
    to_dict,
)
from bridge.struct_decoder import decode_valid
from fleet.runtime.world import World
from fleet.scenario import load_scenario
from planner.traffic.zones import Intent
from tests.test_messages import STATE, samples

INTENT = Intent(
    "a", 7, "wait", passage=2, exit=1, since=3, enter_at=2.5, stalled=True,
    route=[[1.0, 2.0], [3.0, 2.0]], waits_for=["b"], entry=0, hold=[1.5, 2.0],
)  # fmt: skip
COMMAND = AgvCommand("a", 8, 0.4, -0.1, 0.02, "driving", [3.0, 2.0], 1.5, 0.3, "", INTENT, "wait")


def messages():
    tick = World(load_scenario("warehouse")).first_tick()
    tick = dataclasses.replace(tick, intents=[INTENT, dataclasses.replace(INTENT, name="b")])
    return [*samples().values(), COMMAND, tick]


@pytest.mark.parametrize("msg", messages(), ids=lambda m: type(m).__name__)
def test_valid_messages_take_the_fast_path_to_the_same_message(msg):
    assert decode_valid(type(msg), encode(msg)) == msg


# values that each field type must refuse or convert exactly as the reference does
ODD_VALUES = [
    None, True, "x", "", -1, 0, 1, 2.5, -0.0, MAX_COUNT, MAX_COUNT + 1, 2**53 + 1,
    FLOAT_INT_LIMIT - 1, FLOAT_INT_LIMIT, -FLOAT_INT_LIMIT, 1e308, float("nan"),
    float("inf"), [], [1, "x"], [[1.0, 2.0]], {}, "driving", "teleported", "\ud800",
]  # fmt: skip


def variants(msg):
    """Payloads of ``msg`` with one field changed, added or left out, at the top level and
    in nested messages."""
    data = to_dict(msg)
    nested = {"agvs": 0, "moving": 0, "intents": 0}
    for field in data:
        for value in ODD_VALUES:
            yield data | {field: value}
        yield {k: v for k, v in data.items() if k != field}
        if field in nested and data[field]:
            for inner in data[field][0]:
                for value in ODD_VALUES:
                    item = data[field][0] | {inner: value}
                    yield data | {field: [item, *data[field][1:]]}
        if field == "intent":
            for inner in data[field]:
                for value in ODD_VALUES:
                    yield data | {field: data[field] | {inner: value}}
    yield data | {"extra": 1}


@pytest.mark.parametrize("msg", [STATE, COMMAND, messages()[-1]], ids=lambda m: type(m).__name__)
def test_the_fast_path_is_never_more_lenient_than_the_reference(msg):
    cls = type(msg)
    fast_taken = 0
    for variant in variants(msg):
        payload = json.dumps(variant).encode()
        try:
            reference = _reference_decode(cls, payload)
        except MessageError:
            reference = None
        fast = decode_valid(cls, payload)
        if fast is not None:
            fast_taken += 1
            assert reference is not None, variant
            assert fast == reference, variant
            assert all(
                type(getattr(fast, f.name)) is type(getattr(reference, f.name))
                for f in dataclasses.fields(cls)
            ), variant
    assert fast_taken > 0  # the comparison above ran on accepted payloads too


def test_what_only_the_reference_accepts_still_decodes():
    """A lone surrogate is valid for Python's json module, not for msgspec: decode falls
    back and accepts it as it always did."""
    payload = json.dumps(to_dict(STATE) | {"failure": "\ud800"}).encode()
    assert decode_valid(type(STATE), payload) is None
    assert decode("agv/a/state", payload).failure == "\ud800"


def test_a_large_tick_decodes_the_same_both_ways():
    tick = messages()[-1]
    payload = encode(tick)
    assert decode_valid(Tick, payload) == _reference_decode(Tick, payload) == tick
