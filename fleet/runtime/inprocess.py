"""All nodes in one process, no bus: fast and deterministic (``--in-process``)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from bridge.messages import AgvCommand, Tick
from fleet.runtime.agv_node import AgvNode, publish_output
from fleet.runtime.interrupts import raise_if_interrupted
from fleet.runtime.lockstep import Outbox, run_lockstep, tee
from fleet.runtime.summary import RunSummary
from fleet.runtime.world import World
from fleet.scenario import Scenario
from recordings.writer import RecordingWriter, record_sink


def _discard(key: str, msg: object) -> None:
    """The outbox of a run nobody records or watches."""


def run_in_process(
    scenario: Scenario,
    outbox: Outbox | None = None,
    progress: Callable[[World], None] | None = None,
) -> RunSummary:
    """Run ``scenario`` with every AGV node called directly; every message to ``outbox``.
    Ctrl-C (inside ``interrupts_raised``) ends the run at a tick, then raises."""
    summary = _run_nodes(scenario, outbox, progress)
    raise_if_interrupted()
    return summary


def _run_nodes(scenario: Scenario, outbox: Outbox | None, progress) -> RunSummary:
    outbox = outbox or _discard
    nodes = {a.name: AgvNode(scenario, a.name) for a in scenario.agvs}

    def collect(tick: Tick, world: World) -> dict[str, AgvCommand]:
        replies = {}
        for name in world.awaited():
            out = nodes[name].on_tick(tick)
            publish_output(outbox, out)
            replies[name] = out.command
        return replies

    return run_lockstep(World(scenario), collect, outbox, after_tick=progress)


def run_recorded(
    scenario: Scenario,
    path: Path,
    run_facts: dict,
    also: Outbox | None = None,
    progress: Callable[[World], None] | None = None,
) -> RunSummary:
    """``run_in_process`` recorded into ``path`` (and every message to ``also``)."""
    with RecordingWriter(
        path, scenario_name=scenario.name, scenario_text=scenario.source, run_facts=run_facts
    ) as writer:
        record = record_sink(writer, scenario.dt)
        summary = _run_nodes(scenario, tee(record, also) if also else record, progress)
        writer.finish(summary.to_json())
    raise_if_interrupted()  # after the recording is whole: it ended "interrupted"
    return summary
