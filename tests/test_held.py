"""AGVs a shift holds at their goals (``loading``, ``parked``) cost almost nothing per tick:
the world stands them still without integrating a command, and their processes drop
the ticks they would not answer before making them. Neither may change a run."""

from __future__ import annotations

import re
from types import SimpleNamespace

from bridge import keys
from bridge.bus import decode
from bridge.messages import AgvState, Tick, encode
from bridge.wire import to_wire
from fleet.runtime.agv_process import HeldTicks
from fleet.runtime.inprocess import run_in_process
from fleet.runtime.world import World
from fleet.scenario import parse_scenario
from planner.core.status import DRIVING, LOADING, PARKED
from tests.test_missions_fleet import shelves_shift_text

PLAN_TIME = re.compile(rb'"plan_time_ms":[-0-9.e+]+')  # wall time: differs run to run


def messages_of(text: str) -> list[tuple[str, bytes]]:
    out = []

    def sink(key, msg):
        if key != keys.WORLD_RESULT:  # it holds the wall time
            out.append((key, PLAN_TIME.sub(b"", encode(msg))))

    run_in_process(parse_scenario(text), outbox=sink)
    return out


def test_a_held_agv_stands_still_as_if_it_had_answered(monkeypatch):
    """Every message of a shift is the same whether the world stands its held AGVs
    still (``World._stand_still``) or integrates the command of zeros they would send."""
    text = shelves_shift_text(shift=60.0)
    fast = messages_of(text)
    monkeypatch.setattr(World, "_stand_still", lambda self, name: False)
    assert messages_of(text) == fast
    held = [m for k, m in fast if k == keys.WORLD_TICK and b'"status":"loading"' in m]
    assert held  # the shift held AGVs at stations


def tick(k: int, statuses: dict[str, str], final: bool = False) -> SimpleNamespace:
    agvs = [SimpleNamespace(name=n, status=s) for n, s in statuses.items()]
    return SimpleNamespace(tick=k, final=final, agvs=agvs)


def test_an_agv_drops_only_the_next_tick_that_holds_it():
    held = HeldTicks("b")
    listed = ["a", "b"]
    assert not held(tick(0, {"a": DRIVING, "b": PARKED}))  # nothing taken yet
    held.took(0, listed)
    assert held(tick(1, {"a": DRIVING, "b": PARKED}))  # the next, holding b: dropped
    assert held(tick(2, {"a": DRIVING, "b": LOADING}))
    assert not held(tick(2, {"a": DRIVING, "b": LOADING}))  # sent again
    assert not held(tick(4, {"a": DRIVING, "b": LOADING}))  # not the next
    assert not held(tick(3, {"a": DRIVING, "b": DRIVING}))  # b drives: its node answers
    assert not held(tick(3, {"b": LOADING, "a": DRIVING}))  # another order
    assert not held(tick(3, {"b": LOADING}))  # an AGV missing
    assert not held(tick(3, {"a": DRIVING, "b": LOADING}, final=True))  # the run's end
    assert held.dropped == 2


def test_a_dropped_tick_is_checked_in_full_first():
    """``drop`` looks at a tick only once every check of the bus passed: a malformed one
    is refused (counted as invalid) whatever it would say."""
    seen = []

    def drop(msg):
        seen.append(msg.tick)
        return True

    state = AgvState("b", 7, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.3, PARKED)
    good = to_wire(keys.WORLD_TICK, Tick(7, 0.7, [state]))
    assert decode(keys.WORLD_TICK, good, drop) is None and seen == [7]
    bad = to_wire(keys.WORLD_TICK, Tick(8, 0.8, [AgvState(**{**vars(state), "x": float("nan")})]))
    try:
        decode(keys.WORLD_TICK, bad, drop)
    except ValueError:
        pass
    else:
        raise AssertionError("a tick with a NaN pose was not refused")
    assert seen == [7]
