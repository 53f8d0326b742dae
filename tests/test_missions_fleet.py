"""A shift over real Zenoh sessions and AGV processes: the same ticks, goals and task
events as in process (the world decides; both modes run the same dispatcher)."""

from __future__ import annotations

from bridge import keys
from fleet.runtime.inprocess import run_in_process
from fleet.scenario import parse_scenario
from planner.core.status import DELIVERED, TASK_EVENTS
from tests.test_fleet_zenoh import hosted_world, state_key
from tests.test_reservations_fleet import SHELVES

STATIONS = {
    "pick-1": ((5.5, 3.5), 3.0, "pick"),  # in the one-cell aisles
    "pick-2": ((10.5, 1.5), 3.0, "pick"),
    "drop-1": ((15.5, 1.5), 2.0, "drop"),
    "drop-2": ((15.5, 5.5), 2.0, "drop"),
}
STARTS = [(1.5, 1.5), (1.5, 3.5), (1.5, 5.5)]


def shelves_shift_text(shift: float = 90.0) -> str:
    lines = [
        'name = "shelves-shift"',
        "[traffic]",
        'mode = "reservations"',
        "[map]",
        "resolution = 1.0",
        f'grid = """{SHELVES.strip()}"""',
        "[agv_defaults]",
        "radius = 0.3\nmax_speed = 1.0\nmax_accel = 0.5\nmax_omega = 60.0",
    ]
    for name, (position, dwell, group) in STATIONS.items():
        lines += ["[[stations]]", f'name = "{name}"', f"position = {list(position)}"]
        lines += [f"dwell = {dwell}", f'group = "{group}"']
    lines += ["[tasks]", f"shift = {shift}"]
    lines += ['generator = { rate_per_hour = 400, from = "pick", to = "drop", seed = 3 }']
    for i, start in enumerate(STARTS):
        lines += ["[[agvs]]", f'name = "agv{i + 1}"', f"start = {list(start)}"]
    return "\n".join(lines) + "\n"


def _tick_key(msg):
    return ([state_key(s) for s in msg.agvs], msg.reservations, msg.assignments)


def test_a_shift_over_zenoh_makes_the_same_ticks_and_task_events_as_in_process(tmp_path):
    path = tmp_path / "shelves-shift.toml"
    path.write_text(shelves_shift_text())
    expected, expected_events = {}, []

    def sink(key, msg):
        if key == keys.WORLD_TICK:
            expected[msg.tick] = _tick_key(msg)
        elif key == keys.WORLD_EVENT:
            expected_events.append(msg)

    reference = run_in_process(parse_scenario(path.read_text(), path), outbox=sink)
    with hosted_world(str(path)) as (_, bus, server, _):
        ticks = bus.subscribe(keys.WORLD_TICK)
        events = bus.subscribe(keys.WORLD_EVENT)
        summary = server.run()
    seen = {}
    while not ticks.empty():
        msg = ticks.get().msg
        seen[msg.tick] = _tick_key(msg)
    seen_events = []
    while not events.empty():
        seen_events.append(events.get().msg)
    assert seen == expected
    assert seen_events == expected_events
    kinds = [e.kind for e in seen_events if e.kind in TASK_EVENTS]
    assert kinds.count(DELIVERED) >= 2  # the AGVs really worked, through the aisles
    assert summary.to_json()["tasks"] == reference.to_json()["tasks"]
    assert summary.to_json()["agvs"] == reference.to_json()["agvs"]
    assert summary.success and reference.collisions == 0
