"""MCAP recordings: a run round-trips, a cut or killed recording is recovered."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from bridge import keys
from bridge.messages import AgvState, encode, json_schema
from fleet.runtime.inprocess import run_in_process
from fleet.scenario import load_scenario, parse_scenario, with_traffic
from recordings.reader import RecordingError, open_recording
from recordings.writer import (
    CHUNK_SECONDS,
    RecordingWriter,
    default_recording_path,
    record_sink,
)

REPO = Path(__file__).resolve().parents[1]


def record_run(path: Path, name: str = "corridor"):
    """Record an in-process run of a built-in scenario; also return every message sunk."""
    # the zone mode's DWA run: long enough (390 ticks) that a cut falls among the commands
    scenario = with_traffic(load_scenario(name), "zones")
    sunk = []
    with RecordingWriter(
        path,
        scenario_name=scenario.name,
        scenario_text=scenario.source,
        run_facts={"run_id": "test-run", "parameters": {"mode": "in-process"}},
    ) as writer:
        record = record_sink(writer, scenario.dt)

        def sink(key, msg):
            sunk.append((key, encode(msg)))  # now: the world mutates some objects later
            record(key, msg)

        summary = run_in_process(scenario, outbox=sink)
        writer.finish(summary.to_json())
    return scenario, summary, sunk


@pytest.fixture(scope="module")
def corridor(tmp_path_factory):
    path = tmp_path_factory.mktemp("rec") / "corridor.mcap"
    scenario, summary, sunk = record_run(path)
    return path, scenario, summary, sunk


def test_every_message_of_a_run_round_trips_in_order(corridor):
    path, scenario, _, sunk = corridor
    rec = open_recording(path)
    assert not rec.truncated
    # the very bytes the bus would carry: both run modes record the same file content
    ours = [m for m in rec.records if not m.topic.startswith("foxglove/")]
    assert [(m.topic, m.payload) for m in ours] == sunk
    assert rec.undecodable == 0
    dt_ns = round(scenario.dt * 1e9)
    for m in ours:  # sim time after the run's wall-clock start
        assert m.log_time_ns - rec.log_time_zero_ns == m.data.get("tick", 0) * dt_ns, m.topic


def test_each_agv_has_a_command_per_tick_and_the_map_and_plans_are_there(corridor):
    path, scenario, summary, sunk = corridor
    rec = open_recording(path)
    for agv in scenario.agvs:
        states = rec.of(keys.agv_command(agv.name))
        assert len(states) == summary.ticks
        assert [s.data["tick"] for s in states] == list(range(1, summary.ticks + 1))
        plans = [json.loads(p) for k, p in sunk if k == keys.agv_plan(agv.name)]
        assert plans and [m.data for m in rec.of(keys.agv_plan(agv.name))] == plans
    (map_msg,) = rec.of(keys.WORLD_MAP)
    assert map_msg.data["rows"] == scenario.grid.to_text().split("\n")
    assert rec.agv_names() == [a.name for a in scenario.agvs]
    assert rec.topics()[keys.WORLD_TICK] == summary.ticks + 1  # ticks 0..K, K final


def test_the_recording_holds_the_run_facts_the_scenario_and_the_result(corridor):
    path, scenario, summary, _ = corridor
    rec = open_recording(path)
    run = rec.run
    assert run["run_id"] == "test-run"
    assert run["scenario"] == "corridor"
    assert run["parameters"] == {"mode": "in-process"}
    assert run["version"] and run["started_utc"].endswith("+00:00")
    assert rec.result == json.loads(json.dumps(summary.to_json()))
    again = parse_scenario(rec.scenario_text)
    assert rec.scenario_text == scenario.source
    assert (again.name, again.dt, again.time_limit) == (
        scenario.name,
        scenario.dt,
        scenario.time_limit,
    )
    assert again.agvs == scenario.agvs
    assert np.array_equal(again.grid.blocked, scenario.grid.blocked)
    with open(path, "rb") as f:
        (attachment,) = make_reader(f).iter_attachments()
    assert (attachment.name, attachment.media_type) == ("scenario.toml", "application/toml")


def _check(schema: dict, value, where: str) -> None:
    """Validate ``value`` against the subset of JSON Schema that json_schema() emits."""
    if "anyOf" in schema:
        errors = []
        for option in schema["anyOf"]:
            try:
                _check(option, value, where)
                return
            except AssertionError as err:
                errors.append(str(err))
        raise AssertionError(f"{where}: matches no anyOf option: {errors}")
    kind = schema["type"]
    python = {
        "object": dict,
        "array": list,
        "string": str,
        "boolean": bool,
        "null": type(None),
        "integer": int,
        "number": (int, float),
    }[kind]
    assert isinstance(value, python) and not (
        kind in ("integer", "number") and isinstance(value, bool)
    ), f"{where}: {value!r} is not {kind}"
    assert value in schema.get("enum", [value]), f"{where}: {value!r} is not a choice"
    if "minimum" in schema:
        assert value >= schema["minimum"], f"{where}: {value!r} is below the minimum"
    if kind == "object":
        assert set(schema["required"]) <= set(value), f"{where}: missing fields"
        assert set(value) <= set(schema["properties"]), f"{where}: extra fields"
        for name, item in value.items():
            _check(schema["properties"][name], item, f"{where}.{name}")
    elif kind == "array":
        for i, item in enumerate(value):
            _check(schema["items"], item, f"{where}[{i}]")


def test_every_channel_has_its_json_schema_and_every_message_validates(corridor):
    path = corridor[0]
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        seen = set()
        for schema, channel, message in reader.iter_messages():
            assert channel.message_encoding == "json"
            assert schema.encoding == "jsonschema"
            document = json.loads(schema.data)
            seen.add(channel.topic)
            if schema.name.startswith("foxglove."):  # Foxglove's schemas: test_foxglove.py
                continue
            cls = keys.message_type(channel.topic)
            assert document == json_schema(cls) and schema.name == cls.__name__
            assert document["$schema"] == "https://json-schema.org/draft/2020-12/schema"
            _check(document, json.loads(message.data), channel.topic)
    assert seen == {c.topic for c in summary.channels.values()}
    # one schema record per message type, shared by the channels of that type
    assert len(summary.schemas) == len({s.name for s in summary.schemas.values()})


def test_log_times_from_the_run_start_are_sim_times_so_two_recordings_line_up(tmp_path):
    record_run(tmp_path / "a.mcap")
    record_run(tmp_path / "b.mcap")
    first, second = open_recording(tmp_path / "a.mcap"), open_recording(tmp_path / "b.mcap")
    assert first.log_time_zero_ns != second.log_time_zero_ns  # two wall-clock starts

    def times(rec):
        return [(m.topic, m.log_time_ns - rec.log_time_zero_ns) for m in rec.records]

    assert times(first) == times(second)


def test_a_recording_cut_in_the_middle_keeps_its_complete_chunks(corridor, tmp_path):
    path = corridor[0]
    whole = open_recording(path)
    data = path.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    rec = open_recording(cut)
    assert rec.truncated and rec.result is None
    assert 0 < len(rec.records) < len(whole.records)
    assert [(m.topic, m.payload) for m in rec.records] == [
        (m.topic, m.payload) for m in whole.records[: len(rec.records)]
    ]
    assert "no footer" in rec.recovered_note
    assert f"{len(rec.records)} messages" in rec.recovered_note
    assert rec.scenario_text == whole.scenario_text  # written before the first chunk


def _writer_script(path: Path) -> str:
    """A recorder that writes AGV states until it is killed."""
    return textwrap.dedent(
        f"""
        from bridge.messages import AgvState
        from recordings.writer import RecordingWriter
        writer = RecordingWriter({str(path)!r}, scenario_name="s", scenario_text="", run_facts={{}})
        tick = 0
        while True:
            state = AgvState("agv1", tick, tick * 0.01, 0.5, 0.0, 0.1, 0.0, 0.0, 0.3)
            writer.write("agv/agv1/state", state, tick * 100_000_000)
            tick += 1
        """
    )


def test_a_recorder_killed_with_sigkill_leaves_every_completed_chunk_readable(tmp_path):
    path = tmp_path / "killed.mcap"
    child = subprocess.Popen([sys.executable, "-c", _writer_script(path)], cwd=REPO)
    try:
        deadline = time.monotonic() + 60
        while (not path.exists() or path.stat().st_size < 300_000) and child.poll() is None:
            assert time.monotonic() < deadline, "the recorder did not write"
            time.sleep(0.05)
    finally:
        os.kill(child.pid, signal.SIGKILL)
        child.wait()
    assert child.returncode == -signal.SIGKILL
    rec = open_recording(path)
    assert rec.truncated and rec.result is None
    ticks = [m.data["tick"] for m in rec.of("agv/agv1/state")]
    assert len(ticks) > 1000 and ticks == list(range(len(ticks)))  # no hole, no torn message
    assert rec.run["scenario"] == "s"


def test_a_quiet_writer_puts_its_chunk_on_disk_within_chunk_seconds(tmp_path):
    path = tmp_path / "quiet.mcap"
    writer = RecordingWriter(path, scenario_name="s", scenario_text="", run_facts={})
    try:
        for tick in range(3):
            writer.write(keys.agv_state("a"), AgvState("a", tick, 0, 0, 0, 0, 0, 0, 0.3), tick)
        time.sleep(CHUNK_SECONDS + 0.1)
        writer.flush_if_due()  # what a recorder idling on the bus calls
        on_disk = open_recording(path)
        assert on_disk.truncated and len(on_disk.records) == 3
    finally:
        writer.close()
    assert not open_recording(path).truncated


def test_an_undecodable_payload_is_counted_and_skipped(tmp_path):
    path = tmp_path / "bad.mcap"
    with RecordingWriter(path, scenario_name="s", scenario_text="", run_facts={}) as writer:
        writer.write_payload(keys.WORLD_EVENT, b'{"tick":1,"time":0.1,"kind":"end"}', 1)
        writer.write_payload(keys.WORLD_EVENT, b"not json", 2)
        writer.write_payload(keys.WORLD_EVENT, b"[1, 2]", 3)  # JSON but not a message
        writer.write_payload("custom/topic", b'{"any": "thing"}', 4)  # no message type
    rec = open_recording(path)
    assert [m.data["kind"] for m in rec.of(keys.WORLD_EVENT)] == ["end"]
    assert rec.of("custom/topic")[0].data == {"any": "thing"}
    assert rec.channels == {keys.WORLD_EVENT: "Event", "custom/topic": ""}
    assert rec.undecodable == 2 and len(rec.records) == 4


def test_a_file_that_is_not_mcap_or_missing_is_one_clear_error(tmp_path):
    text = tmp_path / "notes.mcap"
    text.write_text("hello, this is not a recording\n")
    with pytest.raises(RecordingError, match="not an MCAP recording"):
        open_recording(text)
    with pytest.raises(RecordingError, match="no such file"):
        open_recording(tmp_path / "missing.mcap")
    with pytest.raises(RecordingError, match="cannot read"):
        open_recording(tmp_path)


def test_default_recording_path_is_under_runs_with_scenario_and_utc_time(tmp_path):
    path = default_recording_path("paper temporary/1", tmp_path / "runs")
    assert path.parent == tmp_path / "runs" and path.parent.is_dir()
    assert path.name.startswith("paper_temporary_1-") and path.name.endswith("Z.mcap")


# --- the command line (needs fleet/cli.py to register fleet.cli.recordings) ----------
def agv_fleet(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "fleet.cli", *args],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.fixture(scope="module")
def truncated(corridor, tmp_path_factory):
    data = corridor[0].read_bytes()
    path = tmp_path_factory.mktemp("cut") / "cut.mcap"
    path.write_bytes(data[: len(data) * 2 // 3])
    return path


def test_cli_info_describes_a_recording(corridor):
    done = agv_fleet("info", str(corridor[0]))
    assert done.returncode == 0, done.stderr
    assert "corridor" in done.stdout and "success" in done.stdout
    assert "agv/left/command" in done.stdout and "AgvCommand" in done.stdout
    described = json.loads(agv_fleet("info", str(corridor[0]), "--json").stdout)
    assert described["agvs"] == ["left", "right"] and described["finished"]


def test_cli_info_and_analyze_recover_a_truncated_recording(truncated):
    info = agv_fleet("info", str(truncated))
    assert info.returncode == 0, info.stderr
    assert "did not finish (recording truncated)" in info.stdout
    assert "truncated" in info.stderr and "Traceback" not in info.stderr
    analysis = agv_fleet("analyze", str(truncated))
    assert analysis.returncode == 0, analysis.stderr
    assert "left" in analysis.stdout and "recording truncated" in analysis.stdout
    assert "truncated" in analysis.stderr


def test_cli_analyze_of_a_recording_cut_before_any_tick_is_one_line_and_exit_2(corridor, tmp_path):
    cut = tmp_path / "early.mcap"
    cut.write_bytes(corridor[0].read_bytes()[:3000])  # the header and metadata only
    analysis = agv_fleet("analyze", str(cut))
    assert analysis.returncode == 2 and analysis.stdout == ""
    assert len(analysis.stderr.strip().splitlines()) == 1, analysis.stderr
    assert "holds no AGV of a run to analyze (truncated" in analysis.stderr
    scenario = agv_fleet("info", str(cut), "--scenario")  # what was recorded is not lost
    assert scenario.returncode == 0 and "left" in scenario.stdout


def test_cli_bad_input_is_one_line_and_exit_2(tmp_path):
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"\x00" * 100)
    for args in (("info", str(junk)), ("analyze", str(tmp_path / "missing.mcap"))):
        done = agv_fleet(*args)
        assert done.returncode == 2
        assert done.stdout == "" and len(done.stderr.strip().splitlines()) == 1, done.stderr
