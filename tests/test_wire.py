"""The tick's MessagePack on the bus: validated as strictly as JSON, recorded as JSON."""

from __future__ import annotations

import dataclasses

import msgspec
import pytest

from bridge import keys
from bridge.bus import _reference_decode, decode
from bridge.messages import AgvState, MessageError, Tick, encode
from bridge.struct_decoder import decode_valid
from bridge.wire import json_payload, to_wire
from fleet.runtime.agv_node import AgvNode
from fleet.runtime.world import World
from fleet.scenario import load_scenario
from tests.test_struct_decoder import messages, variants


def run_ticks(name: str, count: int) -> list[Tick]:
    """The first ``count`` ticks of a built-in scenario, in process."""
    scenario = load_scenario(name)
    world = World(scenario)
    nodes = {a.name: AgvNode(scenario, a.name) for a in scenario.agvs}
    ticks = [world.first_tick()]
    for _ in range(count - 1):
        commands = {n: nodes[n].on_tick(ticks[-1]).command for n in world.live_agvs()}
        ticks.append(world.advance(commands))
    return ticks


def test_the_tick_is_messagepack_on_the_bus_and_decodes_to_the_same_tick():
    for tick in run_ticks("crossing", 30):
        payload = to_wire(keys.WORLD_TICK, tick)
        assert payload != encode(tick)
        assert msgspec.msgpack.decode(payload)["tick"] == tick.tick
        assert decode(keys.WORLD_TICK, payload) == tick


def test_a_recorded_tick_is_the_json_an_in_process_run_writes_byte_for_byte():
    ticks = run_ticks("warehouse", 20)
    # ints in float fields (a scenario's start) and an empty failure stay as they were
    odd = Tick(3, 0.3, [AgvState("a", 3, 5, 2, 0, 0.0, 0.0, 0.0, 0.3)], final=True)
    for tick in [*ticks, odd, messages()[-1]]:
        assert json_payload(keys.WORLD_TICK, to_wire(keys.WORLD_TICK, tick)) == encode(tick)


def test_other_keys_stay_json():
    command = messages()[-2]
    key = keys.agv_command(command.name)
    assert to_wire(key, command) == encode(command)
    assert json_payload(key, encode(command)) == encode(command)


@pytest.mark.parametrize("msg", [messages()[-1]], ids=["Tick"])
def test_the_messagepack_fast_path_is_never_more_lenient_than_the_reference(msg):
    cls = type(msg)
    fast_taken = refused = 0
    for variant in variants(msg):
        try:
            payload = msgspec.msgpack.encode(variant)
        except (TypeError, UnicodeEncodeError, OverflowError):
            continue  # not expressible in MessagePack (a lone surrogate)
        try:
            reference = _reference_decode(cls, payload, binary=True)
        except MessageError:
            reference = None
            refused += 1
        fast = decode_valid(cls, payload, binary=True)
        if fast is not None:
            fast_taken += 1
            assert reference is not None, variant
            assert fast == reference, variant
            assert all(
                type(getattr(fast, f.name)) is type(getattr(reference, f.name))
                for f in dataclasses.fields(cls)
            ), variant
    assert fast_taken > 0 and refused > 0


@pytest.mark.parametrize(
    "payload, why",
    [
        (b"\x91" * 100_000 + b"\xc0", "MessagePack nested too deeply"),
        (b'{"tick": 1}', "not MessagePack"),
        (b"\xc1", "not MessagePack"),
        (msgspec.msgpack.encode({1: 2}), "Tick: "),
        (msgspec.msgpack.encode([1, 2, 3]), "Tick: expected an object"),
        (msgspec.msgpack.encode({"tick": 1, "time": b"\x00", "agvs": []}), "Tick"),
    ],
)
def test_a_malformed_binary_tick_is_refused_with_a_reason(payload, why):
    with pytest.raises(MessageError, match=why):
        decode(keys.WORLD_TICK, payload)
