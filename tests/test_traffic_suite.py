"""The fast subset of the traffic stress suite (benchmarks/traffic_cases.py) as tests:
every AGV arrives, nothing collides, no run reaches its time limit, and no AGV loops (drives
more than ``DETOUR`` times its first route, or crosses its own track). The whole suite and
the cases that still miss are in benchmarks/traffic_bench.py and benchmarks/README.md."""

from __future__ import annotations

import pytest

from benchmarks.traffic_bench import DETOUR
from benchmarks.traffic_cases import make_case
from fleet.runtime.inprocess import run_in_process

# a 1 m door with 6 AGVs swapping rooms (the rule holds the AGVs of one side), a crossing
# of 1.5 m corridors with 4 and a 1.5 m corridor with 2 (two-lane: DWA passes them)
CASES = [("door", 0), ("crossing", 0), ("corridor-3", 0)]


@pytest.mark.parametrize(("family", "seed"), CASES, ids=[f"{f}-s{s}" for f, s in CASES])
def test_every_agv_arrives_without_contact(family, seed):
    case = make_case(family, seed)
    summary = run_in_process(case.scenario)
    assert summary.success, summary.table()
    assert summary.end_reason == "every AGV arrived"
    detours = {a.name: round(a.distance / a.route_length, 2) for a in summary.agvs}
    assert max(detours.values()) <= DETOUR, detours  # waiting aside, yes; loops, no
    assert not [a.name for a in summary.agvs if a.self_crossings]
    if family == "door":  # one side waited while the other went through
        assert sum(a.waiting_time > 0 for a in summary.agvs) >= 2
