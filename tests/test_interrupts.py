"""An interrupt that Python drops still ends the run.

CI once saw Ctrl-C arrive while numba's compiler was freeing an LLVM object in a
``__del__``: the ``KeyboardInterrupt`` was printed as "Exception ignored in ..."
and the run went on to its end. ``_FinalizerInterrupted`` reproduces that: it is
sent Ctrl-C while it is being finalized.
"""

from __future__ import annotations

import json
import os
import signal

import pytest

from bridge import keys
from fleet.runtime.inprocess import run_in_process
from fleet.runtime.interrupts import interrupts_raised, raise_if_interrupted
from fleet.runtime.launcher import FleetOptions, run_fleet
from fleet.scenario import load_scenario

pytestmark = pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")


class _FinalizerInterrupted:
    def __del__(self):
        os.kill(os.getpid(), signal.SIGINT)
        for _ in range(100_000):  # the handler runs here, inside __del__, and is dropped
            pass


def _drop_an_interrupt() -> None:
    try:
        _FinalizerInterrupted()
    except KeyboardInterrupt:  # not dropped: this Python delivers it; the test is moot
        pytest.fail("the interrupt was raised outside the finalizer")


def test_an_interrupt_dropped_in_a_finalizer_is_raised_by_the_next_check():
    with interrupts_raised():
        _drop_an_interrupt()
        with pytest.raises(KeyboardInterrupt):
            raise_if_interrupted()
    raise_if_interrupted()  # outside, the interrupt is forgotten: no raise


def test_a_fleet_run_interrupted_inside_a_finalizer_ends_within_a_tick():
    seen: list[float] = []

    def progress(world) -> None:
        seen.append(world.time)
        if len(seen) == 10:
            _drop_an_interrupt()

    scenario = load_scenario("corridor")
    with pytest.raises(KeyboardInterrupt):
        run_fleet(scenario, FleetOptions(scenario_arg="corridor"), progress=progress)
    assert len(seen) == 10  # no tick after the interrupt


def test_ctrl_c_ends_the_run_at_a_tick_with_its_final_tick_and_result_then_raises():
    sent: list[tuple[str, object]] = []

    def progress(world) -> None:
        if world.tick == 10:
            os.kill(os.getpid(), signal.SIGINT)

    with interrupts_raised(), pytest.raises(KeyboardInterrupt):
        run_in_process(load_scenario("corridor"), lambda k, m: sent.append((k, m)), progress)
    ticks = [m for k, m in sent if k == keys.WORLD_TICK]
    assert ticks[-1].final and ticks[-1].tick == 10 and not any(t.final for t in ticks[:-1])
    assert [e.detail for k, e in sent if k == keys.WORLD_EVENT and e.kind == "end"] == [
        "interrupted"
    ]
    assert sent[-1][0] == keys.WORLD_RESULT
    assert json.loads(sent[-1][1].summary)["end_reason"] == "interrupted"
