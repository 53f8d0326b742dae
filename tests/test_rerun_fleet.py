"""Rerun at fleet scale: the blueprint before the data, a tab with legends for every AGV,
and the fleet's counts over time (AGVs driving / waiting / stopped, arrivals so far).

The files are real .rrd files read back by Rerun's reader (and, for the order of what was
sent, by where each store's id first occurs in the file: every message names its store)."""

from __future__ import annotations

import re

import pytest
from rerun.chunk import RrdReader

from fleet.cli.main import main
from recordings.reader import open_recording
from recordings.rerun_blueprint import blueprint
from recordings.rerun_fleet import STANDING_S, STATE_PLOT, FleetCounts
from recordings.rerun_log import layout_of, recording_dt
from recordings.rerun_rows import RowMaker
from recordings.rerun_view import Outputs, save_rrd
from tests.test_rerun import blueprint_entities, read_rrd

STATES = ("driving", "waiting", "stopped")


@pytest.fixture(scope="module")
def crossing(tmp_path_factory):
    """The built-in single lane (AGVs wait their turn at a one-AGV lane), replayed."""
    folder = tmp_path_factory.mktemp("fleet")
    recording = folder / "crossing.mcap"
    main(["run", "single-lane", "--in-process", "-q", "-o", str(recording)])
    rrd = folder / "crossing.rrd"
    save_rrd(open_recording(recording), rrd)
    return {"recording": open_recording(recording), "rrd": rrd, "folder": folder}


def store_ids(path) -> tuple[bytes, bytes]:
    reader = RrdReader(str(path))
    return reader.recordings()[0].recording_id.encode(), reader.blueprints()[
        0
    ].recording_id.encode()


def messages_before_blueprint(path) -> int:
    """How many messages of the recording's store come before its blueprint's first."""
    data = path.read_bytes()
    recording, layout = store_ids(path)
    first_layout = data.index(layout)
    return sum(1 for m in re.finditer(re.escape(recording), data) if m.start() < first_layout)


def test_the_blueprint_comes_before_any_data(crossing, tmp_path):
    # what the SDK itself writes before anything is logged (store info, properties)
    with Outputs(save=tmp_path / "empty.rrd") as out:
        out.stream.send_blueprint(blueprint([], None))
    own = messages_before_blueprint(tmp_path / "empty.rrd")
    assert messages_before_blueprint(crossing["rrd"]) == own
    recording_messages = len(
        re.findall(re.escape(store_ids(crossing["rrd"])[0]), crossing["rrd"].read_bytes())
    )
    assert recording_messages > own + 10  # and the data did come, after it


def test_the_layout_read_first_is_the_one_the_rows_make(crossing):
    messages = crossing["recording"].messages
    maker = RowMaker(recording_dt(messages))
    for m in messages:
        maker.feed(m.topic, m.data)
    assert layout_of(messages) == (maker.agv_names, maker.map_bounds, maker.end_time)


def test_every_agv_has_a_tab_whose_plots_have_a_legend(crossing):
    parts = blueprint_entities(crossing["rrd"])
    names = crossing["recording"].agv_names()
    tabs = {
        c["ContainerBlueprint:display_name"][0]
        for c in parts.values()
        if "ContainerBlueprint:display_name" in c
    }
    assert set(names) | {"fleet"} <= tabs
    origins = {
        c["ViewBlueprint:space_origin"][0]
        for c in parts.values()
        if "ViewBlueprint:space_origin" in c
    }
    assert {f"/velocity/speed/{n}" for n in names} <= origins
    assert {"/fleet/agvs", "/fleet/arrived"} <= origins
    assert "/velocity/speed" not in origins  # no plot of every AGV's curves at once
    plots = [
        p for p, c in parts.items() if c.get("ViewBlueprint:class_identifier") == ["TimeSeries"]
    ]
    assert len(plots) == 4 * len(names) + 2
    for plot in plots:  # a legend in a corner, not hidden
        legend = parts[f"{plot}/PlotLegend"]
        assert "PlotLegend:corner" in legend and legend.get("PlotLegend:visible", [True]) == [True]


def test_the_fleet_counts_add_up_at_every_tick_and_end_with_the_arrivals(crossing):
    entities = read_rrd(crossing["rrd"])
    ticks = crossing["recording"].of("world/tick")
    counts = {s: entities[f"/fleet/agvs/{s}"].values("Scalars:scalars") for s in STATES}
    arrived = entities["/fleet/arrived"].values("Scalars:scalars")
    assert len(arrived) == len(ticks)
    total = len(crossing["recording"].agv_names())
    for i in range(len(ticks)):
        assert sum(counts[s][i][0] for s in STATES) + arrived[i][0] == total
    result = crossing["recording"].result["agvs"]
    assert arrived[-1][0] == sum(a["status"] == "arrived" for a in result)
    assert max(c[0] for c in counts["waiting"]) >= 1  # the lane makes AGVs wait
    assert max(c[0] for c in counts["driving"]) >= total - 1


def _tick(time: float, speed: float, omega: float = 0.0, status: str = "driving") -> dict:
    agv = {"name": "a", "status": status, "vx": speed, "vy": 0.0, "omega": omega}
    return {"time": time, "agvs": [agv]}


def _state_at(counts: FleetCounts, tick: dict) -> str:
    rows = {r.path: r.payload for r in counts.rows(tick)}
    return next(s for s in STATES if rows[f"{STATE_PLOT}/{s}"] == 1)


def test_a_pause_before_a_turn_on_the_spot_is_driving_and_standing_still_is_stopped():
    counts = FleetCounts()
    # braking to a tight corner's node: below AT_REST for two ticks, then turning
    brake_and_turn = [_tick(0.0, 0.2), _tick(0.1, 0.03), _tick(0.2, 0.01), _tick(0.3, 0.0, 0.09)]
    assert [_state_at(counts, t) for t in brake_and_turn] == ["driving"] * 4
    # at rest from 0.4 s on: driving until STANDING_S has passed, then stopped
    rest = [_tick(0.4 + 0.1 * k, 0.0) for k in range(15)]
    states = [_state_at(counts, t) for t in rest]
    standing = round(STANDING_S / 0.1)
    assert states == ["driving"] * standing + ["stopped"] * (len(rest) - standing)
    # moving again resets it; an AGV blocked or failed at rest is stopped at once
    assert _state_at(counts, _tick(2.0, 0.3)) == "driving"
    assert _state_at(counts, _tick(2.1, 0.0, status="blocked")) == "stopped"
    assert _state_at(FleetCounts(), _tick(0.0, 0.0, status="failed")) == "stopped"
