"""The message codec and its JSON Schemas: what crosses the bus and goes into recordings."""

from __future__ import annotations

import json

import jsonschema
import pytest

from bridge import keys
from bridge.bus import MAX_PAYLOAD_BYTES, decode
from bridge.messages import (
    MAX_LIST_ITEMS,
    MESSAGE_TYPES,
    AgvState,
    Event,
    MessageError,
    ObstacleState,
    PlanMsg,
    Tick,
    encode,
    json_schema,
    to_dict,
)
from bridge.wire import to_wire
from fleet.runtime.world import World, map_message
from fleet.scenario import load_scenario

STATE = AgvState("a", 3, 1.0, 2.0, 0.5, 0.1, 0.0, -0.02, 0.3, "driving", [4.5, 1.5], 0.2)


def samples():
    tick = Tick(4, 0.4, [STATE], [ObstacleState("o", 1, 2, 0.5, 0, 0.4)], [[3, 4]])
    plan = PlanMsg("a", 0, 0.0, "improved", "initial", True, [[0.5, 0.5]], [[0.5, 0.5]], 1, 0, 0, 1)
    return {
        keys.WORLD_TICK: tick,
        keys.WORLD_MAP: map_message(load_scenario("corridor").grid),
        keys.WORLD_EVENT: Event(4, 0.4, "collision", ["a", "b"], "a and b"),
        keys.agv_state("a"): STATE,
        keys.agv_plan("a"): plan,
    }


@pytest.mark.parametrize("key", list(samples()))
def test_every_message_round_trips_exactly(key):
    msg = samples()[key]
    assert decode(key, to_wire(key, msg)) == msg


@pytest.mark.parametrize("key", list(samples()))
def test_encoded_messages_follow_their_schema(key):
    msg = samples()[key]
    schema = json_schema(type(msg))
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.validate(json.loads(encode(msg)), schema)


def test_schemas_reject_what_the_decoder_rejects():
    schema = json_schema(AgvState)
    bad = to_dict(STATE) | {"x": "far"}
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, schema)
    with pytest.raises(MessageError, match=r"AgvState.x: expected a finite number"):
        decode(keys.agv_state("a"), json.dumps(bad).encode())


@pytest.mark.parametrize(
    ("payload", "message"),
    [
        (b"\xff\xfe", "not JSON"),
        (b"[]", "expected an object"),
        (b'{"name": "a"}', "missing field 'tick'"),
        (json.dumps(to_dict(STATE) | {"extra": 1}).encode(), "unknown field 'extra'"),
        (json.dumps(to_dict(STATE) | {"tick": 2.5}).encode(), "AgvState.tick: expected a count"),
        (json.dumps(to_dict(STATE) | {"target": [1, "x"]}).encode(), "expected a finite number"),
        (
            json.dumps(to_dict(STATE) | {"x": float("nan")}).encode(),
            "AgvState.x: expected a finite",
        ),
        (
            json.dumps(to_dict(STATE) | {"vx": float("inf")}).encode(),
            "AgvState.vx: expected a finite",
        ),
        (json.dumps(to_dict(STATE) | {"tick": -1}).encode(), "AgvState.tick: expected a count"),
        (json.dumps(to_dict(STATE) | {"tick": 2**31}).encode(), "AgvState.tick: expected a count"),
        (json.dumps(to_dict(STATE) | {"status": "teleported"}).encode(), "not one of driving"),
        (json.dumps(to_dict(STATE) | {"name": "b"}).encode(), "names AGV 'b'"),
        (b"[" * 100_000 + b"]" * 100_000, "nested too deeply"),
        (b" " * (MAX_PAYLOAD_BYTES + 1), "more than"),
    ],
)
def test_malformed_payloads_raise_message_errors(payload, message):
    with pytest.raises(MessageError, match=message):
        decode(keys.agv_state("a"), payload)


def test_foreign_keys_and_over_long_lists_are_refused():
    with pytest.raises(MessageError, match="no message type"):
        decode("agv/a/elsewhere", encode(STATE))
    many = json.dumps(to_dict(STATE) | {"target": [0.0] * (MAX_LIST_ITEMS + 1)}).encode()
    with pytest.raises(MessageError, match="more than"):
        decode(keys.agv_state("a"), many)


def test_a_real_tick_round_trips():
    world = World(load_scenario("warehouse"))
    tick = world.first_tick()
    assert decode(keys.WORLD_TICK, to_wire(keys.WORLD_TICK, tick)) == tick


def test_keys_name_their_message_types():
    assert {keys.message_type(k) for k in samples()} == {type(m) for m in samples().values()}
    assert keys.message_type("agv/a/unknown") is None
    assert keys.agv_name(keys.agv_plan("agv7")) == "agv7"
    assert set(MESSAGE_TYPES) >= {type(m) for m in samples().values()}
