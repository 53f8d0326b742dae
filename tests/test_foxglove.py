"""Recordings that Foxglove can open: real log times, plain metadata, and the run on
``foxglove.*`` schemas that validate against Foxglove's published JSON Schemas
(copies in tests/data/foxglove, see its README)."""

from __future__ import annotations

import base64
import json
from collections import Counter
from datetime import UTC, datetime

import jsonschema
import pytest
from mcap.reader import make_reader

from fleet.builtin import builtin_scenarios
from fleet.runtime.inprocess import run_in_process
from fleet.scenario import load_scenario
from recordings.writer import RecordingWriter, record_sink
from tests.conftest import PUBLIC_DATA

PUBLISHED = PUBLIC_DATA / "foxglove"
YEAR_2020_NS = int(datetime(2020, 1, 1, tzinfo=UTC).timestamp() * 1e9)


@pytest.fixture(scope="module")
def corridor(tmp_path_factory):
    path = tmp_path_factory.mktemp("foxglove") / "corridor.mcap"
    scenario = load_scenario("corridor")
    text = builtin_scenarios()["corridor"].read_text()
    with RecordingWriter(path, scenario_name="corridor", scenario_text=text, run_facts={}) as w:
        summary = run_in_process(scenario, outbox=record_sink(w, scenario.dt))
        w.finish(summary.to_json())
    with open(path, "rb") as f:
        reader = make_reader(f)
        messages = [
            (schema.name if schema else "", channel.topic, message.log_time, message.data)
            for schema, channel, message in reader.iter_messages()
        ]
        schemas = {s.name: s.data for s in reader.get_summary().schemas.values()}
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
    return {"messages": messages, "schemas": schemas, "metadata": metadata}


def test_log_times_are_after_2020_and_sim_time_stays_in_the_messages(corridor):
    zero = int(corridor["metadata"]["run"]["log_time_zero_ns"])
    assert zero > YEAR_2020_NS
    for _, topic, log_time, data in corridor["messages"]:
        assert log_time >= zero > YEAR_2020_NS, topic
        if topic == "world/tick":
            assert log_time - zero == round(json.loads(data)["time"] * 1e9)


def test_every_foxglove_message_validates_against_the_published_schema(corridor):
    seen = Counter()
    validators = {}
    for schema_name, topic, _, data in corridor["messages"]:
        if not schema_name.startswith("foxglove."):
            continue
        if schema_name not in validators:
            published = json.loads((PUBLISHED / f"{schema_name}.json").read_text())
            assert json.loads(corridor["schemas"][schema_name]) == published
            validators[schema_name] = jsonschema.Draft202012Validator(published)
        validators[schema_name].validate(json.loads(data))
        seen[topic] += 1
    ticks = sum(1 for m in corridor["messages"] if m[1] == "world/tick")
    assert seen == {
        "foxglove/map": 1,
        "foxglove/agvs": 2,  # left and right, once each
        "foxglove/plans": sum(1 for m in corridor["messages"] if m[1].endswith("/plan")),
        "foxglove/tf": 2 * ticks,
    }


def test_the_grid_holds_the_map_bottom_row_first(corridor):
    (map_msg,) = [json.loads(m[3]) for m in corridor["messages"] if m[1] == "world/map"]
    (grid,) = [json.loads(m[3]) for m in corridor["messages"] if m[1] == "foxglove/map"]
    cells = base64.b64decode(grid["data"])
    width = map_msg["width"]
    assert grid["column_count"] == width and len(cells) == width * map_msg["height"]
    bottom = "".join("#" if c else "." for c in cells[:width])
    assert bottom == map_msg["rows"][-1]


def test_agv_frames_follow_the_ticks(corridor):
    ticks = [json.loads(m[3]) for m in corridor["messages"] if m[1] == "world/tick"]
    frames = [json.loads(m[3]) for m in corridor["messages"] if m[1] == "foxglove/tf"]
    last = ticks[-1]["agvs"][0]
    (frame,) = [f for f in frames[-2:] if f["child_frame_id"] == last["name"]]
    assert frame["parent_frame_id"] == "map"
    assert frame["translation"]["x"] == pytest.approx(last["x"])
    assert frame["translation"]["y"] == pytest.approx(last["y"])


def test_metadata_strings_are_plain_text(corridor):
    run = corridor["metadata"]["run"]
    assert run["scenario"] == "corridor"  # not '"corridor"'
    assert json.loads(corridor["metadata"]["result"]["collisions"]) == 0
