"""The world on the bus: the lockstep clock of ``World`` over Zenoh.

Tick k goes out on ``world/tick``; the world then waits for every live AGV's
command for tick k+1 on ``agv/<name>/command``. An AGV whose liveliness token
disappears (its process died, hung past its 1 s lease, or its link was cut) or
that does not answer within ``tick_timeout`` is *lost*: the world cannot tell
these apart, so the clock waits for it up to ``grace`` seconds, re-sending tick k
(it may have missed it) while it waits and as soon as the AGV's token is back.
An AGV that answers within the grace period rejoins as if nothing happened (the
run's outcome is unchanged); after it, the AGV is failed with that reason and
stays in the world as a stopped obstacle at its last pose; the others go on.
"""

from __future__ import annotations

import contextlib
import queue
import time
from collections.abc import Callable

from bridge import keys
from bridge.bus import Bus
from bridge.log import say
from bridge.messages import AgvCommand, Tick
from fleet.runtime.interrupts import interrupted, raise_if_interrupted
from fleet.runtime.lockstep import run_lockstep
from fleet.runtime.summary import RunSummary
from fleet.runtime.world import World
from fleet.runtime.world_watch import DEFAULT_GRACE_S
from fleet.scenario import Scenario
from planner.core.errors import EnvironmentFailure

POLL_S = 0.02
RESEND_S = 0.5  # while an AGV is lost, tick k goes out again this often
START_TIMEOUT_S = 120.0
"""How long the world waits for every AGV before tick 0. A first run on a fresh install
compiles every numba kernel in the AGV host before its AGVs come up: about 55 s on a
2-core machine since the control cycle is compiled (37 s before). 30 s, then 60 s, came
too close to that."""
TICK_TIMEOUT_S = 2.0  # an AGV that does not answer a tick within this is lost
SAY_WAITING_AFTER_S = 3.0  # a wait this long for the AGVs is said (``say_waiting``)


class FleetStartError(EnvironmentFailure):
    """The run cannot start: the AGV processes failed before tick 0."""


