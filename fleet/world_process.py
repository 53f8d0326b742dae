"""The world on the bus: the lockstep clock of ``World`` over Zenoh.

Tick k goes out on ``world/tick``; the world then waits for every live AGV's
state for tick k+1 on ``agv/<name>/state``. An AGV whose liveliness token
disappears (its process died, or hung past its 1 s lease) or that does not
answer within ``tick_timeout`` is marked failed and stays in the world as a
stopped obstacle at its last pose; the others go on.
"""

from __future__ import annotations

import contextlib
import json
import queue
import time
from collections.abc import Callable

from bridge import keys
from bridge.bus import Bus
from bridge.messages import ResultMsg
from fleet.scenario import Scenario
from fleet.summary import RunSummary, summarize
from fleet.world import World, map_message

POLL_S = 0.02


class FleetStartError(RuntimeError):
    """The run cannot start: the AGV processes failed before tick 0."""


class WorldServer:
    def __init__(
        self,
        scenario: Scenario,
        bus: Bus,
        *,
        tick_timeout: float = 2.0,
        start_timeout: float = 30.0,
        realtime: float | None = None,
        progress: Callable[[World], None] | None = None,
        abort_check: Callable[[], str | None] | None = None,
        recorder: bool = False,
    ):
        self.scenario = scenario
        self.bus = bus
        self.tick_timeout = tick_timeout
        self.start_timeout = start_timeout
        self.realtime = realtime
        self.progress = progress
        self.abort_check = abort_check
        self.world = World(scenario)
        self.alive: set[str] = set()
        self._states = bus.subscribe("agv/*/state")
        self._liveliness = bus.watch_alive(f"{keys.ALIVE}/agv/*")
        self._recorder = bus.watch_alive(keys.alive_recorder()) if recorder else None

    def run(self) -> RunSummary:
        t0 = time.perf_counter()
        self._wait_for_agvs()
        self.bus.declare_alive(keys.alive_world())
        self.bus.publish(keys.WORLD_MAP, map_message(self.scenario.grid))
        world = self.world
        tick = world.first_tick()
        paced_from = time.monotonic()
        while tick is not None:
            self.bus.publish(keys.WORLD_TICK, tick)
            replies = self._collect(tick.tick + 1)
            tick = world.advance(replies)
            for event in world.drain_events():
                self.bus.publish(keys.WORLD_EVENT, event)
            if self.progress:
                self.progress(world)
            if self.realtime and tick is not None:
                delay = paced_from + tick.time / self.realtime - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
        self.bus.publish(keys.WORLD_TICK, world.final_tick())
        summary = summarize(world, time.perf_counter() - t0)
        self.bus.publish(keys.WORLD_RESULT, ResultMsg(json.dumps(summary.to_json())))
        return summary

    def _wait_for_agvs(self) -> None:
        """Every AGV's token before tick 0 (it is declared after its tick subscriber),
        and the recorder's, if one is expected, so that it misses nothing."""
        names = {a.name for a in self.scenario.agvs}
        deadline = time.monotonic() + self.start_timeout
        recorder_up = self._recorder is None
        while not (recorder_up and names <= self.alive) and time.monotonic() < deadline:
            self._update_liveliness(timeout=POLL_S)
            if not recorder_up:
                with contextlib.suppress(queue.Empty):
                    recorder_up = self._recorder.get_nowait()[1]
            problem = self.abort_check() if self.abort_check else None
            if problem:
                raise FleetStartError(problem)
        if not recorder_up:
            raise FleetStartError(f"the recorder did not come up within {self.start_timeout:g} s")
        for name in sorted(names - self.alive):
            self.world.mark_failed(name, f"did not come up within {self.start_timeout:g} s")

    def _update_liveliness(self, timeout: float = 0.0) -> None:
        try:
            while True:
                key, is_alive = self._liveliness.get(timeout=timeout)
                timeout = 0.0
                name = key.rsplit("/", 1)[-1]
                if name not in self.world.records:
                    self.bus.count_invalid(key, "a liveliness token of no AGV of this run")
                elif is_alive:
                    self.alive.add(name)
                else:
                    self.alive.discard(name)
                    self.world.mark_failed(name, "process died or hung (liveliness lost)")
        except queue.Empty:
            pass

    def _collect(self, tick: int) -> dict:
        """Every live AGV's state for ``tick``, until all answered, died or timed out."""
        replies: dict = {}
        deadline = time.monotonic() + self.tick_timeout
        while True:
            self._update_liveliness()
            waiting = [n for n in self.world.live_agvs() if n not in replies]
            if not waiting:
                return replies
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                for name in waiting:
                    self.world.mark_failed(name, f"no answer within {self.tick_timeout:g} s")
                return replies
            try:
                received = self._states.get(timeout=min(POLL_S, remaining))
            except queue.Empty:
                continue
            state = received.msg
            if state.tick == tick and received.key == keys.agv_state(state.name):
                replies[state.name] = state