class WorldServer:
    def __init__(
        self,
        scenario: Scenario,
        bus: Bus,
        *,
        tick_timeout: float = TICK_TIMEOUT_S,
        grace: float = DEFAULT_GRACE_S,
        start_timeout: float = START_TIMEOUT_S,
        realtime: float | None = None,
        progress: Callable[[World], None] | None = None,
        abort_check: Callable[[], str | None] | None = None,
        recorder: bool = False,
        say_waiting: bool = False,
        exits: queue.Queue | None = None,
    ):
        self.scenario = scenario
        self.bus = bus
        self.tick_timeout = tick_timeout
        self.grace = grace
        self.start_timeout = start_timeout
        self.say_waiting = say_waiting  # on stderr, a wait for the AGVs that is not short
        self.realtime = realtime
        self.progress = progress
        self.abort_check = abort_check
        self.exits = exits  # (AGV, why) of AGV processes seen ending (launcher.AgvExits)
        self.world = World(scenario)
        self.alive: set[str] = set()
        self._lost: dict[str, float] = {}  # AGV -> when it was lost (monotonic)
        self._rejoined = False  # a lost AGV's token is back: re-send the tick at once
        self._commands = bus.subscribe("agv/*/command")
        self._liveliness = bus.watch_alive(f"{keys.ALIVE}/agv/*")
        self._recorder = bus.watch_alive(keys.alive_recorder()) if recorder else None

    def run(self) -> RunSummary:
        self._wait_for_agvs()
        self.bus.declare_alive(keys.alive_world())
        paced_from = time.monotonic()

        def after_tick(world: World) -> None:
            nonlocal paced_from
            if self.progress:
                self.progress(world)
            if self.realtime and not world.ended:
                delay = paced_from + world.time / self.realtime - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
                elif delay < -self.tick_timeout:  # after a pause: go on at pace, no rush
                    paced_from -= delay

        summary = run_lockstep(self.world, self._collect, self.bus.publish, after_tick=after_tick)
        self._await_departures()
        raise_if_interrupted()  # the run ended "interrupted" and everyone has left
        return summary

    def _await_departures(self) -> None:
        """After the final tick and the result: wait (at most ``tick_timeout``) until every
        AGV and the recorder has left, each on its last message, before the world's token
        goes. Closing at once can drop a final message still on its way to a large fleet,
        and its processes would then take the world's departure for a crash."""
        deadline = time.monotonic() + self.tick_timeout
        recorder_up = self._recorder is not None
        while (self.alive or recorder_up) and time.monotonic() < deadline:
            self._update_liveliness(timeout=POLL_S)
            if recorder_up:
                with contextlib.suppress(queue.Empty):
                    while recorder_up:
                        recorder_up = self._recorder.get_nowait()[1]

    def _wait_for_agvs(self) -> None:
        """Every AGV's token before tick 0 (it is declared after its tick subscriber),
        and the recorder's, if one is expected, so that it misses nothing."""
        names = {a.name for a in self.scenario.agvs}
        start = time.monotonic()
        deadline = start + self.start_timeout
        said = not self.say_waiting
        recorder_up = self._recorder is None
        while not (recorder_up and names <= self.alive) and time.monotonic() < deadline:
            self._update_liveliness(timeout=POLL_S)
            if not said and time.monotonic() > start + SAY_WAITING_AFTER_S:
                said = True
                say(
                    f"waiting for {len(names - self.alive)} of {len(names)} AGVs to come up "
                    f"(up to {self.start_timeout:g} s; the first run after an install compiles "
                    "the planner first)"
                )
            if not recorder_up:
                with contextlib.suppress(queue.Empty):
                    recorder_up = self._recorder.get_nowait()[1]
            raise_if_interrupted()
            problem = self.abort_check() if self.abort_check else None
            if problem:
                raise FleetStartError(problem)
        if not recorder_up:
            raise FleetStartError(f"the recorder did not come up within {self.start_timeout:g} s")
        for name in sorted(names - self.alive):
            self.world.mark_failed(name, f"did not come up within {self.start_timeout:g} s")

    def _update_liveliness(self, timeout: float = 0.0) -> None:
        while self.exits is not None and not self.exits.empty():
            name, why = self.exits.get_nowait()
            if name in self.world.live_agvs():  # its host saw it end: no lease to wait out
                self.world.mark_failed(name, why)
                self._lost.pop(name, None)
        try:
            while True:
                key, is_alive = self._liveliness.get(timeout=timeout)
                timeout = 0.0
                name = key.rsplit("/", 1)[-1]
                if name not in self.world.records:
                    self.bus.count_invalid(key, "a liveliness token of no AGV of this run")
                elif is_alive:
                    self.alive.add(name)
                    self._rejoined |= name in self._lost
                else:
                    self.alive.discard(name)
                    self._lost.setdefault(name, time.monotonic())
        except queue.Empty:
            pass

    def _collect(self, tick: Tick, world: World) -> dict[str, AgvCommand]:
        """Every live AGV's command for the next tick, until each answered or was lost
        for longer than the grace period."""
        replies: dict[str, AgvCommand] = {}
        wanted = tick.tick + 1
        started = sent = time.monotonic()
        while not interrupted():  # Ctrl-C: the clock ends the run at this tick
            self._update_liveliness()
            waiting = [n for n in self.world.awaited() if n not in replies]
            if not waiting:
                return replies
            now = time.monotonic()
            for name in waiting:
                if now - started > self.tick_timeout:
                    self._lost.setdefault(name, started + self.tick_timeout)
                lost = self._lost.get(name)
                if lost is not None and now - lost > self.grace:
                    self.world.mark_failed(name, self._why_failed(name))
                    del self._lost[name]
            someone_lost = any(name in self._lost for name in waiting)
            if someone_lost and (self._rejoined or now - sent > RESEND_S):
                self.bus.publish(keys.WORLD_TICK, tick)
                sent, self._rejoined = now, False
            for received in self._arrived_commands():
                command = received.msg
                if command.tick == wanted and received.key == keys.agv_command(command.name):
                    replies[command.name] = command
                    self._lost.pop(command.name, None)
        return replies

    def _arrived_commands(self) -> list:
        """The commands waiting (at least one, if one comes within POLL_S): taken together,
        so that the check of who is still awaited runs once per batch, not once per AGV
        (with 100 AGVs, 10,000 checks a tick)."""
        try:
            arrived = [self._commands.get(timeout=POLL_S)]
        except queue.Empty:
            return []
        with contextlib.suppress(queue.Empty):
            while True:
                arrived.append(self._commands.get_nowait())
        return arrived

    def _why_failed(self, name: str) -> str:
        if name not in self.alive:
            return f"liveliness lost for more than {self.grace:g} s (died, hung or cut off)"
        return f"no answer for more than {self.tick_timeout + self.grace:g} s"
